#!/usr/bin/env python3
"""Draws a soak's memory curve (the CSV that memory_soak.py --log writes) as an SVG picture.
Standard library only.

  python3 tests/soak/plot_rss.py LOG.csv --out curve.svg [--title TEXT] [--warmup 0.2]
                                 [--tolerance 0.02] [--steps N]

The resident set (MiB) over the run's wall time; the warm-up (its first --warmup fraction)
shaded; the band that memory_soak.py judges by, from the first sample after the warm-up to
--tolerance above it, drawn as two dashed lines. With --steps the x axis also says the steps
(assuming an even rate over the run).
"""
import argparse
import csv
import html
import math
import os
import sys


def read_log(path):
    samples = []
    with open(path, newline='') as f:
        for row in csv.DictReader(f):
            samples.append((float(row['seconds']), int(row['rss_kib']) / 1024.0))
    if len(samples) < 2:
        raise SystemExit(f'plot_rss: {path}: {len(samples)} samples, at least 2 needed')
    return samples


def nice_step(span, ticks=6):
    """A round tick step (1, 2 or 5 times a power of ten) that cuts `span` in about `ticks`."""
    raw = span / ticks
    power = 10 ** math.floor(math.log10(raw))
    for m in (1, 2, 5, 10):
        if m * power >= raw:
            return m * power
    return 10 * power


def svg(samples, title, warmup, tolerance, steps):
    width, height = 900, 420
    left, right, top, bottom = 80, 30, 50, 60
    t_end = samples[-1][0]
    after = [s for s in samples if s[0] >= warmup * t_end]
    base = after[0][1] if after else samples[0][1]
    band = base * (1 + tolerance)
    # The y range: from a little under the lowest sample after the start to over the band.
    lo = min(min(m for _, m in samples[1:]), base) * 0.97
    hi = max(max(m for _, m in samples), band) * 1.02
    x = lambda t: left + (width - left - right) * t / t_end
    y = lambda m: top + (height - top - bottom) * (1 - (min(max(m, lo), hi) - lo) / (hi - lo))
    out = [f'<svg xmlns="http://www.w3.org/2000/svg" width="{width}" height="{height}" '
           f'font-family="sans-serif" font-size="12">',
           f'<rect width="{width}" height="{height}" fill="white"/>',
           f'<text x="{width / 2}" y="24" text-anchor="middle" font-size="15">'
           f'{html.escape(title)}</text>',
           f'<rect x="{left}" y="{top}" width="{x(warmup * t_end) - left:.1f}" '
           f'height="{height - top - bottom}" fill="#eeeeee"/>',
           f'<text x="{left + 6}" y="{top + 16}" fill="#666">warm-up</text>']
    # Axes and ticks.
    step_y = nice_step(hi - lo)
    m = math.ceil(lo / step_y) * step_y
    while m <= hi:
        out.append(f'<line x1="{left}" x2="{width - right}" y1="{y(m):.1f}" y2="{y(m):.1f}" '
                   f'stroke="#e4e4e4"/>')
        out.append(f'<text x="{left - 6}" y="{y(m) + 4:.1f}" text-anchor="end">{m:g}</text>')
        m += step_y
    step_t = nice_step(t_end / 60.0) * 60.0 if t_end > 600 else nice_step(t_end)
    t = 0.0
    while t <= t_end + 1e-9:
        label = f'{t / 60:g} min' if t_end > 600 else f'{t:g} s'
        if steps:
            label += f' ({steps * t / t_end / 1000:.0f}k steps)'
        out.append(f'<line x1="{x(t):.1f}" x2="{x(t):.1f}" y1="{height - bottom}" '
                   f'y2="{height - bottom + 5}" stroke="black"/>')
        out.append(f'<text x="{x(t):.1f}" y="{height - bottom + 20}" text-anchor="middle">'
                   f'{label}</text>')
        t += step_t
    out.append(f'<polyline points="{left},{top} {left},{height - bottom} {width - right},'
               f'{height - bottom}" fill="none" stroke="black"/>')
    out.append(f'<text x="18" y="{(top + height - bottom) / 2}" text-anchor="middle" '
               f'transform="rotate(-90 18 {(top + height - bottom) / 2})">RSS, MiB</text>')
    # The band judged, then the curve.
    for level, name in ((base, 'after the warm-up'), (band, f'+{100 * tolerance:g} %')):
        out.append(f'<line x1="{x(warmup * t_end):.1f}" x2="{width - right}" y1="{y(level):.1f}" '
                   f'y2="{y(level):.1f}" stroke="#c0392b" stroke-dasharray="6 4"/>')
        out.append(f'<text x="{width - right - 4}" y="{y(level) - 4:.1f}" text-anchor="end" '
                   f'fill="#c0392b">{name}: {level:.1f} MiB</text>')
    points = ' '.join(f'{x(t):.1f},{y(m):.1f}' for t, m in samples)
    out.append(f'<polyline points="{points}" fill="none" stroke="#1f5fa8" stroke-width="1.5"/>')
    out.append('</svg>')
    return '\n'.join(out) + '\n'


def main():
    parser = argparse.ArgumentParser(description=__doc__.split('\n\n')[0])
    parser.add_argument('log', help='the CSV of memory_soak.py --log (seconds,rss_kib)')
    parser.add_argument('--out', required=True, help='the SVG to write')
    parser.add_argument('--title', default='resident memory over the soak')
    parser.add_argument('--warmup', type=float, default=0.2, help='fraction of the run (0.2)')
    parser.add_argument('--tolerance', type=float, default=0.02, help='growth judged (0.02)')
    parser.add_argument('--steps', type=int, help='the steps of the run, for the x axis')
    args = parser.parse_args()
    text = svg(read_log(args.log), args.title, args.warmup, args.tolerance, args.steps)
    with open(args.out + '.partial', 'w') as f:
        f.write(text)
    os.replace(args.out + '.partial', args.out)
    return 0


if __name__ == '__main__':
    sys.exit(main())
