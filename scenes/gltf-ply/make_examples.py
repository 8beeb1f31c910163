#!/usr/bin/python3
"""Writes the example glTF and PLY files of scenes/gltf-ply (standard library only).

  /usr/bin/python3 scenes/gltf-ply/make_examples.py [--pt build/renderer/pt]

- table.gltf (one base64 data-URI buffer, the checker texture in checker.png) and table.glb (the
  same scene, buffer and texture inside): a checker-textured table top on four legs, one leg mesh
  placed by four nodes (instancing), a red gem mesh placed by two nodes, one under a scaled,
  rotated parent; a KHR_lights_punctual point light and a perspective camera.
- scan.ply: a binary little-endian PLY converted from `pt gen scan` (a simulated range scan, with
  its long thin triangles and holes), coloured by height (uchar red/green/blue).
- plinth.ply: an ASCII PLY box under the scan: float (linear) colours and normals, its four sides
  as one `tristrips` strip, its top and bottom as quads of a face list (so the example scene, and
  the fuzzer that mutates it, hold an ASCII PLY as well as a binary one).
"""
import base64
import json
import math
import os
import struct
import subprocess
import sys
import tempfile
import zlib

HERE = os.path.dirname(os.path.abspath(__file__))


def png(width, height, rows):
    """An 8-bit RGB PNG from rows of (r, g, b) tuples (zlib + CRC, PNG specification 1.2)."""
    def chunk(kind, data):
        return struct.pack(">I", len(data)) + kind + data + struct.pack(">I", zlib.crc32(kind + data) & 0xFFFFFFFF)
    raw = b"".join(b"\0" + bytes(c for px in row for c in px) for row in rows)
    return (b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", struct.pack(">IIBBBBB", width, height, 8, 2, 0, 0, 0)) +
            chunk(b"IDAT", zlib.compress(raw, 9)) + chunk(b"IEND", b""))


def checker():
    n = 64
    rows = []
    for y in range(n):
        row = []
        for x in range(n):
            light = ((x // 8) + (y // 8)) % 2 == 0
            row.append((225, 205, 160) if light else (120, 70, 40))
        rows.append(row)
    return png(n, n, rows)


class Gltf:
    def __init__(self):
        self.bin = bytearray()
        self.doc = {"asset": {"version": "2.0", "generator": "scenes/gltf-ply/make_examples.py"},
                    "bufferViews": [], "accessors": [], "meshes": [], "nodes": [], "materials": []}

    def view(self, data):
        while len(self.bin) % 4:
            self.bin.append(0)
        self.doc["bufferViews"].append({"buffer": 0, "byteOffset": len(self.bin), "byteLength": len(data)})
        self.bin += data
        return len(self.doc["bufferViews"]) - 1

    def accessor(self, values, kind, n):
        fmt = "<%d%s" % (len(values), "H" if kind == "SCALAR" else "f")
        view = self.view(struct.pack(fmt, *values))
        acc = {"bufferView": view, "componentType": 5123 if kind == "SCALAR" else 5126, "count": len(values) // n, "type": kind}
        if kind == "VEC3":
            acc["min"] = [min(values[i::3]) for i in range(3)]
            acc["max"] = [max(values[i::3]) for i in range(3)]
        self.doc["accessors"].append(acc)
        return len(self.doc["accessors"]) - 1

    def mesh(self, name, positions, normals, uvs, indices, material):
        attributes = {"POSITION": self.accessor(positions, "VEC3", 3), "NORMAL": self.accessor(normals, "VEC3", 3)}
        if uvs:
            attributes["TEXCOORD_0"] = self.accessor(uvs, "VEC2", 2)
        prim = {"attributes": attributes, "indices": self.accessor(indices, "SCALAR", 1), "material": material}
        self.doc["meshes"].append({"name": name, "primitives": [prim]})
        return len(self.doc["meshes"]) - 1

    def node(self, **kw):
        self.doc["nodes"].append(kw)
        return len(self.doc["nodes"]) - 1


def box(sx, sy, sz, uv_scale=1.0):
    """An axis-aligned box from (-sx, 0, -sz) to (sx, sy, sz): 6 faces of 4 vertices, outward normals."""
    faces = [((1, 0, 0), (0, 0, -1), (0, 1, 0)), ((-1, 0, 0), (0, 0, 1), (0, 1, 0)), ((0, 1, 0), (1, 0, 0), (0, 0, -1)),
             ((0, -1, 0), (1, 0, 0), (0, 0, 1)), ((0, 0, 1), (1, 0, 0), (0, 1, 0)), ((0, 0, -1), (-1, 0, 0), (0, 1, 0))]
    half = (sx, sy / 2, sz)
    p, n, t, idx = [], [], [], []
    for normal, u, v in faces:
        base = len(p) // 3
        for a, b in ((-1, -1), (1, -1), (1, 1), (-1, 1)):
            for k in range(3):
                p.append(normal[k] * half[k] + a * u[k] * half[k] + b * v[k] * half[k] + (sy / 2 if k == 1 else 0))
            n.extend(normal)
            t.extend(((a + 1) / 2 * uv_scale, (1 - b) / 2 * uv_scale))
        idx.extend((base, base + 1, base + 2, base, base + 2, base + 3))
    return p, n, t, idx


def octahedron(r):
    """A gem: an octahedron with flat faces (each face its own three vertices and normal)."""
    v = [(r, 0, 0), (-r, 0, 0), (0, r * 1.4, 0), (0, -r * 1.4, 0), (0, 0, r), (0, 0, -r)]
    faces = [(0, 2, 4), (4, 2, 1), (1, 2, 5), (5, 2, 0), (4, 3, 0), (1, 3, 4), (5, 3, 1), (0, 3, 5)]
    p, n, idx = [], [], []
    for f in faces:
        a, b, c = (v[i] for i in f)
        e1 = [b[k] - a[k] for k in range(3)]
        e2 = [c[k] - a[k] for k in range(3)]
        nx = [e1[1] * e2[2] - e1[2] * e2[1], e1[2] * e2[0] - e1[0] * e2[2], e1[0] * e2[1] - e1[1] * e2[0]]
        length = math.sqrt(sum(x * x for x in nx))
        for q in (a, b, c):
            idx.append(len(p) // 3)
            p.extend(q)
            n.extend(x / length for x in nx)
    return p, n, None, idx


def table(embedded):
    g = Gltf()
    g.doc["materials"] = [
        {"name": "checker wood", "pbrMetallicRoughness": {"baseColorTexture": {"index": 0}, "metallicFactor": 0.0,
                                                          "roughnessFactor": 0.8}},
        {"name": "dark leg", "pbrMetallicRoughness": {"baseColorFactor": [0.25, 0.2, 0.18, 1], "metallicFactor": 0.0}},
        {"name": "red gem", "pbrMetallicRoughness": {"baseColorFactor": [0.8, 0.1, 0.1, 1], "metallicFactor": 0.0}},
        {"name": "floor", "pbrMetallicRoughness": {"baseColorFactor": [0.5, 0.5, 0.5, 1], "metallicFactor": 0.0}},
    ]
    top = g.mesh("table top", *box(1.0, 0.08, 0.6, 2.0), 0)
    leg = g.mesh("leg", *box(0.05, 0.7, 0.05), 1)
    gem = g.mesh("gem", *octahedron(0.15), 2)
    floor = g.mesh("floor", *box(3.0, 0.02, 3.0), 3)
    nodes = [g.node(name="floor", mesh=floor, translation=[0, -0.02, 0]),
             g.node(name="top", mesh=top, translation=[0, 0.7, 0])]
    for i, (x, z) in enumerate(((-0.9, -0.5), (0.9, -0.5), (-0.9, 0.5), (0.9, 0.5))):
        nodes.append(g.node(name="leg %d" % i, mesh=leg, translation=[x, 0, z]))
    nodes.append(g.node(name="gem", mesh=gem, translation=[-0.4, 0.99, 0.1]))
    turned = g.node(name="gem 2", mesh=gem)
    nodes.append(g.node(name="turned holder", children=[turned], translation=[0.45, 0.93, -0.1], scale=[0.7, 0.7, 0.7],
                        rotation=[0, 0, math.sin(math.radians(20)), math.cos(math.radians(20))]))
    nodes.append(g.node(name="lamp", translation=[0.8, 2.4, 1.4], extensions={"KHR_lights_punctual": {"light": 0}}))
    # A camera at (0.2, 1.6, 3.2) looking at (0, 0.75, 0): turned about y, then pitched down.
    eye, at = (0.2, 1.6, 3.2), (0.0, 0.75, 0.0)
    d = [at[k] - eye[k] for k in range(3)]
    yaw = math.atan2(-d[0], -d[2])
    pitch = math.atan2(d[1], math.hypot(d[0], d[2]))
    qy = (0, math.sin(yaw / 2), 0, math.cos(yaw / 2))
    qx = (math.sin(pitch / 2), 0, 0, math.cos(pitch / 2))
    q = (qy[3] * qx[0] + qy[0] * qx[3] + qy[1] * qx[2] - qy[2] * qx[1],
         qy[3] * qx[1] - qy[0] * qx[2] + qy[1] * qx[3] + qy[2] * qx[0],
         qy[3] * qx[2] + qy[0] * qx[1] - qy[1] * qx[0] + qy[2] * qx[3],
         qy[3] * qx[3] - qy[0] * qx[0] - qy[1] * qx[1] - qy[2] * qx[2])
    nodes.append(g.node(name="camera", camera=0, translation=list(eye), rotation=list(q)))
    g.doc["scenes"] = [{"nodes": [n for n in nodes if n != turned]}]
    g.doc["scene"] = 0
    g.doc["cameras"] = [{"type": "perspective", "perspective": {"yfov": math.radians(40), "aspectRatio": 4 / 3, "znear": 0.05}}]
    g.doc["extensionsUsed"] = ["KHR_lights_punctual"]
    # 2000 cd: about 2.9 W/sr in pt's units (divided by 683 lm/W).
    g.doc["extensions"] = {"KHR_lights_punctual": {"lights": [{"type": "point", "intensity": 2000.0, "color": [1, 0.95, 0.85]}]}}
    g.doc["samplers"] = [{"wrapS": 10497, "wrapT": 10497}]
    g.doc["textures"] = [{"source": 0, "sampler": 0}]
    image = checker()
    if embedded:
        g.doc["images"] = [{"bufferView": g.view(image), "mimeType": "image/png"}]
    else:
        g.doc["images"] = [{"uri": "checker.png"}]
    return g, image


def write_gltf():
    g, image = table(False)
    with open(os.path.join(HERE, "checker.png"), "wb") as f:
        f.write(image)
    doc = dict(g.doc)
    doc["buffers"] = [{"byteLength": len(g.bin), "uri": "data:application/octet-stream;base64," +
                       base64.b64encode(bytes(g.bin)).decode()}]
    with open(os.path.join(HERE, "table.gltf"), "w") as f:
        json.dump(doc, f, indent=1)
    g, _ = table(True)
    doc = dict(g.doc)
    doc["buffers"] = [{"byteLength": len(g.bin)}]
    text = json.dumps(doc).encode()
    text += b" " * (-len(text) % 4)
    body = bytes(g.bin) + b"\0" * (-len(g.bin) % 4)
    glb = struct.pack("<III", 0x46546C67, 2, 12 + 8 + len(text) + 8 + len(body))
    glb += struct.pack("<II", len(text), 0x4E4F534A) + text + struct.pack("<II", len(body), 0x004E4942) + body
    with open(os.path.join(HERE, "table.glb"), "wb") as f:
        f.write(glb)


def write_ply(pt):
    with tempfile.TemporaryDirectory() as tmp:
        obj = os.path.join(tmp, "scan.obj")
        subprocess.run([pt, "gen", "scan", obj, "--views", "6", "--resolution", "110", "--seed", "3"], check=True)
        verts, faces = [], []
        with open(obj) as f:
            for line in f:
                t = line.split()
                if not t:
                    continue
                if t[0] == "v":
                    verts.append(tuple(float(x) for x in t[1:4]))
                elif t[0] == "f":
                    faces.append([int(c.split("/")[0]) - 1 for c in t[1:]])
    lo = min(v[1] for v in verts)
    hi = max(v[1] for v in verts)
    header = ("ply\nformat binary_little_endian 1.0\ncomment converted from pt gen scan by make_examples.py\n"
              "element vertex %d\nproperty float x\nproperty float y\nproperty float z\n"
              "property uchar red\nproperty uchar green\nproperty uchar blue\n"
              "element face %d\nproperty list uchar int vertex_indices\nend_header\n" % (len(verts), len(faces)))
    out = bytearray(header.encode())
    for x, y, z in verts:
        h = (y - lo) / (hi - lo) if hi > lo else 0
        colour = (int(90 + 140 * h), int(140 + 60 * h), int(200 - 120 * h))  # blue-grey low, warm high
        out += struct.pack("<fffBBB", x, y, z, *colour)
    for f in faces:
        out += struct.pack("<B%di" % len(f), len(f), *f)
    with open(os.path.join(HERE, "scan.ply"), "wb") as f:
        f.write(out)


def write_plinth():
    # Corners of a 1 x 0.2 x 0.6 box standing on y = 0; colours fade from grey (bottom) to sand (top).
    xs, ys, zs = (-0.5, 0.5), (0.0, 0.2), (-0.3, 0.3)
    corners = [(x, y, z) for y in ys for z in zs for x in xs]  # index = 4 * top + 2 * front + right
    lines = []
    for x, y, z in corners:
        c = (0.8, 0.7, 0.5) if y > 0 else (0.35, 0.35, 0.35)
        lines.append("%g %g %g %g %g %g" % (x, y, z, *c))
    # The sides as one strip around the box (bottom, top alternating), closed by repeating the start.
    ring = [0, 2, 3, 1]  # back-left, front-left, front-right, back-right, seen from above
    strip = []
    for i in ring + ring[:1]:
        strip += [i + 4, i]
    # Quads seen counter-clockwise from outside: the top from +y, the bottom from -y.
    faces = ["4 4 6 7 5", "4 0 1 3 2"]
    header = ("ply\nformat ascii 1.0\ncomment written by make_examples.py\n"
              "element vertex 8\nproperty float x\nproperty float y\nproperty float z\n"
              "property float red\nproperty float green\nproperty float blue\n"
              "element face 2\nproperty list uchar int vertex_indices\n"
              "element tristrips 1\nproperty list int int vertex_indices\nend_header\n")
    body = "\n".join(lines) + "\n" + "\n".join(faces) + "\n" + "%d %s\n" % (len(strip), " ".join(map(str, strip)))
    with open(os.path.join(HERE, "plinth.ply"), "w") as f:
        f.write(header + body)


if __name__ == "__main__":
    pt = sys.argv[sys.argv.index("--pt") + 1] if "--pt" in sys.argv else os.path.join(HERE, "../../build/renderer/pt")
    write_gltf()
    write_ply(pt)
    write_plinth()
    print("wrote table.gltf, table.glb, checker.png, scan.ply and plinth.ply in", HERE)
