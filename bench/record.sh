#!/usr/bin/env bash
# What recording to MCAP costs the demo (issue 43), and how fast a recording plays back:
# `saccade demo --duration S` without a recording, with `--record` (zstd at its default level,
# and without compression), in turn, so that the machine's noise hits all alike; the demo's own
# steps per second (its --json: the loop, not the start-up), the file's size per minute of the
# run, then a recording read back: frames per second decoded by saccade.mcap.Reader (every
# message of the two image topics, pixels to numpy) and steps per second of
# `saccade run pipelines/perception.yaml --play FILE --play-pace fast`.
#
#   bash bench/record.sh [ROUNDS (3)] [SECONDS (6)]   # from the repository root, after setup
#
# OUT=DIR puts the recordings there (default: a temporary folder; the disk they go to counts).
set -euo pipefail
cd "$(dirname "$0")/.."
rounds=${1:-3}
seconds=${2:-6}
saccade=${SACCADE_BIN:-build/bin/saccade}
[ -x "$saccade" ] || { echo "record: $saccade is missing: run scripts/setup.sh first" >&2; exit 1; }
out=${OUT:-$(mktemp -d)}
sps() {  # the demo's steps per second, with the given extra options
  "$saccade" demo --duration "$seconds" --json "$@" 2>/dev/null |
    python3 -c 'import json, sys; print(json.load(sys.stdin)["steps_per_second"])'
}
none=() zstd=() raw=()
for ((i = 1; i <= rounds; i++)); do
  none+=("$(sps)")
  zstd+=("$(sps --record "$out/zstd.mcap" --force)")
  raw+=("$(sps --record "$out/none.mcap" --force --record-compression none)")
done
python3 - "$rounds" "$seconds" "$out" "${none[@]}" "${zstd[@]}" "${raw[@]}" <<'PY'
import os, statistics, sys
n, seconds, out = int(sys.argv[1]), float(sys.argv[2]), sys.argv[3]
values = [float(x) for x in sys.argv[4:]]
none, zstd, raw = values[:n], values[n:2 * n], values[2 * n:]
base = statistics.median(none)
print("| demo | steps per second (median) | overhead | MB per minute of the run |")
print("|---|---|---|---|")
print(f"| no recording | {base:.2f} | | |")
for name, v, file in (("--record (zstd)", zstd, "zstd.mcap"), ("--record-compression none", raw, "none.mcap")):
    m = statistics.median(v)
    mb = os.path.getsize(os.path.join(out, file)) / 1e6 / seconds * 60
    print(f"| {name} | {m:.2f} | {100 * (base / m - 1):+.1f} % | {mb:.0f} |")
PY
PYTHONPATH=build/python /usr/bin/python3 - "$out/zstd.mcap" <<'PY'
import sys, time
import saccade
reader = saccade.mcap.Reader(sys.argv[1])
start, frames = time.perf_counter(), 0
for m in reader.messages(topics=["/saccade/left/image_raw", "/saccade/right/image_raw"]):
    frames += m.value["data"].shape[0] > 0
elapsed = time.perf_counter() - start
print(f"\nsaccade.mcap.Reader: {frames} images decoded in {elapsed:.2f} s: {frames / elapsed:.1f} frames/s")
PY
start=$(date +%s.%N)
"$saccade" run pipelines/perception.yaml --dds-domain 217 --play "$out/zstd.mcap" --play-pace fast \
  > "$out/play.txt" 2>&1
end=$(date +%s.%N)
steps=$(grep -o 'play: [0-9]* steps' "$out/play.txt" | grep -o '[0-9]*')
python3 -c "import sys; s, a, b = int(sys.argv[1]), float(sys.argv[2]), float(sys.argv[3]); print(f'--play-pace fast: {s} steps published in {b - a:.2f} s (start-up included): {s / (b - a):.1f} steps/s')" "$steps" "$start" "$end"
