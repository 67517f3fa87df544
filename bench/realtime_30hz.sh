#!/usr/bin/env bash
# Does the loop keep up with 30 Hz cameras? `saccade demo --realtime` at 30 Hz on OpenCV's
# recorded stereo pair (pipelines/hardware/recorded_cameras.yaml played at 30 frames/s instead
# of 25), first with the simulated head, then with the head on the emulated Dynamixel bus
# (saccade-servo-emulator, as pipelines/hardware/emulated_servos.yaml drives it).
#
#   bash bench/realtime_30hz.sh [SECONDS]     # from the repository root, after scripts/setup.sh
#
# Each run prints steps per second, the steps that overran their 33.3 ms (the loop skips
# those ticks: no backlog), the stereo pairs and the frames the cameras dropped, capture to
# motor command (median / p95 / max) and the age of the faces used (detection runs on a
# thread of its own on the real-time clock). The pipeline and hardware files are made from
# the shipped ones in a scratch folder (clock step 1/30 s, fps 30); nothing in the tree changes.
set -euo pipefail
cd "$(dirname "$0")/.."
seconds=${1:-20}
saccade=${SACCADE_BIN:-build/bin/saccade}
emulator=${SACCADE_EMULATOR:-build/bin/saccade-servo-emulator}
for b in "$saccade" "$emulator"; do
  [ -x "$b" ] || { echo "realtime_30hz: $b is missing: run scripts/setup.sh first" >&2; exit 1; }
done
work=$(mktemp -d)
link="$work/servos"
emulator_pid=
cleanup() {
  [ -n "$emulator_pid" ] && kill "$emulator_pid" 2>/dev/null || true
  rm -rf "$work"
}
trap cleanup EXIT

root=$PWD
sed -e "s|fps: 25|fps: 30|" -e "s|scene: ../../scenes/|scene: $root/scenes/|" \
  pipelines/hardware/recorded_cameras.yaml >"$work/recorded.yaml"
grep -q "fps: 30" "$work/recorded.yaml" || { echo "realtime_30hz: recorded_cameras.yaml has no fps: 25 to change" >&2; exit 1; }
# The same cameras, the head (everything from `  head:` on) from emulated_servos.yaml.
{
  sed -n '/^  head:/q;p' "$work/recorded.yaml"
  sed -n '/^  head:/,$p' pipelines/hardware/emulated_servos.yaml | sed "s|port: /tmp/saccade-servos|port: $link|"
} >"$work/recorded_servos.yaml"
for hw in recorded recorded_servos; do
  sed -e "s|step: 0.04,|step: 0.0333333333333333,|" -e "s|hardware: hardware/simulator.yaml|hardware: $work/$hw.yaml|" \
    pipelines/demo.yaml >"$work/demo_$hw.yaml"
  grep -q "$work/$hw.yaml" "$work/demo_$hw.yaml" || { echo "realtime_30hz: demo.yaml's hardware line changed" >&2; exit 1; }
done

"$emulator" --link "$link" >"$work/emulator.log" 2>&1 &
emulator_pid=$!
for _ in $(seq 50); do [ -e "$link" ] && break; sleep 0.1; done

echo "machine: $(nproc) cores, load average $(cut -d' ' -f1-3 /proc/loadavg)"
for hw in recorded recorded_servos; do
  label="recorded cameras, simulated head"
  [ "$hw" = recorded_servos ] && label="recorded cameras, head on the emulated servo bus"
  "$saccade" demo --pipeline "$work/demo_$hw.yaml" --realtime --duration "$seconds" --json >"$work/$hw.json" 2>"$work/$hw.err" || true
  python3 - "$work/$hw.json" "$label" <<'EOF'
import json, sys
try:
    d = json.load(open(sys.argv[1]))
except ValueError:
    sys.exit("realtime_30hz: the demo printed no report")
c2c = d["latency_ms"]["capture_to_command"]
age = d["latency_ms"]["detection_age"]
cams = d["cameras"] or {}
print(f"{sys.argv[2]}: {d['steps_per_second']:.1f} steps/s over {d['wall_s']:.1f} s, "
      f"{d['overruns']} of {d['steps']} steps overran; {cams.get('pairs')} stereo pairs, "
      f"dropped {cams.get('dropped_left')} + {cams.get('dropped_right')}; capture -> command "
      f"{c2c['median']:.2f} / {c2c['p95']:.2f} / {c2c['max']:.2f} ms; faces' age median "
      f"{age['median']:.0f} ms (p95 {age['p95']:.0f})")
EOF
done
