#!/usr/bin/env bash
# saccade's stereo render against MuJoCo's on a comparable scene, in the same run, in turn.
#
#   bash bench/mujoco_ratio.sh [ROUNDS]        # from the repository root, after scripts/setup.sh
#
# Each round times, one after the other (the machine's noise hits both alike):
#   - MuJoCo 2.2 (Debian's libmujoco) rendering two 1024x768 cameras without multisampling and
#     reading them back (the peer benchmark: ../shared/peers/, or SACCADE_PEERS=DIR);
#   - `saccade bench --scene scenes/bench.yaml --no-effect-table`: the same two cameras with the
#     bench scene's lens distortion and sensor noise on (and motion blur on, the head still).
# It prints each round's stereo frames per second and, last, the ratio of the medians
# (saccade / MuJoCo). FRAMES=N sets the frames timed per run (default 100); SCENE=FILE another
# scene of saccade's (scenes/bench_realistic.yaml: the same scene through realistic cameras).
set -euo pipefail
cd "$(dirname "$0")/.."
rounds=${1:-3}
frames=${FRAMES:-100}
scene=${SCENE:-scenes/bench.yaml}
peers=${SACCADE_PEERS:-../shared/peers}
saccade=${SACCADE_BIN:-build/bin/saccade}
[ -x "$saccade" ] || { echo "mujoco_ratio: $saccade is missing: run scripts/setup.sh first" >&2; exit 1; }
[ -f "$peers/build.sh" ] || { echo "mujoco_ratio: no peer benchmark at $peers (SACCADE_PEERS=DIR)" >&2; exit 1; }
export PEERS_OUT=${PEERS_OUT:-/tmp/peers}
mjbench=$(bash "$peers/build.sh" | tail -1)

mujoco=()
ours=()
for ((i = 1; i <= rounds; i++)); do
  m=$("$mjbench" "$PEERS_OUT/scene_nomsaa.xml" "$frames" | sed -n 's/.*: \([0-9.]*\) stereo-frames\/s.*/\1/p')
  s=$("$saccade" bench --scene "$scene" --frames "$frames" --no-effect-table --json |
    python3 -c 'import json, sys; print(round(json.load(sys.stdin)["frames_per_second"], 1))')
  [ -n "$m" ] && [ -n "$s" ] || { echo "mujoco_ratio: a run printed no figure" >&2; exit 1; }
  mujoco+=("$m")
  ours+=("$s")
  printf 'round %d: MuJoCo %6.1f stereo frames/s   saccade (%s) %6.1f   ratio %.2f\n' \
    "$i" "$m" "$(basename "$scene")" "$s" "$(python3 -c "print($s / $m)")"
done
python3 - "${mujoco[*]}" "${ours[*]}" <<'EOF'
import statistics, sys
m = [float(x) for x in sys.argv[1].split()]
s = [float(x) for x in sys.argv[2].split()]
print(f"median: MuJoCo {statistics.median(m):.1f}, saccade {statistics.median(s):.1f} stereo frames/s;"
      f" saccade / MuJoCo = {statistics.median(s) / statistics.median(m):.2f}")
EOF
