"""Type stubs of saccade's extension module (src/python/*.cc); docstrings live in the module."""

from typing import Any, Callable, Dict, List, Optional, Sequence, Tuple, Union

import numpy as np
import numpy.typing as npt

SOURCE_DIR: str

class Error(RuntimeError): ...
class InvalidArgument(Error, ValueError): ...
class FileError(Error):
    file: str
    line: int
    key: str

Matrix = npt.NDArray[np.float64]
Vector = Union[npt.NDArray[np.float64], Sequence[float]]

class core:
    class Image:
        array: npt.NDArray[Any]
        width: int
        height: int
        format: str
        data_address: int
        camera: str
        time: float
        frame_index: int
        exposure_s: float
        gain_db: float
        focus_m: float
        joints: Optional[npt.NDArray[np.float64]]
        K: Optional[Matrix]
        camera_model: Optional["geometry.CameraModel"]
        X_WC: Optional[Matrix]
        def __buffer__(self, flags: int) -> memoryview: ...

class geometry:
    class Intrinsics:
        def __init__(self, width: int, height: int, fx: float, fy: float, cx: float, cy: float,
                     skew: float = 0.0) -> None: ...
        @staticmethod
        def from_matrix(K: Matrix, width: int, height: int) -> "geometry.Intrinsics": ...
        width: int
        height: int
        fx: float
        fy: float
        cx: float
        cy: float
        skew: float
        K: Matrix
        def horizontal_fov(self) -> float: ...
        def vertical_fov(self) -> float: ...
    class Distortion:
        def __init__(self) -> None: ...
        @staticmethod
        def radial_tangential(coefficients: Sequence[float]) -> "geometry.Distortion": ...
        @staticmethod
        def fisheye(coefficients: Sequence[float]) -> "geometry.Distortion": ...
        model: str
        coefficients: List[float]
        def is_identity(self) -> bool: ...
        def distort(self, xy: Vector) -> npt.NDArray[np.float64]: ...
    class CameraModel:
        def __init__(self, intrinsics: "geometry.Intrinsics",
                     distortion: "geometry.Distortion" = ...) -> None: ...
        intrinsics: "geometry.Intrinsics"
        distortion: "geometry.Distortion"
        def project(self, p_C: Vector) -> Optional[npt.NDArray[np.float64]]: ...
        def project_points(self, points_C: Matrix) -> Matrix: ...
        def unproject(self, uv: Vector) -> Optional[npt.NDArray[np.float64]]: ...
        def contains(self, uv: Vector) -> bool: ...
    class CameraCalibration:
        def __init__(self, model: "geometry.CameraModel", name: str = "") -> None: ...
        model: "geometry.CameraModel"
        name: str
    class StereoCalibration:
        left: "geometry.CameraModel"
        right: "geometry.CameraModel"
        R: Matrix
        T: npt.NDArray[np.float64]
    class Ray:
        def __init__(self, origin: Vector, direction: Vector) -> None: ...
        origin: npt.NDArray[np.float64]
        direction: npt.NDArray[np.float64]
    class TriangulationResult:
        point: npt.NDArray[np.float64]
        gap: float
        parallel: bool
        behind: bool
        ok: bool
    @staticmethod
    def read_camera_calibration(path: Any, size: Optional[Tuple[int, int]] = None) -> "geometry.CameraCalibration": ...
    @staticmethod
    def write_camera_calibration(calibration: "geometry.CameraCalibration", path: Any,
                                 format: str = "opencv_yaml") -> None: ...
    @staticmethod
    def read_stereo_calibration(path: Any, extrinsics_path: Any = None,
                                size: Optional[Tuple[int, int]] = None) -> "geometry.StereoCalibration": ...
    @staticmethod
    def rotation_from_rpy(roll: float, pitch: float, yaw: float) -> Matrix: ...
    @staticmethod
    def rpy_from_rotation(R: Matrix) -> npt.NDArray[np.float64]: ...
    @staticmethod
    def make_pose(R: Matrix, t: Vector) -> Matrix: ...
    @staticmethod
    def triangulate_midpoint(a: "geometry.Ray", b: "geometry.Ray", min_angle: float = 1e-9) -> "geometry.TriangulationResult": ...
    @staticmethod
    def triangulate_dlt(view_a: Matrix, xy_a: Vector, view_b: Matrix, xy_b: Vector) -> "geometry.TriangulationResult": ...

JointsLike = Union["head.JointState", Dict[str, float], Sequence[float], npt.NDArray[np.float64]]

class head:
    class JointState:
        def __init__(self, pan: float = 0.0, tilt: float = 0.0, left: float = 0.0,
                     right: float = 0.0) -> None: ...
        pan: float
        tilt: float
        left: float
        right: float
        def to_array(self) -> npt.NDArray[np.float64]: ...
    class JointLimits:
        min: float
        max: float
        max_velocity: float
        max_acceleration: float
    class HeadGeometry:
        B: float
        D: float
        H: float
        delta_l: float
        delta_r: float
    class HeadDescription:
        @staticmethod
        def from_yaml_file(path: Any) -> "head.HeadDescription": ...
        @staticmethod
        def from_yaml_string(text: str, source: str = "<string>") -> "head.HeadDescription": ...
        name: str
        geometry: "head.HeadGeometry"
        X_WB: Matrix
        left_camera: "geometry.CameraModel"
        right_camera: "geometry.CameraModel"
        def limits(self, joint: str) -> "head.JointLimits": ...
        def within_limits(self, joints: JointsLike) -> bool: ...
        def check_limits(self, joints: JointsLike) -> None: ...
    class HeadFrames:
        X_WB: Matrix
        X_WN: Matrix
        X_WC: Matrix
        X_WL: Matrix
        X_WR: Matrix
        X_WCamLeft: Matrix
        X_WCamRight: Matrix
        p_WFixation: Optional[npt.NDArray[np.float64]]
    class IkResult:
        joints: "head.JointState"
        reachability: str
        reachable: bool
        axis_error: float
        iterations: int
        message: str
    @staticmethod
    def forward_kinematics(head: "head.HeadDescription", joints: JointsLike) -> "head.HeadFrames": ...
    @staticmethod
    def axis_errors(head: "head.HeadDescription", joints: npt.ArrayLike,
                    p_W: npt.ArrayLike) -> npt.NDArray[np.float64]: ...
    @staticmethod
    def solve_fixation(head: "head.HeadDescription", p_W: Vector, mode: str = "symmetric",
                       seed: JointsLike = ...) -> "head.IkResult": ...
    @staticmethod
    def solve_fixation_closed_form(head: "head.HeadDescription", p_W: Vector) -> "head.IkResult": ...
    class FixationResult:
        joints: npt.NDArray[np.float64]
        reachability: str
        reachable: bool
        axis_error: float
        iterations: int
        mid_axis: bool
        message: str
    class Head:
        @staticmethod
        def from_file(path: Any) -> "head.Head": ...
        @staticmethod
        def from_yaml_string(text: str, source: str = "<string>", folder: Any = ".") -> "head.Head": ...
        name: str
        joint_names: List[str]
        num_joints: int
        driven_joints: List[str]
        limits_min: npt.NDArray[np.float64]
        limits_max: npt.NDArray[np.float64]
        max_velocity: npt.NDArray[np.float64]
        X_WB: Matrix
        left_camera: "geometry.CameraModel"
        right_camera: "geometry.CameraModel"
        urdf: str
        can_verge: bool
        def joint(self, name: str) -> Dict[str, Any]: ...
        def home(self) -> npt.NDArray[np.float64]: ...
        def within_limits(self, joints: JointsLike) -> bool: ...
        def check_limits(self, joints: JointsLike) -> None: ...
        def link_poses(self, joints: Optional[JointsLike] = None) -> Dict[str, Matrix]: ...
        def camera_poses(self, joints: Optional[JointsLike] = None) -> Tuple[Matrix, Matrix]: ...
        def fixate(self, p_W: Vector, seed: Optional[JointsLike] = None) -> "head.FixationResult": ...
        def axis_errors(self, joints: npt.ArrayLike, p_W: npt.ArrayLike) -> npt.NDArray[np.float64]: ...

class scene:
    class CameraControls:
        def __init__(self, exposure_s: Optional[float] = None, gain_db: Optional[float] = None,
                     focus_m: Optional[float] = None) -> None: ...
        exposure_s: Optional[float]
        gain_db: Optional[float]
        focus_m: Optional[float]
    class SceneState:
        def __init__(self, time: float = 0.0, joints: JointsLike = ...,
                     joint_velocities: JointsLike = ...,
                     camera_controls: Dict[str, "scene.CameraControls"] = ...) -> None: ...
        time: float
        joints: "head.JointState"
        joint_velocities: "head.JointState"
        camera_controls: Dict[str, "scene.CameraControls"]
    class Object:
        name: str
        id: int
        source: str
        scale: npt.NDArray[np.float64]
    class CameraSpec:
        name: str
        model: "geometry.CameraModel"
        mount: str
    class Scene:
        @staticmethod
        def load(path: Any) -> "scene.Scene": ...
        @staticmethod
        def from_yaml_string(text: str, source: str = "<string>", base_dir: Any = ".") -> "scene.Scene": ...
        objects: List["scene.Object"]
        cameras: List["scene.CameraSpec"]
        background: npt.NDArray[np.float32]
        head: Optional["head.Head"]
        robot_id: int
        def initial_state(self) -> "scene.SceneState": ...
        def camera_pose(self, camera: str, state: "scene.SceneState") -> Matrix: ...
        def object_pose(self, object: str, state: "scene.SceneState") -> Matrix: ...

class render:
    class ObjectTruth:
        id: int
        name: str
        X_WO: Matrix
        X_CO: Matrix
        pixels: int
        box: Tuple[int, int, int, int]
    class Frame:
        color: npt.NDArray[np.uint8]
        depth: Optional[npt.NDArray[np.float32]]
        ids: Optional[npt.NDArray[np.uint32]]
        raw: Optional[npt.NDArray[np.uint8]]
        raw_format: Optional[str]
        image: "core.Image"
        objects: List["render.ObjectTruth"]
    class RenderStats:
        frames: int
        scene_update_ms: float
        draw_ms: float
        effects_ms: float
        readback_ms: float
        cpu_effects_ms: float
        total_ms: float
    class BatchHead:
        def __init__(self, state: "scene.SceneState",
                     object_poses: Optional[Sequence[Optional[Matrix]]] = None,
                     hidden: Optional[Sequence[bool]] = None) -> None: ...
        state: "scene.SceneState"
    class Renderer:
        def __init__(self, scene: "scene.Scene", cameras: Optional[Sequence[str]] = None,
                     msaa_samples: int = 0, draw_robot: bool = True, distortion: bool = True,
                     noise: bool = True, motion_blur: bool = True, optics: bool = True,
                     color: bool = True, truth_depth: bool = False,
                     truth_ids: bool = False, truth_objects: bool = False,
                     lod_max_error_px: float = 0.25, batch_contexts: int = 0) -> None: ...
        camera_names: List[str]
        device: str
        stats: "render.RenderStats"
        def render(self, state: "scene.SceneState", frame_index: int = 0,
                   out: Optional[npt.NDArray[np.uint8]] = None) -> Any: ...
        def render_batch(self, heads: Sequence["render.BatchHead"],
                         out: Optional[npt.NDArray[np.uint8]] = None) -> npt.NDArray[np.uint8]: ...
        def set_effects(self, distortion: bool, noise: bool, motion_blur: bool,
                        optics: bool = True, color: bool = True) -> None: ...

class runtime:
    class Pipeline:
        @staticmethod
        def load(path: str, hardware: str = "") -> "runtime.Pipeline": ...
        @staticmethod
        def from_yaml_string(text: str, source: str = "<string>", hardware: str = "") -> "runtime.Pipeline": ...
        steps_done: int
        dt: float
        hardware_file: str
        components: List[str]
        def step(self, count: int = 1) -> None: ...
        def close(self) -> None: ...
        def __enter__(self) -> "runtime.Pipeline": ...
        def __exit__(self, *args: Any) -> None: ...
        def describe(self, component: str) -> Dict[str, Any]: ...
        def watch(self, signal: str) -> None: ...
        def read(self, signal: str) -> Any: ...
        def count(self, signal: str) -> int: ...
        def call(self, component: str, method: str, request: Optional[Dict[str, Any]] = None) -> Any: ...
        def set_enabled(self, component: str, enabled: bool) -> None: ...
        def python_component(self, component: str) -> Any: ...
    @staticmethod
    def register_component(type: str, factory: Callable[[], Any], description: str = "") -> None: ...
    @staticmethod
    def component_types() -> List[str]: ...
    @staticmethod
    def message_types() -> List[str]: ...

class hw:
    class ServoMapping:
        id: int
        zero_offset: float
        direction: int
        gear_ratio: float
        def servo_angle(self, joint_angle: float) -> float: ...
        def joint_angle(self, servo_angle: float) -> float: ...
    @staticmethod
    def servo_mapping(head: "head.HeadDescription", joint: str) -> Optional["hw.ServoMapping"]: ...
    @staticmethod
    def read_pipeline_spec(path: str, hardware: str = "") -> Dict[str, Any]: ...

class mcap:
    class Message:
        topic: str
        type: str
        sequence: int
        log_time: float
        publish_time: float
        value: Any
    class MessageIterator:
        def __iter__(self) -> "mcap.MessageIterator": ...
        def __next__(self) -> "mcap.Message": ...
    class Reader:
        def __init__(self, path: str) -> None: ...
        @property
        def topics(self) -> Dict[str, str]: ...
        @property
        def metadata(self) -> Dict[str, Dict[str, str]]: ...
        @property
        def statistics(self) -> Dict[str, Any]: ...
        @property
        def complete(self) -> bool: ...
        @property
        def lost_bytes(self) -> int: ...
        def messages(self, topics: Optional[List[str]] = None) -> "mcap.MessageIterator": ...
