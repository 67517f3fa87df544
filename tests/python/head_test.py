# tier: unit
"""saccade.head: the description file, forward and inverse kinematics."""

import numpy as np
import pytest

import saccade
from saccade import head

# FK(IK(p)) meets p to this angle: the solver converges to 1e-9 rad (kinematics.h).
AXIS_TOLERANCE_RAD = 1e-8


def test_description_fields(popeye):
    assert popeye.name
    limits = popeye.limits("pan")
    assert limits.min < 0 < limits.max and limits.max_velocity > 0
    assert popeye.X_WB.shape == (4, 4)
    assert popeye.left_camera.intrinsics.width > 0


def test_ik_then_fk_puts_the_target_on_both_optical_axes(popeye):
    rng = np.random.default_rng(3)
    base = popeye.X_WB[:3, 3]
    for _ in range(20):
        target = base + np.array([rng.uniform(1.0, 3.0), rng.uniform(-0.8, 0.8), rng.uniform(-0.5, 0.5)])
        result = head.solve_fixation(popeye, target)
        assert result.reachable, result.message
        frames = head.forward_kinematics(popeye, result.joints)
        for X in (frames.X_WCamLeft, frames.X_WCamRight):
            ray = target - X[:3, 3]
            # atan2 of |cross| and dot: arccos loses the angle below sqrt(eps).
            angle = np.arctan2(np.linalg.norm(np.cross(X[:3, 2], ray)), X[:3, 2] @ ray)
            assert angle < AXIS_TOLERANCE_RAD
        assert np.allclose(frames.p_WFixation, target, atol=1e-6)


def test_axis_errors_of_one_head_and_of_many(popeye):
    # Parallel eyes (all joints 0) and a point 2 m along the left optical axis: the left axis
    # meets it, the right one misses it by the baseline seen from 2 m.
    frames = head.forward_kinematics(popeye, [0.0, 0.0, 0.0, 0.0])
    left, right = frames.X_WCamLeft, frames.X_WCamRight
    p = left[:3, 3] + 2.0 * left[:3, 2]
    baseline = np.linalg.norm(left[:3, 3] - right[:3, 3])
    e = head.axis_errors(popeye, [0.0, 0.0, 0.0, 0.0], p)
    assert e.shape == (2,)
    assert e[0] < 1e-12
    assert e[1] == pytest.approx(np.arctan2(baseline, 2.0), abs=1e-12)

    # Many heads at once: row by row what the frames say.
    rng = np.random.default_rng(5)
    joints = rng.uniform(-0.3, 0.3, size=(16, 4))
    points = popeye.X_WB[:3, 3] + rng.uniform([1.0, -1.0, -0.5], [3.0, 1.0, 0.5], size=(16, 3))
    errors = head.axis_errors(popeye, joints, points)
    assert errors.shape == (16, 2)
    for q, p, e in zip(joints, points, errors):
        f = head.forward_kinematics(popeye, q)
        for eye, X in enumerate((f.X_WCamLeft, f.X_WCamRight)):
            ray = p - X[:3, 3]
            want = np.arctan2(np.linalg.norm(np.cross(X[:3, 2], ray)), X[:3, 2] @ ray)
            assert e[eye] == pytest.approx(want, abs=1e-12)

    with pytest.raises(saccade.InvalidArgument, match=r"joints \(n, 4\) and p_W \(n, 3\)"):
        head.axis_errors(popeye, joints, points[:3])
    with pytest.raises(saccade.InvalidArgument, match="axis_errors"):
        head.axis_errors(popeye, [0.0, 0.0, 0.0], p)


def test_joint_states_from_sequences(popeye):
    a = head.JointState(0.1, -0.2, 0.05, -0.05)
    assert np.allclose(np.asarray(a), [0.1, -0.2, 0.05, -0.05])
    frames_a = head.forward_kinematics(popeye, a)
    frames_b = head.forward_kinematics(popeye, [0.1, -0.2, 0.05, -0.05])
    assert np.allclose(frames_a.X_WCamLeft, frames_b.X_WCamLeft)


def test_unreachable_target_is_reported_not_raised(popeye):
    behind = popeye.X_WB[:3, 3] + np.array([-2.0, 0.0, 0.0])
    result = head.solve_fixation(popeye, behind)
    assert not result.reachable
    assert result.reachability in ("behind", "joint limit", "kBehind", "kJointLimit") or result.message


def test_check_limits_names_the_joint(popeye):
    with pytest.raises(saccade.InvalidArgument, match="tilt"):
        popeye.check_limits(head.JointState(0.0, 3.0, 0.0, 0.0))
    assert not popeye.within_limits([0.0, 3.0, 0.0, 0.0])


def test_bad_description_raises_file_error_with_line():
    text = "name: x\ngeometry:\n  B: -0.1\n"
    with pytest.raises(saccade.FileError) as error:
        head.HeadDescription.from_yaml_string(text, "inline.yaml")
    assert str(error.value).startswith("inline.yaml:")
    assert error.value.line >= 1


def test_bad_ik_mode_is_refused(popeye):
    with pytest.raises(saccade.InvalidArgument, match="symmetric"):
        head.solve_fixation(popeye, np.array([2.0, 0, 1.2]), mode="sideways")


# Issue 42: any head, from its head file (with or without a URDF).
SHIPPED = ["popeye", "popeye_urdf", "humanoid", "pan_tilt_vergence", "pan_tilt_fixed"]


@pytest.mark.parametrize("name", SHIPPED)
def test_head_from_file_fixates_targets_in_front(name):
    h = head.Head.from_file(saccade.source_dir() + f"/robots/{name}.yaml")
    assert h.num_joints == len(h.joint_names) >= 2
    rng = np.random.default_rng(5)
    base = h.X_WB[:3, 3]
    for _ in range(10):
        target = base + np.array([rng.uniform(1.0, 3.0), rng.uniform(-0.5, 0.5), rng.uniform(-0.3, 0.3)])
        result = h.fixate(target)
        assert result.reachable, result.message
        assert h.within_limits(result.joints)
        errors = h.axis_errors(result.joints, target)
        if h.can_verge:
            # Both optical axes through the target (the solver's tolerance is 1e-9 rad).
            assert np.all(errors < AXIS_TOLERANCE_RAD), errors
        else:
            # A fixed pair points the mid-axis: each camera's error is half its vergence angle.
            assert result.mid_axis and np.all(errors < 0.1)
        # The camera poses agree with the link poses' optical frames and with axis_errors.
        X_left, X_right = h.camera_poses(result.joints)
        ray = target - X_left[:3, 3]
        cos = X_left[:3, 2] @ ray / np.linalg.norm(ray)
        assert np.isclose(np.arccos(min(1.0, cos)), errors[0], atol=1e-7)


def test_the_legacy_and_urdf_popeye_agree():
    legacy = head.Head.from_file(saccade.source_dir() + "/robots/popeye.yaml")
    urdf = head.Head.from_file(saccade.source_dir() + "/robots/popeye_urdf.yaml")
    assert legacy.joint_names == urdf.joint_names == ["pan", "tilt", "left", "right"]
    q = [0.2, -0.1, 0.05, -0.07]
    for a, b in zip(legacy.camera_poses(q), urdf.camera_poses(q)):
        assert np.allclose(a, b, atol=1e-12)
    assert urdf.urdf.startswith("<?xml") or "<robot" in urdf.urdf


def test_joints_by_name_and_bad_joints_are_named():
    h = head.Head.from_file(saccade.source_dir() + "/robots/humanoid.yaml")
    q = {name: 0.0 for name in h.joint_names}
    q["neck_yaw"] = 0.3
    by_name = h.link_poses(q)
    by_order = h.link_poses(np.array([q[n] for n in h.joint_names]))
    assert by_name.keys() == by_order.keys()
    for link in by_name:
        assert np.allclose(by_name[link], by_order[link])
    with pytest.raises(saccade.InvalidArgument, match="unknown joint.*elbow"):
        h.link_poses({"elbow": 1.0})
    with pytest.raises(saccade.InvalidArgument, match="expected a dict .* or 6 values"):
        h.camera_poses([0.0, 0.0])
    with pytest.raises(saccade.InvalidArgument, match="neck_yaw"):
        h.check_limits(dict(q, neck_yaw=9.0))
    with pytest.raises(saccade.InvalidArgument, match="no joint 'elbow'"):
        h.joint("elbow")


def test_unreachable_target_is_refused_with_a_reason():
    h = head.Head.from_file(saccade.source_dir() + "/robots/pan_tilt_vergence.yaml")
    behind = h.X_WB[:3, 3] + np.array([-2.0, 0.0, 0.0])
    result = h.fixate(behind)
    assert not result.reachable and result.reachability != "reachable"
    assert np.all(np.isfinite(result.joints)) and h.within_limits(result.joints)
    assert result.message


def test_a_bad_head_file_names_the_file_and_line():
    with pytest.raises(saccade.FileError) as error:
        head.Head.from_yaml_string("name: x\nurdf: missing.urdf\n", "inline.yaml")
    assert "missing.urdf" in str(error.value)
