"""Gymnasium's spaces Box and Dict, for when gymnasium is not installed.

When ``gymnasium`` is importable, :func:`box` and :func:`dict_space` return the real
``gymnasium.spaces.Box`` and ``gymnasium.spaces.Dict``; otherwise these minimal classes with
the same contract: ``shape``, ``dtype``, ``low``/``high``, ``sample()`` (from the space's own
``np_random``), ``contains(x)`` / ``x in space``, ``seed(seed)``, equality.
"""

from typing import Any, Dict as TDict, Optional

import numpy as np

try:  # pragma: no cover - exercised only where gymnasium is installed
    import gymnasium as _gymnasium
except ImportError:
    _gymnasium = None


def _np_random(seed: Optional[int] = None):
    # gymnasium.utils.seeding.np_random: a PCG64 generator from a SeedSequence. With gymnasium
    # importable, its own function (a bad seed raises gymnasium.error.Error, as Gymnasium's
    # envs do); else the same generator, and a bad seed raises saccade.InvalidArgument.
    if _gymnasium is not None:  # pragma: no cover
        return _gymnasium.utils.seeding.np_random(seed)
    if seed is not None and not (isinstance(seed, (int, np.integer)) and seed >= 0):
        from saccade import InvalidArgument

        raise InvalidArgument(f"seed must be a non-negative integer or None, got {seed!r}")
    seed_seq = np.random.SeedSequence(seed)
    return np.random.Generator(np.random.PCG64(seed_seq)), seed_seq.entropy


class Space:
    """What Box and Dict share: the random generator of sample()."""

    def __init__(self, shape=None, dtype=None, seed: Optional[int] = None):
        self._shape = None if shape is None else tuple(shape)
        self.dtype = None if dtype is None else np.dtype(dtype)
        self._np_random = None
        if seed is not None:
            self.seed(seed)

    @property
    def shape(self):
        return self._shape

    @property
    def np_random(self) -> np.random.Generator:
        if self._np_random is None:
            self.seed()
        return self._np_random

    def seed(self, seed: Optional[int] = None):
        self._np_random, entropy = _np_random(seed)
        return [entropy]

    def __contains__(self, x: Any) -> bool:
        return self.contains(x)


class Box(Space):
    """A box in R^n: each element within [low, high] (gymnasium.spaces.Box)."""

    def __init__(self, low, high, shape=None, dtype=np.float32, seed: Optional[int] = None):
        dtype = np.dtype(dtype)
        if shape is None:
            shape = np.shape(low) if np.ndim(low) else np.shape(high)
        shape = tuple(int(n) for n in shape)
        self.low = np.full(shape, low, dtype=dtype) if np.ndim(low) == 0 else np.asarray(low, dtype)
        self.high = np.full(shape, high, dtype=dtype) if np.ndim(high) == 0 else np.asarray(high, dtype)
        if self.low.shape != shape or self.high.shape != shape:
            raise ValueError(f"Box: low {self.low.shape} and high {self.high.shape} must have shape {shape}")
        super().__init__(shape, dtype, seed)

    def sample(self, mask=None) -> np.ndarray:
        if np.issubdtype(self.dtype, np.integer):
            high = self.high.astype(np.int64) + 1
            return self.np_random.integers(self.low, high, size=self.shape).astype(self.dtype)
        low = np.where(np.isfinite(self.low), self.low, -1e6).astype(np.float64)
        high = np.where(np.isfinite(self.high), self.high, 1e6).astype(np.float64)
        return self.np_random.uniform(low, high, size=self.shape).astype(self.dtype)

    def contains(self, x: Any) -> bool:
        if not isinstance(x, np.ndarray):
            try:
                x = np.asarray(x, dtype=self.dtype)
            except (ValueError, TypeError):
                return False
        return bool(
            np.can_cast(x.dtype, self.dtype)
            and x.shape == self.shape
            and np.all(x >= self.low)
            and np.all(x <= self.high)
        )

    def __eq__(self, other) -> bool:
        return (
            isinstance(other, Box)
            and self.shape == other.shape
            and self.dtype == other.dtype
            and np.array_equal(self.low, other.low)
            and np.array_equal(self.high, other.high)
        )

    def __repr__(self) -> str:
        return f"Box({self.low.min()}, {self.high.max()}, {self.shape}, {self.dtype})"


class Dict(Space):
    """A dictionary of spaces (gymnasium.spaces.Dict); samples are dicts."""

    def __init__(self, spaces: TDict[str, Space], seed: Optional[int] = None):
        self.spaces = dict(spaces)
        super().__init__(None, None, None)
        if seed is not None:
            self.seed(seed)

    def seed(self, seed: Optional[int] = None):
        seeds = super().seed(seed)
        for space in self.spaces.values():
            seeds += space.seed(int(self.np_random.integers(np.iinfo(np.int32).max)))
        return seeds

    def sample(self, mask=None) -> TDict[str, Any]:
        return {key: space.sample() for key, space in self.spaces.items()}

    def contains(self, x: Any) -> bool:
        return (
            isinstance(x, dict)
            and x.keys() == self.spaces.keys()
            and all(space.contains(x[key]) for key, space in self.spaces.items())
        )

    def __getitem__(self, key: str) -> Space:
        return self.spaces[key]

    def keys(self):
        return self.spaces.keys()

    def __eq__(self, other) -> bool:
        return isinstance(other, Dict) and self.spaces == other.spaces

    def __repr__(self) -> str:
        return "Dict(" + ", ".join(f"{k!r}: {v}" for k, v in self.spaces.items()) + ")"


def box(low, high, shape=None, dtype=np.float32):
    """gymnasium.spaces.Box when gymnasium is installed, else :class:`Box`."""
    if _gymnasium is not None:  # pragma: no cover
        return _gymnasium.spaces.Box(low, high, shape=shape, dtype=dtype)
    return Box(low, high, shape=shape, dtype=dtype)


def dict_space(spaces):
    """gymnasium.spaces.Dict when gymnasium is installed, else :class:`Dict`."""
    if _gymnasium is not None:  # pragma: no cover
        return _gymnasium.spaces.Dict(spaces)
    return Dict(spaces)


def batch_box(space, n: int):
    """The space of n stacked samples (gymnasium.vector.utils.batch_space for a Box)."""
    low = np.broadcast_to(space.low, (n,) + space.shape)
    high = np.broadcast_to(space.high, (n,) + space.shape)
    return box(np.array(low), np.array(high), dtype=space.dtype)


def batch_space(space, n: int):
    """Box -> stacked Box; Dict -> Dict of stacked spaces (gymnasium.vector.utils.batch_space
    itself when gymnasium is importable)."""
    if _gymnasium is not None:  # pragma: no cover
        from gymnasium.vector.utils import batch_space as gymnasium_batch_space

        return gymnasium_batch_space(space, n)
    if hasattr(space, "spaces") and isinstance(space.spaces, dict):
        return dict_space({k: batch_space(v, n) for k, v in space.spaces.items()})
    return batch_box(space, n)


def seeding_np_random(seed: Optional[int] = None):
    """gymnasium.utils.seeding.np_random: (Generator, the seed's entropy)."""
    return _np_random(seed)
