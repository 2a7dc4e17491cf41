#!/usr/bin/env python3
"""Writes scenes/meshes/leaves.obj: 100 leaves, each a flat 0.10 x 0.07 m sheet of 6 x 4 quads
(48 triangles), scattered with random positions and orientations in the air above the floor of
scenes/cloth_leaves.json (a scaled-down Selle Fig. 6.9: 100 cloths in strong wind near the ground).
Leaves are at least 0.14 m apart (centre to centre, more than a diagonal and a thickness),
so none touches another at the start.

Usage: python3 scripts/make_leaves_mesh.py [output.obj] [quads_u quads_v]
The quads per leaf default to 6 x 4; 25 x 20 gives 100 leaves of 1000 triangles (100k in all),
the resolution of docs/PERFORMANCE.md's leaves frame time.
"""
import math
import random
import sys

COUNT = 100
LENGTH, WIDTH = 0.10, 0.07
QUADS_U, QUADS_V = 6, 4
REGION_MIN, REGION_MAX = (-1.2, 0.15, -0.5), (-0.2, 0.75, 0.5)
SPACING = 0.14
SEED = 7


def rotation(rng):
    """A uniformly random rotation matrix (from a random unit quaternion)."""
    u1, u2, u3 = rng.random(), rng.random(), rng.random()
    a, b = math.sqrt(1.0 - u1), math.sqrt(u1)
    w, x, y, z = a * math.sin(2 * math.pi * u2), a * math.cos(2 * math.pi * u2), b * math.sin(2 * math.pi * u3), b * math.cos(2 * math.pi * u3)
    return ((1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)),
            (2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)),
            (2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)))


def main():
    out = sys.argv[1] if len(sys.argv) > 1 else "scenes/meshes/leaves.obj"
    quads_u, quads_v = (int(sys.argv[2]), int(sys.argv[3])) if len(sys.argv) > 3 else (QUADS_U, QUADS_V)
    rng = random.Random(SEED)
    centres = []
    while len(centres) < COUNT:
        c = tuple(lo + (hi - lo) * rng.random() for lo, hi in zip(REGION_MIN, REGION_MAX))
        if all(math.dist(c, o) >= SPACING for o in centres):
            centres.append(c)
    with open(out, "w") as fh:
        fh.write("# %d leaves for scenes/cloth_leaves.json (scripts/make_leaves_mesh.py)\n" % COUNT)
        for c in centres:
            r = rotation(rng)
            for j in range(quads_v + 1):
                for i in range(quads_u + 1):
                    local = (LENGTH * (i / quads_u - 0.5), 0.0, WIDTH * (j / quads_v - 0.5))
                    p = [c[k] + sum(r[k][m] * local[m] for m in range(3)) for k in range(3)]
                    fh.write("v %.6f %.6f %.6f\n" % tuple(p))
        per_leaf = (quads_u + 1) * (quads_v + 1)
        for leaf in range(COUNT):
            base = leaf * per_leaf + 1
            for j in range(quads_v):
                for i in range(quads_u):
                    a = base + j * (quads_u + 1) + i
                    b, c, d = a + 1, a + quads_u + 2, a + quads_u + 1
                    fh.write("f %d %d %d\nf %d %d %d\n" % (a, b, c, a, c, d))
    print("%s: %d vertices, %d triangles" % (out, COUNT * (quads_u + 1) * (quads_v + 1), COUNT * 2 * quads_u * quads_v))


if __name__ == "__main__":
    main()
