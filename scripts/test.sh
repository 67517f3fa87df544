#!/usr/bin/env bash
# The README's second command: set up, build, and run every test.
# With CI=true, warnings are errors and the unit tests run once more under ASan and UBSan.
set -euo pipefail
cd "$(dirname "$0")/.."
jobs=$(nproc)

bash scripts/setup.sh build
echo "== tests (build/)"
ctest --test-dir build --output-on-failure -j "$jobs" --timeout 600

if [ "${CI:-}" = "true" ] || [ "${SACCADE_SANITIZE:-}" = "1" ]; then
  echo "== unit tests under AddressSanitizer + UndefinedBehaviorSanitizer (build-asan/)"
  bash scripts/setup.sh build-asan -DSACCADE_SANITIZE=ON -DSACCADE_BUILD_BENCH=OFF \
    -DCMAKE_BUILD_TYPE=Debug
  ASAN_OPTIONS=detect_leaks=1:abort_on_error=0 UBSAN_OPTIONS=print_stacktrace=1 \
    ctest --test-dir build-asan --output-on-failure -j "$jobs" -L unit --timeout 900
fi
