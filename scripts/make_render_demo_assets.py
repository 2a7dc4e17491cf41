#!/usr/bin/env python3
"""Makes the two synthetic inputs of the docs/render.md pictures: a sand pile (PLY points) and a
cloth-like sheet draped over smoke_sphere's ball (OBJ). Until msim's granular and cloth modules
exist, these stand in for their output. Usage: scripts/make_render_demo_assets.py OUT_DIR"""
import math
import random
import sys

out = sys.argv[1] if len(sys.argv) > 1 else "docs/assets"

# Sand: 30000 grains in a cone of repose angle 32 degrees on the floor, centre (0.5, 0, 0.5).
random.seed(3)
angle = math.radians(32.0)
base = 0.25
grains = []
while len(grains) < 30000:
    x, z, y = random.uniform(-base, base), random.uniform(-base, base), random.uniform(0.0, base * math.tan(angle))
    r = math.hypot(x, z)
    if r <= base and y <= (base - r) * math.tan(angle):
        grains.append((0.5 + x, y, 0.5 + z))
with open(f"{out}/sand_pile.ply", "w") as f:
    f.write("ply\nformat ascii 1.0\nelement vertex %d\nproperty float x\nproperty float y\nproperty float z\nend_header\n" % len(grains))
    for g in grains:
        f.write("%.5f %.5f %.5f\n" % g)

# Cloth: a 0.7 m square sheet, 90 x 90 vertices, resting on a ball of radius 0.16 at (0.5, 0.6, 0.5):
# on the ball it follows the sphere (plus 3 mm), beyond it it hangs down at 60 degrees with folds.
n, half, centre, radius = 90, 0.35, (0.5, 0.6, 0.5), 0.163
verts = []
for j in range(n):
    for i in range(n):
        u, v = -half + 2 * half * i / (n - 1), -half + 2 * half * j / (n - 1)
        d = math.hypot(u, v)
        if d < radius * 0.8:
            y = centre[1] + math.sqrt(radius * radius - d * d)
        else:
            d0 = radius * 0.8
            y0 = centre[1] + math.sqrt(radius * radius - d0 * d0)
            fold = 0.012 * math.sin(10.0 * math.atan2(v, u)) * (d - d0) / half
            y = y0 - (d - d0) * math.tan(math.radians(60.0)) + fold
            shrink = 1.0 - 0.45 * (d - d0) / (half * 1.42)  # the hanging part draws in
            u, v = u * shrink, v * shrink
        verts.append((centre[0] + u, y, centre[2] + v))
with open(f"{out}/draped_cloth.obj", "w") as f:
    f.write("# msim docs asset: a sheet draped over a ball (made by scripts/make_render_demo_assets.py)\n")
    for p in verts:
        f.write("v %.5f %.5f %.5f\n" % p)
    for j in range(n - 1):
        for i in range(n - 1):
            a = j * n + i + 1
            f.write("f %d %d %d\nf %d %d %d\n" % (a, a + 1, a + n + 1, a, a + n + 1, a + n))
