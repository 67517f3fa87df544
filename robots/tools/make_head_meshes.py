#!/usr/bin/env python3
"""Writes the meshes of the shipped heads (robots/*/meshes/), deterministically.

    python3 robots/tools/make_head_meshes.py [--check]

Only python3 and numpy. The outputs are committed; rerun this after changing it (--check
compares the files on disk with what it would write and fails on a difference).

humanoid/meshes/skull.obj + skull.mtl  the skull shell of robots/humanoid/humanoid.urdf, in
    head_link's frame (the neck yaw joint; x forward, y left, z up): an ellipsoid cut by the
    plane x = SKULL_CUT_X, closed by a flat face plate there. The eyes' rotation centres are at
    x = 0.07 and their optical centres further ahead, so the shell stays behind every eye
    camera's optical centre for every joint angle and never blocks a camera's view.
humanoid/meshes/neck.stl  (binary STL) the neck column in neck_roll_link's frame: a tapered,
    closed 24-sided frustum from z = 0 to the neck yaw joint.
"""

import argparse
import pathlib
import struct
import sys

import numpy as np

ROBOTS = pathlib.Path(__file__).resolve().parent.parent

# Skull: ellipsoid centre and semi-axes (metres, head_link frame), and the cut plane.
SKULL_CENTRE = np.array([0.0, 0.0, 0.10])
SKULL_AXES = np.array([0.10, 0.08, 0.11])
SKULL_CUT_X = 0.055
SKULL_RINGS = 8  # latitude bands from the back pole to the cut
SKULL_SEGMENTS = 24  # around the x axis

# Neck column: bottom and top radii, height (the neck yaw joint is 0.04 above neck roll).
NECK_BOTTOM_RADIUS = 0.030
NECK_TOP_RADIUS = 0.024
NECK_HEIGHT = 0.04
NECK_SEGMENTS = 24


def skull():
    """Vertices and counter-clockwise (outward) triangles of the closed skull shell."""
    a, b, c = SKULL_AXES
    # Parameter along x: u = (x - centre_x) / a from -1 (back pole) to the cut.
    u_cut = (SKULL_CUT_X - SKULL_CENTRE[0]) / a
    theta_cut = np.arccos(-u_cut)  # polar angle from the back pole (-x)
    thetas = np.linspace(0.0, theta_cut, SKULL_RINGS + 1)[1:]
    phis = np.linspace(0.0, 2.0 * np.pi, SKULL_SEGMENTS, endpoint=False)
    vertices = [SKULL_CENTRE + np.array([-a, 0.0, 0.0])]  # back pole
    for theta in thetas:
        for phi in phis:
            vertices.append(
                SKULL_CENTRE
                + np.array([-a * np.cos(theta), b * np.sin(theta) * np.cos(phi),
                            c * np.sin(theta) * np.sin(phi)]))
    vertices.append(np.array([SKULL_CUT_X, SKULL_CENTRE[1], SKULL_CENTRE[2]]))  # plate centre
    vertices = np.array(vertices)
    vertices[-SKULL_SEGMENTS - 1:-1, 0] = SKULL_CUT_X  # the last ring exactly on the cut

    n = SKULL_SEGMENTS
    ring = lambda i, j: 1 + i * n + (j % n)  # noqa: E731
    triangles = []
    for j in range(n):  # cap at the back pole
        triangles.append((0, ring(0, j + 1), ring(0, j)))
    for i in range(SKULL_RINGS - 1):
        for j in range(n):
            triangles.append((ring(i, j), ring(i, j + 1), ring(i + 1, j + 1)))
            triangles.append((ring(i, j), ring(i + 1, j + 1), ring(i + 1, j)))
    centre = len(vertices) - 1
    for j in range(n):  # the flat face plate at the cut, facing +x
        triangles.append((centre, ring(SKULL_RINGS - 1, j), ring(SKULL_RINGS - 1, j + 1)))
    return vertices, np.array(triangles)


def neck():
    """Vertices and outward triangles of the closed neck frustum."""
    n = NECK_SEGMENTS
    phis = np.linspace(0.0, 2.0 * np.pi, n, endpoint=False)
    bottom = [(NECK_BOTTOM_RADIUS * np.cos(p), NECK_BOTTOM_RADIUS * np.sin(p), 0.0) for p in phis]
    top = [(NECK_TOP_RADIUS * np.cos(p), NECK_TOP_RADIUS * np.sin(p), NECK_HEIGHT) for p in phis]
    vertices = np.array(bottom + top + [(0.0, 0.0, 0.0), (0.0, 0.0, NECK_HEIGHT)])
    triangles = []
    for j in range(n):
        k = (j + 1) % n
        triangles.append((j, k, n + k))
        triangles.append((j, n + k, n + j))
        triangles.append((2 * n, k, j))  # bottom, facing -z
        triangles.append((2 * n + 1, n + j, n + k))  # top, facing +z
    return vertices, np.array(triangles)


def check_closed_and_outward(vertices, triangles, name):
    """Every edge shared by exactly two triangles in opposite directions; positive volume."""
    edges = {}
    for t in triangles:
        for e in ((t[0], t[1]), (t[1], t[2]), (t[2], t[0])):
            edges[e] = edges.get(e, 0) + 1
    for (i, j), count in edges.items():
        if count != 1 or edges.get((j, i)) != 1:
            sys.exit(f"{name}: edge {i}-{j} is not shared by exactly two triangles")
    v = vertices[triangles]
    volume = np.einsum("ij,ij->i", v[:, 0], np.cross(v[:, 1], v[:, 2])).sum() / 6.0
    if not volume > 0.0:
        sys.exit(f"{name}: the triangles face inward (volume {volume})")
    return volume


def fmt(x):
    """Six decimals (micrometres), trailing zeros dropped, never "-0"."""
    text = f"{round(float(x), 6) + 0.0:.6f}".rstrip("0").rstrip(".")
    return "0" if text in ("", "-0") else text


def obj_text(vertices, triangles, material_file, material):
    lines = ["# Written by robots/tools/make_head_meshes.py; do not edit by hand.",
             f"# {len(vertices)} vertices, {len(triangles)} triangles, metres.",
             f"mtllib {material_file}", "o skull"]
    lines += [f"v {fmt(x)} {fmt(y)} {fmt(z)}" for x, y, z in vertices]
    lines += [f"usemtl {material}", "s off"]
    lines += [f"f {a + 1} {b + 1} {c + 1}" for a, b, c in triangles]
    return "\n".join(lines) + "\n"


def mtl_text(material, colour):
    r, g, b = colour
    return "\n".join([
        "# Written by robots/tools/make_head_meshes.py; do not edit by hand.",
        f"newmtl {material}",
        f"Ka {r * 0.3:.3f} {g * 0.3:.3f} {b * 0.3:.3f}",
        f"Kd {r:.3f} {g:.3f} {b:.3f}",
        "Ks 0.200 0.200 0.200",
        "Ns 20.000",
        "d 1.000",
        "illum 2",
    ]) + "\n"


def stl_bytes(vertices, triangles, name):
    header = f"saccade {name}: robots/tools/make_head_meshes.py".encode("ascii")
    out = bytearray(header.ljust(80, b" ")[:80])
    out += struct.pack("<I", len(triangles))
    for t in triangles:
        p = vertices[t].astype(np.float64)
        normal = np.cross(p[1] - p[0], p[2] - p[0])
        normal /= np.linalg.norm(normal)
        out += struct.pack("<12fH", *normal, *p[0], *p[1], *p[2], 0)
    return bytes(out)


def outputs():
    skull_v, skull_t = skull()
    neck_v, neck_t = neck()
    check_closed_and_outward(skull_v, skull_t, "skull")
    check_closed_and_outward(neck_v, neck_t, "neck")
    for name, t in (("skull", skull_t), ("neck", neck_t)):
        if len(t) > 600:
            sys.exit(f"{name}: {len(t)} triangles, more than 600")
    meshes = ROBOTS / "humanoid" / "meshes"
    return {
        meshes / "skull.obj": obj_text(skull_v, skull_t, "skull.mtl", "skull_shell").encode(),
        meshes / "skull.mtl": mtl_text("skull_shell", (0.82, 0.84, 0.86)).encode(),
        meshes / "neck.stl": stl_bytes(neck_v, neck_t, "humanoid neck"),
    }


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--check", action="store_true",
                        help="compare with the files on disk instead of writing them")
    args = parser.parse_args()
    stale = []
    for path, data in outputs().items():
        if args.check:
            if not path.exists() or path.read_bytes() != data:
                stale.append(path)
        else:
            path.parent.mkdir(parents=True, exist_ok=True)
            path.write_bytes(data)
            print(f"wrote {path.relative_to(ROBOTS.parent)} ({len(data)} bytes)")
    if stale:
        sys.exit("out of date: " + ", ".join(str(p) for p in stale))


if __name__ == "__main__":
    main()
