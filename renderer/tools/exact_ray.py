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
"""
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


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("mesh")
    ap.add_argument("disagreements")
    args = ap.parse_args()
    triangles = load_obj(args.mesh)
    if not triangles:
        sys.exit(f"exact_ray: {args.mesh}: no triangles")
    with open(args.disagreements) as f:
        rows = list(csv.DictReader(f))
    print(f"{args.mesh}: {len(triangles)} triangles; {len(rows)} rays")
    for row in rows:
        names = [k[:-2] for k in row if k.endswith("_t")]
        beyond = [n for n in names if float.fromhex(row[n + "_t"]) != float("inf") and int(row[n + "_prim"]) >= len(triangles)]
        if beyond:
            print(f"{row['kind']} ray {row['ray']}: {', '.join(beyond)} answered a triangle past the file's (the studio's "
                  "ground?): not judged")
            continue
        o = tuple(float.fromhex(row[k]) for k in ("ox", "oy", "oz"))
        d = tuple(float.fromhex(row[k]) for k in ("dx", "dy", "dz"))
        tmin, tmax = float.fromhex(row["tmin"]), float.fromhex(row["tmax"])
        fo, fd = tuple(Fraction(x) for x in o), tuple(Fraction(x) for x in d)
        ftmin = Fraction(tmin)
        ftmax = Fraction(tmax) if tmax != float("inf") else Fraction(10) ** 40
        best, nearest_miss = None, None
        for i, tri in enumerate(triangles):
            if not near_candidate(o, d, tri):
                continue
            r = exact_hit(fo, fd, tri, ftmin, ftmax)
            if r is None:
                continue
            t, wmin, in_range = r
            if wmin >= 0 and in_range:
                if best is None or t < best[0]:
                    best = (t, i)
            elif in_range and (nearest_miss is None or wmin > nearest_miss[0]):
                nearest_miss = (wmin, i, t)
        said = {n: float.fromhex(row[n + "_t"]) != float("inf") for n in names}
        truth = best is not None
        right = [n for n in names if said[n] == truth]
        wrong = [n for n in names if said[n] != truth]
        if truth:
            what = f"hits triangle {best[1]} at t = {float(best[0]):.9g}"
        elif nearest_miss:
            what = (f"misses every triangle; nearest, triangle {nearest_miss[1]} at t = {float(nearest_miss[2]):.9g}, "
                    f"by {-float(nearest_miss[0]):.3g} in barycentrics")
        else:
            what = "misses every triangle"
        print(f"{row['kind']} ray {row['ray']}: exactly, the ray {what}: {', '.join(right) or 'neither'} right, "
              f"{', '.join(wrong) or 'neither'} wrong")


if __name__ == "__main__":
    main()
