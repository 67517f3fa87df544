"""Gymnasium-style environments (docs/python.md): FixationEnv and VectorFixationEnv.

They implement Gymnasium's API contract without gymnasium installed; when it is importable,
they are ``gymnasium.Env`` and ``gymnasium.vector.VectorEnv``, their spaces are
gymnasium.spaces, and ``import saccade`` registers them as ``saccade/Fixation-v0``
(``gymnasium.make``; ``gymnasium.make_vec`` uses VectorFixationEnv, its vector entry point).
The registered ``max_episode_steps`` is the envs' default limit, 200: ``make`` puts it (or
``make(..., max_episode_steps=k)``'s k) in its TimeLimit wrapper and builds the env with no
limit of its own; ``make_vec`` passes it (or k) to VectorFixationEnv, which truncates itself.
"""

from saccade.envs.fixation import AutoresetMode, EpisodeEnded, FixationEnv, VectorFixationEnv

__all__ = ["AutoresetMode", "EpisodeEnded", "FixationEnv", "VectorFixationEnv"]

MAX_EPISODE_STEPS = 200  # FixationEnv's and VectorFixationEnv's default, and the spec's

ENV_ID = "saccade/Fixation-v0"


def _register() -> None:  # pragma: no cover - needs gymnasium
    import gymnasium

    if ENV_ID in gymnasium.registry:
        return
    gymnasium.register(
        id=ENV_ID,
        entry_point="saccade.envs.fixation:gymnasium_entry_point",
        vector_entry_point="saccade.envs.fixation:VectorFixationEnv",
        max_episode_steps=MAX_EPISODE_STEPS,
    )
