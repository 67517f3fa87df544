#!/usr/bin/env bash
# The DDS link between two processes, in one run (issue 16; figures in bench/baselines/):
#   1. ddsperf (cyclonedds-tools): 2.25 MiB samples (a 1024x768 RGB image) at 60 Hz, pub/sub
#      (throughput, loss) and ping/pong (round trip; one way is about half);
#   2. dds_link_bench --raw: plain Cyclone DDS, sensor_msgs/Image, 2 x 1024x768 RGB at 30 Hz;
#   3. dds_link_bench: the same through saccade's writers and readers (camera info, /tf, the
#      conversion to saccade's Image).
# Everything on loopback (config/dds/loopback.xml), in DDS domains of its own.
#
#   bash bench/dds_bench.sh [BUILD_DIR] [SECONDS]
set -euo pipefail
cd "$(dirname "$0")/.."
build="${1:-build}"
seconds="${2:-10}"
export CYCLONEDDS_URI="file://$PWD/config/dds/loopback.xml"
size=$((1024 * 768 * 3))

echo "== ddsperf pub/sub: ${size}-byte samples at 60 Hz, reliable, ${seconds} s"
ddsperf -i 191 -D "$seconds" sub > /tmp/saccade-ddsperf-sub.txt 2>&1 &
sub=$!
ddsperf -i 191 -D "$seconds" pub 60Hz size "$size" > /tmp/saccade-ddsperf-pub.txt 2>&1 || true
wait "$sub" || true
tail -n 3 /tmp/saccade-ddsperf-sub.txt

echo "== ddsperf ping/pong: ${size}-byte samples at 30 Hz, ${seconds} s (round trip)"
ddsperf -i 192 -D "$((seconds + 2))" pong > /tmp/saccade-ddsperf-pong.txt 2>&1 &
pong=$!
ddsperf -i 192 -D "$seconds" ping 30Hz size "$size" > /tmp/saccade-ddsperf-ping.txt 2>&1 || true
wait "$pong" || true
tail -n 3 /tmp/saccade-ddsperf-ping.txt

echo "== plain Cyclone DDS: 2 x 1024x768 RGB at 30 Hz, ${seconds} s"
"$build/bin/dds_link_bench" --raw --seconds "$seconds" --domain 193 || true  # 1: images lost
echo "== saccade's writers and readers: 2 x 1024x768 RGB at 30 Hz, ${seconds} s"
"$build/bin/dds_link_bench" --seconds "$seconds" --domain 194 || true
