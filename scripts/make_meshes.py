#!/usr/bin/env python3
"""Writes the meshes the project uses (all made here, from formulas; no third-party models):

  scenes/examples/meshes/boulder.obj   the dam break's obstacle: an icosphere (4 subdivisions)
                                       whose radius varies smoothly with direction, flattened below
  tests/data/meshes/cube.{obj,stl,ply} a unit cube [0, 1]^3 in each format the loader reads (the STL
                                       binary, the PLY binary little-endian, the OBJ with quads)
  tests/data/meshes/sphere.obj         an icosphere of radius 1 (3 subdivisions), centred at 0
  tests/scene/bad/meshes/*             broken meshes for the bad-input corpus: open, degenerate,
                                       inconsistently oriented, empty, not a mesh at all

Run from the repository root: python3 scripts/make_meshes.py. The output is deterministic.
"""
import math
import os
import struct

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


def icosphere(subdivisions):
    t = (1 + math.sqrt(5)) / 2
    verts = [(-1, t, 0), (1, t, 0), (-1, -t, 0), (1, -t, 0), (0, -1, t), (0, 1, t), (0, -1, -t), (0, 1, -t),
             (t, 0, -1), (t, 0, 1), (-t, 0, -1), (-t, 0, 1)]
    verts = [tuple(c / math.sqrt(sum(x * x for x in v)) for c in v) for v in verts]
    faces = [(0, 11, 5), (0, 5, 1), (0, 1, 7), (0, 7, 10), (0, 10, 11), (1, 5, 9), (5, 11, 4), (11, 10, 2),
             (10, 7, 6), (7, 1, 8), (3, 9, 4), (3, 4, 2), (3, 2, 6), (3, 6, 8), (3, 8, 9), (4, 9, 5), (2, 4, 11),
             (6, 2, 10), (8, 6, 7), (9, 8, 1)]
    for _ in range(subdivisions):
        cache = {}

        def middle(a, b):
            key = (min(a, b), max(a, b))
            if key not in cache:
                m = [(verts[a][k] + verts[b][k]) / 2 for k in range(3)]
                n = math.sqrt(sum(x * x for x in m))
                verts.append(tuple(x / n for x in m))
                cache[key] = len(verts) - 1
            return cache[key]

        new = []
        for a, b, c in faces:
            ab, bc, ca = middle(a, b), middle(b, c), middle(c, a)
            new += [(a, ab, ca), (b, bc, ab), (c, ca, bc), (ab, bc, ca)]
        faces = new
    return verts, faces


def write_obj(path, verts, faces, comment):
    os.makedirs(os.path.dirname(path), exist_ok=True)
    with open(path, "w") as f:
        f.write(f"# {comment}\n# written by scripts/make_meshes.py\n")
        for v in verts:
            f.write("v {:.9g} {:.9g} {:.9g}\n".format(*v))
        for face in faces:
            f.write("f " + " ".join(str(i + 1) for i in face) + "\n")


def triangles(faces):
    for face in faces:
        for k in range(1, len(face) - 1):
            yield face[0], face[k], face[k + 1]


def normal(a, b, c):
    u = [b[k] - a[k] for k in range(3)]
    w = [c[k] - a[k] for k in range(3)]
    n = [u[1] * w[2] - u[2] * w[1], u[2] * w[0] - u[0] * w[2], u[0] * w[1] - u[1] * w[0]]
    length = math.sqrt(sum(x * x for x in n)) or 1
    return [x / length for x in n]


def write_stl_binary(path, verts, faces):
    tris = list(triangles(faces))
    with open(path, "wb") as f:
        f.write(b"binary STL written by scripts/make_meshes.py".ljust(80, b" "))
        f.write(struct.pack("<I", len(tris)))
        for a, b, c in tris:
            f.write(struct.pack("<3f", *normal(verts[a], verts[b], verts[c])))
            for i in (a, b, c):
                f.write(struct.pack("<3f", *verts[i]))
            f.write(struct.pack("<H", 0))


def write_ply_binary(path, verts, faces):
    tris = list(triangles(faces))
    with open(path, "wb") as f:
        f.write(("ply\nformat binary_little_endian 1.0\ncomment written by scripts/make_meshes.py\n"
                 f"element vertex {len(verts)}\nproperty float x\nproperty float y\nproperty float z\n"
                 f"element face {len(tris)}\nproperty list uchar int vertex_indices\nend_header\n").encode())
        for v in verts:
            f.write(struct.pack("<3f", *v))
        for t in tris:
            f.write(struct.pack("<B3i", 3, *t))


CUBE_VERTS = [(x, y, z) for z in (0, 1) for y in (0, 1) for x in (0, 1)]
# Quads, counter-clockwise seen from outside (vertex index = x + 2 y + 4 z).
CUBE_QUADS = [(0, 2, 3, 1), (4, 5, 7, 6), (0, 1, 5, 4), (2, 6, 7, 3), (0, 4, 6, 2), (1, 3, 7, 5)]


def boulder():
    verts, faces = icosphere(4)
    out = []
    for x, y, z in verts:
        # A smooth, deterministic radius: a few low-order lobes, so that the boulder is round but not a sphere.
        r = 1 + 0.12 * math.sin(3 * x + 1.3) * math.cos(2 * y) + 0.08 * math.cos(4 * z + 0.7 * x) + 0.05 * math.sin(5 * y * z)
        p = [x * r, y * r, z * r]
        # A flat underside that sits on the floor, cut near the widest part: its sides meet the floor
        # at nearly a right angle, leaving no thin wedge under an overhang for particles to be
        # squeezed into.
        p[1] = max(p[1], -0.25)
        # About 0.36 m long, 0.2 m tall, 0.25 m deep, its underside at y = 0.
        out.append((0.16 * p[0], 0.14 * (p[1] + 0.25), 0.11 * p[2]))
    return out, faces


def main():
    verts, faces = boulder()
    write_obj(os.path.join(ROOT, "scenes/examples/meshes/boulder.obj"), verts, faces,
              "a boulder for scenes/examples/dam_break_boulder_3d.json, its underside at y = 0")

    data = os.path.join(ROOT, "tests/data/meshes")
    write_obj(os.path.join(data, "cube.obj"), CUBE_VERTS, CUBE_QUADS, "the unit cube [0, 1]^3, quads")
    write_stl_binary(os.path.join(data, "cube.stl"), CUBE_VERTS, CUBE_QUADS)
    write_ply_binary(os.path.join(data, "cube.ply"), CUBE_VERTS, CUBE_QUADS)
    sv, sf = icosphere(3)
    write_obj(os.path.join(data, "sphere.obj"), sv, sf, "an icosphere of radius 1 about the origin")

    bad = os.path.join(ROOT, "tests/scene/bad/meshes")
    write_obj(os.path.join(bad, "open_box.obj"), CUBE_VERTS, CUBE_QUADS[1:], "a unit cube without its bottom face")
    flipped = list(CUBE_QUADS)
    flipped[2] = tuple(reversed(flipped[2]))
    write_obj(os.path.join(bad, "flipped_face.obj"), CUBE_VERTS, flipped, "a unit cube with one face turned inside")
    # A sliver: the cube with one quad split through an extra vertex on an edge (a triangle of zero area).
    dverts = CUBE_VERTS + [(0.5, 0, 0)]
    dfaces = [q for q in CUBE_QUADS if q not in ((0, 2, 3, 1), (0, 1, 5, 4))]
    dfaces += [(0, 2, 3), (0, 3, 1), (0, 1, 8), (8, 1, 5), (8, 5, 4), (8, 4, 0)]
    write_obj(os.path.join(bad, "degenerate.obj"), dverts, dfaces, "a cube with a triangle of zero area")
    os.makedirs(bad, exist_ok=True)
    with open(os.path.join(bad, "empty.obj"), "w") as f:
        f.write("# no vertices, no faces\n")
    with open(os.path.join(bad, "not_a_mesh.stl"), "w") as f:
        f.write("These are not the triangles you are looking for.\n")


if __name__ == "__main__":
    main()
