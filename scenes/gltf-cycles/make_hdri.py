#!/usr/bin/python3
"""Writes the two environment maps of the glTF-under-an-HDRI comparison (docs/cycles/gltf_compare.py):

    /usr/bin/python3 scenes/gltf-cycles/make_hdri.py

courtyard.exr  Blender's studio-light HDRI courtyard.exr (Greg Zaal, HDRI Haven, CC0; Debian's blender
               ships it in /usr/share/blender/datafiles/studiolights/world/), box-filtered from 1024x512
               to 256x128 and stored as half floats, to keep the repository small.
bands.exr      64x32 test map for the orientation check: 8 columns of distinct hues (u), 4 rows of
               brightness (v), so that any turn, mirror or flip between two renderers' mappings shows.
Needs python3-openimageio and numpy.
"""
import os

import numpy as np
import OpenImageIO as oiio

HERE = os.path.dirname(os.path.abspath(__file__))
SRC = "/usr/share/blender/datafiles/studiolights/world/courtyard.exr"


def write(path, px):
    spec = oiio.ImageSpec(px.shape[1], px.shape[0], 3, oiio.HALF)
    spec.attribute("compression", "piz")
    out = oiio.ImageOutput.create(path)
    out.open(path, spec)
    out.write_image(px.astype(np.float32))
    out.close()


src = oiio.ImageBuf(SRC).get_pixels(oiio.FLOAT)[:, :, :3]
h, w = src.shape[0] // 4, src.shape[1] // 4
write(os.path.join(HERE, "courtyard.exr"), src.reshape(h, 4, w, 4, 3).mean(axis=(1, 3)))

hues = np.array([[1, 0, 0], [1, 0.5, 0], [1, 1, 0], [0, 1, 0], [0, 1, 1], [0, 0, 1], [0.6, 0, 1], [1, 0, 1]])
bands = np.zeros((32, 64, 3))
for row in range(32):
    for col in range(64):
        bands[row, col] = hues[col // 8] * (0.25 + 0.25 * (row // 8)) + 0.02
write(os.path.join(HERE, "bands.exr"), bands)
