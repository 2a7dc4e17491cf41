#!/usr/bin/env python3
"""Writes scenes/assets/hourglass.obj: the closed cavity of an hourglass (a surface of revolution
about the y axis, capped at both ends) for scenes/granular_hourglass.json, where it is an
'inverted' solid: the glass is everything outside this cavity.

Units are metres; the cavity is centred on x = z = 0.25 and spans y = 0.02 .. 0.98, inside the
scene's 0.5 x 1.0 x 0.5 m domain (25 x 50 x 25 cells of 2 cm). The neck radius is 4 cm, two
cells, so that the sand flows through at the grid's resolution.

Usage: python3 scripts/make_hourglass_mesh.py [output.obj]
"""
import math
import sys

CENTRE_X, CENTRE_Z = 0.25, 0.25
Y_LO, Y_HI = 0.02, 0.98
R_MAX, R_NECK = 0.22, 0.04
SEGMENTS, RINGS = 40, 48


def radius(y):
    """Bulbs of radius R_MAX joined smoothly to the neck at mid height."""
    s = abs(2.0 * (y - Y_LO) / (Y_HI - Y_LO) - 1.0)  # 0 at the neck, 1 at the ends
    t = min(1.0, s / 0.6)
    smooth = t * t * (3.0 - 2.0 * t)
    # The ends round off a little so that the bulbs are not cylinders.
    shoulder = 1.0 - 0.25 * max(0.0, (s - 0.85) / 0.15) ** 2
    return R_NECK + (R_MAX - R_NECK) * smooth * shoulder


def main():
    out = sys.argv[1] if len(sys.argv) > 1 else "scenes/assets/hourglass.obj"
    vertices, faces = [], []
    for i in range(RINGS + 1):
        y = Y_LO + (Y_HI - Y_LO) * i / RINGS
        r = radius(y)
        for j in range(SEGMENTS):
            a = 2.0 * math.pi * j / SEGMENTS
            vertices.append((CENTRE_X + r * math.cos(a), y, CENTRE_Z + r * math.sin(a)))
    bottom = len(vertices)
    vertices.append((CENTRE_X, Y_LO, CENTRE_Z))
    top = len(vertices)
    vertices.append((CENTRE_X, Y_HI, CENTRE_Z))
    # Outward winding: with the angle running from +x towards +z, the side quads go (j, j+1) on
    # ring i then back on ring i + 1.
    for i in range(RINGS):
        for j in range(SEGMENTS):
            a = i * SEGMENTS + j
            b = i * SEGMENTS + (j + 1) % SEGMENTS
            faces.append((a, b + SEGMENTS, b))
            faces.append((a, a + SEGMENTS, b + SEGMENTS))
    for j in range(SEGMENTS):
        faces.append((bottom, j, (j + 1) % SEGMENTS))
        last = RINGS * SEGMENTS
        faces.append((top, last + (j + 1) % SEGMENTS, last + j))
    with open(out, "w") as f:
        f.write("# hourglass cavity, written by scripts/make_hourglass_mesh.py\n")
        for v in vertices:
            f.write("v %.6f %.6f %.6f\n" % v)
        for a, b, c in faces:
            f.write("f %d %d %d\n" % (a + 1, b + 1, c + 1))


if __name__ == "__main__":
    main()
