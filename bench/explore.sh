#!/usr/bin/env bash
# Exploration and mapping (issue 44): `saccade explore` on the three exploration scenes, every
# strategy for the same simulated time; each scene's report (text), then one table: the
# simulated time each strategy takes to reach 50 % and 80 % completeness, its final
# completeness, the map's RMS distance to the truth at 1-3 m, and saliency's time to 80 % (or,
# where raster never gets there, to raster's final completeness) against raster's.
#
#   bash bench/explore.sh [SECONDS (30)] [SCENE ...]   # from the repository root, after setup
#
# OUT=DIR keeps the JSON reports and the maps there (default: a temporary folder, removed).
set -euo pipefail
cd "$(dirname "$0")/.."
seconds=${1:-30}
shift || true
scenes=("$@")
[ ${#scenes[@]} -gt 0 ] || scenes=(scenes/explore_wall.yaml scenes/explore_shelf.yaml scenes/explore_room.yaml)
saccade=${SACCADE_BIN:-build/bin/saccade}
[ -x "$saccade" ] || { echo "explore: $saccade is missing: run scripts/setup.sh first" >&2; exit 1; }
if [ -n "${OUT:-}" ]; then
  out=$OUT
  mkdir -p "$out"
else
  out=$(mktemp -d)
  trap 'rm -rf "$out"' EXIT
fi
for scene in "${scenes[@]}"; do
  name=$(basename "$scene" .yaml)
  mkdir -p "$out/$name"
  echo "== $scene, $seconds s simulated per strategy"
  "$saccade" explore --scene "$scene" --seconds "$seconds" --quiet --json "$out/$name.json" \
    --map-dir "$out/$name"
done
python3 - "$out" "${scenes[@]}" <<'PY'
import json, os, sys
out, scenes = sys.argv[1], sys.argv[2:]
print("\n== summary (simulated seconds; completeness within 2 cm of the map)")
print(f"{'scene':<16} {'strategy':<9} {'to 50 %':>8} {'to 80 %':>8} {'final':>7} {'RMS 1-3 m':>10} {'fix/s':>6}")
def first(curve, level):
    return next((c["time_s"] for c in curve if c["completeness"] >= level), None)
for scene in scenes:
    name = os.path.basename(scene)[:-5]
    report = json.load(open(os.path.join(out, name + ".json")))
    by = {s["strategy"]: s for s in report["strategies"]}
    for s in report["strategies"]:
        f = lambda t: "never" if t is None else f"{t:.1f}"
        print(f"{name:<16} {s['strategy']:<9} {f(s['time_to_50_s']):>8} {f(s['time_to_80_s']):>8} "
              f"{100 * s['map']['completeness']:6.1f}% {1000 * s['map_1_to_3m']['rms_m']:8.1f} mm "
              f"{s['fixations_per_wall_second']:6.2f}")
    if "raster" in by and "saliency" in by:
        raster, saliency = by["raster"], by["saliency"]
        level = 0.8 if raster["time_to_80_s"] is not None else raster["map"]["completeness"]
        r, s = first(raster["completeness_curve"], level), first(saliency["completeness_curve"], level)
        ratio = "saliency never gets there" if s is None else f"{s / r:.2f}"
        print(f"{'':<16} saliency / raster time to {100 * level:.0f} %: {ratio}")
PY
