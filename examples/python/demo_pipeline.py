#!/usr/bin/python3
"""Run the demo pipeline (pipelines/demo.yaml) from Python and plot the fixation error:
the angle between each optical axis and the attended target, step by step.

    PYTHONPATH=build/python /usr/bin/python3 examples/python/demo_pipeline.py --steps 50
"""

import argparse
import math
import os

import numpy as np

import saccade


def axis_error(head, joints, p_W):
    frames = saccade.head.forward_kinematics(head, joints)
    errors = []
    for X in (frames.X_WCamLeft, frames.X_WCamRight):
        ray = p_W - X[:3, 3]
        errors.append(math.degrees(math.acos(np.clip(X[:3, 2] @ ray / np.linalg.norm(ray), -1, 1))))
    return max(errors)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--pipeline", default=os.path.join(saccade.source_dir(), "pipelines", "demo.yaml"),
                        help="pipeline YAML (pipelines/demo.yaml)")
    parser.add_argument("--steps", type=int, default=50, help="steps to run (50)")
    args = parser.parse_args()

    scene = saccade.scene.Scene.load(os.path.join(saccade.source_dir(), "scenes", "portraits.yaml"))
    errors, times = [], []
    with saccade.runtime.Pipeline.load(args.pipeline) as pipeline:
        for signal in ("head.joints", "attention.selection", "cameras.left"):
            pipeline.watch(signal)
        for step in range(args.steps):
            pipeline.step()
            joints = pipeline.read("head.joints")
            selection = pipeline.read("attention.selection")
            if joints is None or selection is None or not selection["valid"]:
                continue
            q = [joints["positions"][j] for j in ("pan", "tilt", "left", "right")]
            p_W = np.array([selection["p_W"][k] for k in ("x", "y", "z")]) \
                if isinstance(selection["p_W"], dict) else np.array(selection["p_W"])
            errors.append(axis_error(scene.head, q, p_W))
            times.append(joints["time"])
        image = pipeline.read("cameras.left")
        print(f"{args.steps} steps; last left image {image.array.shape} at t = {image.time:.2f} s")
    if errors:
        print(f"fixation error (deg): first {errors[0]:.2f}, last {errors[-1]:.2f}, "
              f"min {min(errors):.2f}")
    try:
        import matplotlib.pyplot as plt
    except ImportError:
        print("matplotlib is not installed: not plotting (apt install python3-matplotlib)")
        return
    plt.plot(times, errors)
    plt.xlabel("time (s)")
    plt.ylabel("fixation error (deg)")
    plt.show()


if __name__ == "__main__":
    main()
