#!/usr/bin/env python3
"""Writes scenes/meshes/torus.obj: a closed torus about the y axis (major radius 0.3 m, minor
radius 0.12 m, centred at (0, 0.5, 0)) for scenes/solid_torus.json (Selle Fig. 5.3).

Usage: python3 scripts/make_torus_mesh.py [output.obj]
"""
import math
import sys

CENTRE = (0.0, 0.5, 0.0)
MAJOR, MINOR = 0.3, 0.12
AROUND, ACROSS = 64, 24


def main():
    out = sys.argv[1] if len(sys.argv) > 1 else "scenes/meshes/torus.obj"
    with open(out, "w") as fh:
        fh.write("# torus for scenes/solid_torus.json (scripts/make_torus_mesh.py)\n")
        for i in range(AROUND):
            u = 2.0 * math.pi * i / AROUND
            for j in range(ACROSS):
                v = 2.0 * math.pi * j / ACROSS
                r = MAJOR + MINOR * math.cos(v)
                fh.write("v %.6f %.6f %.6f\n" % (CENTRE[0] + r * math.cos(u), CENTRE[1] + MINOR * math.sin(v),
                                                 CENTRE[2] + r * math.sin(u)))
        for i in range(AROUND):
            for j in range(ACROSS):
                a = i * ACROSS + j + 1
                b = ((i + 1) % AROUND) * ACROSS + j + 1
                c = ((i + 1) % AROUND) * ACROSS + (j + 1) % ACROSS + 1
                d = i * ACROSS + (j + 1) % ACROSS + 1
                fh.write("f %d %d %d\nf %d %d %d\n" % (a, c, b, a, d, c))
    print("%s: %d vertices, %d triangles" % (out, AROUND * ACROSS, 2 * AROUND * ACROSS))


if __name__ == "__main__":
    main()
