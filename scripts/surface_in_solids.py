#!/usr/bin/env python3
"""How far a run's free surfaces reach into its mesh obstacles (docs/visualization.md, "Surfaces").

    python3 scripts/surface_in_solids.py RUN_DIR SURFACE_DIR [TOLERANCE_M]

For each SURFACE_DIR/surface_NNNNNN.obj (`sph surface RUN_DIR --format obj`), the vertices that lie
inside one of the run's mesh obstacles (RUN_DIR/scene.json's Obstacles[].geometryFile, placed by
its scale, rotation and translation) by more than TOLERANCE_M (default 0.001 m), and the deepest.
Obstacles without a mesh, moving ones and inverted ones are not measured. Plain Python: the
distance to a mesh is that of the nearest triangle, found through a grid of the triangles'
bounding boxes; its sign is the side of that triangle's plane (the meshes here are closed and
turned outwards).
"""
import json
import math
import sys
from pathlib import Path


def read_obj(path):
    vertices, faces = [], []
    for line in Path(path).read_text().splitlines():
        parts = line.split()
        if not parts:
            continue
        if parts[0] == "v":
            vertices.append(tuple(float(c) for c in parts[1:4]))
        elif parts[0] == "f":
            idx = [int(p.split("/")[0]) for p in parts[1:]]
            for k in range(1, len(idx) - 1):
                faces.append((idx[0] - 1, idx[k] - 1, idx[k + 1] - 1))
    return vertices, faces


def sub(a, b):
    return (a[0] - b[0], a[1] - b[1], a[2] - b[2])


def dot(a, b):
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]


def cross(a, b):
    return (a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0])


def closest_on_triangle(p, a, b, c):
    """The point of triangle abc nearest p (Ericson, Real-Time Collision Detection, 5.1.5)."""
    ab, ac, ap = sub(b, a), sub(c, a), sub(p, a)
    d1, d2 = dot(ab, ap), dot(ac, ap)
    if d1 <= 0 and d2 <= 0:
        return a
    bp = sub(p, b)
    d3, d4 = dot(ab, bp), dot(ac, bp)
    if d3 >= 0 and d4 <= d3:
        return b
    vc = d1 * d4 - d3 * d2
    if vc <= 0 and d1 >= 0 and d3 <= 0:
        v = d1 / (d1 - d3)
        return (a[0] + v * ab[0], a[1] + v * ab[1], a[2] + v * ab[2])
    cp = sub(p, c)
    d5, d6 = dot(ab, cp), dot(ac, cp)
    if d6 >= 0 and d5 <= d6:
        return c
    vb = d5 * d2 - d1 * d6
    if vb <= 0 and d2 >= 0 and d6 <= 0:
        w = d2 / (d2 - d6)
        return (a[0] + w * ac[0], a[1] + w * ac[1], a[2] + w * ac[2])
    va = d3 * d6 - d5 * d4
    if va <= 0 and (d4 - d3) >= 0 and (d5 - d6) >= 0:
        w = (d4 - d3) / ((d4 - d3) + (d5 - d6))
        return (b[0] + w * (c[0] - b[0]), b[1] + w * (c[1] - b[1]), b[2] + w * (c[2] - b[2]))
    denom = 1.0 / (va + vb + vc)
    v, w = vb * denom, vc * denom
    return (a[0] + ab[0] * v + ac[0] * w, a[1] + ab[1] * v + ac[1] * w, a[2] + ab[2] * v + ac[2] * w)


class Solid:
    """A closed, outward mesh placed as the scene places it, with a grid of its triangles."""

    def __init__(self, obstacle, cell):
        vertices, self.faces = read_obj(obstacle["geometryFile"])
        s = obstacle.get("scale", [1, 1, 1])
        t = obstacle.get("translation", [0, 0, 0])
        k = obstacle.get("rotationAxis", [0, 0, 1])
        n = math.sqrt(dot(k, k))
        k = (k[0] / n, k[1] / n, k[2] / n)
        angle = obstacle.get("rotationAngle", 0.0)
        c, sn = math.cos(angle), math.sin(angle)
        self.v = []
        for x in vertices:  # x = t + R (s * X), Rodrigues' rotation (as the scene reader places it)
            v = (x[0] * s[0], x[1] * s[1], x[2] * s[2])
            kxv, kv = cross(k, v), dot(k, v)
            self.v.append(tuple(t[d] + v[d] * c + kxv[d] * sn + k[d] * kv * (1 - c) for d in range(3)))
        self.cell = cell
        self.grid = {}
        for f, (i, j, m) in enumerate(self.faces):
            lo = [min(self.v[i][d], self.v[j][d], self.v[m][d]) for d in range(3)]
            hi = [max(self.v[i][d], self.v[j][d], self.v[m][d]) for d in range(3)]
            for gx in range(math.floor(lo[0] / cell), math.floor(hi[0] / cell) + 1):
                for gy in range(math.floor(lo[1] / cell), math.floor(hi[1] / cell) + 1):
                    for gz in range(math.floor(lo[2] / cell), math.floor(hi[2] / cell) + 1):
                        self.grid.setdefault((gx, gy, gz), []).append(f)
        self.lo = [min(v[d] for v in self.v) for d in range(3)]
        self.hi = [max(v[d] for v in self.v) for d in range(3)]

    def depth(self, p, reach):
        """How far p lies inside the solid (> 0 inside), if it is within `reach` of the surface; else None."""
        if any(p[d] < self.lo[d] - reach or p[d] > self.hi[d] + reach for d in range(3)):
            return None
        g = [math.floor(p[d] / self.cell) for d in range(3)]
        r = math.ceil(reach / self.cell)
        best, best_face = None, None
        seen = set()
        for gx in range(g[0] - r, g[0] + r + 1):
            for gy in range(g[1] - r, g[1] + r + 1):
                for gz in range(g[2] - r, g[2] + r + 1):
                    for f in self.grid.get((gx, gy, gz), ()):
                        if f in seen:
                            continue
                        seen.add(f)
                        i, j, m = self.faces[f]
                        q = closest_on_triangle(p, self.v[i], self.v[j], self.v[m])
                        d2 = dot(sub(p, q), sub(p, q))
                        if best is None or d2 < best[0]:
                            best, best_face = (d2, q), f
        if best is None or best[0] > reach * reach:
            return None
        i, j, m = self.faces[best_face]
        normal = cross(sub(self.v[j], self.v[i]), sub(self.v[m], self.v[i]))
        inside = dot(sub(p, best[1]), normal) < 0
        return math.sqrt(best[0]) * (1 if inside else -1)


def main():
    if len(sys.argv) < 3:
        sys.exit(__doc__)
    run, surfaces = Path(sys.argv[1]), Path(sys.argv[2])
    tolerance = float(sys.argv[3]) if len(sys.argv) > 3 else 0.001
    scene = json.loads((run / "scene.json").read_text())
    cell = 2 * scene["Configuration"]["particleRadius"]
    solids = [Solid(o, cell) for o in scene.get("Obstacles", [])
              if "geometryFile" in o and not o.get("inverted") and not o.get("dynamic")
              and o.get("motion", {}).get("type", "none") == "none"]
    if not solids:
        sys.exit("surface_in_solids: the run has no static mesh obstacle to measure")
    for path in sorted(surfaces.glob("surface_*.obj")):
        vertices, _ = read_obj(path)
        inside, deepest = 0, 0.0
        for p in vertices:
            for s in solids:
                d = s.depth(p, 2 * cell)
                if d is not None and d > 0:
                    deepest = max(deepest, d)
                    inside += d > tolerance
        print(f"{path.name}: {len(vertices)} vertices, {inside} more than {tolerance:g} m inside an obstacle, "
              f"the deepest {1000 * deepest:.2f} mm")


if __name__ == "__main__":
    main()
