# tier: unit
"""Pipelines with DDS topics from Python (docs/dds.md): a component written in Python drives a
robot pipeline's head over a topic, in lockstep, as pipelines/perception.yaml drives
pipelines/robot.yaml. Both pipelines in this process, on loopback, in a DDS domain of their
own; the robot's head waits for the Python side's answer to each step."""

import os
import time

import pytest

import saccade
from conftest import path

# Cyclone reads its configuration when the first participant is made: loopback only, whatever
# the environment says (every DDS test stays on this machine).
os.environ["CYCLONEDDS_URI"] = "file://" + path("config", "dds", "loopback.xml")

SCENE = path("scenes", "portraits.yaml")
DOMAIN = 189
ZERO = {"pan": 0.0, "tilt": 0.0, "left": 0.0, "right": 0.0}


class EveryOtherStep(saccade.Component):
    """Commands pan 0.1, 0.2, ... on even steps and nothing on odd ones."""

    outputs = {"command": "head.command"}

    def step(self, context, inputs):
        if context["step"] % 2:
            return None
        pan = 0.1 * (context["step"] // 2 + 1)
        return {"command": {"time": context["time"], "positions": dict(ZERO, pan=pan),
                            "velocities": ZERO, "target_id": -1}}


saccade.runtime.register_component("test.every_other_step", EveryOtherStep)

ROBOT = f"""
clock: {{mode: simulated, step: 0.04, steps: 100}}
scene: {SCENE}
transport: {{domain: {DOMAIN}, namespace: /pytest}}
components:
  - name: head
    type: sim.head
    inputs: {{command: {{topic: head/command, lockstep: true, wait_s: 30, start_wait_s: 10}}}}
"""

BRAIN = f"""
clock: {{mode: simulated, step: 0.04, steps: 100}}
transport: {{domain: {DOMAIN}, namespace: /pytest}}
components:
  - name: brain
    type: test.every_other_step
    outputs: {{command: {{topic: head/command, lockstep: true}}}}
"""


def test_a_python_pipeline_drives_a_robot_pipeline_in_lockstep_over_dds():
    with saccade.runtime.Pipeline.from_yaml_string(BRAIN, "brain.yaml") as brain, \
            saccade.runtime.Pipeline.from_yaml_string(ROBOT, "robot.yaml") as robot:
        # The topic's reader is a component of the robot pipeline, before the head.
        assert robot.components == ["head-command-topic", "head"]
        robot.watch("head.joints")
        targets = []
        for k in range(6):
            brain.step()  # the Python side answers step k: a command, or a step mark
            start = time.monotonic()
            robot.step()  # waits for that answer (at most 30 s), then moves the head
            # The answer was there: a step without one would wait out its 30 s.
            assert time.monotonic() - start < 10.0, f"step {k} waited for its answer"
            targets.append(robot.read("head.joints")["targets"]["pan"])
        # Even steps carried a command, taken at that very step; odd steps only marked the
        # step done, and the head kept its target.
        assert targets == pytest.approx([0.1, 0.1, 0.2, 0.2, 0.3, 0.3])


def test_lockstep_only_on_head_commands_from_python_too():
    text = ROBOT.replace("inputs: {command: {topic: head/command, lockstep: true, wait_s: 30, "
                         "start_wait_s: 10}}",
                         "outputs: {joints: {topic: joint_states, lockstep: true}}")
    with pytest.raises(saccade.Error, match=r"robot.yaml:\d+: .*head.joints.lockstep: only head "
                                            r"commands \(head.command\) mark steps"):
        saccade.runtime.Pipeline.from_yaml_string(text, "robot.yaml")
