# tier: unit
"""saccade.geometry: the camera model against OpenCV (cv2) where it is installed and against
the equations otherwise, calibration files, poses and triangulation."""

import math

import numpy as np
import pytest

import saccade
from saccade import geometry

# Projection agrees with OpenCV to this many pixels (double precision both sides).
PIXEL_TOLERANCE = 1e-9


def random_points(rng, n=200):
    p = rng.uniform([-1, -1, 1], [1, 1, 5], size=(n, 3))
    return p


def test_intrinsics_matrix_and_fields():
    k = geometry.Intrinsics(640, 480, 500.0, 510.0, 320.5, 240.25, skew=0.5)
    assert np.allclose(k.K, [[500, 0.5, 320.5], [0, 510, 240.25], [0, 0, 1]])
    assert (k.width, k.height) == (640, 480)
    assert geometry.Intrinsics.from_matrix(k.K, 640, 480) == k


def test_intrinsics_refuses_bad_focal_length_naming_it():
    with pytest.raises(saccade.InvalidArgument, match="fx"):
        geometry.Intrinsics(640, 480, -1.0, 500.0, 320.0, 240.0)
    # InvalidArgument is also a ValueError and a saccade.Error.
    with pytest.raises(ValueError):
        geometry.Intrinsics(0, 480, 500.0, 500.0, 320.0, 240.0)


def test_radtan_projection_matches_opencv_or_its_equations():
    rng = np.random.default_rng(7)
    coefficients = [-0.28, 0.07, 0.001, -0.0005, 0.01]
    k = geometry.Intrinsics(1024, 768, 800.0, 805.0, 511.0, 383.0)
    model = geometry.CameraModel(k, geometry.Distortion.radial_tangential(coefficients))
    points = random_points(rng) * np.array([0.5, 0.5, 1.0])
    uv = model.project_points(points)
    try:
        import cv2
    except ImportError:
        cv2 = None
    if cv2 is not None:
        expected, _ = cv2.projectPoints(points.reshape(-1, 1, 3), np.zeros(3), np.zeros(3), k.K,
                                        np.array(coefficients))
        expected = expected.reshape(-1, 2)
    else:
        # OpenCV's radial-tangential equations, written out independently.
        k1, k2, p1, p2, k3 = coefficients
        x, y = points[:, 0] / points[:, 2], points[:, 1] / points[:, 2]
        r2 = x * x + y * y
        radial = 1 + k1 * r2 + k2 * r2 ** 2 + k3 * r2 ** 3
        xd = x * radial + 2 * p1 * x * y + p2 * (r2 + 2 * x * x)
        yd = y * radial + p1 * (r2 + 2 * y * y) + 2 * p2 * x * y
        expected = np.stack([800.0 * xd + 511.0, 805.0 * yd + 383.0], axis=1)
    assert np.max(np.abs(uv - expected)) < PIXEL_TOLERANCE


def test_project_unproject_round_trip_and_behind_camera():
    model = geometry.CameraModel(geometry.Intrinsics(640, 480, 500, 500, 319.5, 239.5),
                                 geometry.Distortion.fisheye([0.1, -0.02, 0.003, -0.001]))
    p = np.array([0.3, -0.2, 2.0])
    uv = model.project(p)
    ray = model.unproject(uv)
    assert np.allclose(ray, p / np.linalg.norm(p), atol=1e-9)
    pinhole = geometry.CameraModel(geometry.Intrinsics(640, 480, 500, 500, 319.5, 239.5))
    assert pinhole.project(np.array([0.0, 0.0, -1.0])) is None


def test_calibration_file_round_trip(tmp_path):
    k = geometry.Intrinsics(800, 600, 700.0, 701.0, 399.0, 299.0)
    model = geometry.CameraModel(k, geometry.Distortion.radial_tangential([0.1, -0.05, 0.001, 0.002]))
    for fmt, name in (("opencv_yaml", "c.yml"), ("opencv_xml", "c.xml"), ("ros_yaml", "c.yaml")):
        geometry.write_camera_calibration(geometry.CameraCalibration(model, "eye"), tmp_path / name, fmt)
        back = geometry.read_camera_calibration(tmp_path / name)
        assert back.model.intrinsics == k, fmt
        assert np.allclose(back.model.distortion.coefficients[:4], [0.1, -0.05, 0.001, 0.002])


def test_bad_calibration_file_raises_file_error_with_file_and_line(tmp_path):
    bad = tmp_path / "bad.yml"
    bad.write_text("%YAML:1.0\n---\nimage_width: 640\nimage_height: -3\n"
                   "camera_matrix: !!opencv-matrix\n  rows: 3\n  cols: 3\n  dt: d\n"
                   "  data: [500, 0, 320, 0, 500, 240, 0, 0, 1]\n")
    with pytest.raises(saccade.FileError) as error:
        geometry.read_camera_calibration(bad)
    assert str(bad) in str(error.value)
    assert error.value.file == str(bad)
    assert error.value.line >= 1
    assert f"{bad}:{error.value.line}:" in str(error.value)


def test_triangulation_recovers_a_point_from_two_rays():
    p = np.array([0.4, -0.3, 2.5])
    a = geometry.Ray(np.array([-0.1, 0, 0]), p - np.array([-0.1, 0, 0]))
    b = geometry.Ray(np.array([0.1, 0, 0]), p - np.array([0.1, 0, 0]))
    result = geometry.triangulate_midpoint(a, b)
    assert result.ok
    assert np.allclose(result.point, p, atol=1e-12)
    assert result.gap < 1e-12
    parallel = geometry.triangulate_midpoint(a, geometry.Ray(np.array([0.1, 0, 0]), a.direction))
    assert parallel.parallel and not parallel.ok


def test_triangulate_dlt_agrees_with_the_projections():
    p = np.array([0.2, 0.1, 3.0, 1.0])
    view_a = np.hstack([np.eye(3), np.array([[0.1], [0], [0]])])
    view_b = np.hstack([np.eye(3), np.array([[-0.1], [0], [0]])])
    xa, xb = view_a @ p, view_b @ p
    result = geometry.triangulate_dlt(view_a, xa[:2] / xa[2], view_b, xb[:2] / xb[2])
    assert np.allclose(result.point, p[:3], atol=1e-9)


def test_rpy_round_trip():
    R = geometry.rotation_from_rpy(0.1, -0.2, 0.3)
    assert np.allclose(R @ R.T, np.eye(3))
    assert np.allclose(geometry.rpy_from_rotation(R), [0.1, -0.2, 0.3])
    X = geometry.make_pose(R, np.array([1.0, 2.0, 3.0]))
    assert X.shape == (4, 4) and np.allclose(X[:3, 3], [1, 2, 3])
