#!/bin/sh
# Builds one libFuzzer driver with coverage instrumentation (stable rustc: the sancov pass and
# LLVM options, no sanitizer) and runs it for SECONDS from the committed corpus.
#
#   fuzz/libfuzzer/run.sh TARGET [SECONDS] [libFuzzer options ...]
#
# New inputs go to fuzz/libfuzzer/corpus-run/TARGET (not committed; copy the interesting ones
# into fuzz/corpus/TARGET), crashes to fuzz/libfuzzer/artifacts/TARGET/. Targets: the names of
# kerf_fuzz::TARGETS (fuzz/libfuzzer/fuzz_targets/). CARGO_BUILD_JOBS limits the build's jobs.
set -eu
here=$(cd "$(dirname "$0")" && pwd)
target=${1:?usage: run.sh TARGET [SECONDS] [libFuzzer options ...]}
seconds=${2:-300}
[ $# -ge 2 ] && shift 2 || shift 1
host=$(rustc -vV | sed -n 's/^host: //p')
export CARGO_TARGET_DIR="${CARGO_TARGET_DIR:-$here/target}"
RUSTFLAGS="-Cpasses=sancov-module \
  -Cllvm-args=-sanitizer-coverage-level=4 \
  -Cllvm-args=-sanitizer-coverage-inline-8bit-counters \
  -Cllvm-args=-sanitizer-coverage-pc-table \
  -Cllvm-args=-sanitizer-coverage-trace-compares \
  --cfg fuzzing -Cdebug-assertions -Coverflow-checks" \
  cargo build --release --manifest-path "$here/Cargo.toml" --target "$host" --bin "$target"
mkdir -p "$here/corpus-run/$target" "$here/artifacts/$target"
exec "$CARGO_TARGET_DIR/$host/release/$target" -max_total_time="$seconds" -timeout=10 \
  -rss_limit_mb=2048 -print_final_stats=1 \
  -artifact_prefix="$here/artifacts/$target/" "$@" "$here/corpus-run/$target" "$here/../corpus/$target"
