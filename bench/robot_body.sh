#!/usr/bin/env bash
# What the robot's own meshes cost to render (issue 42): `saccade bench` on bench/robot_body.yaml
# (three cameras: the head's two eyes and a world camera 0.6 m in front of the head, which the
# head fills) for each shipped head, with its body drawn and without it (--hide-robot), in turn,
# so that the machine's noise hits both alike.
#
#   bash bench/robot_body.sh [ROUNDS (3)]      # from the repository root, after scripts/setup.sh
#
# Prints, per head, the median frames per second of each (a frame: all three cameras) and the
# milliseconds per frame the body adds. FRAMES=N frames timed per run (default 60). The scene's
# effects stay as `saccade bench` has them (levels of detail on: --lod-max-error's default).
set -euo pipefail
cd "$(dirname "$0")/.."
rounds=${1:-3}
frames=${FRAMES:-60}
saccade=${SACCADE_BIN:-build/bin/saccade}
[ -x "$saccade" ] || { echo "robot_body: $saccade is missing: run scripts/setup.sh first" >&2; exit 1; }
fps() {
  "$saccade" bench --scene bench/robot_body.yaml --head "robots/$1.yaml" $2 --frames "$frames" \
    --no-effect-table --json | python3 -c 'import json, sys; print(json.load(sys.stdin)["frames_per_second"])'
}
echo "| head | body drawn (fps) | hidden (fps) | the body's cost (ms per frame) |"
echo "|---|---|---|---|"
for head in popeye humanoid pan_tilt_vergence pan_tilt_fixed; do
  on=()
  off=()
  for ((i = 1; i <= rounds; i++)); do
    on+=("$(fps "$head" "")")
    off+=("$(fps "$head" --hide-robot)")
  done
  python3 - "$head" "${#on[@]}" "${on[@]}" "${off[@]}" <<'PY'
import statistics, sys
head, n = sys.argv[1], int(sys.argv[2])
on = [float(x) for x in sys.argv[3:3 + n]]
off = [float(x) for x in sys.argv[3 + n:]]
m_on, m_off = statistics.median(on), statistics.median(off)
print(f"| {head} | {m_on:.1f} | {m_off:.1f} | {1000 / m_on - 1000 / m_off:+.2f} |")
PY
done
