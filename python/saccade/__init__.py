"""saccade: a simulator and human-robot interface for active-vision stereo robot heads.

The C++ library's layers as submodules (docs/python.md):

- ``saccade.geometry``: camera model (OpenCV's), calibration files, poses, triangulation
- ``saccade.head``: head description, forward and inverse kinematics
- ``saccade.scene``: scene files and the state that changes (time, joints)
- ``saccade.render``: the headless OpenGL renderer, frames as numpy arrays, batch rendering
- ``saccade.runtime``: pipelines from YAML, signals, methods, components written in Python
- ``saccade.hw``: hardware files and servo mappings of the real robot
- ``saccade.mcap``: recordings (``--record FILE.mcap``): topics, messages decoded, images as numpy
- ``saccade.envs``: Gymnasium-style environments (FixationEnv, VectorFixationEnv)

Errors are ``saccade.Error`` (a RuntimeError) and its subclasses ``InvalidArgument`` (also a
ValueError) and ``FileError`` (with ``file``, ``line`` and ``key``), carrying the C++ message.

Build the package with the project's CMake and use Debian's interpreter::

    PYTHONPATH=build/python /usr/bin/python3 -c "import saccade"
"""

import os as _os

from . import _saccade
from ._saccade import Error, FileError, InvalidArgument
from ._saccade import core, geometry, head, hw, mcap, render, runtime, scene
from ._saccade.core import Image
from .components import Component

__all__ = [
    "Component",
    "Error",
    "FileError",
    "Image",
    "InvalidArgument",
    "core",
    "geometry",
    "head",
    "hw",
    "mcap",
    "render",
    "runtime",
    "scene",
    "source_dir",
]


def source_dir() -> str:
    """The saccade checkout this package was built from (robots/, scenes/, pipelines/)."""
    return _os.environ.get("SACCADE_SOURCE_DIR", _saccade.SOURCE_DIR)


def _register_gymnasium() -> None:
    # Registers the environments with Gymnasium when it is installed (it is not a Debian
    # package: saccade.envs implements its API contract without it).
    try:
        import gymnasium  # noqa: F401
    except ImportError:
        return
    from .envs import _register

    _register()


_register_gymnasium()
