#!/usr/bin/python3
"""Benchmarks of the Python package (docs/python.md; figures in bench/baselines/):

1. VectorFixationEnv steps per second with 128 x 128 stereo observations for N = 1, 4, 16,
   64 heads (one batch render per step), and the cost per stereo observation;
2. one FixationEnv step through Python against the same step in C++ (build/bin/env_step_bench:
   the action checked, joints moved, forward kinematics, both eyes drawn through
   RenderBatch), on the same scene and the same objects: each side in a fresh process,
   --step-rounds rounds in turn, every round printed and the median of their overheads (the
   same render costs 0.12-0.16 ms from one process to the next).

    PYTHONPATH=build/python /usr/bin/python3 bench/python_env_bench.py [--sizes 1 4 16 64]
"""

import argparse
import json
import math
import os
import statistics
import subprocess
import sys
import tempfile
import time

import numpy as np

import saccade
from saccade.envs import FixationEnv, VectorFixationEnv


def vector_rate(n: int, size: int, scenes: int, steps: int):
    """N heads at a time over the same content for every N: the scenes of seeds 0 .. scenes - 1
    (scenes / n vector envs in turn, env i of a batch on seed first + i), each run `steps` steps
    of the same slow pan from its reset. The content moves with the steps (the pan reaches its
    limit, the objects leave the view), so a fixed time per N would compare different views;
    a fixed number of steps over the same scenes compares the cost of the same images."""
    times = []
    for first in range(0, scenes, n):
        env = VectorFixationEnv(num_envs=n, image_size=size, max_episode_steps=10**9)
        env.reset(seed=list(range(first, first + n)))
        actions = np.zeros((n, 4), np.float32)
        actions[:, 0] = 0.05  # a slow pan: every step draws a new view
        env.step(actions)  # the first draw (programs, levels of detail) untimed
        for _ in range(steps):
            t0 = time.perf_counter()
            env.step(actions)
            times.append(time.perf_counter() - t0)
        env.close()
    # The total (every view counted once) and, less sensitive to the shared machine's load, the
    # median step times the steps.
    total, median = float(np.sum(times)), float(np.median(times)) * len(times)
    observations = scenes * steps
    return observations / n / total, observations / total, observations / median


def same_layout(env: FixationEnv):
    # The C++ bench's layout (bench/env_step_bench.cc): the first three objects 2 m ahead.
    heads = env._heads
    count = heads.pool.count
    base = heads.X_WB[:3, 3]
    poses, hidden = [None] * count, [True] * count
    for i in range(min(3, count)):
        X = np.eye(4)
        X[:3, :3] = [[-1, 0, 0], [0, -1, 0], [0, 0, 1]]
        X[:3, 3] = base + np.array([2.0, -0.6 + 0.6 * i, 0.0])
        poses[i], hidden[i] = X, False
    heads.object_poses[0], heads.hidden[0] = poses, hidden
    heads.batch[0] = saccade.render.BatchHead(saccade.scene.SceneState(), poses, hidden)
    heads.target[0] = poses[0][:3, 3]
    heads.joints[0] = 0.0


def python_step_ms(size: int, repetitions: int = 30, seconds: float = 0.1) -> float:
    # As env_step_bench: the mean of each short repetition, the least disturbed one kept.
    env = FixationEnv(image_size=size, max_episode_steps=10**9)
    env.reset(seed=0)
    same_layout(env)
    action = np.array([0.1, -0.05, 0.02, -0.02], np.float32)
    for _ in range(5):
        env.step(action)
    best = math.inf
    for _ in range(repetitions):
        steps = 0
        start = time.perf_counter()
        while time.perf_counter() - start < seconds:
            env.step(action)
            steps += 1
        best = min(best, 1000.0 * (time.perf_counter() - start) / steps)
    env.close()
    return best


def cpp_step_ms(size: int, binary: str) -> float:
    env = FixationEnv(image_size=size)
    with tempfile.NamedTemporaryFile("w", suffix=".yaml", delete=False) as scene:
        scene.write(env._heads.pool.yaml)
    env.close()
    try:
        result = subprocess.run(
            [binary, "--benchmark_format=json", "--benchmark_filter=BM_FixationEnvStep"],
            check=True, capture_output=True, text=True,
            env=dict(os.environ, SACCADE_ENV_SCENE=scene.name))
    finally:
        os.unlink(scene.name)
    report = [b for b in json.loads(result.stdout)["benchmarks"] if b.get("aggregate_name") == "min"][0]
    return report["real_time"] if report["time_unit"] == "ms" else report["real_time"] / 1e6


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--sizes", type=int, nargs="*", default=[1, 4, 16, 64],
                        help="batch sizes N (1 4 16 64)")
    parser.add_argument("--image", type=int, default=128, help="image side in pixels (128)")
    parser.add_argument("--scenes", type=int, default=64,
                        help="scenes (seeds 0 .. N-1) every batch size covers: a multiple of each size")
    parser.add_argument("--steps", type=int, default=100, help="steps from each reset, timed")
    parser.add_argument("--rounds", type=int, default=2, help="alternating rounds (the best is kept)")
    parser.add_argument("--cpp", default=os.path.join(saccade.source_dir(), "build", "bin", "env_step_bench"),
                        help="the C++ step bench (build/bin/env_step_bench)")
    parser.add_argument("--step-rounds", type=int, default=5,
                        help="rounds of the Python / C++ step comparison, each a fresh process a side (5)")
    parser.add_argument("--python-step", type=int, metavar="SIZE",
                        help="only time one FixationEnv step of SIZE x SIZE eyes in this process and "
                             "print its ms (what each round of the comparison runs)")
    args = parser.parse_args()
    if args.python_step is not None:
        print(f"{python_step_ms(args.python_step):.4f}")
        return
    for n in args.sizes:
        if n < 1 or args.scenes % n:
            parser.error(f"--scenes {args.scenes} is not a multiple of the batch size {n}")

    renderer = saccade.render.Renderer(FixationEnv(image_size=8)._heads.scene, cameras=["left"])
    print(f"device: {renderer.device}")
    print(f"\nVectorFixationEnv, {args.image}x{args.image} stereo, the same {args.scenes} scenes and "
          f"{args.steps} steps from each reset for every N, best of {args.rounds} rounds:")
    print("| N | vector steps/s | stereo obs/s | ms per stereo obs | vs N = 1 | obs/s (median step) |")
    print("|---|---|---|---|---|---|")
    best = {n: (0.0, 0.0, 0.0) for n in args.sizes}
    for _ in range(args.rounds):
        for n in args.sizes:
            result = vector_rate(n, args.image, args.scenes, args.steps)
            if result[1] > best[n][1]:
                best[n] = result
    base = 1000.0 / best[args.sizes[0]][1]
    for n in args.sizes:
        steps, obs, obs_median = best[n]
        print(f"| {n} | {steps:.1f} | {obs:.0f} | {1000.0 / obs:.2f} | {1000.0 / obs / base:.2f} | {obs_median:.0f} |")

    if os.path.exists(args.cpp):
        # Each side in a process of its own, in turn: a process's renderer is a little faster or
        # slower than the next one's (0.12-0.16 ms for the same batch render), so one process
        # a side would compare two draws of that lottery; pairs of fresh ones compare its spread.
        print(f"\nFixationEnv.step, {args.image}x{args.image} stereo, same scene and objects, "
              f"a fresh process each side and round (least disturbed of 30 x 0.1 s each):")
        print("| round | Python ms | C++ ms | Python overhead |")
        print("|---|---|---|---|")
        overheads = []
        for round_ in range(args.step_rounds):
            p = float(subprocess.run(
                [sys.executable, os.path.abspath(__file__), "--python-step", str(args.image)],
                check=True, capture_output=True, text=True).stdout.split()[-1])
            c = cpp_step_ms(args.image, args.cpp)
            overheads.append(100.0 * (p - c) / c)
            print(f"| {round_ + 1} | {p:.3f} | {c:.3f} | {overheads[-1]:+.1f} % |")
        print(f"Python overhead: median {statistics.median(overheads):+.1f} % "
              f"({min(overheads):+.1f} to {max(overheads):+.1f} %, {len(overheads)} rounds)")
    else:
        print(f"\n{args.cpp} not built: no C++ comparison (cmake --build build --target env_step_bench)")


if __name__ == "__main__":
    main()
