#!/usr/bin/env bash
# The README's second command: set up, build, and run every test.
# With CI=true: warnings are errors, the scene loader is fuzzed briefly (libFuzzer), and the
# unit tests run once more under AddressSanitizer and UndefinedBehaviorSanitizer.
set -euo pipefail
cd "$(dirname "$0")/.."
jobs=$(nproc)
ci=false
[ "${CI:-}" = "true" ] && ci=true

bash scripts/setup.sh build

if $ci || [ "${SACCADE_FUZZ:-}" = "1" ]; then
  echo "== scene loader fuzzing (libFuzzer, ${SACCADE_FUZZ_SECONDS:-60} s over fuzz/corpus/scene)"
  bash fuzz/run.sh "${SACCADE_FUZZ_SECONDS:-60}"
fi

if $ci || [ "${SACCADE_SANITIZE:-}" = "1" ]; then
  echo "== unit tests under AddressSanitizer + UndefinedBehaviorSanitizer (build-asan/)"
  bash scripts/setup.sh build-asan -DSACCADE_SANITIZE=ON -DSACCADE_BUILD_BENCH=OFF \
    -DCMAKE_BUILD_TYPE=Debug
  ASAN_OPTIONS=detect_leaks=1 UBSAN_OPTIONS=print_stacktrace=1 \
    ctest --test-dir build-asan --output-on-failure -j "$jobs" -L unit --timeout 900
fi

echo "== all tests (build/)"
ctest --test-dir build --output-on-failure -j "$jobs" --timeout 900
