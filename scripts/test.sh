#!/usr/bin/env bash
# The README's second command: set up, build, and run every test.
# Warnings are errors (scripts/setup.sh). With CI=true: the first command's unity build of the
# programs (build-program/, as scripts/demo.sh builds them), every libFuzzer target (fuzz/run.sh:
# scene, pipeline, hardware, head, calibration, GUI command, Dynamixel parser) is fuzzed
# briefly, and the unit tests run a second time under AddressSanitizer and
# UndefinedBehaviorSanitizer (build-asan/, which builds the unit tier only). Each phase's wall
# time is printed as it ends, and all of them at the end, also when a phase fails. Compiles go
# through ccache (scripts/setup.sh).
set -euo pipefail
cd "$(dirname "$0")/.."
jobs=$(nproc)
ci=false
[ "${CI:-}" = "true" ] && ci=true

phases=()
phase_start=$(date +%s)
run_start=$phase_start
current=""
begin() {
  current="$1"
  phase_start=$(date +%s)
  echo "== $1"
}
end() {
  local took=$(($(date +%s) - phase_start))
  phases+=("$(printf '%-50s %4d:%02d' "$current" $((took / 60)) $((took % 60)))")
  echo "== $current: $((took / 60)) min $((took % 60)) s"
  current=""
}
cache_figures() {
  if command -v ccache >/dev/null; then
    ccache --print-stats 2>/dev/null | awk -F'\t' '
      $1 == "direct_cache_hit" || $1 == "preprocessed_cache_hit" { hits += $2 }
      $1 == "cache_miss" { misses += $2 }
      END { if (hits + misses > 0) printf "ccache (all runs so far): %d hits, %d misses\n", hits, misses }'
  fi
}
summary() {
  local status=$1
  [ -n "$current" ] && end
  local took=$(($(date +%s) - run_start))
  echo
  echo "== phases (wall clock, min:s)"
  for p in "${phases[@]}"; do echo "  $p"; done
  printf '  %-50s %4d:%02d\n' "total" $((took / 60)) $((took % 60))
  if [ "$status" -ne 0 ]; then
    echo "== FAILED (status $status) in: ${failed_phase:-?}"
  fi
  # ctest's closing line once more, last, for whoever reads the end of the log.
  if [ -s "${results:-}" ]; then grep -E "tests passed|tests failed out of" "$results" | tail -1; fi
  return "$status"
}
trap 'status=$?; failed_phase="$current"; summary "$status"' EXIT

begin "setup and build (build/)"
bash scripts/setup.sh build
cache_figures
end

if $ci; then
  # The first command's build (scripts/setup.sh --program): a unity build, 8 sources a compile,
  # where names in anonymous namespaces must differ between a library's sources (CMakeLists.txt).
  # Compiled here so that a clash fails CI, not a newcomer's first command.
  begin "the first command's unity build (build-program/)"
  cmake -S . -B build-program -G Ninja -DSACCADE_WERROR=ON -DSACCADE_PROGRAM_ONLY=ON >/dev/null
  cmake --build build-program --target saccade saccade-servo-emulator
  cache_figures
  end
fi

if $ci || [ "${SACCADE_FUZZ:-}" = "1" ]; then
  begin "fuzzing: ten targets (libFuzzer, ${SACCADE_FUZZ_SECONDS:-60} s)"
  bash fuzz/run.sh "${SACCADE_FUZZ_SECONDS:-60}"
  end
fi

if $ci || [ "${SACCADE_SANITIZE:-}" = "1" ]; then
  begin "ASan+UBSan build of the unit tier (build-asan/)"
  # -O1, as sanitizers are usually run: at -O0 the Eigen-heavy lens-map tests took 100-230 s
  # each under ASan (less than 1 s at -O2), at -O1 about 20 times less; asserts stay on (Debug).
  SACCADE_BUILD_TARGET=tests_unit bash scripts/setup.sh build-asan -DSACCADE_SANITIZE=ON \
    -DSACCADE_BUILD_BENCH=OFF -DCMAKE_BUILD_TYPE=Debug "-DCMAKE_CXX_FLAGS_DEBUG=-g -O1" \
    -DSACCADE_TEST_TIERS=unit
  cache_figures
  end
  begin "unit tests under ASan+UBSan"
  ASAN_OPTIONS=detect_leaks=1 UBSAN_OPTIONS=print_stacktrace=1 \
    ctest --test-dir build-asan --output-on-failure -j "$jobs" -L unit --timeout 900
  end
fi

begin "all tests (build/)"
results=build/ctest-all.log
ctest --test-dir build --output-on-failure -j "$jobs" --timeout 900 2>&1 | tee "$results"
end
