"""Fixation: bring a chosen target onto both optical axes of the stereo head.

``FixationEnv`` (one head) and ``VectorFixationEnv`` (N heads rendered in one batch) follow
Gymnasium's API contract exactly, without needing gymnasium (docs/python.md). When gymnasium
is importable they are ``gymnasium.Env`` and ``gymnasium.vector.VectorEnv`` (so
``gymnasium.make``, its wrappers and ``check_env`` take them), and both pickle (rebuilt from
their constructor arguments, then their state):

- ``reset(*, seed=None, options=None) -> (obs, info)``; ``step(action) -> (obs, reward,
  terminated, truncated, info)``; ``render()``; ``close()``;
- ``observation_space`` / ``action_space`` (gymnasium.spaces when gymnasium is installed);
  ``metadata`` with ``render_modes`` and ``render_fps``; ``render_mode`` fixed at construction;
- ``np_random`` seeded by ``reset(seed=...)`` as gymnasium.utils.seeding does: two
  ``reset(seed=123)`` give the same observations, and the same actions the same steps;
- the vector env: ``num_envs``, ``single_observation_space``, ``single_action_space``,
  batched spaces, ``metadata["autoreset_mode"]`` (next step by default, same step, disabled).

The head is POPEYE unless ``head=`` names another: a shipped head (``"humanoid"``,
``"pan_tilt_vergence"``, ``"pan_tilt_fixed"``, ``"popeye_urdf"``: ``robots/<name>.yaml``) or the
path of any head file (docs/formats.md). The env's joints are the head's driven joints, in its
order (``env.joint_names``); joints the head file holds stay at their value.

Observations: ``{"left": HxWx3 uint8, "right": HxWx3 uint8, "joints": K float32}``, K driven
joints (POPEYE: pan, tilt, left, right in rad). Actions (K float32): joint velocities in rad/s
(``action_mode="velocity"``, within each joint's velocity limit) or joint targets in rad
(``"target"``, within the joint limits, approached at the joints' maximum velocity). An action outside the action space, of
another shape, or not finite is refused with saccade.InvalidArgument (a ValueError).

Reward: minus the mean angle (rad) between each camera's optical axis and the ray from that
camera to the target's centre (a head that cannot verge scores each camera's axis too, so its
best is pointing midway); +1 and ``terminated`` once both angles are below
``success_deg``. ``truncated`` after ``max_episode_steps``.

Scenes are randomised from the seed at each reset: which of a pool of objects appear
(pictures, boxes, spheres, the mug when installed), where (in front of the head, 1 to 3 m),
their colours' placement, which one is the target, and the head's start joints. The pool,
the lights and the ground are fixed when the env is made (``scene_seed`` varies the lights).
"""

import enum
import math
import os
from typing import Any, Dict, List, Optional, Sequence, Tuple, Union

import numpy as np

import saccade
from saccade.envs import spaces

try:  # pragma: no cover - exercised only where gymnasium is importable
    import gymnasium as _gymnasium
    from gymnasium.vector import VectorEnv as _VectorEnvBase

    _EnvBase = _gymnasium.Env
except ImportError:
    _gymnasium = None
    _EnvBase = object
    _VectorEnvBase = object

JOINTS = ("pan", "tilt", "left", "right")  # POPEYE's, the default head's


def head_file(head: Optional[str]) -> str:
    """The head file of ``head=``: None (POPEYE), a shipped head's name, or a path."""
    robots = os.path.join(saccade.source_dir(), "robots")
    if head is None:
        return os.path.join(robots, "popeye.yaml")
    head = os.fspath(head)
    if os.sep not in head and not head.endswith((".yaml", ".yml")):
        path = os.path.join(robots, head + ".yaml")
        if not os.path.isfile(path):
            shipped = sorted(f[:-5] for f in os.listdir(robots) if f.endswith(".yaml"))
            raise saccade.InvalidArgument(
                f"head={head!r}: no shipped head of that name; shipped: {', '.join(shipped)} "
                "(or give a head file's path)")
        return path
    if not os.path.isfile(head):
        raise saccade.InvalidArgument(f"head={head!r}: no such head file")
    return os.path.abspath(head)


class EpisodeEnded(saccade.Error, AssertionError):
    """step() of a vector env in AutoresetMode.DISABLED while a sub-env's episode has ended and
    was not reset (an AssertionError too, as gymnasium.vector.SyncVectorEnv raises there)."""


class AutoresetMode(enum.Enum):
    """When a vector env resets a sub-environment that ended (gymnasium.vector.AutoresetMode)."""

    NEXT_STEP = "NextStep"  # the step after the end returns the reset observation
    SAME_STEP = "SameStep"  # the ending step returns the reset observation; final_obs in info
    DISABLED = "Disabled"  # reset(options={"reset_mask": mask}) by the caller


def _gymnasium_autoreset(mode: AutoresetMode):
    try:
        from gymnasium.vector import AutoresetMode as GymMode  # pragma: no cover
    except ImportError:
        return mode
    return GymMode(mode.value)  # pragma: no cover


def _asset(name: str) -> Optional[str]:
    path = os.path.join(saccade.source_dir(), "assets", name)
    return path if os.path.exists(path) else None


class _Pool:
    """The objects a scene may show, and the scene YAML that holds all of them."""

    COLORS = [
        (0.85, 0.15, 0.15), (0.15, 0.7, 0.2), (0.2, 0.3, 0.9), (0.9, 0.8, 0.1),
        (0.8, 0.3, 0.8), (0.1, 0.8, 0.8),
    ]

    def __init__(self, image_size: Tuple[int, int], fov_deg: float, scene_seed: int, head: str):
        width, height = image_size
        rng = np.random.default_rng(scene_seed)
        f = 0.5 * width / math.tan(math.radians(fov_deg) / 2)
        camera = f"{{calibration: {{width: {width}, height: {height}, fx: {f:.6f}, fy: {f:.6f}}}}}"
        light_dir = [float(rng.uniform(-0.6, 0.6)), float(rng.uniform(-0.6, 0.6)), -1.0]
        lines = [
            "background: [0.62, 0.72, 0.82]",
            "lights:",
            f"  - {{type: ambient, intensity: {rng.uniform(0.3, 0.45):.3f}}}",
            f"  - {{type: directional, direction: {light_dir}, intensity: {rng.uniform(0.6, 0.9):.3f}}}",
            "ground: {size: 16, pattern: checker, cell: 0.5}",
            "robot:",
            f"  head: {head}",
            "  visible: false",
            f"  cameras: {{left: {camera}, right: {camera}}}",
            "objects:",
        ]
        self.kinds: List[str] = []
        self.half_heights: List[float] = []
        for i, picture in enumerate(("astronaut.png", "chelsea.png")):
            path = _asset(picture)
            if path:
                lines.append(f"  - {{name: picture{i}, kind: picture, image: {path}, height: 0.5}}")
                self.kinds.append("picture")
                self.half_heights.append(0.25)
        mug = _asset("mug/mug.obj")
        if mug:
            # Y-up in its file: the env's poses stand it upright (randomise).
            lines.append(f"  - {{name: mug, kind: model, file: {mug}, unit_scale: 0.01}}")
            self.kinds.append("mug")
            self.half_heights.append(0.05)
        for i, color in enumerate(self.COLORS):
            c = list(color) + [1.0]
            if i % 2 == 0:
                lines.append(f"  - {{name: box{i}, kind: box, size: 0.25, color: {c}}}")
                self.kinds.append("box")
            else:
                lines.append(f"  - {{name: sphere{i}, kind: sphere, radius: 0.14, color: {c}}}")
                self.kinds.append("sphere")
            self.half_heights.append(0.13)
        self.yaml = "\n".join(lines) + "\n"
        self.scene = saccade.scene.Scene.from_yaml_string(self.yaml, "<FixationEnv scene>", ".")
        self.count = len(self.kinds)


class _Heads:
    """N heads' state, their randomisation, dynamics and rewards (numpy, vectorised)."""

    def __init__(self, n: int, image_size, action_mode: str, max_episode_steps: int,
                 success_deg: float, dt: float, fov_deg: float, scene_seed: int,
                 head: Optional[str]):
        if action_mode not in ("velocity", "target"):
            raise saccade.InvalidArgument(
                f"action_mode must be 'velocity' or 'target', got {action_mode!r}")
        if isinstance(image_size, (int, np.integer)):
            image_size = (int(image_size), int(image_size))
        image_size = tuple(int(v) for v in image_size)
        if len(image_size) != 2 or min(image_size) < 8 or max(image_size) > 2048:
            raise saccade.InvalidArgument(
                f"image_size must be a side or (width, height), each 8..2048, got {image_size}")
        if max_episode_steps is not None and not (
                isinstance(max_episode_steps, (int, np.integer)) and max_episode_steps >= 1):
            raise saccade.InvalidArgument(
                f"max_episode_steps must be an integer >= 1 or None (no limit), got "
                f"{max_episode_steps!r}")
        if not (0 < success_deg < 90):
            raise saccade.InvalidArgument(f"success_deg must be in (0, 90), got {success_deg}")
        if not (0 < dt <= 1):
            raise saccade.InvalidArgument(f"dt must be in (0, 1] s, got {dt}")
        self.n = n
        self.width, self.height = image_size
        self.action_mode = action_mode
        self.max_episode_steps = None if max_episode_steps is None else int(max_episode_steps)
        self.step_limit = math.inf if max_episode_steps is None else int(max_episode_steps)
        self.success = math.radians(success_deg)
        self.dt = float(dt)
        self.pool = _Pool(image_size, fov_deg, scene_seed, head_file(head))
        self.scene = self.pool.scene
        self.head = self.scene.head
        # The env's joints: the head's driven ones; the held ones stay at home in `posture`.
        driven = set(self.head.driven_joints)
        self.driven = np.array([j for j, name in enumerate(self.head.joint_names) if name in driven])
        self.joint_names = [self.head.joint_names[j] for j in self.driven]
        self.joint_min = self.head.limits_min[self.driven]
        self.joint_max = self.head.limits_max[self.driven]
        self.max_velocity = self.head.max_velocity[self.driven]
        self.posture = np.tile(self.head.home(), (n, 1))
        self.all_driven = len(self.driven) == self.head.num_joints
        # POPEYE's four joints go to C++ as a sequence; any other head's by name.
        self.by_name = self.head.joint_names != list(JOINTS)
        self.renderer = saccade.render.Renderer(
            self.scene, cameras=["left", "right"], draw_robot=False, distortion=False,
            noise=False, motion_blur=False)
        self.X_WB = self.head.X_WB
        self.joints = np.zeros((n, len(self.driven)))
        self.steps = np.zeros(n, dtype=np.int64)
        self.object_poses: List[List[Optional[np.ndarray]]] = [[None] * self.pool.count for _ in range(n)]
        self.hidden = [[True] * self.pool.count for _ in range(n)]
        self.batch: List[Any] = [None] * n
        self.target = np.zeros((n, 3))
        self.target_index = np.zeros(n, dtype=np.int64)
        self.axis_error = np.zeros((n, 2))
        self._bounds_tolerant: Optional[Tuple[np.ndarray, np.ndarray]] = None  # check_actions

    # -- spaces ---------------------------------------------------------------------------
    def observation_space(self):
        image = spaces.box(0, 255, shape=(self.height, self.width, 3), dtype=np.uint8)
        image2 = spaces.box(0, 255, shape=(self.height, self.width, 3), dtype=np.uint8)
        joints = spaces.box(self.joint_min.astype(np.float32), self.joint_max.astype(np.float32),
                            dtype=np.float32)
        return spaces.dict_space({"left": image, "right": image2, "joints": joints})

    def action_space(self):
        if self.action_mode == "velocity":
            return spaces.box((-self.max_velocity).astype(np.float32),
                              self.max_velocity.astype(np.float32), dtype=np.float32)
        return spaces.box(self.joint_min.astype(np.float32), self.joint_max.astype(np.float32),
                          dtype=np.float32)

    def action_bounds(self):
        if self.action_mode == "velocity":
            return -self.max_velocity, self.max_velocity
        return self.joint_min, self.joint_max

    # -- episodes -------------------------------------------------------------------------
    def randomise(self, i: int, rng: np.random.Generator, options: Optional[Dict[str, Any]]):
        """A new scene for head i from its generator."""
        count = self.pool.count
        shown = rng.permutation(count)[: int(rng.integers(2, min(count, 5) + 1))]
        base = self.X_WB[:3, 3]
        hidden = [True] * count
        poses: List[Optional[np.ndarray]] = [None] * count
        used: List[np.ndarray] = []
        for k in shown:
            for _ in range(20):  # keep objects apart, so that none hides another whole
                distance = rng.uniform(1.0, 3.0)
                azimuth = rng.uniform(-0.5, 0.5)
                z = max(self.pool.half_heights[k] + 0.01, base[2] + rng.uniform(-0.5, 0.3))
                p = base + np.array([distance * math.cos(azimuth), distance * math.sin(azimuth), 0.0])
                p[2] = z
                if all(np.linalg.norm(p[:2] - q[:2]) > 0.45 for q in used):
                    break
            used.append(p)
            yaw = azimuth + math.pi  # pictures face the head
            c, s = math.cos(yaw), math.sin(yaw)
            X = np.eye(4)
            X[:3, :3] = np.array([[c, -s, 0], [s, c, 0], [0, 0, 1]])
            if self.pool.kinds[k] == "mug":  # the OBJ is y-up
                X[:3, :3] = X[:3, :3] @ np.array([[1, 0, 0], [0, 0, -1], [0, 1, 0]])
            X[:3, 3] = p
            poses[k] = X
            hidden[k] = False
        target = int(shown[int(rng.integers(len(shown)))])
        if options and "target" in options:
            target = int(options["target"])
            if not 0 <= target < count or hidden[target]:
                raise saccade.InvalidArgument(
                    f"reset: options['target'] = {target} is not an object shown in this scene; "
                    f"shown: {sorted(int(k) for k in shown)}")
        self.object_poses[i] = poses
        self.hidden[i] = hidden
        # Converted to C++ once per episode; each step only sets the state.
        self.batch[i] = saccade.render.BatchHead(saccade.scene.SceneState(), poses, hidden)
        self.target_index[i] = target
        self.target[i] = poses[target][:3, 3]
        if self.pool.kinds[target] == "mug":
            self.target[i][2] += 0.05  # the mug's origin is its base
        start = rng.uniform(-0.15, 0.15, size=len(self.driven)) * (self.joint_max - self.joint_min) / 2
        self.joints[i] = np.clip(start, self.joint_min, self.joint_max)
        self.steps[i] = 0
        self.update_errors(i)

    def check_actions(self, actions: np.ndarray, who: str) -> np.ndarray:
        try:
            a = np.asarray(actions, dtype=np.float64)
        except (TypeError, ValueError):
            raise saccade.InvalidArgument(
                f"{who}: the action must be numbers, got {type(actions).__name__}") from None
        k = len(self.driven)
        shape = (self.n, k) if who.startswith("Vector") else (k,)
        if a.shape != shape:
            raise saccade.InvalidArgument(
                f"{who}: the action must have shape {shape} ({', '.join(self.joint_names)}"
                f"{' per env' if len(shape) == 2 else ''}), got {a.shape}")
        low, high = self.action_bounds()
        if self._bounds_tolerant is None:
            self._bounds_tolerant = (low - 1e-6, high + 1e-6)
        ok = (a >= self._bounds_tolerant[0]) & (a <= self._bounds_tolerant[1])  # NaN fails both
        if not ok.all():
            bad = ~ok
            if not np.all(np.isfinite(a)):
                raise saccade.InvalidArgument(f"{who}: the action has a non-finite value: {actions}")
            index = np.argwhere(bad)[0]
            joint = int(index[-1])
            unit = "rad/s" if self.action_mode == "velocity" else "rad"
            raise saccade.InvalidArgument(
                f"{who}: action for joint '{self.joint_names[joint]}' is {a[tuple(index)]:.6g} {unit}; "
                f"expected [{low[joint]:.6g}, {high[joint]:.6g}] ({self.action_mode} mode)")
        return a.reshape(-1, k)

    def apply(self, rows, actions: np.ndarray):
        """Moves heads `rows` (an index array, or one index) by their actions over dt (joint
        limits, velocity limits)."""
        q = self.joints[rows]
        if self.action_mode == "velocity":
            q = q + actions * self.dt
        else:
            reach = self.max_velocity * self.dt
            q = q + np.minimum(np.maximum(actions - q, -reach), reach)
        # minimum/maximum: np.clip's checks cost more than the rest of a step.
        self.joints[rows] = np.minimum(np.maximum(q, self.joint_min), self.joint_max)
        self.steps[rows] += 1
        self.update_errors(rows)

    def update_errors(self, rows):
        """The optical axes' angles to the targets of heads `rows` (an index or an array)."""
        self.axis_error[rows] = self.head.axis_errors(self.postures(rows), self.target[rows])

    def postures(self, rows) -> np.ndarray:
        """The whole postures (every joint of the head) of heads `rows`."""
        if self.all_driven:
            return self.joints[rows]
        if np.ndim(rows) == 0:
            self.posture[rows, self.driven] = self.joints[rows]
        else:
            self.posture[np.ix_(np.asarray(rows), self.driven)] = self.joints[rows]
        return self.posture[rows]

    def outcome(self, i: int) -> Tuple[float, bool, bool]:
        left, right = self.axis_error[i].tolist()  # Python floats: numpy on two values costs more
        success = left < self.success and right < self.success
        reward = -0.5 * (left + right) + (1.0 if success else 0.0)
        return reward, success, bool(self.steps[i] >= self.step_limit)

    def render(self, rows: Sequence[int], out: np.ndarray) -> np.ndarray:
        heads = []
        for i in rows:
            head = self.batch[i]
            q = self.postures(i)
            if self.by_name:
                q = dict(zip(self.head.joint_names, q.tolist()))
            head.state = saccade.scene.SceneState(float(self.steps[i]) * self.dt, q)
            heads.append(head)
        return self.renderer.render_batch(heads, out=out)

    def state(self) -> Dict[str, Any]:
        """What changes after construction (for pickling; set_state restores it)."""
        return {
            "joints": self.joints.copy(), "steps": self.steps.copy(),
            "object_poses": [list(p) for p in self.object_poses],
            "hidden": [list(h) for h in self.hidden], "target": self.target.copy(),
            "target_index": self.target_index.copy(), "axis_error": self.axis_error.copy(),
        }

    def set_state(self, state: Dict[str, Any]):
        for key in ("joints", "steps", "target", "target_index", "axis_error"):
            getattr(self, key)[...] = state[key]
        self.object_poses = [list(p) for p in state["object_poses"]]
        self.hidden = [list(h) for h in state["hidden"]]
        for i in range(self.n):
            if all(self.hidden[i]):
                continue  # never reset
            self.batch[i] = saccade.render.BatchHead(saccade.scene.SceneState(),
                                                     self.object_poses[i], self.hidden[i])

    def info(self, i: int) -> Dict[str, Any]:
        return {
            "axis_error": self.axis_error[i].copy(),
            "target_W": self.target[i].copy(),
            "target_index": int(self.target_index[i]),
            "target_kind": self.pool.kinds[int(self.target_index[i])],
            "is_success": bool(self.axis_error[i, 0] < self.success and
                               self.axis_error[i, 1] < self.success),
        }


class FixationEnv(_EnvBase):
    """One stereo head that must fixate a target (Gymnasium's Env contract; module docstring).
    A ``gymnasium.Env`` when gymnasium is importable.

    Args:
        render_mode: None or "rgb_array" (render() returns both eyes side by side).
        image_size: the eyes' image side, or (width, height), pixels.
        action_mode: "velocity" (rad/s) or "target" (rad).
        max_episode_steps: steps before ``truncated``; None: no limit of its own (what
            ``gymnasium.make`` builds: its TimeLimit wrapper holds the registered limit).
        success_deg: both optical axes within this angle of the target ends the episode.
        dt: seconds per step (render_fps = 1 / dt).
        fov_deg: the eyes' horizontal field of view.
        scene_seed: the lights (fixed for the env's life).
        head: None (POPEYE), a shipped head's name (``robots/<name>.yaml``) or a head file's
            path (module docstring); ``joint_names`` lists the env's joints.
    """

    metadata = {"render_modes": ["rgb_array"], "render_fps": 25}

    def __init__(self, render_mode: Optional[str] = None, image_size: Union[int, Tuple[int, int]] = 64,
                 action_mode: str = "velocity", max_episode_steps: Optional[int] = 200,
                 success_deg: float = 1.0, dt: float = 0.04, fov_deg: float = 60.0,
                 scene_seed: int = 0, head: Optional[str] = None):
        if render_mode is not None and render_mode not in self.metadata["render_modes"]:
            raise saccade.InvalidArgument(
                f"render_mode must be None or one of {self.metadata['render_modes']}, got {render_mode!r}")
        self._kwargs = dict(render_mode=render_mode, image_size=image_size, action_mode=action_mode,
                            max_episode_steps=max_episode_steps, success_deg=success_deg, dt=dt,
                            fov_deg=fov_deg, scene_seed=scene_seed, head=head)
        self.render_mode = render_mode
        self._heads = _Heads(1, image_size, action_mode, max_episode_steps, success_deg, dt,
                             fov_deg, scene_seed, head)
        self.joint_names = list(self._heads.joint_names)
        self.metadata = dict(self.metadata, render_fps=int(round(1.0 / dt)))
        self.observation_space = self._heads.observation_space()
        self.action_space = self._heads.action_space()
        self.spec = None
        self._np_random: Optional[np.random.Generator] = None
        self._np_random_seed: Optional[int] = None
        self._images = np.zeros((1, 2, self._heads.height, self._heads.width, 3), np.uint8)
        self._needs_reset = True

    @property
    def np_random(self) -> np.random.Generator:
        """The env's generator (seeded by reset(seed=...), else from OS entropy)."""
        if self._np_random is None:
            self._np_random, self._np_random_seed = spaces.seeding_np_random()
        return self._np_random

    @np_random.setter
    def np_random(self, value: np.random.Generator):
        self._np_random = value
        self._np_random_seed = -1

    @property
    def np_random_seed(self) -> Optional[int]:
        if self._np_random_seed is None:
            self.np_random  # noqa: B018 - makes the generator
        return self._np_random_seed

    @property
    def unwrapped(self):
        return self

    def _observation(self) -> Dict[str, np.ndarray]:
        out = np.empty_like(self._images)
        self._heads.render([0], out)
        self._images = out
        return {"left": out[0, 0], "right": out[0, 1],
                "joints": self._heads.joints[0].astype(np.float32)}

    def reset(self, *, seed: Optional[int] = None, options: Optional[Dict[str, Any]] = None):
        """Starts an episode: a new scene and target from np_random (seeded by `seed`)."""
        if seed is not None:
            self._np_random, self._np_random_seed = spaces.seeding_np_random(seed)
        self._heads.randomise(0, self.np_random, options)
        self._needs_reset = False
        return self._observation(), self._heads.info(0)

    def step(self, action):
        """Moves the joints by `action` for dt; returns (obs, reward, terminated, truncated, info)."""
        if self._needs_reset:
            raise saccade.Error("FixationEnv.step: call reset() before the first step")
        a = self._heads.check_actions(action, "FixationEnv.step")
        self._heads.apply(0, a[0])  # an index, not an array of one: numpy's views are cheaper
        reward, terminated, truncated = self._heads.outcome(0)
        return self._observation(), reward, terminated, truncated, self._heads.info(0)

    def render(self):
        """rgb_array: the last observation's eyes side by side (H x 2W x 3); None otherwise."""
        if self.render_mode is None:
            return None
        return np.concatenate([self._images[0, 0], self._images[0, 1]], axis=1)

    def close(self):
        self._heads = None

    def __getstate__(self) -> Dict[str, Any]:
        # The renderer (a GL context) and the scene do not pickle: the constructor's arguments
        # rebuild them, then the state (episode, generators, spaces, last images) is restored.
        return {
            "kwargs": self._kwargs, "spec": self.spec,
            "heads": None if self._heads is None else self._heads.state(),
            "np_random": self._np_random, "np_random_seed": self._np_random_seed,
            "observation_space": self.observation_space, "action_space": self.action_space,
            "images": self._images, "needs_reset": self._needs_reset,
        }

    def __setstate__(self, state: Dict[str, Any]):
        FixationEnv.__init__(self, **state["kwargs"])
        self.spec = state["spec"]
        self._np_random, self._np_random_seed = state["np_random"], state["np_random_seed"]
        self.observation_space, self.action_space = state["observation_space"], state["action_space"]
        # A copy: the renderer writes into arrays like it, and unpickled ones may be unaligned.
        self._images, self._needs_reset = np.array(state["images"]), state["needs_reset"]
        if state["heads"] is None:
            self.close()
        else:
            self._heads.set_state(state["heads"])

    def __enter__(self):
        return self

    def __exit__(self, *args):
        self.close()
        return False

    def __str__(self):
        return f"<FixationEnv {self._heads.width}x{self._heads.height} {self._heads.action_mode}>"


class VectorFixationEnv(_VectorEnvBase):
    """N FixationEnv heads stepped together and rendered in one batch (one renderer call,
    one readback per step). Gymnasium's VectorEnv contract, step for step what
    ``gymnasium.vector.SyncVectorEnv`` of N FixationEnv gives (docs/python.md): observations and
    rewards are stacked along a first axis of num_envs; infos are dicts of arrays with "_key"
    masks, built as SyncVectorEnv builds them. A ``gymnasium.vector.VectorEnv`` when gymnasium
    is importable.

    Args: as FixationEnv, plus
        num_envs: N >= 1.
        autoreset_mode: AutoresetMode (or its value): NEXT_STEP (default), SAME_STEP,
            DISABLED.
    """

    metadata = {"render_modes": ["rgb_array"], "render_fps": 25,
                "autoreset_mode": _gymnasium_autoreset(AutoresetMode.NEXT_STEP)}

    def __init__(self, num_envs: int = 4, render_mode: Optional[str] = None,
                 image_size: Union[int, Tuple[int, int]] = 64, action_mode: str = "velocity",
                 max_episode_steps: Optional[int] = 200, success_deg: float = 1.0,
                 dt: float = 0.04, fov_deg: float = 60.0, scene_seed: int = 0,
                 head: Optional[str] = None, autoreset_mode: Union[AutoresetMode, str] = AutoresetMode.NEXT_STEP):
        if not (isinstance(num_envs, (int, np.integer)) and num_envs >= 1):
            raise saccade.InvalidArgument(f"num_envs must be an integer >= 1, got {num_envs!r}")
        if render_mode is not None and render_mode not in self.metadata["render_modes"]:
            raise saccade.InvalidArgument(
                f"render_mode must be None or one of {self.metadata['render_modes']}, got {render_mode!r}")
        try:
            mode = AutoresetMode(getattr(autoreset_mode, "value", autoreset_mode))
        except ValueError:
            raise saccade.InvalidArgument(
                f"autoreset_mode must be one of {[m.value for m in AutoresetMode]}, "
                f"got {autoreset_mode!r}") from None
        self._kwargs = dict(num_envs=num_envs, render_mode=render_mode, image_size=image_size,
                            action_mode=action_mode, max_episode_steps=max_episode_steps,
                            success_deg=success_deg, dt=dt, fov_deg=fov_deg,
                            scene_seed=scene_seed, head=head, autoreset_mode=mode.value)
        self.num_envs = int(num_envs)
        self.render_mode = render_mode
        self.autoreset_mode = mode
        self._heads = _Heads(self.num_envs, image_size, action_mode, max_episode_steps,
                             success_deg, dt, fov_deg, scene_seed, head)
        self.joint_names = list(self._heads.joint_names)
        self.metadata = dict(self.metadata, render_fps=int(round(1.0 / dt)),
                             autoreset_mode=_gymnasium_autoreset(mode))
        self.single_observation_space = self._heads.observation_space()
        self.single_action_space = self._heads.action_space()
        self.observation_space = spaces.batch_space(self.single_observation_space, self.num_envs)
        self.action_space = spaces.batch_space(self.single_action_space, self.num_envs)
        self.spec = None
        self.closed = False
        self._rngs: List[Optional[np.random.Generator]] = [None] * self.num_envs
        self._np_random_seed: Optional[Tuple[int, ...]] = None
        self._images = np.zeros((self.num_envs, 2, self._heads.height, self._heads.width, 3), np.uint8)
        self._autoreset = np.zeros(self.num_envs, dtype=bool)
        self._needs_reset = True

    @property
    def np_random(self) -> np.random.Generator:
        """The first sub-environment's generator (each sub-env has its own)."""
        return self._rng(0)

    @property
    def np_random_seed(self):
        return self._np_random_seed

    @property
    def unwrapped(self):
        return self

    def _rng(self, i: int) -> np.random.Generator:
        if self._rngs[i] is None:
            self._rngs[i], _ = spaces.seeding_np_random()
        return self._rngs[i]

    def _observations(self) -> Dict[str, np.ndarray]:
        out = np.empty_like(self._images)
        self._heads.render(range(self.num_envs), out)
        self._images = out
        return {"left": out[:, 0], "right": out[:, 1],
                "joints": self._heads.joints.astype(np.float32)}

    def _infos(self, rows: np.ndarray) -> Dict[str, Any]:
        """The infos of sub-envs `rows` (an index array), as SyncVectorEnv batches the single
        envs' infos: each key an array over all envs (zeros, or None for strings, outside
        `rows`) and its "_key" mask."""
        n = self.num_envs
        h = self._heads
        mask = np.zeros(n, dtype=bool)
        mask[rows] = True
        axis_error = np.zeros((n, 2))
        axis_error[rows] = h.axis_error[rows]
        target_W = np.zeros((n, 3))
        target_W[rows] = h.target[rows]
        target_index = np.zeros(n, dtype=int)
        target_index[rows] = h.target_index[rows]
        target_kind = np.full(n, None, dtype=object)
        for i in rows:
            target_kind[i] = h.pool.kinds[int(h.target_index[i])]
        is_success = np.zeros(n, dtype=bool)
        is_success[rows] = np.all(h.axis_error[rows] < h.success, axis=1)
        return {
            "axis_error": axis_error, "_axis_error": mask.copy(),
            "target_W": target_W, "_target_W": mask.copy(),
            "target_index": target_index, "_target_index": mask.copy(),
            "target_kind": target_kind, "_target_kind": mask.copy(),
            "is_success": is_success, "_is_success": mask,
        }

    def reset(self, *, seed: Optional[Union[int, Sequence[Optional[int]]]] = None,
              options: Optional[Dict[str, Any]] = None):
        """Resets every sub-environment, or those of options["reset_mask"] (a bool array of
        num_envs, at least one True) as SyncVectorEnv does: the others keep their episode and
        their generator. `seed`: an int (env i gets seed + i), a list of one seed (or None)
        per env, or None; a sub-env outside the mask ignores its seed."""
        if seed is None:
            seeds: List[Optional[int]] = [None] * self.num_envs
        elif isinstance(seed, (int, np.integer)):
            seeds = [int(seed) + i for i in range(self.num_envs)]
        else:
            seeds = list(seed)
            if len(seeds) != self.num_envs:
                raise saccade.InvalidArgument(
                    f"VectorFixationEnv.reset: {len(seeds)} seeds for {self.num_envs} envs")
        mask = np.ones(self.num_envs, dtype=bool)
        if options and "reset_mask" in options:
            options = dict(options)
            mask = np.asarray(options.pop("reset_mask"))
            if mask.dtype != np.bool_ or mask.shape != (self.num_envs,):
                raise saccade.InvalidArgument(
                    f"VectorFixationEnv.reset: options['reset_mask'] must be a bool array of "
                    f"shape ({self.num_envs},), got {mask.dtype} {mask.shape}")
            if not mask.any():
                raise saccade.InvalidArgument(
                    "VectorFixationEnv.reset: options['reset_mask'] must hold at least one True "
                    f"value, got {mask}")
        rows = np.flatnonzero(mask)
        for i in rows:
            if seeds[i] is not None:
                self._rngs[i], _ = spaces.seeding_np_random(seeds[i])
            self._heads.randomise(int(i), self._rng(int(i)), options)
        if seed is not None:
            self._np_random_seed = tuple(seeds)
        self._autoreset[mask] = False
        self._needs_reset = False
        return self._observations(), self._infos(rows)

    def step(self, actions):
        """Steps every sub-environment; returns (obs, rewards, terminations, truncations, infos)
        stacked along the first axis. Raises EpisodeEnded in AutoresetMode.DISABLED when a
        sub-env's episode ended and was not reset (reset(options={"reset_mask": ...}))."""
        if self._needs_reset:
            raise saccade.Error("VectorFixationEnv.step: call reset() before the first step")
        a = self._heads.check_actions(actions, "VectorFixationEnv.step")
        n = self.num_envs
        if self.autoreset_mode == AutoresetMode.DISABLED and self._autoreset.any():
            raise EpisodeEnded(
                f"VectorFixationEnv.step: the episodes of sub-envs "
                f"{np.flatnonzero(self._autoreset).tolist()} ended; expected reset(options="
                f"{{'reset_mask': mask}}) of them before the next step (AutoresetMode.DISABLED)")
        rewards = np.zeros(n, dtype=np.float64)
        terminations = np.zeros(n, dtype=bool)
        truncations = np.zeros(n, dtype=bool)
        if self.autoreset_mode == AutoresetMode.NEXT_STEP:
            resetting = self._autoreset
            for i in np.flatnonzero(resetting):
                self._heads.randomise(int(i), self._rng(int(i)), None)
            moving = np.flatnonzero(~resetting)
        else:
            moving = np.arange(n)
        if len(moving):
            self._heads.apply(moving, a[moving])
        for i in moving:
            rewards[i], terminations[i], truncations[i] = self._heads.outcome(int(i))
        ended = terminations | truncations
        infos: Dict[str, Any] = {}
        if self.autoreset_mode == AutoresetMode.SAME_STEP and ended.any():
            # As SyncVectorEnv: final_obs an object array of the ended envs' observations,
            # final_info their infos batched with masks; then the new episodes' observations
            # and infos in their place.
            final = self._observations()
            rows = np.flatnonzero(ended)
            final_obs = np.full(n, None, dtype=object)
            for i in rows:
                final_obs[i] = {k: v[i].copy() for k, v in final.items()}
            infos["final_obs"], infos["_final_obs"] = final_obs, ended.copy()
            infos["final_info"], infos["_final_info"] = self._infos(rows), ended.copy()
            for i in rows:
                self._heads.randomise(int(i), self._rng(int(i)), None)
        infos.update(self._infos(np.arange(n)))
        self._autoreset = ended
        return self._observations(), rewards, terminations, truncations, infos

    def render(self):
        """rgb_array: a tuple of each env's eyes side by side (H x 2W x 3); None otherwise."""
        if self.render_mode is None:
            return None
        return tuple(np.concatenate([self._images[i, 0], self._images[i, 1]], axis=1)
                     for i in range(self.num_envs))

    def close(self, **kwargs):
        self._heads = None
        self.closed = True

    def __getstate__(self) -> Dict[str, Any]:
        # As FixationEnv's: rebuilt from the constructor's arguments, then the state restored.
        return {
            "kwargs": self._kwargs, "spec": self.spec,
            "heads": None if self._heads is None else self._heads.state(),
            "rngs": list(self._rngs), "np_random_seed": self._np_random_seed,
            "spaces": (self.single_observation_space, self.single_action_space,
                       self.observation_space, self.action_space),
            "images": self._images, "autoreset": self._autoreset,
            "needs_reset": self._needs_reset,
        }

    def __setstate__(self, state: Dict[str, Any]):
        VectorFixationEnv.__init__(self, **state["kwargs"])
        self.spec = state["spec"]
        self._rngs, self._np_random_seed = list(state["rngs"]), state["np_random_seed"]
        (self.single_observation_space, self.single_action_space, self.observation_space,
         self.action_space) = state["spaces"]
        self._images, self._autoreset = np.array(state["images"]), np.array(state["autoreset"])
        self._needs_reset = state["needs_reset"]
        if state["heads"] is None:
            self.close()
        else:
            self._heads.set_state(state["heads"])

    def __enter__(self):
        return self

    def __exit__(self, *args):
        self.close()
        return False

    def __str__(self):
        return f"<VectorFixationEnv num_envs={self.num_envs}>"


def gymnasium_entry_point(**kwargs) -> FixationEnv:
    """``gymnasium.make``'s entry point of saccade/Fixation-v0: a FixationEnv with no step
    limit of its own unless `max_episode_steps` is given, since make's TimeLimit wrapper holds
    the limit (the registered 200, the env's default, or make(..., max_episode_steps=k))."""
    kwargs.setdefault("max_episode_steps", None)
    return FixationEnv(**kwargs)


gymnasium_entry_point.metadata = FixationEnv.metadata
