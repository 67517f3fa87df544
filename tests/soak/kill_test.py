#!/usr/bin/env python3
"""Kills `saccade render` and `saccade demo --record` with SIGKILL at random moments and checks
that what they wrote is whole (issue 18, item 3). Not part of the default test run: it takes a
few minutes. Standard library only.

  /usr/bin/python3 tests/soak/kill_test.py [--binary build/bin/saccade] [--runs 20] [--seed 1]

render: every frame listed in frames.jsonl (a line ended by a newline) has every image it names
on disk, and each PNG is whole (every chunk's CRC right, IEND at the end).
demo --record: every frames/NNNNNN.jpg is whole (starts with SOI, ends with EOI), the frames
are numbered without a gap and play back as an image sequence (OpenCV's CAP_IMAGES, every one
decoded), demo.avi plays back (FFmpeg's reader, which reads an AVI cut before its index) up to
all but the last two frames on disk (OpenCV's writer holds up to ~32 KB, less than a frame, and
a frame's JPEG is written before its video chunk), and summary.json, if present, is valid JSON.
Prints one line per run and a summary; exits 1 if any run left a broken file.

Needs Debian's python3-opencv (scripts/setup.sh installs it): run it with /usr/bin/python3.
"""
import argparse
import json
import os
import random
import signal
import struct
import subprocess
import sys
import tempfile
import time
import zlib

try:
    import cv2
except ImportError:
    sys.exit('kill_test.py: needs OpenCV for Python (Debian python3-opencv): run it with '
             '/usr/bin/python3')
# An image sequence is read until the first missing number: OpenCV warns about that one.
cv2.setLogLevel(2)  # errors only (OpenCV 4.6: 0 silent .. 6 verbose)

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))


def png_whole(path):
    """None when the PNG is whole, else why not."""
    with open(path, 'rb') as f:
        data = f.read()
    if data[:8] != b'\x89PNG\r\n\x1a\n':
        return 'no PNG signature'
    at = 8
    while at + 12 <= len(data):
        (length,) = struct.unpack('>I', data[at:at + 4])
        kind = data[at + 4:at + 8]
        end = at + 12 + length
        if end > len(data):
            return f'chunk {kind!r} cut at byte {len(data)}'
        (crc,) = struct.unpack('>I', data[end - 4:end])
        if zlib.crc32(data[at + 4:end - 4]) & 0xffffffff != crc:
            return f'chunk {kind!r} has a bad CRC'
        if kind == b'IEND':
            return None
        at = end
    return 'no IEND chunk'


def jpeg_whole(path):
    with open(path, 'rb') as f:
        data = f.read()
    if data[:2] != b'\xff\xd8':
        return 'no SOI marker'
    if data[-2:] != b'\xff\xd9':
        return 'no EOI marker at the end'
    return None


def check_render(out):
    """(frames listed, problems)."""
    index = os.path.join(out, 'frames.jsonl')
    if not os.path.exists(index):
        return 0, []
    with open(index, 'rb') as f:
        text = f.read().decode('utf-8', 'replace')
    lines = text.split('\n')[:-1]  # a last line without its newline is not listed
    problems = []
    for line in lines:
        try:
            frame = json.loads(line)
        except ValueError as e:
            problems.append(f'frames.jsonl: a listed line is not JSON ({e})')
            continue
        for camera in frame['cameras'].values():
            for key in ('file', 'depth', 'ids'):
                if key not in camera:
                    continue
                path = os.path.join(out, camera[key])
                if not os.path.exists(path):
                    problems.append(f'{camera[key]}: listed but missing')
                elif (why := png_whole(path)) is not None:
                    problems.append(f'{camera[key]}: {why}')
    return len(lines), problems


def play_back(capture):
    """(frames decoded, their sizes) of an OpenCV capture, read to its end."""
    count, sizes = 0, set()
    while capture.isOpened():
        ok, image = capture.read()
        if not ok:
            break
        count += 1
        sizes.add(image.shape)
    capture.release()
    return count, sizes


def check_demo(out):
    """(frames on disk, problems, frames demo.avi played)."""
    frames_dir = os.path.join(out, 'frames')
    problems = []
    names = sorted(n for n in os.listdir(frames_dir) if n.endswith('.jpg') and not n.startswith('.')) \
        if os.path.isdir(frames_dir) else []
    for name in names:
        if (why := jpeg_whole(os.path.join(frames_dir, name))) is not None:
            problems.append(f'frames/{name}: {why}')
    numbers = [int(n[:-4]) for n in names]
    if numbers and numbers != list(range(numbers[0], numbers[0] + len(numbers))):
        problems.append(f'frames/: numbered {numbers[0]} to {numbers[-1]} with gaps '
                        f'({len(numbers)} files)')
    video_frames = 0
    if names and not problems:
        played, sizes = play_back(
            cv2.VideoCapture(os.path.join(frames_dir, '%06d.jpg'), cv2.CAP_IMAGES))
        if played != len(names) or len(sizes) != 1:
            problems.append(f'frames/ as an image sequence: {played} of {len(names)} frames '
                            f'played, sizes {sorted(sizes)}')
        video = os.path.join(out, 'demo.avi')
        if len(names) >= 3:
            video_frames, video_sizes = play_back(cv2.VideoCapture(video, cv2.CAP_FFMPEG)) \
                if os.path.exists(video) else (0, set())
            if video_frames < len(names) - 2 or video_frames > len(names) or \
                    (video_frames and video_sizes != sizes):
                problems.append(f'demo.avi: {video_frames} frames played back of {len(names)} '
                                f'on disk, sizes {sorted(video_sizes)} (frames/: {sorted(sizes)})')
    summary = os.path.join(out, 'summary.json')
    if os.path.exists(summary):
        try:
            with open(summary) as f:
                json.load(f)
        except ValueError as e:
            problems.append(f'summary.json: not JSON ({e})')
    return len(names), problems, video_frames


def run_and_kill(command, delay):
    process = subprocess.Popen(command, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    time.sleep(delay)
    finished = process.poll() is not None
    if not finished:
        process.send_signal(signal.SIGKILL)
    process.wait()
    return finished


def main():
    parser = argparse.ArgumentParser(description=__doc__.split('\n\n')[0])
    parser.add_argument('--binary', default=os.path.join(ROOT, 'build', 'bin', 'saccade'))
    parser.add_argument('--runs', type=int, default=20, help='kills of each program (20)')
    parser.add_argument('--seed', type=int, default=1)
    parser.add_argument('--min-s', type=float, default=2.0, help='earliest kill, s after start')
    parser.add_argument('--max-s', type=float, default=12.0, help='latest kill, s after start')
    args = parser.parse_args()
    rng = random.Random(args.seed)
    scene = os.path.join(ROOT, 'scenes', 'portraits.yaml')
    failures = 0
    totals = {'render': 0, 'demo': 0, 'video': 0}
    with tempfile.TemporaryDirectory(prefix='saccade-kill-') as tmp:
        for kind in ('render', 'demo'):
            for i in range(args.runs):
                out = os.path.join(tmp, f'{kind}{i}')
                delay = rng.uniform(args.min_s, args.max_s)
                if kind == 'render':
                    command = [args.binary, 'render', '--scene', scene, '--frames', '1000',
                               '--truth', 'depth,ids,boxes', '--out', out]
                else:
                    command = [args.binary, 'demo', '--duration', '40', '--record', out]
                finished = run_and_kill(command, delay)
                video = ''
                if kind == 'render':
                    count, problems = check_render(out)
                else:
                    count, problems, video_frames = check_demo(out)
                    totals['video'] += video_frames
                    video = f', demo.avi played {video_frames}'
                totals[kind] += count
                failures += bool(problems)
                state = 'finished before the kill' if finished else f'killed at {delay:.2f} s'
                print(f'{kind} run {i + 1:2d}: {state}; {count} frames on record{video}, '
                      f'{len(problems)} broken' + ''.join(f'\n    {p}' for p in problems[:5]),
                      flush=True)
    print(f'kill test: {args.runs} kills of saccade render ({totals["render"]} frames checked) and '
          f'{args.runs} of saccade demo --record ({totals["demo"]} frames checked, '
          f'{totals["video"]} played back from the cut demo.avi); {failures} runs with broken '
          f'files')
    return 1 if failures else 0


if __name__ == '__main__':
    sys.exit(main())
