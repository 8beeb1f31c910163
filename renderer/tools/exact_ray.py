#!/usr/bin/env python3
"""Who is right where Embree and the BVH disagree: each ray of `pt bench rays --disagreements FILE`
traced against every triangle of the mesh in exact rational arithmetic (on the float corners and
the float ray, as both backends see them), with a verdict per ray.

    pt bench rays MESH.obj --studio none --disagreements DISAGREEMENTS.csv
    renderer/tools/exact_ray.py MESH.obj DISAGREEMENTS.csv

MESH.obj holds triangles only (the bench's scans and generated meshes; a polygon is split as a fan,
which may not be how pt split it), in the order pt numbers them. The default studio's ground is not
in the file, so run the bench with `--studio none`: a row whose answer is a triangle past the
file's (the ground) is reported as not judged. A ray hits a triangle when its line passes inside
or on the triangle's edges at a distance within [tmin, tmax]; the exact test needs no tolerance.
Slow (pure Python): meant for the handful of rays a sweep reports.

    pt bench rays SCENE.json --studio none --disagreements DISAGREEMENTS.csv
    renderer/tools/exact_ray.py SCENE.json DISAGREEMENTS.csv

A JSON scene of OBJ objects placed by "matrix" (as `pt gen instances` writes them), each object
once or as "instances": each placement is tested exactly too, the world ray taken into the mesh's
space by the exact inverse of the float matrix (so t and the barycentrics are the world's). Both
backends round that transform, so on a ray that starts within its rounding of a surface either
answer can be the float transform's truth and the exact one's lie; the report gives the exact
distance of the origin from the nearest surface to tell those rows apart.
"""
import json
import os
import argparse
import csv
import struct
import sys
from fractions import Fraction


def f32(text):
    return struct.unpack("f", struct.pack("f", float(text)))[0]


def load_obj(path):
    vertices, triangles = [], []
    with open(path) as f:
        for line in f:
            parts = line.split()
            if not parts:
                continue
            if parts[0] == "v":
                vertices.append(tuple(f32(x) for x in parts[1:4]))
            elif parts[0] == "f":
                idx = [int(p.split("/")[0]) for p in parts[1:]]
                idx = [i - 1 if i > 0 else len(vertices) + i for i in idx]
                for k in range(1, len(idx) - 1):
                    triangles.append((vertices[idx[0]], vertices[idx[k]], vertices[idx[k + 1]]))
    return triangles


def f32_matrix(values, where):
    if len(values) not in (12, 16):
        sys.exit(f"exact_ray: {where}: a matrix of 12 or 16 numbers expected")
    return [[f32(values[4 * r + c]) for c in range(4)] for r in range(3)]


IDENTITY = [[1.0, 0.0, 0.0, 0.0], [0.0, 1.0, 0.0, 0.0], [0.0, 0.0, 1.0, 0.0]]


def mat_mul(a, b):
    """a * b of two affine 3x4 matrices, each product and sum rounded to float as pt does (the object's
    own matrix times an instance's)."""
    out = []
    for r in range(3):
        row = []
        for c in range(4):
            v = f32(f32(a[r][0] * b[0][c]) + f32(a[r][1] * b[1][c]))
            v = f32(v + f32(a[r][2] * b[2][c]))
            if c == 3:
                v = f32(v + a[r][3])
            row.append(v)
        out.append(row)
    return out


def load_scene(path):
    """(meshes, placements): each mesh a list of triangles; each placement (mesh index, matrix or None)
    in pt's numbering of instances (objects placed once are not instances: their triangles are
    transformed in float by pt, which this does not imitate, so only the identity is taken)."""
    with open(path) as f:
        scene = json.load(f)
    base = os.path.dirname(path)
    meshes, placements, flat = [], [], []
    for k, o in enumerate(scene.get("objects", [])):
        where = f"{path}: /objects/{k}"
        if any(key in o for key in ("translate", "rotate", "scale")) or any(
                key in i for i in o.get("instances", []) for key in ("translate", "rotate", "scale")):
            sys.exit(f"exact_ray: {where}: only 'matrix' placements are read")
        file = os.path.join(base, o["file"])
        if not file.lower().endswith(".obj"):
            sys.exit(f"exact_ray: {where}: only OBJ files are read")
        own = f32_matrix(o["matrix"], where + "/matrix") if "matrix" in o else IDENTITY
        if "instances" not in o:
            if own != IDENTITY:
                sys.exit(f"exact_ray: {where}: an object placed once must be untransformed")
            flat.extend(load_obj(file))
            continue
        meshes.append(load_obj(file))
        for i, inst in enumerate(o["instances"]):
            m = f32_matrix(inst["matrix"], f"{where}/instances/{i}/matrix") if "matrix" in inst else IDENTITY
            placements.append((len(meshes) - 1, mat_mul(own, m) if own != IDENTITY else m))
    return flat, meshes, placements


class Bvh:
    """A plain bounding-volume tree over one mesh's triangles (float boxes, widened): only to find the
    few triangles near a ray before the exact test."""

    def __init__(self, triangles):
        self.tris = triangles
        boxes = []
        for a, b, c in triangles:
            lo = tuple(min(a[i], b[i], c[i]) for i in range(3))
            hi = tuple(max(a[i], b[i], c[i]) for i in range(3))
            boxes.append((lo, hi))
        self.nodes = []  # (lo, hi, left, right, items)
        self.root = self._build(list(range(len(triangles))), boxes)

    def _build(self, items, boxes):
        lo = [min(boxes[i][0][k] for i in items) for k in range(3)]
        hi = [max(boxes[i][1][k] for i in items) for k in range(3)]
        pad = 1e-6 * max(1.0, max(abs(x) for x in lo + hi))
        lo = tuple(x - pad for x in lo)
        hi = tuple(x + pad for x in hi)
        node = len(self.nodes)
        self.nodes.append(None)
        if len(items) <= 8:
            self.nodes[node] = (lo, hi, -1, -1, items)
            return node
        axis = max(range(3), key=lambda k: hi[k] - lo[k])
        items.sort(key=lambda i: boxes[i][0][axis] + boxes[i][1][axis])
        mid = len(items) // 2
        left = self._build(items[:mid], boxes)
        right = self._build(items[mid:], boxes)
        self.nodes[node] = (lo, hi, left, right, None)
        return node

    def near(self, o, d, tmin, tmax):
        """Indices of the triangles whose widened boxes the ray (float64) passes within [tmin, tmax]."""
        out, stack = [], [self.root]
        while stack:
            lo, hi, left, right, items = self.nodes[stack.pop()]
            if not box_hit(o, d, lo, hi, tmin, tmax):
                continue
            if items is not None:
                out.extend(items)
            else:
                stack += [left, right]
        return out


def box_hit(o, d, lo, hi, tmin, tmax):
    t0, t1 = tmin, tmax
    for k in range(3):
        if d[k] == 0.0:
            if o[k] < lo[k] or o[k] > hi[k]:
                return False
            continue
        a, b = (lo[k] - o[k]) / d[k], (hi[k] - o[k]) / d[k]
        if a > b:
            a, b = b, a
        t0, t1 = max(t0, a - 1e-9 * abs(a)), min(t1, b + 1e-9 * abs(b))
        if t0 > t1:
            return False
    return True


def affine_inverse(m, number=float):
    """The inverse of an affine 3x4 matrix, as (3x3 linear part, translation), in `number` arithmetic."""
    a = [[number(m[r][c]) for c in range(3)] for r in range(3)]
    t = [number(m[r][3]) for r in range(3)]
    det = (a[0][0] * (a[1][1] * a[2][2] - a[1][2] * a[2][1]) - a[0][1] * (a[1][0] * a[2][2] - a[1][2] * a[2][0]) +
           a[0][2] * (a[1][0] * a[2][1] - a[1][1] * a[2][0]))
    inv = [[(a[(c + 1) % 3][(r + 1) % 3] * a[(c + 2) % 3][(r + 2) % 3] -
             a[(c + 1) % 3][(r + 2) % 3] * a[(c + 2) % 3][(r + 1) % 3]) / det for c in range(3)] for r in range(3)]
    it = [-(inv[r][0] * t[0] + inv[r][1] * t[1] + inv[r][2] * t[2]) for r in range(3)]
    return inv, it


def apply(inv, it, o, d):
    o2 = tuple(inv[r][0] * o[0] + inv[r][1] * o[1] + inv[r][2] * o[2] + it[r] for r in range(3))
    d2 = tuple(inv[r][0] * d[0] + inv[r][1] * d[1] + inv[r][2] * d[2] for r in range(3))
    return o2, d2


def sub(a, b):
    return (a[0] - b[0], a[1] - b[1], a[2] - b[2])


def cross(a, b):
    return (a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0])


def dot(a, b):
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]


def near_candidate(o, d, tri, slack=1e-3):
    """A float Möller-Trumbore test with a wide margin: only triangles it keeps are tested exactly."""
    a, b, c = tri
    e1, e2 = sub(b, a), sub(c, a)
    p = cross(d, e2)
    det = dot(e1, p)
    if det == 0.0:
        return False
    s = sub(o, a)
    u = dot(s, p) / det
    if u < -slack or u > 1 + slack:
        return False
    q = cross(s, e1)
    v = dot(d, q) / det
    return v >= -slack and u + v <= 1 + slack


def exact_hit(o, d, tri, tmin, tmax):
    """(t, the least barycentric, whether t is in [tmin, tmax]) where the ray's line meets the triangle's
    plane, exactly; None where it is parallel to it."""
    a, b, c = [tuple(Fraction(x) for x in p) for p in tri]
    n = cross(sub(b, a), sub(c, a))
    den = dot(n, d)
    if den == 0:
        return None
    t = dot(n, sub(a, o)) / den
    p = tuple(o[i] + t * d[i] for i in range(3))
    nn = dot(n, n)
    w = [dot(cross(sub(b, p), sub(c, p)), n) / nn, dot(cross(sub(c, p), sub(a, p)), n) / nn,
         dot(cross(sub(a, p), sub(b, p)), n) / nn]
    return t, min(w), tmin <= t <= tmax


class Judge:
    """The exact nearest hit of a ray in a mesh or a scene of placed meshes."""

    def __init__(self, path):
        if path.lower().endswith(".json"):
            flat, self.meshes, self.placements = load_scene(path)
        else:
            flat, self.meshes, self.placements = load_obj(path), [], []
        self.flat = Bvh(flat) if flat else None
        self.trees = [Bvh(m) for m in self.meshes]
        self.count = len(flat) + sum(len(self.meshes[k]) for k, _ in self.placements)
        self.world_boxes, self.inverses = [], []
        for k, m in self.placements:
            lo, hi = self.trees[k].nodes[self.trees[k].root][:2]
            corners = [(x, y, z) for x in (lo[0], hi[0]) for y in (lo[1], hi[1]) for z in (lo[2], hi[2])]
            world = [tuple(m[r][0] * c[0] + m[r][1] * c[1] + m[r][2] * c[2] + m[r][3] for r in range(3)) for c in corners]
            wlo = tuple(min(p[r] for p in world) for r in range(3))
            whi = tuple(max(p[r] for p in world) for r in range(3))
            pad = 1e-6 * max(1.0, max(abs(x) for x in wlo + whi))
            self.world_boxes.append((tuple(x - pad for x in wlo), tuple(x + pad for x in whi)))
            self.inverses.append(affine_inverse(m))

    def candidates(self):
        """(label, tree, float64 object ray transform or None, placement index or None) per mesh to search."""
        if self.flat:
            yield "triangle", self.flat, None
        for i in range(len(self.placements)):
            yield f"instance {i} triangle", self.trees[self.placements[i][0]], i

    def trace(self, o, d, tmin, tmax):
        """(best, nearest_miss): best = (t, label) of the exact nearest hit within [tmin, tmax];
        nearest_miss = (least barycentric, label, t) of the closest miss within the range."""
        fo, fd = tuple(Fraction(x) for x in o), tuple(Fraction(x) for x in d)
        ftmin = Fraction(tmin)
        ftmax = Fraction(tmax) if tmax != float("inf") else Fraction(10) ** 40
        search_tmax = tmax if tmax != float("inf") else 1e30
        best, nearest_miss = None, None
        for label, tree, inst in self.candidates():
            if inst is None:
                oo, dd, eo, ed = o, d, fo, fd
            else:
                if not box_hit(o, d, *self.world_boxes[inst], tmin, search_tmax):
                    continue
                oo, dd = apply(*self.inverses[inst], o, d)
                inv, it = affine_inverse(self.placements[inst][1], Fraction)
                eo, ed = apply(inv, it, fo, fd)
            for j in tree.near(oo, dd, tmin, search_tmax):
                tri = tree.tris[j]
                if not near_candidate(oo, dd, tri):
                    continue
                r = exact_hit(eo, ed, tri, ftmin, ftmax)
                if r is None:
                    continue
                t, wmin, in_range = r
                if wmin >= 0 and in_range:
                    if best is None or t < best[0]:
                        best = (t, f"{label} {j}")
                elif in_range and (nearest_miss is None or wmin > nearest_miss[0]):
                    nearest_miss = (wmin, f"{label} {j}", t)
        return best, nearest_miss


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("mesh", help="the OBJ mesh, or a JSON scene of OBJ objects placed by matrices")
    ap.add_argument("disagreements")
    args = ap.parse_args()
    judge = Judge(args.mesh)
    if judge.count == 0:
        sys.exit(f"exact_ray: {args.mesh}: no triangles")
    with open(args.disagreements) as f:
        rows = list(csv.DictReader(f))
    flat_count = len(judge.flat.tris) if judge.flat else 0
    print(f"{args.mesh}: {judge.count} triangles ({len(judge.placements)} instances); {len(rows)} rays")
    for row in rows:
        names = [k[:-2] for k in row if k.endswith("_t")]
        # An answer that is not an instance's and lies past the file's triangles is the studio's ground
        # (an occlusion answer names no triangle: a shadow row is judged on hit or miss alone).
        beyond = [n for n in names if row["kind"] != "shadow" and float.fromhex(row[n + "_t"]) != float("inf") and
                  not row.get(n + "_inst") and int(row[n + "_prim"]) >= flat_count]
        if beyond:
            print(f"{row['kind']} ray {row['ray']}: {', '.join(beyond)} answered a triangle past the file's (the studio's "
                  "ground?): not judged")
            continue
        o = tuple(float.fromhex(row[k]) for k in ("ox", "oy", "oz"))
        d = tuple(float.fromhex(row[k]) for k in ("dx", "dy", "dz"))
        tmin, tmax = float.fromhex(row["tmin"]), float.fromhex(row["tmax"])
        best, nearest_miss = judge.trace(o, d, tmin, tmax)
        said = {n: float.fromhex(row[n + "_t"]) != float("inf") for n in names}
        truth = best is not None
        right = [n for n in names if said[n] == truth]
        wrong = [n for n in names if said[n] != truth]
        if truth:
            what = f"hits {best[1]} at t = {float(best[0]):.9g}"
        elif nearest_miss:
            what = (f"misses every triangle; nearest, {nearest_miss[1]} at t = {float(nearest_miss[2]):.9g}, "
                    f"by {-float(nearest_miss[0]):.3g} in barycentrics")
        else:
            what = "misses every triangle"
        print(f"{row['kind']} ray {row['ray']}: exactly, the ray {what}: {', '.join(right) or 'neither'} right, "
              f"{', '.join(wrong) or 'neither'} wrong")


if __name__ == "__main__":
    main()
