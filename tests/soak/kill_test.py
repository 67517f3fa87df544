#!/usr/bin/env python3
"""Kills `saccade render` and `saccade demo --record` with SIGKILL at random moments and checks
that what they wrote is whole (issue 18, item 3). Not part of the default test run: it takes a
few minutes. Standard library only.

  python3 tests/soak/kill_test.py [--binary build/bin/saccade] [--runs 20] [--seed 1]

render: every frame listed in frames.jsonl (a line ended by a newline) has every image it names
on disk, and each PNG is whole (every chunk's CRC right, IEND at the end).
demo --record: every frames/NNNNNN.jpg is whole (starts with SOI, ends with EOI), and
summary.json, if present, is valid JSON.
Prints one line per run and a summary; exits 1 if any run left a broken file.
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


def check_demo(out):
    frames_dir = os.path.join(out, 'frames')
    problems = []
    names = sorted(n for n in os.listdir(frames_dir) if n.endswith('.jpg') and not n.startswith('.')) \
        if os.path.isdir(frames_dir) else []
    for name in names:
        if (why := jpeg_whole(os.path.join(frames_dir, name))) is not None:
            problems.append(f'frames/{name}: {why}')
    summary = os.path.join(out, 'summary.json')
    if os.path.exists(summary):
        try:
            with open(summary) as f:
                json.load(f)
        except ValueError as e:
            problems.append(f'summary.json: not JSON ({e})')
    return len(names), problems


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
    totals = {'render': 0, 'demo': 0}
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
                count, problems = (check_render if kind == 'render' else check_demo)(out)
                totals[kind] += count
                failures += bool(problems)
                state = 'finished before the kill' if finished else f'killed at {delay:.2f} s'
                print(f'{kind} run {i + 1:2d}: {state}; {count} frames on record, '
                      f'{len(problems)} broken' + ''.join(f'\n    {p}' for p in problems[:5]),
                      flush=True)
    print(f'kill test: {args.runs} kills of saccade render ({totals["render"]} frames checked) and '
          f'{args.runs} of saccade demo --record ({totals["demo"]} frames checked); '
          f'{failures} runs with broken files')
    return 1 if failures else 0


if __name__ == '__main__':
    sys.exit(main())
