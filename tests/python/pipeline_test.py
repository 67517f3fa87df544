# tier: unit
"""saccade.runtime: pipelines from YAML stepped from Python, signals, methods, and a component
written in Python whose outputs reach a C++ component (sim.head, no rendering)."""

import math

import numpy as np
import pytest

import saccade
from conftest import path

SCENE = path("scenes", "portraits.yaml")


class Commander(saccade.Component):
    """Commands the pan joint to a target and records the joints it is sent back."""

    inputs = {"joints": "head.joints"}
    outputs = {"command": "head.command", "seen": "runtime.value"}

    def configure(self, params):
        self.pan = float(params["pan"])
        self.received = []

    def step(self, context, inputs):
        joints = inputs["joints"]
        if joints is not None:
            self.received.append(joints["positions"]["pan"])
        zero = {"pan": 0.0, "tilt": 0.0, "left": 0.0, "right": 0.0}
        command = {"time": context["time"], "positions": dict(zero, pan=self.pan),
                   "velocities": zero, "target_id": -1}
        return {"command": command, "seen": {"value": float(len(self.received))}}


class Failing(saccade.Component):
    outputs = {"out": "runtime.value"}

    def step(self, context, inputs):
        if context["step"] == 2:
            raise RuntimeError("the Python component broke")
        return {"out": {"value": 1.0}}


saccade.runtime.register_component("test.commander", Commander, "commands the pan joint")
saccade.runtime.register_component("test.failing", Failing)


def loop(pan=0.5, extra=""):
    return f"""
clock: {{mode: simulated, step: 0.04, steps: 100}}
scene: {SCENE}
components:
  - name: brain
    type: test.commander
    params: {{pan: {pan}}}
    inputs: {{joints: {{from: head.joints, delay: 1}}}}
  - name: head
    type: sim.head
    inputs: {{command: brain.command}}
{extra}"""


def test_python_component_receives_signals_and_drives_a_cpp_component():
    with saccade.runtime.Pipeline.from_yaml_string(loop(), "loop.yaml") as pipeline:
        assert pipeline.components == ["brain", "head"]
        assert "test.commander" in saccade.runtime.component_types()
        pipeline.watch("head.joints")
        assert pipeline.read("brain.seen") is None  # watched from now on, nothing yet
        pipeline.step(40)
        joints = pipeline.read("head.joints")
        # sim.head (C++) moved the pan joint to the Python component's command.
        assert joints["positions"]["pan"] == pytest.approx(0.5, abs=1e-6)
        assert joints["targets"]["pan"] == pytest.approx(0.5)
        brain = pipeline.python_component("brain")
        # ... and the Python component received sim.head's joints, delayed by one step.
        assert len(brain.received) == 39
        assert brain.received[0] < brain.received[-1] == pytest.approx(0.5, abs=1e-6)
        assert pipeline.read("brain.seen") == {"value": 39.0}
        assert pipeline.count("head.joints") == 40
        assert pipeline.steps_done == 40


def test_describe_and_unknown_signal():
    with saccade.runtime.Pipeline.from_yaml_string(loop(), "loop.yaml") as pipeline:
        description = pipeline.describe("head")
        assert description["inputs"] == {"command": "head.command"}
        assert description["outputs"]["joints"] == "head.joints"
        with pytest.raises(saccade.InvalidArgument, match="no output 'elbow'.*joints"):
            pipeline.read("head.elbow")
        with pytest.raises(saccade.InvalidArgument, match="brain, head"):
            pipeline.read("nose.joints")


def test_methods_are_called_by_name_with_dict_requests():
    text = f"""
clock: {{mode: simulated, step: 0.04, steps: 10}}
scene: {SCENE}
components:
  - name: head
    type: hw.head
    params: {{driver: simulated}}
"""
    with saccade.runtime.Pipeline.from_yaml_string(text, "hw.yaml") as pipeline:
        assert "move" in pipeline.describe("head")["methods"]
        pipeline.step(1)
        zero = {"pan": 0.0, "tilt": 0.0, "left": 0.0, "right": 0.0}
        reply = pipeline.call("head", "move", {"time": 0.0, "positions": dict(zero, pan=0.2),
                                               "velocities": zero, "target_id": -1})
        assert reply["targets"]["pan"] == pytest.approx(0.2)
        state = pipeline.call("head", "state")
        assert set(state["positions"]) == {"pan", "tilt", "left", "right"}
        with pytest.raises(saccade.Error, match="no_such_method"):
            pipeline.call("head", "no_such_method", {})
        with pytest.raises(saccade.Error, match="move"):
            pipeline.call("head", "move", {"positions": "nowhere"})


def test_python_exception_fails_the_step_naming_component_and_step():
    text = f"""
clock: {{mode: simulated, step: 0.04, steps: 10}}
components:
  - name: broken
    type: test.failing
"""
    pipeline = saccade.runtime.Pipeline.from_yaml_string(text, "fail.yaml")
    pipeline.step(2)
    with pytest.raises(saccade.Error, match="component 'broken' failed at step 2:.*the Python component broke"):
        pipeline.step(1)
    pipeline.close()


@pytest.mark.parametrize("on_error, threads, head_steps", [
    ("stop", 1, 2),      # one after the other: the step ends at the failing component
    ("stop", 2, 3),      # one level at the same time: head, beside it, finishes its step
    ("continue", 1, 3),  # the step goes on; the failure is raised after it
])
def test_a_failing_step_ends_as_the_schedulers_does(on_error, threads, head_steps):
    # Pipeline.step is the scheduler's step (runtime::Stepper): its threads and its on_error.
    text = f"""
clock: {{mode: simulated, step: 0.04, steps: 10}}
on_error: {on_error}
threads: {threads}
scene: {SCENE}
components:
  - name: broken
    type: test.failing
  - name: head
    type: sim.head
"""
    with saccade.runtime.Pipeline.from_yaml_string(text, "fail.yaml") as pipeline:
        pipeline.watch("head.joints")
        with pytest.raises(saccade.Error, match="component 'broken' failed at step 2:"):
            pipeline.step(5)
        assert pipeline.steps_done == 3
        assert pipeline.count("head.joints") == head_steps
        pipeline.step(2)  # a failed step does not end the pipeline
        assert pipeline.steps_done == 5
        assert pipeline.count("head.joints") == head_steps + 2


def test_bad_pipeline_file_raises_file_error_with_line():
    text = loop(extra="  - name: extra\n    type: no.such_type\n")
    with pytest.raises(saccade.FileError) as error:
        saccade.runtime.Pipeline.from_yaml_string(text, "bad_pipeline.yaml")
    assert str(error.value).startswith("bad_pipeline.yaml:")
    assert "no.such_type" in str(error.value)
    assert error.value.line > 1


def test_python_component_with_unknown_message_type_is_refused():
    class Odd(saccade.Component):
        outputs = {"x": "no.such_message"}

        def step(self, context, inputs):
            return None

    saccade.runtime.register_component("test.odd", Odd)
    text = "clock: {mode: simulated, step: 0.04, steps: 1}\ncomponents:\n  - {name: odd, type: test.odd}\n"
    with pytest.raises(saccade.Error, match="no.such_message.*head.command"):
        saccade.runtime.Pipeline.from_yaml_string(text, "odd.yaml")


def test_bad_output_value_names_the_output():
    class Bad(saccade.Component):
        outputs = {"command": "head.command"}

        def step(self, context, inputs):
            return {"command": {"time": "noon"}}

    saccade.runtime.register_component("test.bad_output", Bad)
    text = "clock: {mode: simulated, step: 0.04, steps: 1}\ncomponents:\n  - {name: bad, type: test.bad_output}\n"
    with saccade.runtime.Pipeline.from_yaml_string(text, "bad.yaml") as pipeline:
        with pytest.raises(saccade.Error, match="output 'command': not a head.command"):
            pipeline.step()
