#!/usr/bin/env bash
# Runs the libFuzzer target on the stable toolchain (cargo-fuzz itself needs nightly): builds
# with the SanitizerCoverage passes cargo-fuzz would add, seeds the corpus with the form
# library, and fuzzes for $1 seconds (default 300). Crashes land in ./artifacts.
set -euo pipefail
cd "$(dirname "$0")"
export RUSTFLAGS="-Cpasses=sancov-module -Cllvm-args=-sanitizer-coverage-level=4 \
 -Cllvm-args=-sanitizer-coverage-inline-8bit-counters -Cllvm-args=-sanitizer-coverage-pc-table \
 -Cllvm-args=-sanitizer-coverage-trace-compares --cfg fuzzing -Cdebug-assertions"
target=$(rustc -vV | sed -n 's/^host: //p')
cargo build --release --target "$target" --bin check
mkdir -p corpus/check artifacts
cp ../../forms/*.wf ../../forms/schemes/*.wf corpus/check/
"./target/$target/release/check" corpus/check -artifact_prefix=artifacts/ -max_total_time="${1:-300}" -max_len=4096
