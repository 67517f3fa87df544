#!/usr/bin/python3
"""Fixate a point with inverse kinematics and show both eyes (matplotlib if installed, else
PNG-free text output).

    PYTHONPATH=build/python /usr/bin/python3 examples/python/fixate_ik.py [--save both.npy]
"""

import argparse
import math
import os

import numpy as np

import saccade


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--scene", default=os.path.join(saccade.source_dir(), "scenes", "portraits.yaml"),
                        help="scene YAML (scenes/portraits.yaml)")
    parser.add_argument("--object", default=None, help="object to fixate (default: the first)")
    parser.add_argument("--save", default=None, help="save both eyes side by side as .npy")
    args = parser.parse_args()

    scene = saccade.scene.Scene.load(args.scene)
    state = scene.initial_state()
    name = args.object or scene.objects[0].name
    target = scene.object_pose(name, state)[:3, 3]
    result = saccade.head.solve_fixation(scene.head, target)
    print(f"fixating '{name}' at {np.round(target, 3)} m: {result.reachability}, "
          f"joints (deg) {np.round(np.degrees(np.asarray(result.joints)), 2)}, "
          f"axis error {math.degrees(result.axis_error):.2e} deg")
    state.joints = result.joints
    renderer = saccade.render.Renderer(scene, cameras=["left", "right"])
    left, right = renderer.render(state)
    both = np.concatenate([left.color, right.color], axis=1)
    # The target lands on both principal points: print where each eye sees it.
    for frame in (left, right):
        X_CW = np.linalg.inv(frame.image.X_WC)
        uv = frame.image.camera_model.project((X_CW @ np.append(target, 1.0))[:3])
        print(f"{frame.image.camera}: target at pixel {np.round(uv, 2)}, "
              f"principal point {np.round(frame.image.K[:2, 2], 2)}")
    if args.save:
        np.save(args.save, both)
    try:
        import matplotlib.pyplot as plt
    except ImportError:
        print("matplotlib is not installed: not showing the images (apt install python3-matplotlib)")
        return
    plt.imshow(both)
    plt.title(f"left | right, fixating {name}")
    plt.axis("off")
    plt.show()


if __name__ == "__main__":
    main()
