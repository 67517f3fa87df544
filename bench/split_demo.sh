#!/usr/bin/env bash
# The demo split in two processes over DDS against the single process, in one run (issue 16;
# figures in bench/baselines/dds-2core-loopback.md): each fixation scored against the scene's
# ground truth (`saccade run --score`: the object, the 3D error of the triangulated target and
# each eye's axis error at arrival), the single process's beside the split loop's, which
# perception.yaml scores from what it receives. Perception runs STEPS steps, on its images'
# stamps (clock.source); the robot runs until perception is done, in lockstep with it
# (simulated clock: its head waits for perception's answer to each frame pair, so the split
# loop is the single one), unless --realtime-robot paces it at its clock's rate (lockstep off:
# perception takes the newest frames and the joints of their capture time, and misses the
# others). Everything on loopback, in DDS domain 195.
#
#   bash bench/split_demo.sh [BUILD_DIR] [STEPS] [--realtime-robot]
set -euo pipefail
cd "$(dirname "$0")/.."
build="${1:-build}"
steps="${2:-150}"
robot_args=()
[[ "${3:-}" == "--realtime-robot" ]] && robot_args=(--realtime)
export CYCLONEDDS_URI="file://$PWD/config/dds/loopback.xml"
bin="$build/bin/saccade"
out="$(mktemp -d /tmp/saccade-split-bench.XXXXXX)"
trap 'rm -rf "$out"' EXIT

echo "== single process: pipelines/demo.yaml, $steps steps"
start=$(date +%s.%N)
"$bin" run pipelines/demo.yaml --score --json --steps "$steps" > "$out/single.json" 2> "$out/single.err"
single_s=$(echo "$(date +%s.%N) - $start" | bc)

echo "== two processes: pipelines/robot.yaml ${robot_args[*]:-} until pipelines/perception.yaml has done $steps steps"
start=$(date +%s.%N)
"$bin" run pipelines/robot.yaml --dds-domain 195 --steps 0 "${robot_args[@]}" \
  > "$out/robot.txt" 2>&1 &
robot=$!
"$bin" run pipelines/perception.yaml --score --json --dds-domain 195 --steps "$steps" \
  > "$out/split.json" 2> "$out/perception.err"
kill -TERM "$robot"
wait "$robot" || true
split_s=$(echo "$(date +%s.%N) - $start" | bc)
grep -h "dds: /saccade" "$out/perception.err" | sed 's/^\[info\] /perception: /'

/usr/bin/python3 - "$out/single.json" "$out/split.json" "$single_s" "$split_s" <<'EOF'
import json, sys
single, split = (json.load(open(p)) for p in sys.argv[1:3])
print(f"\nwall: single {float(sys.argv[3]):.1f} s, split {float(sys.argv[4]):.1f} s")
print(f"faces fixated: single {single['faces_fixated']} of {single['faces']}, "
      f"split {split['faces_fixated']} of {split['faces']}\n")
def rows(run):
    return [f for f in run["scored"] if f["fixated"]]
print(f"{'':3} {'single':>52}   {'split':>52}")
print(f"{'#':3} " + "   ".join([f"{'object':<16} {'at s':>6} {'3D mm':>7} {'L deg':>7} {'R deg':>7}"] * 2))
def cell(f):
    if f is None:
        return f"{'-':<16} {'':>6} {'':>7} {'':>7} {'':>7}"
    if "error_3d_m" not in f:
        return f"{f['object']:<16} {f['fixated_at_s']:6.2f} {'-':>7} {'-':>7} {'-':>7}"
    e = f["eye_error_deg"]
    return (f"{f['object']:<16} {f['fixated_at_s']:6.2f} {1e3 * f['error_3d_m']:7.2f} "
            f"{e['left']:7.3f} {e['right']:7.3f}")
a, b = rows(single), rows(split)
for i in range(max(len(a), len(b))):
    print(f"{i + 1:<3} {cell(a[i] if i < len(a) else None)}   {cell(b[i] if i < len(b) else None)}")
EOF
