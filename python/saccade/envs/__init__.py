"""Gymnasium-style environments (docs/python.md): FixationEnv and VectorFixationEnv.

They implement Gymnasium's API contract without gymnasium installed; when it is, their
spaces are gymnasium.spaces and ``import saccade`` registers them as ``saccade/Fixation-v0``
(``gymnasium.make``; ``gymnasium.make_vec`` uses VectorFixationEnv, its vector entry point).
"""

from saccade.envs.fixation import AutoresetMode, FixationEnv, VectorFixationEnv

__all__ = ["AutoresetMode", "FixationEnv", "VectorFixationEnv"]

ENV_ID = "saccade/Fixation-v0"


def _register() -> None:  # pragma: no cover - needs gymnasium
    import gymnasium

    if ENV_ID in gymnasium.registry:
        return
    gymnasium.register(
        id=ENV_ID,
        entry_point="saccade.envs.fixation:FixationEnv",
        vector_entry_point="saccade.envs.fixation:VectorFixationEnv",
        max_episode_steps=None,
    )
