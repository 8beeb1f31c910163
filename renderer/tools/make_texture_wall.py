#!/usr/bin/env python3
"""A wall of N textured quads, each with its own SIZE x SIZE 8-bit PNG (a smooth colour field with
fine stripes, so every MIP level differs), for measuring the texture cache's memory bound:

    python3 renderer/tools/make_texture_wall.py build/wall --count 64 --size 4096
    /usr/bin/time -v build/renderer/pt render build/wall --res 640x640 --spp 4 -o wall.exr

Standard library only (zlib writes the PNGs)."""
import argparse
import json
import math
import os
import struct
import zlib


def png(path, size, seed):
    def chunk(kind, data):
        body = kind + data
        return struct.pack(">I", len(data)) + body + struct.pack(">I", zlib.crc32(body) & 0xFFFFFFFF)

    raw = bytearray()
    a, b = 0.5 + 0.4 * math.sin(seed), 0.5 + 0.4 * math.cos(seed * 1.7)
    period = 8 + seed % 13
    for y in range(size):
        raw.append(0)  # filter: none
        g = int(255 * (0.3 + 0.6 * y / size))
        row = bytearray(3 * size)
        for x in range(0, size, period):
            stripe = 255 if (x // period) % 2 else int(255 * a)
            row[3 * x : 3 * min(size, x + period) : 3] = bytes([stripe]) * len(range(x, min(size, x + period)))
        row[1::3] = bytes([g]) * size
        row[2::3] = bytes([int(255 * b)]) * size
        raw += row
    data = b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", struct.pack(">IIBBBBB", size, size, 8, 2, 0, 0, 0))
    data += chunk(b"IDAT", zlib.compress(bytes(raw), 6)) + chunk(b"IEND", b"")
    with open(path, "wb") as f:
        f.write(data)


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("folder")
    ap.add_argument("--count", type=int, default=64)
    ap.add_argument("--size", type=int, default=4096)
    a = ap.parse_args()
    os.makedirs(a.folder, exist_ok=True)
    side = math.ceil(math.sqrt(a.count))
    obj = ["# one unit quad per texture, on a side x side grid in the plane z = 0"]
    materials, objects = {}, []
    for i in range(a.count):
        name = f"t{i:03d}.png"
        if not os.path.exists(os.path.join(a.folder, name)):
            png(os.path.join(a.folder, name), a.size, i)
        materials[f"m{i}"] = {"texture": name}
        with open(os.path.join(a.folder, f"quad{i}.obj"), "w") as f:
            x, y = i % side, i // side
            f.write(f"v {x} {y} 0\nv {x + 1} {y} 0\nv {x + 1} {y + 1} 0\nv {x} {y + 1} 0\n")
            f.write("vt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\nf 1/1 2/2 3/3 4/4\n")
        objects.append({"file": f"quad{i}.obj", "material": f"m{i}"})
    scene = {
        "camera": {"position": [side / 2, side / 2, side * 1.2], "look_at": [side / 2, side / 2, 0], "fov": 45},
        "materials": materials,
        "objects": objects,
        "environment": {"radiance": 1},
        "render": {"integrator": "path", "max_depth": 2},
    }
    with open(os.path.join(a.folder, "scene.json"), "w") as f:
        json.dump(scene, f, indent=1)


if __name__ == "__main__":
    main()
