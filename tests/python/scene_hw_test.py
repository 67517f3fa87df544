# tier: unit
"""saccade.scene and saccade.hw: scene files, state, hardware files, servo mappings."""

import numpy as np
import pytest

import saccade
from conftest import path


def test_load_portraits_scene():
    scene = saccade.scene.Scene.load(path("scenes", "portraits.yaml"))
    names = [o.name for o in scene.objects]
    assert len(names) >= 4
    assert {c.name for c in scene.cameras} >= {"left", "right"}
    state = scene.initial_state()
    X = scene.camera_pose("left", state)
    assert X.shape == (4, 4) and np.allclose(X[:3, :3] @ X[:3, :3].T, np.eye(3))
    assert scene.object_pose(names[0], state).shape == (4, 4)
    assert scene.head is not None


def test_bad_scene_raises_file_error_with_file_line_and_key():
    text = "objects:\n  - name: a\n    kind: box\n    size: [1, 2]\n"
    with pytest.raises(saccade.FileError) as error:
        saccade.scene.Scene.from_yaml_string(text, "bad_scene.yaml", ".")
    message = str(error.value)
    assert message.startswith("bad_scene.yaml:4:"), message
    assert error.value.line == 4
    assert "size" in error.value.key


def test_unknown_camera_is_named():
    scene = saccade.scene.Scene.load(path("scenes", "portraits.yaml"))
    with pytest.raises(saccade.InvalidArgument, match="nose"):
        scene.camera_pose("nose", scene.initial_state())


def test_hardware_file_swaps_the_robot():
    sim = saccade.hw.read_pipeline_spec(path("pipelines", "demo.yaml"))
    robot = saccade.hw.read_pipeline_spec(path("pipelines", "demo.yaml"),
                                          hardware=path("pipelines", "hardware", "robot.yaml"))
    types = lambda spec: {c["name"]: c["type"] for c in spec["components"]}  # noqa: E731
    assert types(sim)["head"] == "sim.head"
    assert types(robot)["head"] == "hw.head"
    assert robot["hardware_file"].endswith("robot.yaml")


def test_missing_hardware_file_is_a_file_error():
    with pytest.raises(saccade.FileError, match="nowhere.yaml"):
        saccade.hw.read_pipeline_spec(path("pipelines", "demo.yaml"), hardware="nowhere.yaml")


def test_servo_mapping_round_trip(popeye):
    servo = saccade.hw.servo_mapping(popeye, "tilt")
    assert servo is not None and servo.id == 2
    assert servo.joint_angle(servo.servo_angle(0.3)) == pytest.approx(0.3)
    with pytest.raises(saccade.InvalidArgument, match="elbow"):
        saccade.hw.servo_mapping(popeye, "elbow")
