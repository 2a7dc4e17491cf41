#!/usr/bin/env python3
"""Writes scenes/meshes/glass.obj: a drinking glass (a closed surface of revolution about the y
axis: outer wall, rim, inner wall and a thick base) for scenes/pour_glass.json.

Units are metres; the glass stands on y = 0 centred on x = z = 0.3 with an outer radius of 12 cm,
a height of 22 cm, 2 cm walls and a 2.5 cm base, so that at the scene's 9.4 mm cells its walls
are two cells thick (a wall thinner than a cell lets the liquid through the solid).

Usage: python3 scripts/make_glass_mesh.py [output.obj]
"""
import math
import sys

CENTRE_X, CENTRE_Z = 0.3, 0.3
R_OUT, HEIGHT, WALL, BASE = 0.12, 0.22, 0.02, 0.025
SEGMENTS = 64

# The profile (radius, height) from the axis under the base round to the axis on the inner floor.
PROFILE = [(0.0, 0.0), (R_OUT, 0.0), (R_OUT, HEIGHT), (R_OUT - WALL, HEIGHT), (R_OUT - WALL, BASE), (0.0, BASE)]


def main():
    out = sys.argv[1] if len(sys.argv) > 1 else "scenes/meshes/glass.obj"
    vertices, faces = [], []
    # The two profile points on the axis are single vertices; the others are rings.
    axis_bottom = len(vertices) + 1
    vertices.append((CENTRE_X, PROFILE[0][1], CENTRE_Z))
    rings = []
    for r, y in PROFILE[1:-1]:
        ring = []
        for k in range(SEGMENTS):
            a = 2.0 * math.pi * k / SEGMENTS
            vertices.append((CENTRE_X + r * math.cos(a), y, CENTRE_Z + r * math.sin(a)))
            ring.append(len(vertices))
        rings.append(ring)
    vertices.append((CENTRE_X, PROFILE[-1][1], CENTRE_Z))
    axis_top = len(vertices)
    for k in range(SEGMENTS):
        n = (k + 1) % SEGMENTS
        faces.append((axis_bottom, rings[0][k], rings[0][n]))
        for lo, hi in zip(rings, rings[1:]):
            faces.append((lo[k], hi[k], hi[n]))
            faces.append((lo[k], hi[n], lo[n]))
        faces.append((rings[-1][k], axis_top, rings[-1][n]))
    # Outward normals: flip every face if the enclosed volume comes out negative.
    volume = 0.0
    for f in faces:
        a, b, c = (vertices[i - 1] for i in f)
        volume += (a[0] * (b[1] * c[2] - b[2] * c[1]) - a[1] * (b[0] * c[2] - b[2] * c[0]) +
                   a[2] * (b[0] * c[1] - b[1] * c[0])) / 6.0
    if volume < 0.0:
        faces = [(f[0], f[2], f[1]) for f in faces]
    with open(out, "w") as fh:
        fh.write("# drinking glass for scenes/pour_glass.json.(scripts/make_glass_mesh.py)\n")
        for v in vertices:
            fh.write("v %.6f %.6f %.6f\n" % v)
        for f in faces:
            fh.write("f %d %d %d\n" % f)
    print("%s: %d vertices, %d triangles, volume %.6f m^3" % (out, len(vertices), len(faces), abs(volume)))


if __name__ == "__main__":
    main()
