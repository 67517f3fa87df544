"""Shared fixtures of the Python package's tests (tests/CMakeLists.txt runs each file under
Debian's /usr/bin/python3 with PYTHONPATH=build/python; the first line of a file names its tier)."""

import os

import pytest

import saccade

ROOT = saccade.source_dir()


def path(*parts: str) -> str:
    """A file of the checkout (robots/, scenes/, pipelines/)."""
    return os.path.join(ROOT, *parts)


@pytest.fixture(scope="session")
def popeye():
    return saccade.head.HeadDescription.from_yaml_file(path("robots", "popeye.yaml"))
