"""Components written in Python, for pipelines (saccade.runtime.register_component)."""

from typing import Any, Dict, Optional, Tuple, Union

PortSpec = Union[str, Tuple[str, bool]]


class Component:
    """Base of a pipeline component written in Python.

    Subclasses declare their ports as class or instance attributes, each port's message type
    by name (``saccade.runtime.message_types()`` lists them)::

        class Gain(saccade.Component):
            inputs = {"target": ("vision.target", True)}   # (type, required)
            outputs = {"command": "head.command"}

            def configure(self, params):                     # the pipeline file's params
                self.gain = params.get("gain", 1.0)

            def step(self, context, inputs):
                target = inputs["target"]                    # dict (JSON form) or None
                ...
                return {"command": {...}}                    # emitted to connected inputs

        saccade.runtime.register_component("py.gain", Gain)

    Inputs arrive as their messages' JSON form (dicts), images as ``saccade.Image`` (its
    ``array`` is a numpy view without a copy); an output takes the same forms, or a numpy
    array for an image (copied once into the C++ image). ``context`` is a dict with ``step``,
    ``time``, ``dt`` and ``seed``. An exception in a method fails the pipeline's step with the
    component's name and the Python message.
    """

    inputs: Dict[str, PortSpec] = {}
    outputs: Dict[str, str] = {}

    def configure(self, params: Optional[Dict[str, Any]]) -> None:
        """Receives the pipeline file's ``params`` (None when absent)."""
        if params:
            raise ValueError(
                f"{type(self).__name__} takes no params; got {sorted(params)}")

    def start(self) -> None:
        """Called once before the first step."""

    def step(self, context: Dict[str, Any], inputs: Dict[str, Any]) -> Optional[Dict[str, Any]]:
        """One tick: returns {output: message} to emit (or None)."""
        raise NotImplementedError

    def stop(self) -> None:
        """Called once after the last step."""
