#!/usr/bin/python3
"""A random-policy rollout of the vector env: vector steps and stereo observations per second.

    PYTHONPATH=build/python /usr/bin/python3 examples/python/vector_rollout.py --num-envs 16
"""

import argparse
import time

import numpy as np

from saccade.envs import VectorFixationEnv


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--num-envs", type=int, default=16, help="heads stepped together (16)")
    parser.add_argument("--size", type=int, default=128, help="image side in pixels (128)")
    parser.add_argument("--steps", type=int, default=100, help="vector steps timed (100)")
    args = parser.parse_args()
    env = VectorFixationEnv(num_envs=args.num_envs, image_size=args.size)
    env.reset(seed=0)
    env.action_space.seed(0)
    returns = np.zeros(args.num_envs)
    start = time.perf_counter()
    for _ in range(args.steps):
        _, rewards, terminated, truncated, _ = env.step(env.action_space.sample())
        returns += rewards
    elapsed = time.perf_counter() - start
    print(f"{args.num_envs} envs x {args.steps} steps at {args.size}x{args.size} stereo: "
          f"{args.steps / elapsed:.1f} vector steps/s, "
          f"{args.steps * args.num_envs / elapsed:.0f} stereo observations/s; "
          f"mean return {returns.mean():.2f}")
    env.close()


if __name__ == "__main__":
    main()
