# tier: unit
"""saccade.mcap.Reader on a recording nobody here wrote: an MCAP file written by Foxglove's
@mcap/core with ROS 2 messages serialized by @foxglove/rosmsg2-serialization (the schemas from
common_interfaces' definitions), as a ROS 2 recorder writes one
(tests/record/mcap_reference/ros2_sample.mjs). Every message comes back decoded, an image's
pixels as a numpy array of its height, width and channels, rows re-packed from its step."""

import json
import os
import subprocess

import numpy as np
import pytest

import saccade

SCRIPT = os.path.join(saccade.source_dir(), "tests", "record", "mcap_reference", "ros2_sample.mjs")


def header(sec, nanosec, frame):
    return {"stamp": {"sec": sec, "nanosec": nanosec}, "frame_id": frame}


@pytest.fixture(scope="module")
def recording(tmp_path_factory):
    rng = np.random.default_rng(5)
    rgb = rng.integers(0, 256, size=(3, 4, 3), dtype=np.uint8)
    # Each row padded to 16 bytes (step > width * 3), as some drivers send them.
    padded = np.zeros((3, 16), dtype=np.uint8)
    padded[:, :12] = rgb.reshape(3, 12)
    depth = np.array([[1, 2], [65535, 256]], dtype="<u2")
    inputs = [
        {"topic": "/cam/image_raw", "type": "sensor_msgs/Image",
         "message": {"header": header(1, 5, "cam_optical"), "height": 3, "width": 4,
                     "encoding": "rgb8", "is_bigendian": 0, "step": 16,
                     "data": {"bytes": padded.ravel().tolist()}}},
        {"topic": "/joint_states", "type": "sensor_msgs/JointState",
         "message": {"header": header(1, 40000000, ""), "name": ["pan", "tilt"],
                     "position": [0.25, -1e-9], "velocity": [], "effort": []}},
        {"topic": "/faces", "json": {"faces": [{"box": [1, 2, 3, 4]}], "time": 0.08}},
        {"topic": "/depth", "type": "sensor_msgs/Image",
         "message": {"header": header(2, 0, "cam_optical"), "height": 2, "width": 2,
                     "encoding": "16UC1", "is_bigendian": 0, "step": 4,
                     "data": {"bytes": list(depth.tobytes())}}},
    ]
    folder = tmp_path_factory.mktemp("mcap")
    spec = folder / "inputs.json"
    spec.write_text(json.dumps(inputs))
    out = folder / "foxglove.mcap"
    subprocess.run(["node", SCRIPT, str(spec), str(out)], check=True)
    return out, rgb, depth


def test_the_reader_decodes_every_message_of_a_foreign_recording(recording):
    path, rgb, depth = recording
    reader = saccade.mcap.Reader(str(path))
    assert reader.complete
    assert reader.topics == {"/cam/image_raw": "sensor_msgs/msg/Image",
                             "/joint_states": "sensor_msgs/msg/JointState",
                             "/faces": "json", "/depth": "sensor_msgs/msg/Image"}
    assert reader.statistics["messages"] == 4
    messages = list(reader.messages())
    assert [m.topic for m in messages] == ["/cam/image_raw", "/joint_states", "/faces", "/depth"]
    image = messages[0].value
    assert image["header"] == header(1, 5, "cam_optical")
    assert image["data"].shape == (3, 4, 3) and image["data"].dtype == np.uint8
    np.testing.assert_array_equal(image["data"], rgb)
    joints = messages[1]
    assert joints.value["name"] == ["pan", "tilt"]
    assert joints.value["position"] == [0.25, -1e-9]
    assert joints.log_time == pytest.approx(0.04)
    assert messages[2].type == "json" and messages[2].value["faces"][0]["box"] == [1, 2, 3, 4]
    assert messages[3].value["data"].dtype == np.dtype("<u2")
    np.testing.assert_array_equal(messages[3].value["data"], depth)
    only = [m.topic for m in reader.messages(topics=["/joint_states"])]
    assert only == ["/joint_states"]


def test_a_file_that_is_not_a_recording_raises_file_error(tmp_path):
    bad = tmp_path / "bad.mcap"
    bad.write_text("hello")
    with pytest.raises(saccade.FileError, match="not an MCAP file"):
        saccade.mcap.Reader(str(bad))
