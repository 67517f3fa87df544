#!/usr/bin/env bash
# Builds the fuzzers with clang, libFuzzer, AddressSanitizer and UndefinedBehaviorSanitizer
# against the project's own sources, then fuzzes every target for a share of SECONDS (default
# 60, CI's budget), each from a copy of its seeds in fuzz/corpus/<target>/ (the committed
# seeds never grow):
#   scene_fuzzer        scene YAML (Scene::FromYamlString)                          12/60
#   pipeline_fuzzer     pipeline YAML, parsed and built (runtime/pipeline.h)         7/60
#   hardware_fuzzer     hardware files, with the pipeline that names them            7/60
#   urdf_fuzzer         URDF text with Gazebo cameras (head::ParseUrdf)              7/60
#   head_fuzzer         legacy head descriptions (HeadDescription::FromYamlString)   6/60
#   head_model_fuzzer   head files of both formats (HeadModel::FromYamlString)       6/60
#   calibration_fuzzer  OpenCV YAML/XML and ROS CameraInfo files, read and re-read   6/60
#   command_fuzzer      the GUI protocol's command envelope (server/internal_command.h) 5/60
#   dynamixel_fuzzer    bytes from a servo bus in any split (hw/dynamixel_protocol.h)  4/60
#   mcap_fuzzer         MCAP recordings, cut short or damaged (record/mcap.h)         5/60
# Each fuzz/<target>.cc says what it checks beyond "no crash". Exits non-zero when a fuzzer
# finds a crash, a failed check, a sanitizer report, a leak or a hang; the reproducer is left
# in build-fuzz/ (crash-*, leak-*, timeout-*). Reproduce one with
#   build-fuzz/scene_fuzzer build-fuzz/crash-<hash>
#
# Usage: fuzz/run.sh [SECONDS]
#   SACCADE_FUZZ_TARGETS="head calibration"  runs only those targets (names without _fuzzer),
#                                            SECONDS shared among them by the same weights;
#   SACCADE_FUZZ_BUILD_ONLY=1                builds the fuzzers and stops.
# Needs (Debian 12): clang, libclang-rt-14-dev, libyaml-cpp-dev, libassimp-dev, libeigen3-dev,
# libfmt-dev, libpng-dev, libstb-dev, nlohmann-json3-dev, liburdfdom-dev, libtinyxml-dev,
# libzstd-dev; the
# scenes' assets (see scenes/portraits.yaml) are not needed: the seeds use robots/popeye.yaml and
# assimp-testmodels' small files when present.
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
# urdfdom (and the TinyXML 1 and console_bridge it reads and reports with): every target that
# compiles src/head/ (the URDF loader, issue 42).
libs=($(pkg-config --libs yaml-cpp assimp libpng fmt) -lstb -lurdfdom_model -ltinyxml
      -lconsole_bridge -lzstd -lz -lpthread)

# Each target: its sources, its weight in the time budget, its longest input.
declare -A target_sources target_weight target_max_len
core=(src/core/*.cc)
geometry=("${core[@]}" src/geometry/*.cc)
head=("${geometry[@]}" src/head/*.cc)
runtime=("${core[@]}" src/runtime/*.cc)
target_sources[scene]="${head[*]} src/scene/*.cc fuzz/scene_fuzzer.cc"
target_sources[pipeline]="${runtime[*]} fuzz/pipeline_fuzzer.cc"
target_sources[hardware]="${runtime[*]} fuzz/hardware_fuzzer.cc"
target_sources[head]="${head[*]} fuzz/head_fuzzer.cc"
target_sources[head_model]="${head[*]} fuzz/head_model_fuzzer.cc"
target_sources[urdf]="${head[*]} fuzz/urdf_fuzzer.cc"
target_sources[calibration]="${geometry[*]} fuzz/calibration_fuzzer.cc"
target_sources[command]="src/server/internal_command.cc fuzz/command_fuzzer.cc"
target_sources[dynamixel]="${core[*]} src/hw/dynamixel_protocol.cc fuzz/dynamixel_fuzzer.cc"
target_sources[mcap]="${core[*]} src/record/*.cc fuzz/mcap_fuzzer.cc"
target_weight=([scene]=12 [pipeline]=7 [hardware]=7 [urdf]=7 [head]=6 [head_model]=6
               [calibration]=6 [command]=5 [dynamixel]=4 [mcap]=5)
# The URDF and head-file seeds are the shipped heads (humanoid.urdf is 9 KB).
target_max_len=([scene]=4096 [pipeline]=4096 [hardware]=4096 [urdf]=16384 [head]=4096
                [head_model]=8192 [calibration]=4096 [command]=1024 [dynamixel]=1024
                [mcap]=16384)
all_targets=(scene pipeline hardware urdf head head_model calibration command dynamixel mcap)
read -r -a targets <<< "${SACCADE_FUZZ_TARGETS:-${all_targets[*]}}"
for target in "${targets[@]}"; do
  if [[ -z "${target_weight[$target]:-}" ]]; then
    echo "fuzz: unknown target '$target' (known: ${all_targets[*]})" >&2
    exit 2
  fi
done

# Compile each source once, again only when it or any header changed since.
declare -A seen
sources=()
for target in "${targets[@]}"; do
  for source in ${target_sources[$target]}; do
    if [[ -z "${seen[$source]:-}" ]]; then
      seen[$source]=1
      sources+=("$source")
    fi
  done
done
newest_header="$(find include src fuzz -name '*.h' -printf '%T@ %p\n' | sort -n | tail -1 |
                 cut -d' ' -f2)"
object_of() { echo "$out/obj/$(echo "$1" | tr '/' '_').o"; }
stale=()
for source in "${sources[@]}"; do
  object="$(object_of "$source")"
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
for target in "${targets[@]}"; do
  objects=()
  for source in ${target_sources[$target]}; do objects+=("$(object_of "$source")"); done
  "$cxx" -fsanitize=fuzzer,address,undefined "${objects[@]}" "${libs[@]}" \
    -o "$out/${target}_fuzzer"
done
if [[ -n "${SACCADE_FUZZ_BUILD_ONLY:-}" ]]; then
  echo "fuzz: built ${targets[*]} in $out"
  exit 0
fi

# Shares of the budget by weight, at least 1 s each.
total_weight=0
for target in "${targets[@]}"; do total_weight=$((total_weight + target_weight[$target])); done
# The fuzzers that write files (hardware, calibration: the readers take paths, and the
# calibration writers fsync) write them in memory when /dev/shm is there.
scratch="${TMPDIR:-/tmp}"
[[ -d /dev/shm && -w /dev/shm ]] && scratch=/dev/shm
work="$(mktemp -d "$scratch/saccade-fuzz.XXXXXX")"
trap 'rm -rf "$work"' EXIT
for target in "${targets[@]}"; do
  share=$((seconds * target_weight[$target] / total_weight))
  ((share >= 1)) || share=1
  # Fuzz a copy of the seeds: new inputs go to the copy, never into the repository.
  corpus="$work/corpus-$target"
  mkdir -p "$corpus"
  if [[ -d "fuzz/corpus/$target" ]]; then cp "fuzz/corpus/$target/"* "$corpus/" 2>/dev/null || true; fi
  dict=()
  [[ -f "fuzz/$target.dict" ]] && dict=(-dict="fuzz/$target.dict")
  echo "fuzz: $target, ${share}s over $(ls "$corpus" | wc -l) seeds"
  status=0
  TMPDIR="$work" SACCADE_FUZZ_BASE_DIR="$root/scenes" SACCADE_FUZZ_ROBOTS_DIR="$root/robots" \
    "$out/${target}_fuzzer" \
    -max_total_time="$share" -timeout=10 -rss_limit_mb=4096 -max_len="${target_max_len[$target]}" \
    "${dict[@]}" -artifact_prefix="$out/" -print_final_stats=1 "$corpus" || status=$?
  if ((status != 0)); then
    echo "fuzz: $target FAILED (status $status); reproducer in $out/" >&2
    exit "$status"
  fi
done
echo "fuzz: no crash in ${seconds}s (${targets[*]})"
