#!/usr/bin/env bash
# Packs what the lent GPU machine needs to time the renderer (the `device` tool of this
# workplace; bench/baselines/h100-nvidia-egl.md): the benchmarks built here, stripped, with the
# Debian libraries they need that its Ubuntu lacks, Assimp's sample models of the demo's scene,
# MuJoCo's mug and the peer benchmark, into .gpu/ (ignored by git), and Debian's libglvnd/libEGL
# into .gl/. Run from the repository root after scripts/setup.sh; then, on the device, with
# `carry` [".gl", ".gpu", "assets"]:
#
#   bash bench/gpu/run.sh
#
# which prints render_bench's frame times for the bench and realistic scenes, each realistic
# effect in turn and the MuJoCo peer's rate, as the 2026-11-30 section of that baseline has them.
set -euo pipefail
cd "$(dirname "$0")/../.."
[ -x build/bin/render_bench ] && [ -x build/bin/pixels_bench ] ||
  { echo "gpu/pack.sh: build/bin/render_bench is missing: run scripts/setup.sh first" >&2; exit 1; }
grep -qx '/.gpu/' .git/info/exclude 2>/dev/null || { mkdir -p .git/info; echo '/.gpu/' >> .git/info/exclude; }
rm -rf .gpu && mkdir -p .gpu/lib .gpu/peers .gpu/mug .gpu/models/Collada .gpu/models/glTF2 .gpu/models/glTF
strip -o .gpu/render_bench build/bin/render_bench
strip -o .gpu/pixels_bench build/bin/pixels_bench
PEERS_OUT=/tmp/peers bash ../shared/peers/build.sh >/dev/null
cp /tmp/peers/* .gpu/peers/
# The libraries the machine's Ubuntu 24.04 does not have (its libc, libstdc++, libz and EGL do).
for lib in $( (ldd build/bin/render_bench; ldd build/bin/pixels_bench; ldd /tmp/peers/mjbench) |
  awk '/=>/ {print $3}' | sort -u |
  grep -v 'libc\.so\|libm\.so\|libgcc_s\|libstdc\|libdl\|libz\.so\|libEGL\|libGLdispatch'); do
  cp -L "$lib" .gpu/lib/
done
cp -L assets/mug/* .gpu/mug/
m=/usr/share/assimp/models
cp "$m"/Collada/duck* .gpu/models/Collada/
cp -r "$m"/glTF2/BoxTextured-glTF-Binary .gpu/models/glTF2/
cp -r "$m"/glTF/CesiumMilkTruck .gpu/models/glTF/
o='-oAPT::Architecture=amd64 -oAPT::Architectures=amd64 -oDir::State::Lists=/tmp/amd64'
mkdir -p .gl /tmp/amd64/partial
apt-get $o update -qq
(cd .gl && apt-get $o download libegl1 libglvnd0 libopengl0 libgl1 libglx0 libgles2 2>/dev/null)
du -sh .gpu .gl
