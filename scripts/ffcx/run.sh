#!/usr/bin/env bash
# FFCx's neo-Hookean tangent on P2 triangles, timed per cell by harness.c (the kernel alone, and
# with what DOLFINx's assemble_matrix does per cell: gather, kernel, CSR add), at the quadrature
# degrees `signorini bench assemble` times ours at. Optional tooling: CI does not run it.
#   scripts/ffcx/run.sh [VENV] [N]   (VENV with fenics-ffcx installed; N×N squares, 2N² cells)
set -euo pipefail
here="$(cd "$(dirname "$0")" && pwd)"
venv="${1:-/tmp/ffcx-venv}"
n="${2:-300}"
work="$(mktemp -d)"
include="$(find "$venv" -name ufcx.h -printf '%h\n' | head -1)"
cd "$work"
for degree in 2 4 6; do
  mkdir "q$degree" && cp "$here/nh2d.py" "q$degree/" && (cd "q$degree" && CELL=triangle QDEG=$degree "$venv/bin/python" -m ffcx nh2d.py)
  kernel="$(grep -o 'tabulate_tensor_integral_[0-9a-f]*_triangle' "q$degree/nh2d.c" | head -1)"
  gcc -O2 -I"$include" -DTDIM=2 -DKERNEL="$kernel" "$here/harness.c" "q$degree/nh2d.c" -lm -o "bench$degree"
  echo "degree $degree:"
  "./bench$degree" "$n" 5
done
