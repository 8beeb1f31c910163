#!/usr/bin/python3
"""Writes the two textures of scenes/textured-sphere (no downloaded images):

planet.png  512 x 256 lat-long map of a made-up earth-like planet: 3D fractal value noise
            sampled on the unit sphere (so the map has no seam at u = 0/1 and no pinching at
            the poles), thresholded into oceans (darker where deeper) and land (green to brown
            with height), ice caps above |latitude| ~75 degrees (ragged, reaching further over land), and a faint graticule (lightened by a quarter) every 30
            degrees. Row 0 is the north pole (+y), column u = 0.5 faces +z, u = 0.75 faces +x: the
            sphere mapping of core/scene/scene.cpp (Scene::interaction).
tiles.png   256 x 256 two-tone checkerboard (4 x 4 tiles) with grout lines, for the ground quad.

Run: /usr/bin/python3 make_textures.py  (needs numpy and PIL; writes beside itself; deterministic).
"""
import os

import numpy as np
from PIL import Image

HERE = os.path.dirname(os.path.abspath(__file__))
rng = np.random.default_rng(7)
LATTICE = rng.random((64, 64, 64))


def value_noise(p):
    """Trilinearly interpolated value noise with smoothstep weights; p has shape (..., 3)."""
    i = np.floor(p).astype(int)
    f = p - i
    w = f * f * (3 - 2 * f)
    out = 0.0
    for dx in (0, 1):
        for dy in (0, 1):
            for dz in (0, 1):
                c = LATTICE[(i[..., 0] + dx) % 64, (i[..., 1] + dy) % 64, (i[..., 2] + dz) % 64]
                wx = w[..., 0] if dx else 1 - w[..., 0]
                wy = w[..., 1] if dy else 1 - w[..., 1]
                wz = w[..., 2] if dz else 1 - w[..., 2]
                out = out + c * wx * wy * wz
    return out


def fbm(p, octaves=7):
    total, amp, norm = 0.0, 1.0, 0.0
    for o in range(octaves):
        total = total + amp * value_noise(p * (2.0 ** o) + 17.3 * o)
        norm += amp
        amp *= 0.5
    return total / norm


def planet(w=512, h=256):
    u = (np.arange(w) + 0.5) / w
    v = (np.arange(h) + 0.5) / h  # 0 at the top row (north pole)
    uu, vv = np.meshgrid(u, v)
    theta = vv * np.pi              # polar angle from +y
    phi = (uu - 0.5) * 2 * np.pi    # 0 toward +z, +pi/2 toward +x (atan2(x, z))
    d = np.stack([np.sin(theta) * np.sin(phi), np.cos(theta), np.sin(theta) * np.cos(phi)], axis=-1)
    height = fbm(d * 2.2 + 5.0)
    height = (height - height.mean()) / height.std()
    sea = 0.35  # about 64 % ocean
    lat = 90 - np.degrees(theta)
    img = np.zeros((h, w, 3))
    ocean = height < sea
    depth = np.clip((sea - height) / 2.0, 0, 1)[..., None]
    img[:] = (1 - depth) * np.array([0.10, 0.35, 0.62]) + depth * np.array([0.02, 0.08, 0.28])
    t = np.clip((height - sea) / 1.6, 0, 1)[..., None]
    land = (1 - t) * np.array([0.22, 0.50, 0.16]) + t * np.array([0.55, 0.42, 0.26])
    desert = np.clip(1 - np.abs(np.abs(lat) - 22) / 12, 0, 1)[..., None] * 0.45  # dry belts
    land = (1 - desert) * land + desert * np.array([0.80, 0.68, 0.42])
    img = np.where(ocean[..., None], img, land)
    ice = np.abs(lat) + 40 * (fbm(d * 4.0 + 2.0) - 0.5) + 8 * (~ocean) > 76
    img[ice] = [0.92, 0.94, 0.96]
    # Graticule every 30 degrees of longitude and latitude, one texel wide, lightened.
    lon = np.degrees(phi)
    grid = (np.abs((lon + 180) % 30 - 15) > 15 - 360 / w * 0.6) | (np.abs((lat + 90) % 30 - 15) > 15 - 180 / h * 0.6)
    img[grid] = 0.75 * img[grid] + 0.2
    return img


def tiles(size=256, n=4, grout=3):
    y, x = np.mgrid[0:size, 0:size]
    cell = size // n
    checker = ((x // cell) + (y // cell)) % 2 == 0
    img = np.where(checker[..., None], np.array([0.78, 0.74, 0.66]), np.array([0.36, 0.30, 0.27]))
    g = (x % cell < grout) | (y % cell < grout)
    img[g] = [0.55, 0.55, 0.55]
    return img


def save(img, name):
    # The values are sRGB-encoded reflectances (the renderer linearises 8-bit textures).
    data = np.clip(np.round(img * 255), 0, 255).astype(np.uint8)
    Image.fromarray(data, "RGB").save(os.path.join(HERE, name), optimize=True)


if __name__ == "__main__":
    save(planet(), "planet.png")
    save(tiles(), "tiles.png")
