#!/usr/bin/env python3
"""Writes street.obj and street.mtl: a street at night, 400 m long, between two rows of buildings
(boxes, the occluders) whose facades hold lit windows of many powers and colours, facing the street
and facing along it, and street lamps (small emissive boxes) on both sides: about 1,500 emitters
spread over a large space, for many-light sampling (scenes/street/scene.json, README there)."""
import random

random.seed(7)
verts, faces = [], []  # faces: (material, [v indices 1-based])
materials = {}


def material(name, kd, ke=None):
    materials[name] = (kd, ke)
    return name


def quad(mat, a, b, c, d):
    base = len(verts) + 1
    verts.extend([a, b, c, d])
    faces.append((mat, [base, base + 1, base + 2, base + 3]))


def box(mat, lo, hi):
    x0, y0, z0 = lo
    x1, y1, z1 = hi
    # Outward faces, counter-clockwise seen from outside.
    quad(mat, (x0, y0, z1), (x1, y0, z1), (x1, y1, z1), (x0, y1, z1))  # +z
    quad(mat, (x1, y0, z0), (x0, y0, z0), (x0, y1, z0), (x1, y1, z0))  # -z
    quad(mat, (x1, y0, z1), (x1, y0, z0), (x1, y1, z0), (x1, y1, z1))  # +x
    quad(mat, (x0, y0, z0), (x0, y0, z1), (x0, y1, z1), (x0, y1, z0))  # -x
    quad(mat, (x0, y1, z1), (x1, y1, z1), (x1, y1, z0), (x0, y1, z0))  # +y
    quad(mat, (x0, y0, z0), (x1, y0, z0), (x1, y0, z1), (x0, y0, z1))  # -y


material("asphalt", (0.08, 0.08, 0.09))
material("pavement", (0.35, 0.34, 0.32))
material("lamp_post", (0.2, 0.2, 0.2))
walls = [material("wall%d" % i, c) for i, c in enumerate([(0.55, 0.5, 0.45), (0.45, 0.42, 0.4), (0.6, 0.55, 0.5), (0.4, 0.4, 0.45)])]
# Window emissions: warm to cool, over two decades of brightness; a few kinds so the MTL stays short.
window_mats = []
for i in range(24):
    warm = random.random()
    level = 10 ** random.uniform(-0.3, 1.7)
    colour = (level * (0.9 + 0.1 * warm), level * (0.7 + 0.2 * warm), level * (0.45 + 0.5 * (1 - warm)))
    window_mats.append(material("window%d" % i, (0, 0, 0), colour))
lamp = material("lamp", (0, 0, 0), (400.0, 330.0, 220.0))

L = 200.0
quad("asphalt", (-8, 0, L), (8, 0, L), (8, 0, -L), (-8, 0, -L))
for s in (-1, 1):
    # Pavements, from the road to the facades.
    x_in, x_out = 8 * s, 12 * s
    a, b = (min(x_in, x_out), max(x_in, x_out))
    quad("pavement", (a, 0.15, L), (b, 0.15, L), (b, 0.15, -L), (a, 0.15, -L))

windows = 0
for s in (-1, 1):
    z = -L
    while z < L - 8:
        width = random.uniform(12, 24)
        depth = random.uniform(10, 20)
        height = random.choice([9, 12, 15, 18, 24, 30])
        gap = random.uniform(0, 4)
        z0, z1 = z + gap, min(z + gap + width, L)
        x_face = 12 * s
        x_back = (12 + depth) * s
        box(random.choice(walls), (min(x_face, x_back), 0, z0), (max(x_face, x_back), height, z1))
        # Windows on the street facade (normal -s x) and on the two ends (normals -z, +z).
        off = 0.03
        for floor_y in range(3, int(height) - 1, 3):
            zz = z0 + 1.5
            while zz + 1.2 < z1 - 1.0:
                if random.random() < 0.55:
                    m = random.choice(window_mats)
                    x = x_face - off * s
                    y0, y1 = floor_y - 0.8, floor_y + 0.8
                    if s > 0:  # facade at +x facing -x
                        quad(m, (x, y0, zz), (x, y0, zz + 1.2), (x, y1, zz + 1.2), (x, y1, zz))
                    else:      # facade at -x facing +x
                        quad(m, (x, y0, zz + 1.2), (x, y0, zz), (x, y1, zz), (x, y1, zz + 1.2))
                    windows += 1
                zz += 2.5
            for end, normal in ((z0, -1), (z1, 1)):
                xx = 13.0
                while xx + 1.2 < 12 + depth - 1:
                    if random.random() < 0.35:
                        m = random.choice(window_mats)
                        zf = end + off * normal
                        xa, xb = xx * s, (xx + 1.2) * s
                        y0, y1 = floor_y - 0.8, floor_y + 0.8
                        # Counter-clockwise seen from the side the normal points to.
                        lo_x, hi_x = min(xa, xb), max(xa, xb)
                        if normal > 0:
                            quad(m, (lo_x, y0, zf), (hi_x, y0, zf), (hi_x, y1, zf), (lo_x, y1, zf))
                        else:
                            quad(m, (hi_x, y0, zf), (lo_x, y0, zf), (lo_x, y1, zf), (hi_x, y1, zf))
                        windows += 1
                    xx += 2.5
        z = z1

lamps = 0
for s in (-1, 1):
    for zl in range(-190, 191, 20):
        zl += 10 * (s > 0)
        x = 9.0 * s
        box("lamp_post", (x - 0.08, 0, zl - 0.08), (x + 0.08, 6.0, zl + 0.08))
        # The lamp: a small box whose underside and sides emit.
        box(lamp, (x - 0.3, 6.0, zl - 0.3), (x + 0.3, 6.3, zl + 0.3))
        lamps += 1

with open("street.mtl", "w") as f:
    f.write("# Written by make_street.py\n")
    for name, (kd, ke) in materials.items():
        f.write("newmtl %s\nKd %g %g %g\n" % (name, *kd))
        if ke:
            f.write("Ke %g %g %g\n" % ke)
with open("street.obj", "w") as f:
    f.write("# Written by make_street.py: %d windows, %d lamps\nmtllib street.mtl\n" % (windows, lamps))
    for v in verts:
        f.write("v %g %g %g\n" % v)
    current = None
    for m, idx in faces:
        if m != current:
            f.write("usemtl %s\n" % m)
            current = m
        f.write("f %s\n" % " ".join(map(str, idx)))
print(windows, "windows,", lamps, "lamps,", len(faces), "quads")
