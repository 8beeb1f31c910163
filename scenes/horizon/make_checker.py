#!/usr/bin/python3
"""Writes checker.ppm: 64 x 64 texels, 2 x 2 checks of black and white (bytes 0 and 255, so the
linear-light average is 0.5). A binary PPM needs no image library."""
import os

size, check = 64, 32
rows = bytearray()
for y in range(size):
    for x in range(size):
        v = 255 if ((x // check) + (y // check)) % 2 else 0
        rows += bytes((v, v, v))
with open(os.path.join(os.path.dirname(os.path.abspath(__file__)), "checker.ppm"), "wb") as f:
    f.write(b"P6\n%d %d\n255\n" % (size, size) + rows)
