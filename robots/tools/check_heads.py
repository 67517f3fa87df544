#!/usr/bin/env python3
"""Checks the heads saccade ships (robots/*.yaml with a `urdf:`), with python3 and numpy only.

    python3 robots/tools/check_heads.py            # exit status 0 when every check passes

For each head it parses the URDF with xml.etree and computes the forward kinematics of every
link the URDF way: X_child = X_parent * T(origin xyz) * R(origin rpy) * M(q), with
R(rpy) = Rz(yaw) Ry(pitch) Rx(roll), M a rotation about (revolute, continuous) or a
translation along (prismatic) the normalised axis, and a mimic joint's q = multiplier *
q_source + offset. Then:
  - joints: the expected names, types and axes; finite limits with lower < 0 < upper (0 inside),
    velocity > 0, effort given; a mimic joint's limits contain the image of its source's;
  - head file: the URDF, camera links or Gazebo sensors and joint names it names exist, every
    driven joint has an acceleration, servo ids are unique;
  - cameras: at zero joints both optical frames look along the base's +x with the image's x
    to the base's -y (upright), and with the head file's pose they sit about 1.2 m high
    looking along the world's +x; the baseline (distance between the optical centres) is
    printed and compared with the design's;
  - signs: the eye joints turn the way the URDF's comments say (vergence > 0 converges);
  - POPEYE: both optical frames of popeye/popeye.urdf equal the legacy forward kinematics
    (src/head/kinematics.cc, ForwardKinematics, eqs. 4-8, geometry of robots/popeye.yaml),
    re-implemented below, to 1e-12 on 1,000 random joint vectors within the limits;
  - self-view: on 1,000 random joint vectors and every corner of the joint box, no camera sees
    any point of its own eye's visuals or of the head's shell (the links listed per head
    below), with a 10 % margin around the image; what else a camera can see of its own head
    at some posture is printed, not an error.
"""

import itertools
import math
import pathlib
import re
import struct
import sys
import xml.etree.ElementTree as ET

import numpy as np

ROBOTS = pathlib.Path(__file__).resolve().parent.parent
PACKAGE = "saccade_heads"  # package://saccade_heads/... is the robots/ folder
RNG_SEED = 42
SAMPLES = 1000

# The optical frame in a link with x forward, y left, z up (URDF rpy -pi/2 0 -pi/2).
R_LINK_OPTICAL = np.array([[0.0, 0.0, 1.0], [-1.0, 0.0, 0.0], [0.0, -1.0, 0.0]])

# What each head must be. joints: name -> (type, axis); baseline in metres; never_seen: links
# no camera may ever see (besides the camera's own eye, found from the tree).
HEADS = {
    "popeye_urdf.yaml": dict(
        joints={"pan": ("revolute", (0, 0, 1)), "tilt": ("revolute", (0, 1, 0)),
                "left": ("revolute", (0, 0, 1)), "right": ("revolute", (0, 0, 1))},
        eyes={"left": "left", "right": "right"}, eye_sign=+1, baseline=0.2,
        never_seen=["cyclopean_link", "left_eye_link", "right_eye_link"]),
    "humanoid.yaml": dict(
        joints={"neck_pitch": ("revolute", (0, 1, 0)), "neck_roll": ("revolute", (1, 0, 0)),
                "neck_yaw": ("revolute", (0, 0, 1)), "eye_tilt": ("revolute", (0, 1, 0)),
                "left_eye_pan": ("revolute", (0, 0, 1)),
                "right_eye_pan": ("revolute", (0, 0, 1))},
        eyes={"left": "left_eye_pan", "right": "right_eye_pan"}, eye_sign=+1, baseline=0.068,
        never_seen=["head_link", "eye_tilt_link", "left_eye_link", "right_eye_link"]),
    "pan_tilt_vergence.yaml": dict(
        joints={"pan": ("revolute", (0, 0, 1)), "tilt": ("revolute", (0, 1, 0)),
                "vergence": ("revolute", (0, 0, -1)),
                "right_eye_vergence": ("revolute", (0, 0, -1))},
        mimic={"right_eye_vergence": ("vergence", -1.0, 0.0)},
        vergence="vergence", baseline=0.12,
        never_seen=["bar_link", "left_eye_link", "right_eye_link"]),
    "pan_tilt_fixed.yaml": dict(
        joints={"pan": ("revolute", (0, 0, 1)), "tilt": ("revolute", (0, 1, 0))},
        baseline=0.06, never_seen=["camera_link"]),
}

failures = []


def check(condition, message):
    if not condition:
        failures.append(message)
        print("  FAIL: " + message)
    return condition


# ---------------------------------------------------------------------------------------
# Transforms.

def rot_x(a):
    c, s = math.cos(a), math.sin(a)
    return np.array([[1.0, 0.0, 0.0], [0.0, c, -s], [0.0, s, c]])


def rot_y(a):
    c, s = math.cos(a), math.sin(a)
    return np.array([[c, 0.0, s], [0.0, 1.0, 0.0], [-s, 0.0, c]])


def rot_z(a):
    c, s = math.cos(a), math.sin(a)
    return np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])


def rpy_matrix(rpy):
    return rot_z(rpy[2]) @ rot_y(rpy[1]) @ rot_x(rpy[0])


def transform(R=np.eye(3), t=(0.0, 0.0, 0.0)):
    X = np.eye(4)
    X[:3, :3] = R
    X[:3, 3] = t
    return X


def axis_angle(axis, angle):
    """Rodrigues: rotation by angle about the unit axis."""
    k = np.asarray(axis, dtype=float)
    K = np.array([[0.0, -k[2], k[1]], [k[2], 0.0, -k[0]], [-k[1], k[0], 0.0]])
    return np.eye(3) + math.sin(angle) * K + (1.0 - math.cos(angle)) * (K @ K)


# ---------------------------------------------------------------------------------------
# URDF.

def floats(text, default):
    return [float(v) for v in text.split()] if text is not None else list(default)


def parse_origin(element):
    origin = element.find("origin") if element is not None else None
    if origin is None:
        return transform()
    return transform(rpy_matrix(floats(origin.get("rpy"), (0, 0, 0))),
                     floats(origin.get("xyz"), (0, 0, 0)))


def parse_urdf(path):
    root = ET.parse(path).getroot()
    assert root.tag == "robot", f"{path}: the root element is <{root.tag}>, not <robot>"
    materials = {m.get("name") for m in root.findall("material")}
    links = {}
    for link in root.findall("link"):
        visuals = []
        for visual in link.findall("visual"):
            geometry = visual.find("geometry")[0]
            visuals.append(dict(X=parse_origin(visual), kind=geometry.tag,
                                attributes=dict(geometry.attrib),
                                material=visual.find("material")))
        links[link.get("name")] = visuals
    joints = {}
    for joint in root.findall("joint"):
        axis = joint.find("axis")
        limit = joint.find("limit")
        mimic = joint.find("mimic")
        joints[joint.get("name")] = dict(
            type=joint.get("type"), parent=joint.find("parent").get("link"),
            child=joint.find("child").get("link"), X=parse_origin(joint),
            axis=np.array(floats(axis.get("xyz") if axis is not None else None, (1, 0, 0))),
            limit=None if limit is None else {k: float(v) for k, v in limit.attrib.items()},
            mimic=None if mimic is None else (mimic.get("joint"),
                                              float(mimic.get("multiplier", "1")),
                                              float(mimic.get("offset", "0"))))
    sensors = {}
    for gazebo in root.findall("gazebo"):
        for sensor in gazebo.findall("sensor"):
            if sensor.get("type") != "camera":
                continue
            camera = sensor.find("camera")
            pose = floats(sensor.findtext("pose"), (0, 0, 0, 0, 0, 0))
            clip = camera.find("clip")
            distortion = camera.find("distortion")
            sensors[sensor.get("name")] = dict(
                link=gazebo.get("reference"),
                X=transform(rpy_matrix(pose[3:]), pose[:3]),
                hfov=float(camera.findtext("horizontal_fov")),
                width=int(camera.find("image").findtext("width")),
                height=int(camera.find("image").findtext("height")),
                near=float(clip.findtext("near")) if clip is not None else 0.0,
                distortion=None if distortion is None else
                {c.tag: c.text.strip() for c in distortion})
    children = {j["child"] for j in joints.values()}
    roots = [name for name in links if name not in children]
    assert len(roots) == 1, f"{path}: roots {roots}"
    return dict(root=roots[0], links=links, joints=joints, sensors=sensors,
                materials=materials)


def joint_value(model, name, q):
    joint = model["joints"][name]
    if joint["mimic"] is not None:
        source, multiplier, offset = joint["mimic"]
        return multiplier * joint_value(model, source, q) + offset
    return q.get(name, 0.0)


def forward_kinematics(model, q):
    """{link: 4x4 pose in the root link} for the joint values q (dict; missing ones 0)."""
    X = {model["root"]: np.eye(4)}
    pending = list(model["joints"].items())
    while pending:
        rest = []
        for name, joint in pending:
            if joint["parent"] not in X:
                rest.append((name, joint))
                continue
            axis = joint["axis"] / np.linalg.norm(joint["axis"])
            motion = np.eye(4)
            if joint["type"] in ("revolute", "continuous"):
                motion = transform(axis_angle(axis, joint_value(model, name, q)))
            elif joint["type"] == "prismatic":
                motion = transform(t=axis * joint_value(model, name, q))
            X[joint["child"]] = X[joint["parent"]] @ joint["X"] @ motion
        assert len(rest) < len(pending), "the joints do not form a tree"
        pending = rest
    return X


def driven_joints(model):
    return [n for n, j in model["joints"].items()
            if j["type"] in ("revolute", "prismatic", "continuous") and j["mimic"] is None]


def random_configurations(model, rng, count):
    names = driven_joints(model)
    lower = np.array([model["joints"][n]["limit"]["lower"] for n in names])
    upper = np.array([model["joints"][n]["limit"]["upper"] for n in names])
    for _ in range(count):
        yield dict(zip(names, rng.uniform(lower, upper)))
    for corner in itertools.product(*zip(lower, upper)):
        yield dict(zip(names, corner))


# ---------------------------------------------------------------------------------------
# The head file (only the few keys checked here; the C++ loader is the real parser).

def head_file_facts(path):
    text = re.sub(r"\s*#.*", "", path.read_text())  # no comments (the files have no "#" in values)
    text = "\n".join(line for line in text.splitlines() if line.strip()) + "\n"
    urdf = re.search(r"^urdf:\s*(\S+)", text, re.M).group(1)
    position = [float(v) for v in re.search(
        r"position:\s*\[([^\]]*)\]", text).group(1).split(",")]
    rpy_deg = re.search(r"rpy_deg:\s*\[([^\]]*)\]", text)
    rpy = [math.radians(float(v)) for v in rpy_deg.group(1).split(",")] if rpy_deg else [0] * 3
    cameras_text = re.search(r"^cameras:\n((?:[ #].*\n|\n)*)", text, re.M).group(1)
    cameras = {}
    for side in ("left", "right"):
        block = re.search(rf"^  {side}:(.*(?:\n    .*)*)", cameras_text, re.M).group(1)
        sensor = re.search(r"gazebo_sensor:\s*(\w+)", block)
        if sensor:
            cameras[side] = ("gazebo", sensor.group(1), None)
            continue
        link = re.search(r"link:\s*(\w+)", block).group(1)
        value = lambda key: (float(m.group(1)) if (m := re.search(  # noqa: E731
            rf"\b{key}:\s*([-0-9.eE+]+)", block)) else None)
        width, height = value("width"), value("height")
        fx, fy = value("fx"), value("fy")
        if fx is None:
            fx = fy = value("focal_length_mm") / (value("pixel_size_um") * 1e-3)
        cx = value("cx") if value("cx") is not None else (width - 1) / 2
        cy = value("cy") if value("cy") is not None else (height - 1) / 2
        cameras[side] = ("link", link, dict(width=width, height=height, fx=fx, fy=fy,
                                            cx=cx, cy=cy, near=0.0))
    joints_text = re.search(r"^joints:\n((?:[ #].*\n|\n)*)", text, re.M)
    joint_blocks = dict(re.findall(r"^  (\w+):(.*(?:\n    .*)*)", joints_text.group(1), re.M)) \
        if joints_text else {}
    return dict(urdf=urdf, X_W_root=transform(rpy_matrix(rpy), position), cameras=cameras,
                joints=joint_blocks, text=text)


def camera_frames(model, cameras):
    """For each side: (link whose pose carries the camera, X_link_optical, intrinsics)."""
    frames = {}
    for side, (form, name, intrinsics) in cameras.items():
        if form == "gazebo":
            s = model["sensors"][name]
            fx = s["width"] / (2.0 * math.tan(s["hfov"] / 2.0))
            intrinsics = dict(width=s["width"], height=s["height"], fx=fx, fy=fx,
                              cx=(s["width"] - 1) / 2, cy=(s["height"] - 1) / 2,
                              near=s["near"], distortion=s["distortion"])
            frames[side] = (s["link"], s["X"] @ transform(R_LINK_OPTICAL), intrinsics)
        else:
            frames[side] = (name, np.eye(4), intrinsics)
    return frames


# ---------------------------------------------------------------------------------------
# Legacy POPEYE forward kinematics (src/head/kinematics.cc), in the base frame B.

def legacy_popeye(q, B=0.1, D=0.0, H=0.0, delta_l=0.0, delta_r=0.0):
    paper_to_base = np.array([[0.0, 0.0, 1.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]])
    eye_to_camera = lambda d: transform(np.diag([-1.0, -1.0, 1.0]), (0, 0, d))  # noqa: E731
    X_N = transform(paper_to_base) @ transform(rot_y(q["pan"]))
    X_C = X_N @ transform(t=(0, D, 0)) @ transform(rot_x(q["tilt"])) @ transform(t=(0, H, 0))
    X_L = X_C @ transform(t=(B, 0, 0)) @ transform(rot_y(q["left"]))    # eq. 5
    X_R = X_C @ transform(t=(-B, 0, 0)) @ transform(rot_y(q["right"]))  # eq. 6
    return X_L @ eye_to_camera(delta_l), X_R @ eye_to_camera(delta_r)   # eqs. 7-8


# ---------------------------------------------------------------------------------------
# Visuals as point samples, for the self-view check.

def resolve_mesh(filename, urdf_dir):
    if filename.startswith("package://"):
        package, _, rest = filename[len("package://"):].partition("/")
        assert package == PACKAGE, f"unknown package {package}"
        return ROBOTS / rest
    return urdf_dir / filename


def mesh_triangles(path):
    """Triangles (n, 3, 3) of an OBJ, a binary STL or a COLLADA file's <triangles>."""
    if path.suffix == ".obj":
        vertices, faces = [], []
        for line in path.read_text().splitlines():
            parts = line.split()
            if parts and parts[0] == "v":
                vertices.append([float(v) for v in parts[1:4]])
            elif parts and parts[0] == "f":
                idx = [int(p.split("/")[0]) - 1 for p in parts[1:]]
                faces += [(idx[0], idx[i], idx[i + 1]) for i in range(1, len(idx) - 1)]
        return np.array(vertices)[np.array(faces)]
    if path.suffix == ".stl":
        data = path.read_bytes()
        (count,) = struct.unpack_from("<I", data, 80)
        assert len(data) == 84 + 50 * count, f"{path}: not a binary STL"
        return np.array([struct.unpack_from("<12f", data, 84 + 50 * i)[3:]
                         for i in range(count)]).reshape(count, 3, 3)
    if path.suffix == ".dae":
        ns = {"c": "http://www.collada.org/2005/11/COLLADASchema"}
        root = ET.parse(path).getroot()
        positions = np.array(floats(root.find(".//c:source/c:float_array", ns).text, ()))
        positions = positions.reshape(-1, 3)
        triangles = root.find(".//c:triangles", ns)
        stride = len(triangles.findall("c:input", ns))
        p = np.array([int(v) for v in triangles.find("c:p", ns).text.split()])
        return positions[p[0::stride]].reshape(-1, 3, 3)
    raise ValueError(f"{path}: unknown mesh format")


def visual_points(visual, urdf_dir):
    """Points on the visual's surface, in its link's frame."""
    kind, a = visual["kind"], visual["attributes"]
    if kind == "box":
        sx, sy, sz = floats(a["size"], ())
        g = np.linspace(-0.5, 0.5, 9)
        u, v = [m.ravel() for m in np.meshgrid(g, g)]
        one = np.full_like(u, 0.5)
        faces = [np.stack([s * one, u, v], 1) for s in (-1, 1)]
        faces += [np.stack([u, s * one, v], 1) for s in (-1, 1)]
        faces += [np.stack([u, v, s * one], 1) for s in (-1, 1)]
        points = np.concatenate(faces) * [sx, sy, sz]
    elif kind == "sphere":
        n = 600
        i = np.arange(n) + 0.5
        z = 1 - 2 * i / n
        phi = i * math.pi * (3 - math.sqrt(5))
        r = np.sqrt(1 - z * z)
        points = float(a["radius"]) * np.stack([r * np.cos(phi), r * np.sin(phi), z], 1)
    elif kind == "cylinder":
        radius, length = float(a["radius"]), float(a["length"])
        phi = np.linspace(0, 2 * math.pi, 36, endpoint=False)
        rings = [np.stack([rr * np.cos(phi), rr * np.sin(phi), np.full_like(phi, z)], 1)
                 for z in np.linspace(-length / 2, length / 2, 5)
                 for rr in ((radius,) if abs(z) < length / 2 else (radius, radius / 2))]
        points = np.concatenate(rings + [np.array([[0, 0, -length / 2], [0, 0, length / 2]])])
    elif kind == "mesh":
        triangles = mesh_triangles(resolve_mesh(a["filename"], urdf_dir))
        triangles = triangles * floats(a.get("scale"), (1, 1, 1))
        w = np.array([[1, 0, 0], [0, 1, 0], [0, 0, 1], [1 / 3, 1 / 3, 1 / 3],
                      [0.5, 0.5, 0], [0, 0.5, 0.5], [0.5, 0, 0.5]])
        points = np.einsum("kv,tvc->tkc", w, triangles).reshape(-1, 3)
    else:
        raise ValueError(f"unknown geometry <{kind}>")
    return (visual["X"][:3, :3] @ points.T).T + visual["X"][:3, 3]


def in_view(points_optical, k, margin=0.1):
    x, y, z = points_optical.T
    front = z > 1e-9
    zs = np.where(front, z, 1.0)
    u = k["fx"] * x / zs + k["cx"]
    v = k["fy"] * y / zs + k["cy"]
    mw, mh = margin * k["width"], margin * k["height"]
    return front & (u > -mw) & (u < k["width"] + mw) & (v > -mh) & (v < k["height"] + mh)


def eye_links(model, camera_link):
    """The camera link and its ancestors up to the last moving joint: the eye."""
    parent_joint = {j["child"]: (n, j) for n, j in model["joints"].items()}
    links, link = [camera_link], camera_link
    while link in parent_joint:
        name, joint = parent_joint[link]
        link = joint["parent"]
        if joint["type"] != "fixed":
            break
        links.append(link)
    return links + [link] if link not in links else links


# ---------------------------------------------------------------------------------------

def check_head(head_file, spec, rng):
    print(f"== {head_file}")
    facts = head_file_facts(ROBOTS / head_file)
    urdf_path = ROBOTS / facts["urdf"]
    model = parse_urdf(urdf_path)
    print(f"   urdf {facts['urdf']}, root {model['root']}, {len(model['links'])} links")

    # Joints.
    movable = {n: j for n, j in model["joints"].items() if j["type"] != "fixed"}
    check(set(movable) == set(spec["joints"]),
          f"{head_file}: joints {sorted(movable)}, expected {sorted(spec['joints'])}")
    for name, joint in movable.items():
        kind, axis = spec["joints"].get(name, (None, None))
        check(joint["type"] == kind, f"{name}: type {joint['type']}, expected {kind}")
        check(np.allclose(joint["axis"], axis, atol=0), f"{name}: axis {joint['axis']}")
        limit = joint["limit"]
        ok = check(limit is not None and {"lower", "upper", "velocity", "effort"} <= set(limit),
                   f"{name}: <limit> needs lower, upper, velocity and effort")
        if ok:
            check(all(math.isfinite(v) for v in limit.values()), f"{name}: non-finite limit")
            check(limit["lower"] < 0.0 < limit["upper"],
                  f"{name}: limits [{limit['lower']}, {limit['upper']}] must contain 0")
            check(limit["velocity"] > 0.0, f"{name}: velocity must be > 0")
            mimic = joint["mimic"]
            text = ""
            if mimic:
                source, multiplier, offset = mimic
                check(spec.get("mimic", {}).get(name) == mimic, f"{name}: mimic {mimic}")
                s = model["joints"][source]["limit"]
                image = sorted([multiplier * s["lower"] + offset,
                                multiplier * s["upper"] + offset])
                check(limit["lower"] <= image[0] + 1e-15 and image[1] - 1e-15 <= limit["upper"],
                      f"{name}: limits do not contain the image {image} of {source}'s")
                text = f", mimic {source} x {multiplier:g} + {offset:g}"
            print(f"   joint {name:<19} {joint['type']:<9} axis {' '.join(f'{v:g}' for v in joint['axis']):<7}"
                  f" [{math.degrees(limit['lower']):7.2f}, {math.degrees(limit['upper']):6.2f}] deg,"
                  f" {limit['velocity']:g} rad/s{text}")
    check(not spec.get("mimic") or all(movable[m]["mimic"] for m in spec["mimic"]),
          f"{head_file}: a mimic joint is missing")

    # Head file: joints, accelerations, servos.
    driven = driven_joints(model)
    for name, block in facts["joints"].items():
        check(name in driven, f"{head_file}: joints.{name} is not a driven URDF joint")
    servo_ids = []
    for name in driven:
        block = facts["joints"].get(name, "")
        if re.search(r"driven:\s*false", block):
            continue
        check(re.search(r"max_acceleration(_deg)?:\s*[0-9.]+", block),
              f"{head_file}: driven joint {name} has no max_acceleration")
        servo = re.search(r"servo:.*?\bid:\s*(\d+)", block, re.S)
        if servo:
            servo_ids.append(int(servo.group(1)))
    check(len(servo_ids) == len(set(servo_ids)), f"{head_file}: servo ids {servo_ids} repeat")
    if servo_ids:
        print(f"   servo ids {servo_ids}")
    for hold in re.findall(r"hold:\s*\[([^\]]*)\]", facts["text"]):
        for name in filter(None, (n.strip() for n in hold.split(","))):
            check(name in driven, f"{head_file}: fixation holds {name}, not a driven joint")
    for pair in re.findall(r"\[\[(\w+),\s*(\w+),", facts["text"]):
        check(all(n in driven for n in pair), f"{head_file}: symmetric pair {pair}")

    # Cameras at zero joints.
    for side, (form, name, _) in facts["cameras"].items():
        known = model["sensors"] if form == "gazebo" else model["links"]
        check(name in known, f"{head_file}: camera {side}: no {form} {name} in the URDF")
    frames = camera_frames(model, facts["cameras"])
    X0 = forward_kinematics(model, {})
    optical = {side: X0[link] @ X for side, (link, X, _) in frames.items()}
    for side, X in optical.items():
        check(np.allclose(X[:3, 2], [1, 0, 0], atol=1e-12, rtol=0),
              f"{side} camera: optical axis {X[:3, 2]} at zero joints, not the base's +x")
        check(np.allclose(X[:3, 0], [0, -1, 0], atol=1e-12, rtol=0),
              f"{side} camera: image x {X[:3, 0]} at zero joints, not the base's -y")
        check(X[1, 3] > 0 if side == "left" else X[1, 3] < 0, f"{side} camera on the wrong side")
        W = facts["X_W_root"] @ X
        check(abs(W[2, 3] - 1.2) < 0.05 and np.allclose(W[:3, 2], [1, 0, 0], atol=1e-9),
              f"{side} camera in the world at {W[:3, 3]} looking {W[:3, 2]}")
        k = frames[side][2]
        print(f"   {side:<5} camera {facts['cameras'][side][0]} {facts['cameras'][side][1]}:"
              f" {k['width']:g}x{k['height']:g}, fx {k['fx']:.4f} fy {k['fy']:.4f}"
              f" cx {k['cx']:g} cy {k['cy']:g}; in the world at"
              f" ({W[0, 3]:.4f}, {W[1, 3]:.4f}, {W[2, 3]:.4f})"
              + (f", distortion {k['distortion']}" if k.get("distortion") else ""))
    baseline = np.linalg.norm(optical["left"][:3, 3] - optical["right"][:3, 3])
    print(f"   baseline {baseline:.6f} m")
    check(abs(baseline - spec["baseline"]) < 1e-12, f"baseline, expected {spec['baseline']}")

    # Signs of the eyes: a positive eye angle turns that eye left (+y); vergence > 0 converges.
    for side, joint in spec.get("eyes", {}).items():
        X = forward_kinematics(model, {joint: 0.1})
        axis = (X[frames[side][0]] @ frames[side][1])[:3, 2]
        check(np.sign(axis[1]) == spec["eye_sign"], f"{joint} > 0 turns the {side} eye {axis}")
    if "vergence" in spec:
        X = forward_kinematics(model, {spec["vergence"]: 0.1})
        left = (X[frames["left"][0]] @ frames["left"][1])[:3, 2]
        right = (X[frames["right"][0]] @ frames["right"][1])[:3, 2]
        check(left[1] < 0 < right[1], f"vergence > 0 must converge: left {left}, right {right}")
        check(abs(left[1] + right[1]) < 1e-15, "vergence is not symmetric")
        print(f"   vergence 0.1 rad: left axis y {left[1]:+.6f}, right axis y {right[1]:+.6f}"
              " (converging)")

    # POPEYE against the legacy kinematics.
    if head_file == "popeye_urdf.yaml":
        worst = 0.0
        for q in itertools.islice(random_configurations(model, rng, SAMPLES), SAMPLES):
            X = forward_kinematics(model, q)
            legacy = legacy_popeye(q)
            for side, L in zip(("left", "right"), legacy):
                worst = max(worst, np.abs(X[f"{side}_camera_optical"] - L).max())
        print(f"   legacy FK: max |X_urdf - X_legacy| over {SAMPLES} random joint vectors:"
              f" {worst:.3e}")
        check(worst <= 1e-12, f"popeye.urdf differs from the legacy FK by {worst:g}")

    # Self-view.
    urdf_dir = urdf_path.parent
    points = {link: np.concatenate([visual_points(v, urdf_dir) for v in visuals])
              for link, visuals in model["links"].items() if visuals}
    forbidden = {side: set(spec["never_seen"]) | set(eye_links(model, frames[side][0]))
                 for side in frames}
    seen = {}
    configurations = 0
    for q in random_configurations(model, rng, SAMPLES):
        configurations += 1
        X = forward_kinematics(model, q)
        for side, (link, X_link_optical, k) in frames.items():
            X_O = X[link] @ X_link_optical
            R, t = X_O[:3, :3], X_O[:3, 3]
            for other, p in points.items():
                p_root = (X[other][:3, :3] @ p.T).T + X[other][:3, 3]
                hits = in_view((p_root - t) @ R, k).sum()
                if hits:
                    seen.setdefault((side, other), [0, 0])
                    seen[(side, other)][0] += 1
                    seen[(side, other)][1] = max(seen[(side, other)][1], int(hits))
    for (side, other), (count, most) in sorted(seen.items()):
        bad = other in forbidden[side]
        print(f"   {'FAIL: ' if bad else 'note: '}the {side} camera sees {other} in {count} of"
              f" {configurations} postures (at most {most} sample points)")
        if bad:
            failures.append(f"{head_file}: the {side} camera sees {other}")
    if not any(other in forbidden[side] for side, other in seen):
        print(f"   self-view: over {configurations} postures no camera sees its own eye or"
              f" {', '.join(spec['never_seen'])}")


def main():
    rng = np.random.default_rng(RNG_SEED)
    for head_file, spec in HEADS.items():
        check_head(head_file, spec, rng)
    if failures:
        print(f"\n{len(failures)} check(s) FAILED")
        sys.exit(1)
    print("\nall heads pass")


if __name__ == "__main__":
    main()
