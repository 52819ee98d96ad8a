#!/usr/bin/env bash
# Runs one libFuzzer harness (tests/fuzz) for a bounded time and prints its figures:
# executions, executions per second, and the edges of firmware/ (core) or sil/src/scenario*.c
# (scenario) that the run covered (libFuzzer -print_coverage).
# Usage: tools/run_fuzz.sh core|scenario|console [seconds=60]
# Builds the fuzz tree (preset fuzz, clang) first. Exit 77 (skipped) if clang cannot build a
# libFuzzer binary (install clang and libclang-rt-14-dev: tools/install_deps.sh does).
# The committed corpus is copied, never written; what the run adds stays in build/fuzz/corpus-<name>.
set -euo pipefail
cd "$(dirname "$0")/.."
target=${1:?usage: run_fuzz.sh core|scenario|console [seconds]}
seconds=${2:-60}
case $target in
  core) prefix=firmware/src/ ;;
  scenario) prefix=sil/src/scenario ;;
  console) prefix=firmware/console/src/ ;;
  *) echo "run_fuzz: unknown fuzzer '$target'" >&2; exit 2 ;;
esac
sources=("$prefix"*.c) # what the figures count: the fuzzed module's own sources

probe=$(mktemp -d)
trap 'rm -rf "$probe"' EXIT
echo 'int LLVMFuzzerTestOneInput(const unsigned char *d, unsigned long n) { (void)d; (void)n; return 0; }' \
  > "$probe/probe.c"
if ! command -v clang >/dev/null 2>&1 || ! clang -fsanitize=fuzzer "$probe/probe.c" -o "$probe/probe" 2>/dev/null; then
  echo "run_fuzz: clang with libFuzzer not available: skipped"
  exit 77
fi

cmake --preset fuzz >/dev/null
cmake --build --preset fuzz -j2 >/dev/null

work=build/fuzz/corpus-$target
rm -rf "$work" build/fuzz/artifacts-$target
mkdir -p "$work" build/fuzz/artifacts-$target
cp tests/fuzz/corpus/$target/* "$work/"
log=build/fuzz/fuzz-$target.log
status=0
# -timeout: one input may take at most 10 s (a hang fails the run); -rss_limit_mb: memory bound.
build/fuzz/tests/fuzz/fuzz_$target -max_total_time="$seconds" -timeout=10 -rss_limit_mb=2048 \
  -print_final_stats=1 -print_coverage=1 -artifact_prefix=build/fuzz/artifacts-$target/ "$work" >"$log" 2>&1 \
  || status=$?
if [ $status -ne 0 ]; then
  # The report without the coverage dump that -print_coverage appends, then the failing input
  # itself, so that a run on a machine whose build tree is gone can still be reproduced.
  grep -v '^\(UN\)\?COVERED_\(FUNC\|PC\|MODULE\)' "$log" | tail -40
  for artifact in build/fuzz/artifacts-$target/*; do
    [ -f "$artifact" ] || continue
    echo "run_fuzz: $artifact ($(wc -c < "$artifact") bytes), base64:"
    base64 "$artifact" | head -c 16384
    echo
  done
  echo "run_fuzz: $target FAILED (exit $status); the input is in build/fuzz/artifacts-$target/"
  exit 1
fi
execs=$(sed -n 's/^stat::number_of_executed_units: *//p' "$log")
rate=$(sed -n 's/^stat::average_exec_per_sec: *//p' "$log")
# COVERED_FUNC: hits: H edges: c/t name file:line  (UNCOVERED_FUNC: no edges reached)
read -r covered total functions reached < <(awk -v src="$prefix" '
  /^(COVERED|UNCOVERED)_FUNC:/ && index($0, src) {
    split($0, f, "edges: "); split(f[2], e, "[/ ]");
    c += e[1]; t += e[2]; n++; if ($1 == "COVERED_FUNC:") r++
  }
  END { printf "%d %d %d %d\n", c, t, n, r }' "$log")
corpus=$(ls "$work" | wc -l)
echo "run_fuzz: $target: $execs executions in $seconds s ($rate/s), corpus $corpus inputs, no invariant broken;" \
     "functions of ${prefix}* reached: $reached of $functions"

# Line coverage of the final corpus (source-based, llvm-cov): the harness rebuilt without
# sanitizers (their checks are not source lines) and the replay driver.
llvm_cov=$(command -v llvm-cov || ls /usr/bin/llvm-cov-* 2>/dev/null | sort -V | tail -1 || true)
llvm_profdata=$(command -v llvm-profdata || ls /usr/bin/llvm-profdata-* 2>/dev/null | sort -V | tail -1 || true)
if [ -z "$llvm_cov" ] || [ -z "$llvm_profdata" ]; then
  echo "run_fuzz: llvm-cov not found: no line coverage"
  exit 0
fi
cov=build/fuzz-cov
cmake -S . -B "$cov" -G Ninja -DCMAKE_C_COMPILER=clang -DCMAKE_BUILD_TYPE=RelWithDebInfo \
  -DPMSTEP_FUZZ=ON -DPMSTEP_FUZZ_COVERAGE=ON >/dev/null
cmake --build "$cov" --target "fuzz_${target}_replay" >/dev/null
rm -f "$cov/replay-$target.profraw"
LLVM_PROFILE_FILE="$cov/replay-$target.profraw" "$cov/tests/fuzz/fuzz_${target}_replay" "$work" >/dev/null
"$llvm_profdata" merge -sparse "$cov/replay-$target.profraw" -o "$cov/replay-$target.profdata"
"$llvm_cov" report "$cov/tests/fuzz/fuzz_${target}_replay" -instr-profile="$cov/replay-$target.profdata" "${sources[@]}" \
  > "$cov/report-$target.txt"
awk -v t="$target" '$1 == "TOTAL" {
  printf "run_fuzz: %s: line coverage of the final corpus: %s of lines (%s missed of %s), regions %s, branches %s\n",
         t, $10, $9, $8, $4, $13 }' "$cov/report-$target.txt"
