#!/usr/bin/env bash
# On the lent GPU machine, from the repository root, after bench/gpu/pack.sh here (see there).
# RB=.gpu/OTHER times another render_bench carried beside it; ROUNDS=N (default 3).
set -u
for f in .gl/*.deb; do dpkg -x "$f" /; done
ldconfig
rm -rf assets/mug && cp -r .gpu/mug assets/mug
mkdir -p /usr/share/assimp/models && cp -r .gpu/models/* /usr/share/assimp/models/
export LD_LIBRARY_PATH=$PWD/.gpu/lib
vendor=/usr/local/nvidia/share/glvnd/egl_vendor.d/10_nvidia.json
[ -f "$vendor" ] && export __EGL_VENDOR_LIBRARY_FILENAMES=$vendor
nvidia-smi --query-gpu=name,driver_version --format=csv,noheader
nproc
python3 bench/gpu/effect_scenes.py
rb=${RB:-.gpu/render_bench}
frame() {
  timeout 60 "$rb" "scenes/$1.yaml" "$2" --no-effect-table 2>&1 | grep -A1 'per frame' | tr '\n' ' '
  echo
}
rm -rf /tmp/peers && cp -r .gpu/peers /tmp/peers
for ((r = 1; r <= ${ROUNDS:-3}; r++)); do
  echo "== round $r"
  (cd /tmp/peers && timeout 60 ./mjbench scene_nomsaa.xml 300 | tail -1)
  for s in bench _e1_vignetting _e2_bayer _e3_emva bench_realistic portraits portraits_realistic; do
    echo "$s: $(frame "$s" 200)"
  done
done
rm -f scenes/_e*.yaml
timeout 120 .gpu/pixels_bench --benchmark_min_time=0.2 2>&1 | grep BM_
