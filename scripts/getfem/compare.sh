#!/usr/bin/env bash
# Runs disc.py and `signorini run disc` for the given cases and prints the relative column of
# `signorini compare` (max|Δ| / max|GetFEM|) as a Markdown table. GetFEM's series are cached:
# an existing $OUT/getfem-*.csv is reused.
#
#   scripts/getfem/compare.sh MESH OUT SIGNORINI CASE...
#
# CASE is scheme:contact:theta, with scheme newmark|hht|midpoint|trbdf2 (hht with alpha = 0.05),
# contact nitsche|nitsche-normal|penalty (disc.py's names; signorini runs nitsche-traction,
# nitsche and penalty for them) and theta 1|0|-1 (ignored by penalty). Example:
#
#   scripts/getfem/compare.sh disc_r10_h1_v22.msh /tmp/gf target/release/signorini \
#       newmark:nitsche-normal:1 trbdf2:penalty:1
#
# MATERIAL=neo_hookean runs forms/neo_hookean.wf on both sides (disc.py --material neo_hookean
# --polish 1, signorini --material neo_hookean); its series are named getfem-nh-*, ours-nh-*.
set -euo pipefail
mesh=$1 out=$2 signorini=$3
shift 3
here=$(dirname "$0")
material=${MATERIAL:-elasticity}
case $material in
    elasticity) tag="" gf_material=() ours_material=() ;;
    neo_hookean) tag="nh-" gf_material=(--material neo_hookean --polish 1) ours_material=(--material neo_hookean) ;;
    *) echo "unknown material $material" >&2; exit 2 ;;
esac
mkdir -p "$out"
echo "| scheme | law | θ | energy | energy_aug | uy_mean_nodal | fy_contact |"
echo "|---|---|---|---|---|---|---|"
for case in "$@"; do
    IFS=: read -r scheme contact theta <<<"$case"
    name="$tag$scheme-$contact-t$theta"
    gf_args=(--scheme "$scheme" --contact "$contact" --theta "$theta")
    ours_args=(--scheme "$scheme" --param "theta=$theta")
    case $contact in
        nitsche) ours_args+=(--contact nitsche-traction) ;;
        nitsche-normal) ours_args+=(--contact nitsche) ;;
        penalty) ours_args=(--scheme "$scheme" --contact penalty) ;;
        *) echo "unknown contact law $contact" >&2; exit 2 ;;
    esac
    if [ "$scheme" = hht ]; then
        gf_args+=(--alpha 0.05)
        ours_args+=(--param alpha=0.05)
    fi
    if [ ! -s "$out/getfem-$name.csv" ]; then
        /usr/bin/python3 "$here/disc.py" --mesh "$mesh" "${gf_args[@]}" ${gf_material[@]+"${gf_material[@]}"} --out "$out/getfem-$name.csv.tmp" 2>/dev/null
        mv "$out/getfem-$name.csv.tmp" "$out/getfem-$name.csv"
    fi
    "$signorini" run disc "${ours_args[@]}" ${ours_material[@]+"${ours_material[@]}"} --cell-size getfem --mesh "$mesh" --t-end 20 --out "$out/ours-$name" >/dev/null
    rel() { awk -v c="$1" '$1 == c { print $3 }' <<<"$cmp"; }
    cmp=$("$signorini" compare "$out/getfem-$name.csv" "$out/ours-$name")
    echo "| $scheme | $contact | $theta | $(rel energy) | $(rel energy_aug) | $(rel uy_mean_nodal) | $(rel fy_contact) |"
done
