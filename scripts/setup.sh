#!/usr/bin/env bash
# Sets up a Debian 12 machine for saccade and builds it. Idempotent: installs only the Debian
# packages that are missing (apt-get update runs only then), reconfigures only what changed.
#
#   bash scripts/setup.sh [--program] [BUILD_DIR] [extra cmake args...]
#
# --program (the README's first command, scripts/demo.sh): only what the programs need, to build
#   and run them: their Debian packages, the GUI's three.js (fetched from the npm registry without
#   Node.js), and the targets saccade and saccade-servo-emulator, without debug information, as a
#   unity build (CMakeLists.txt). The tests' packages (Chromium, clang,
#   GoogleTest, Python's, reference data ...) and targets come with the full setup (the second
#   command, scripts/test.sh).
# SACCADE_BUILD_TARGET=T builds only target T (e.g. tests_unit) instead of everything.
#
# Runs as root (or through sudo when it is there). Nothing is downloaded at run time: every
# asset comes from these packages.
set -euo pipefail
cd "$(dirname "$0")/.."

program_only=false
if [ "${1:-}" = "--program" ]; then
  program_only=true
  shift
fi

packages=(
  # toolchain
  g++ cmake ninja-build pkg-config
  # the compiler cache (its directory, ~/.cache/ccache, lies outside the clone, so a fresh clone
  # builds warm after any earlier build on the machine)
  ccache
  # libraries (README lists what each is for)
  libeigen3-dev libyaml-cpp-dev nlohmann-json3-dev libcli11-dev libfmt-dev libspdlog-dev
  libopencv-core-dev libopencv-imgproc-dev libopencv-calib3d-dev libopencv-imgcodecs-dev
  libopencv-objdetect-dev libopencv-video-dev libopencv-videoio-dev libopencv-features2d-dev
  libassimp-dev libpng-dev libstb-dev libepoxy-dev libegl-dev libgl-dev libmeshoptimizer-dev
  # the browser GUI's HTTP and WebSocket server (Boost.Beast and Boost.Asio, header-only)
  libboost-dev
  # IIDC (IEEE 1394) cameras for the real head (optional: hw builds without it); GStreamer's
  # base elements (appsink, videoconvert, videotestsrc) for gstreamer: camera sources and tests
  libdc1394-dev gstreamer1.0-plugins-base
  # OpenGL without a display or GPU: Mesa's EGL and llvmpipe
  libegl-mesa0 libgl1-mesa-dri
  # demo assets: MuJoCo's mug, Assimp's test models (the scenes' duck, cube and truck; broken
  # ones besides, for the tests); OpenCV's trained Haar cascades (faces, eyes, cat faces) for the
  # perception loop
  libmujoco-samples assimp-testmodels opencv-data
  # DDS beyond one process (ROS 2's wire): Cyclone DDS's C library (cyclonedds-dev), its IDL
  # compiler idlc and ddsperf, for the transport benchmark (cyclonedds-tools)
  cyclonedds-dev cyclonedds-tools
  # any robot head from its URDF (issue 42): urdfdom parses URDF (it brings TinyXML, which also
  # reads the URDF's <gazebo> camera blocks, and console_bridge, which carries its messages)
  liburdfdom-dev
  # recordings in MCAP (issue 43): zstd chunk compression, zlib's CRC-32
  libzstd-dev zlib1g-dev
  # the world map of exploration (issue 44): OctoMap's occupancy octree (occupied, free and
  # unknown space; two packages, where Open3D brings 79 and PCL 508)
  liboctomap-dev
)
# What the tests, benchmarks and the Python package add (the full setup only).
test_packages=(
  # the code's format (.clang-format), for whoever changes the code
  clang-format
  # tests, benchmarks, the scene fuzzer (clang's libFuzzer)
  libgtest-dev libgmock-dev libbenchmark-dev clang libclang-rt-14-dev
  # the browser tests of the GUI: Debian's Chromium, driven by playwright-core (npm)
  chromium
  # reference data: OpenCV's sample calibration files
  opencv-doc
  # the Python package (docs/python.md): pybind11 bindings for Debian's /usr/bin/python3, numpy
  # arrays, its tests under pytest
  pybind11-dev python3-numpy python3-pytest python3-dev
  # what Gymnasium needs besides numpy (../shared/third_party/gymnasium, for the envs' tests:
  # tests/python/gymnasium_test.py)
  python3-cloudpickle python3-typing-extensions
  # the reference of the Python tests for the camera model (cv2.projectPoints)
  python3-opencv
  # the reference of the kinematics tests for any head: Orocos KDL's forward kinematics and
  # Jacobians; urdfdom's check_urdf for the shipped heads' URDF files
  liborocos-kdl-dev liburdfdom-tools
)
if ! $program_only; then
  packages+=("${test_packages[@]}")
fi

# Node.js and npm install the GUI's three.js and the browser tests' playwright-core (web/):
# Debian's packages, unless a Node.js with npm is already there. --program needs neither (npm
# and its Debian dependencies are 300-odd packages): it fetches three.js from the npm registry
# with curl, checked against the lock file as npm ci checks it (below).
if $program_only; then
  packages+=(curl)
elif ! command -v npm >/dev/null || ! command -v node >/dev/null; then
  packages+=(nodejs npm)
fi

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

# Demo assets into assets/ (gitignored): the portraits astronaut.png and chelsea.png from
# python3-skimage's data folder (unpacked from the .deb: the package itself would pull in
# SciPy), and MuJoCo's mug.
mkdir -p assets
if [ ! -s assets/astronaut.png ] || [ ! -s assets/chelsea.png ]; then
  echo "setup: unpacking the portraits from python3-skimage into assets/"
  tmp=$(mktemp -d)
  chmod 755 "$tmp"  # apt's sandbox user must be able to write the download
  if ! (cd "$tmp" && apt-get download -qq python3-skimage 2>/dev/null); then
    apt-get update -qq
    (cd "$tmp" && apt-get download -qq python3-skimage)
  fi
  dpkg-deb -x "$tmp"/python3-skimage_*.deb "$tmp/x"
  for f in astronaut.png chelsea.png; do
    cp "$tmp/x/usr/lib/python3/dist-packages/skimage/data/$f" "assets/.$f.tmp"
    mv "assets/.$f.tmp" "assets/$f"
  done
  rm -rf "$tmp"
fi
ln -sfn /usr/share/mujoco/model/mug assets/mug

# The GUI's runtime npm packages (three.js), for --program: each tarball that web/package-lock.json
# pins (its development dependencies left out) from the npm registry ($npm_config_registry, else
# registry.npmjs.org), its SHA-512 checked against the lock's integrity, unpacked into
# web/node_modules/ in place of the old one. Only when the lock file changed; the full setup's
# npm ci replaces them all.
fetch_npm_runtime_packages() {
  local registry="${npm_config_registry:-https://registry.npmjs.org/}" tmp path name version
  local integrity expected actual
  registry="${registry%/}"
  tmp=$(mktemp -d)
  cmake -DLOCK=web/package-lock.json -P cmake/npm_lock_packages.cmake >"$tmp/list"
  while read -r path name version integrity; do
    if [ "${integrity#sha512-}" = "$integrity" ]; then
      echo "setup: web/package-lock.json: $path: expected a sha512- integrity, got '$integrity'" >&2
      rm -rf "$tmp"
      return 1
    fi
    expected=$(printf %s "${integrity#sha512-}" | base64 -d | od -An -v -tx1 | tr -d ' \n')
    if ! curl -fsSL --retry 3 -o "$tmp/package.tgz" "$registry/$name/-/${name##*/}-$version.tgz"; then
      echo "setup: cannot fetch $name $version from $registry" >&2
      rm -rf "$tmp"
      return 1
    fi
    actual=$(sha512sum "$tmp/package.tgz" | cut -d' ' -f1)
    if [ "$actual" != "$expected" ]; then
      echo "setup: $name $version from $registry: SHA-512 $actual, the lock file says $expected" >&2
      rm -rf "$tmp"
      return 1
    fi
    rm -rf "web/$path.partial"
    mkdir -p "web/$path.partial"
    tar -xzf "$tmp/package.tgz" -C "web/$path.partial" --strip-components=1 --no-same-owner
    rm -rf "web/$path"
    mv "web/$path.partial" "web/$path"
    echo "setup: $name $version (npm registry, SHA-512 as locked) in web/$path"
  done <"$tmp/list"
  rm -rf "$tmp"
  cp web/package-lock.json web/node_modules/.saccade-runtime-lock
}
if $program_only; then
  if ! cmp -s web/package-lock.json web/node_modules/.saccade-installed-lock 2>/dev/null &&
    ! cmp -s web/package-lock.json web/node_modules/.saccade-runtime-lock 2>/dev/null; then
    echo "setup: fetching the GUI's npm packages (web/package-lock.json, without its dev ones)"
    fetch_npm_runtime_packages
  fi
# The GUI's npm packages (three.js for the page, playwright-core for its browser tests), exactly
# as web/package-lock.json pins them; again only when the lock file changed.
elif ! cmp -s web/package-lock.json web/node_modules/.saccade-installed-lock 2>/dev/null; then
  echo "setup: installing the GUI's npm packages (web/package-lock.json)"
  (cd web && npm ci --no-audit --no-fund --loglevel=error)
  cp web/package-lock.json web/node_modules/.saccade-installed-lock
fi

# The DDS tests' independent ROS 2 serializer (Foxglove's, tests/dds/ros2_reference/), exactly
# as its package-lock.json pins it; again only when the lock file changed.
ref=tests/dds/ros2_reference
if ! $program_only && ! cmp -s $ref/package-lock.json $ref/node_modules/.saccade-installed-lock 2>/dev/null; then
  echo "setup: installing the DDS tests' npm packages ($ref/package-lock.json)"
  (cd $ref && npm ci --no-audit --no-fund --loglevel=error)
  cp $ref/package-lock.json $ref/node_modules/.saccade-installed-lock
fi

# The recording tests' reference MCAP implementation (Foxglove's @mcap/core and @mcap/support,
# tests/record/mcap_reference/), exactly as its package-lock.json pins it.
ref=tests/record/mcap_reference
if ! $program_only && ! cmp -s $ref/package-lock.json $ref/node_modules/.saccade-installed-lock 2>/dev/null; then
  echo "setup: installing the recording tests' npm packages ($ref/package-lock.json)"
  (cd $ref && npm ci --no-audit --no-fund --loglevel=error)
  cp $ref/package-lock.json $ref/node_modules/.saccade-installed-lock
fi

build_dir="${1:-build}"
shift || true
# Warnings are errors here as in CI (g++ 12 on Debian 12 builds the tree without one): the same
# flags as CI's, so that ccache serves CI's fresh clone from a developer's build and back.
# SACCADE_WERROR=OFF in the environment turns it off.
# --program configures the program alone (SACCADE_PROGRAM_ONLY); the full setup turns that off
# again, in the same build folder.
cmake -S . -B "$build_dir" -G Ninja -DSACCADE_WERROR="${SACCADE_WERROR:-ON}" \
  -DSACCADE_PROGRAM_ONLY="$($program_only && echo ON || echo OFF)" "$@" >/dev/null
if $program_only; then
  echo "setup: building the programs (the tests' targets come with scripts/test.sh)"
  cmake --build "$build_dir" --target saccade saccade-servo-emulator
elif [ -n "${SACCADE_BUILD_TARGET:-}" ]; then
  cmake --build "$build_dir" --target "$SACCADE_BUILD_TARGET"
else
  cmake --build "$build_dir"
fi
