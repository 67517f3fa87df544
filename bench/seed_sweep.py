#!/usr/bin/env python3
"""The demo's accuracy over many noise seeds: one setting judged on many fixations, not one run.

    python3 bench/seed_sweep.py [--pipeline pipelines/demo.yaml] [--scene scenes/portraits.yaml]
                                [--seeds 30] [--first-seed 1000] [--jobs 2] [--json]

Runs `saccade demo --json` once per seed pair: a copy of the scene whose eye cameras' sensor
seeds are FIRST + 2k and FIRST + 2k + 1 (k = 0 .. SEEDS - 1), so that each run sees other noise
and the loop's small differences grow into another realisation. Prints, over all runs: every
portrait fixated and each once, the decoys never; the eyes' largest error over each fixation
(its mean, median, 90th percentile, how many exceed --bound-deg, the largest); the 3D error;
the steps each run took. A maximum over a fixation has a long tail: one run, or five, ranks
realisations more than settings (bench/baselines/loop-issue14-2core.md, "over 30 noise seed
pairs"). Simulated runs are the same to the bit at any speed, so --jobs runs them side by
side; their steps per second only rank settings run together.

Python's standard library only. Exit status 0, or 1 when a run failed or a file is wrong.
"""

import argparse
import json
import os
import re
import shutil
import statistics
import subprocess
import sys
import tempfile
from concurrent.futures import ThreadPoolExecutor

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
SENSOR_SEED = re.compile(r"^(\s*sensor:\s*\{.*\bseed:\s*)(-?\d+)(.*)$")


def seeded_scenes(scene: str, first: int, count: int, folder: str):
    """Copies of `scene` in folder/scenes/ (beside a link to the repository's assets/, so that
    the scene's relative paths still resolve) with the k-th pair of sensor seeds."""
    with open(scene, encoding="utf-8") as f:
        lines = f.read().split("\n")
    sensors = [i for i, line in enumerate(lines) if SENSOR_SEED.match(line)]
    if not sensors:
        raise SystemExit(f"{scene}: no camera line with `sensor: {{..., seed: N}}` to vary")
    source_dir = os.path.dirname(os.path.abspath(scene))
    scenes_dir = os.path.join(folder, os.path.basename(source_dir))
    os.makedirs(scenes_dir)
    # The scene's relative paths (../assets/..., a calibration file beside it) resolve as before.
    parent = os.path.dirname(source_dir)
    for entry in os.listdir(parent):
        if entry != os.path.basename(source_dir):
            os.symlink(os.path.join(parent, entry), os.path.join(folder, entry))
    for entry in os.listdir(source_dir):
        os.symlink(os.path.join(source_dir, entry), os.path.join(scenes_dir, entry))
    paths = []
    for k in range(count):
        out = list(lines)
        for n, i in enumerate(sensors):
            m = SENSOR_SEED.match(out[i])
            out[i] = f"{m.group(1)}{first + len(sensors) * k + n}{m.group(3)}"
        path = os.path.join(scenes_dir, f"seed-sweep-{k}.yaml")
        with open(path, "w", encoding="utf-8") as f:
            f.write("\n".join(out))
        paths.append(path)
    return paths, len(sensors)


def run(binary: str, pipeline: str, scene: str):
    result = subprocess.run([binary, "demo", "--pipeline", pipeline, "--scene", scene, "--json"],
                            capture_output=True, text=True)
    if result.returncode not in (0, 3):  # 3: nothing fixated, still a report
        return None, result.stderr.strip().splitlines()[-1:] or [f"exit {result.returncode}"]
    return json.loads(result.stdout), None


def percentile(values, q):
    ordered = sorted(values)
    return ordered[min(len(ordered) - 1, int(q * len(ordered)))]


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--pipeline", default=os.path.join(ROOT, "pipelines", "demo.yaml"))
    parser.add_argument("--scene", default=os.path.join(ROOT, "scenes", "portraits.yaml"),
                        help="a scene whose eye cameras have `sensor: {..., seed: N}` lines")
    parser.add_argument("--seeds", type=int, default=30, help="seed pairs, one run each (30)")
    parser.add_argument("--first-seed", type=int, default=1000, help="the first seed (1000)")
    parser.add_argument("--jobs", type=int, default=2, help="runs side by side (2)")
    parser.add_argument("--bound-deg", type=float, default=0.15,
                        help="count the fixations whose eyes' largest error exceeds it (0.15)")
    parser.add_argument("--binary", default=os.path.join(ROOT, "build", "bin", "saccade"))
    parser.add_argument("--json", action="store_true", help="print the summary and every run as JSON")
    args = parser.parse_args()
    if args.seeds < 1 or args.jobs < 1:
        parser.error("--seeds and --jobs must be at least 1")
    for path, what in ((args.binary, "--binary"), (args.pipeline, "--pipeline"), (args.scene, "--scene")):
        if not os.path.isfile(path):
            parser.error(f"{what} {path}: no such file")

    folder = tempfile.mkdtemp(prefix="saccade-seed-sweep-")
    try:
        scenes, cameras = seeded_scenes(args.scene, args.first_seed, args.seeds, folder)
        reports = [None] * args.seeds
        failures = []
        done = 0
        with ThreadPoolExecutor(max_workers=args.jobs) as pool:
            futures = {pool.submit(run, args.binary, os.path.abspath(args.pipeline), s): k
                       for k, s in enumerate(scenes)}
            for future in futures:
                k = futures[future]
                report, error = future.result()
                done += 1
                if error:
                    failures.append(f"seeds {args.first_seed + cameras * k}...: {' '.join(error)}")
                reports[k] = report
                print(f"run {done}/{args.seeds}", file=sys.stderr, flush=True)
    finally:
        shutil.rmtree(folder, ignore_errors=True)

    ok = [r for r in reports if r is not None]
    eyes, mm, runs = [], [], []
    incomplete = extra_visits = decoys_fixated = 0
    for k, r in enumerate(reports):
        if r is None:
            continue
        fixated = [f for f in r["fixations"] if f["fixated"]]
        objects = [f["object"] for f in fixated]
        incomplete += r["faces_fixated"] < r["faces"]
        extra_visits += len(objects) - len(set(objects))
        decoys_fixated += sum(1 for d in r.get("decoys", []) if d.get("fixated"))
        for f in fixated:
            d = f["dwell_eye_error_deg"]
            eyes.append(max(d["left_max"], d["right_max"]))
            mm.append(1e3 * f["error_3d_m"])
        runs.append({"seeds": [args.first_seed + cameras * k + n for n in range(cameras)],
                     "steps": r["steps"], "steps_per_second": r["steps_per_second"],
                     "fixations": [{"object": f["object"], "error_3d_mm": 1e3 * f["error_3d_m"],
                                    "eyes_largest_deg": max(f["dwell_eye_error_deg"]["left_max"],
                                                            f["dwell_eye_error_deg"]["right_max"])}
                                   for f in fixated]})
    summary = {"pipeline": args.pipeline, "scene": args.scene, "runs": len(ok), "failed": failures,
               "incomplete_runs": incomplete, "extra_visits": extra_visits,
               "decoys_fixated": decoys_fixated, "fixations": len(eyes)}
    if eyes:
        summary.update({
            "eyes_largest_deg": {"mean": statistics.mean(eyes), "median": statistics.median(eyes),
                                 "p90": percentile(eyes, 0.9), "max": max(eyes),
                                 "over_bound": sum(e > args.bound_deg for e in eyes),
                                 "bound": args.bound_deg},
            "error_3d_mm": {"mean": statistics.mean(mm), "max": max(mm)},
            "steps_mean": statistics.mean(r["steps"] for r in runs),
            "steps_per_second_mean": statistics.mean(r["steps_per_second"] for r in runs)})
    if args.json:
        print(json.dumps({"summary": summary, "runs": runs}, indent=1))
    else:
        print(f"{args.pipeline} on {args.scene}, {args.seeds} seed pairs from {args.first_seed}:")
        print(f"  runs {len(ok)} ({len(failures)} failed), every face fixated in "
              f"{len(ok) - incomplete}, faces visited again {extra_visits}, decoys fixated {decoys_fixated}")
        if eyes:
            e = summary["eyes_largest_deg"]
            print(f"  eyes' largest error over a fixation ({len(eyes)} fixations): mean {e['mean']:.3f}, "
                  f"median {e['median']:.3f}, p90 {e['p90']:.3f}, max {e['max']:.3f} deg; "
                  f"over {args.bound_deg} deg: {e['over_bound']}")
            print(f"  3D error: mean {summary['error_3d_mm']['mean']:.2f}, max {summary['error_3d_mm']['max']:.1f} mm; "
                  f"steps {summary['steps_mean']:.1f} a run (steps/s {summary['steps_per_second_mean']:.1f}, "
                  f"with {args.jobs} side by side)")
        for failure in failures:
            print(f"  failed: {failure}")
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
