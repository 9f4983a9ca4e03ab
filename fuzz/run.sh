#!/usr/bin/env bash
# Runs a libFuzzer target on the stable toolchain (cargo-fuzz itself needs nightly), built with
# the SanitizerCoverage passes cargo-fuzz would add. Usage: fuzz/run.sh TARGET [seconds]
# (TARGET: gmsh or case_file; default 300 s). Seeds are copied in at run time from the repository's
# meshes; crashes land in ./artifacts/TARGET.
set -euo pipefail
cd "$(dirname "$0")"
name=${1:?usage: run.sh gmsh|case_file [seconds]}
export RUSTFLAGS="-Cpasses=sancov-module -Cllvm-args=-sanitizer-coverage-level=4 \
 -Cllvm-args=-sanitizer-coverage-inline-8bit-counters -Cllvm-args=-sanitizer-coverage-pc-table \
 -Cllvm-args=-sanitizer-coverage-trace-compares --cfg fuzzing -Cdebug-assertions"
target=$(rustc -vV | sed -n 's/^host: //p')
cargo build --release --target "$target" --bin "$name"
mkdir -p "corpus/$name" "artifacts/$name"
case $name in
  gmsh)
    cp ../assets/meshes/*.msh ../runtime/tests/*.msh ../runtime/tests/gmsh_bad/*.msh "corpus/$name/" 2>/dev/null || true
    max_len=131072 ;;
  case_file)
    cp ../examples/*.toml "corpus/$name/"
    max_len=4096 ;;
  *) echo "unknown target $name" >&2; exit 2 ;;
esac
"${CARGO_TARGET_DIR:-target}/$target/release/$name" "corpus/$name" -artifact_prefix="artifacts/$name/" \
  -max_total_time="${2:-300}" -max_len="$max_len" -timeout=10 -rss_limit_mb=2048
