#!/usr/bin/env bash
# Sets up a Debian 12 machine for saccade and builds it. Idempotent: installs only the Debian
# packages that are missing (apt-get update runs only then), reconfigures only what changed.
#
#   bash scripts/setup.sh [BUILD_DIR] [extra cmake args...]
#
# Runs as root (or through sudo when it is there). Nothing is downloaded at run time: every
# asset comes from these packages.
set -euo pipefail
cd "$(dirname "$0")/.."

packages=(
  # toolchain
  g++ cmake ninja-build pkg-config clang-format
  # libraries (README lists what each is for)
  libeigen3-dev libyaml-cpp-dev nlohmann-json3-dev libcli11-dev libfmt-dev libspdlog-dev
  libopencv-core-dev libopencv-imgproc-dev libopencv-calib3d-dev libopencv-imgcodecs-dev
  libopencv-objdetect-dev libopencv-video-dev libopencv-features2d-dev
  # tests and benchmarks
  libgtest-dev libgmock-dev libbenchmark-dev
  # reference data: OpenCV's sample calibration files
  opencv-doc
)

missing=()
for p in "${packages[@]}"; do
  if ! dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed"; then
    missing+=("$p")
  fi
done
if ((${#missing[@]})); then
  sudo=""
  if [ "$(id -u)" -ne 0 ]; then
    command -v sudo >/dev/null || { echo "setup: run as root to install: ${missing[*]}" >&2; exit 1; }
    sudo=sudo
  fi
  echo "setup: installing ${#missing[@]} Debian packages: ${missing[*]}"
  $sudo apt-get update -qq
  DEBIAN_FRONTEND=noninteractive $sudo apt-get install -y -qq --no-install-recommends "${missing[@]}"
else
  echo "setup: all ${#packages[@]} Debian packages present"
fi

build_dir="${1:-build}"
shift || true
werror=OFF
[ "${CI:-}" = "true" ] && werror=ON
cmake -S . -B "$build_dir" -G Ninja -DSACCADE_WERROR="$werror" "$@" >/dev/null
cmake --build "$build_dir"
