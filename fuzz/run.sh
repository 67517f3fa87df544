#!/usr/bin/env bash
# Builds the fuzzers with clang, libFuzzer, AddressSanitizer and UndefinedBehaviorSanitizer
# against the project's own sources, then fuzzes for SECONDS in all (default 60):
#   scene_fuzzer      scene YAML (fuzz/scene_fuzzer.cc), three quarters of the time, from a
#                     copy of fuzz/corpus/scene (the committed seeds never grow);
#   dynamixel_fuzzer  bytes from a servo bus in any split (fuzz/dynamixel_fuzzer.cc), the rest.
# Exits non-zero when the fuzzer finds a crash, a sanitizer report, a leak or a hang; the
# reproducer is left in build-fuzz/ (crash-*, leak-*, timeout-*). Reproduce one with
#   build-fuzz/scene_fuzzer build-fuzz/crash-<hash>
#
# Usage: fuzz/run.sh [SECONDS]
# Needs (Debian 12): clang, libclang-rt-14-dev, libyaml-cpp-dev, libassimp-dev, libeigen3-dev,
# libfmt-dev, libpng-dev, libstb-dev; the scenes' assets (see scenes/portraits.yaml) are not
# needed: the seeds use robots/popeye.yaml and assimp-testmodels' small files when present.
set -euo pipefail

seconds="${1:-60}"
if ! [[ "$seconds" =~ ^[0-9]+$ ]]; then
  echo "usage: $0 [SECONDS]" >&2
  exit 2
fi
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
out="${SACCADE_FUZZ_BUILD:-$root/build-fuzz}"
cxx="${CXX_FUZZ:-clang++}"
mkdir -p "$out/obj"
cd "$root"

flags=(-std=c++20 -O1 -g -fno-omit-frame-pointer
       -fsanitize=fuzzer-no-link,address,undefined -fno-sanitize-recover=all
       -Iinclude -Isrc -I/usr/include/stb
       $(pkg-config --cflags eigen3 libpng))
libs=($(pkg-config --libs yaml-cpp assimp libpng fmt) -lstb -lpthread)

# Compile each source once, again only when it or any header changed since.
scene_sources=(src/core/*.cc src/geometry/*.cc src/head/*.cc src/scene/*.cc fuzz/scene_fuzzer.cc)
dxl_sources=(src/core/*.cc src/hw/dynamixel_protocol.cc fuzz/dynamixel_fuzzer.cc)
sources=("${scene_sources[@]}" src/hw/dynamixel_protocol.cc fuzz/dynamixel_fuzzer.cc)
newest_header="$(find include src -name '*.h' -printf '%T@ %p\n' | sort -n | tail -1 | cut -d' ' -f2)"
objects=()
stale=()
for source in "${sources[@]}"; do
  object="$out/obj/$(echo "$source" | tr '/' '_').o"
  objects+=("$object")
  if [[ ! -f "$object" || "$source" -nt "$object" || "$newest_header" -nt "$object" ]]; then
    stale+=("$source")
  fi
done
if ((${#stale[@]} > 0)); then
  echo "fuzz: compiling ${#stale[@]} sources with $cxx"
  # Through ccache when it is there (paths are relative to the repository, so a fresh clone
  # hits the cache of an earlier one).
  compile="$cxx"
  if command -v ccache >/dev/null; then
    compile="ccache $cxx"
    export CCACHE_BASEDIR="$root" CCACHE_NOHASHDIR=true
  fi
  export FLAGS="${flags[*]}" OUT="$out" CXX_FUZZ="$compile"
  printf '%s\n' "${stale[@]}" | xargs -P 2 -I{} sh -c \
    '$CXX_FUZZ $FLAGS -c "$1" -o "$OUT/obj/$(echo "$1" | tr / _).o"' _ {}
fi
objects_of() {
  for source in "$@"; do echo "$out/obj/$(echo "$source" | tr '/' '_').o"; done
}
"$cxx" -fsanitize=fuzzer,address,undefined $(objects_of "${scene_sources[@]}") "${libs[@]}" \
  -o "$out/scene_fuzzer"
"$cxx" -fsanitize=fuzzer,address,undefined $(objects_of "${dxl_sources[@]}") "${libs[@]}" \
  -o "$out/dynamixel_fuzzer"
dxl_seconds=$((seconds / 4))
scene_seconds=$((seconds - dxl_seconds))

# Fuzz a copy of the seeds: new inputs go to the copy, never into the repository.
corpus="$(mktemp -d "${TMPDIR:-/tmp}/saccade-scene-corpus.XXXXXX")"
trap 'rm -rf "$corpus"' EXIT
cp fuzz/corpus/scene/* "$corpus/"
echo "fuzz: scene files, ${scene_seconds}s over $(ls "$corpus" | wc -l) seeds"
status=0
SACCADE_FUZZ_BASE_DIR="$root/scenes" "$out/scene_fuzzer" \
  -max_total_time="$scene_seconds" -timeout=10 -rss_limit_mb=4096 -max_len=4096 \
  -dict=fuzz/scene.dict -artifact_prefix="$out/" -print_final_stats=1 \
  "$corpus" || status=$?
if ((status != 0)); then
  echo "fuzz: scene files FAILED (status $status); reproducer in $out/" >&2
  exit "$status"
fi
echo "fuzz: servo bus bytes, ${dxl_seconds}s"
dxl_corpus="$(mktemp -d "${TMPDIR:-/tmp}/saccade-dxl-corpus.XXXXXX")"
trap 'rm -rf "$corpus" "$dxl_corpus"' EXIT
"$out/dynamixel_fuzzer" -max_total_time="$dxl_seconds" -timeout=10 -rss_limit_mb=4096 \
  -max_len=1024 -artifact_prefix="$out/" -print_final_stats=1 "$dxl_corpus" || status=$?
if ((status != 0)); then
  echo "fuzz: servo bus bytes FAILED (status $status); reproducer in $out/" >&2
  exit "$status"
fi
echo "fuzz: no crash in ${seconds}s"
