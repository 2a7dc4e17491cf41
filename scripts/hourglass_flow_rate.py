#!/usr/bin/env python3
"""Mass flow rate through the neck of the hourglass scenes (issue #6, Narain 2011 Table 5.1).

Sand runs through an hourglass at a rate independent of how full the upper bulb is; a liquid
slows as its head falls (Torricelli). This script runs scenes/granular_hourglass.json (sand) and
scenes/granular_hourglass_liquid.json (the same glass and mass, liquid), or reads runs already
made, and reports for each the mass above the neck per frame and the flow rate while the upper
bulb drains from 80% to 20% of its initial mass: the mean rate (a line fitted to mass against
time) and the rates over the four quarters of that time, with their spread (max - min over the
mean). The liquid's head (surface above the neck) at 80% and 20% is printed with it.

Usage:
  scripts/hourglass_flow_rate.py [--msim build/release/bin/msim] [--out out/hourglass] [--no-run]
                                  [--duration-sand 16] [--duration-liquid 12]

Reads the PLY particle frames (binary little endian: x, y, z, ..., mass) the granular scenes
write; plain Python, no third-party modules. A full sand run takes about 20 minutes on 2 cores.
"""
import argparse
import array
import glob
import os
import subprocess
import sys

NECK_Y = 0.5  # scripts/make_hourglass_mesh.py: the neck is at mid height of the 1 m glass
FPS = 24.0


def read_frame(path):
    raw = open(path, "rb").read()
    end = raw.index(b"end_header\n") + len(b"end_header\n")
    header = raw[:end].decode("ascii").splitlines()
    count = int(next(line for line in header if line.startswith("element vertex")).split()[2])
    names = [line.split()[2] for line in header if line.startswith("property")]
    values = array.array("f")
    values.frombytes(raw[end:end + 4 * count * len(names)])
    if sys.byteorder != "little":
        values.byteswap()
    k = len(names)
    iy, im = names.index("y"), names.index("mass")
    above = sorted((values[i * k + iy], values[i * k + im]) for i in range(count) if values[i * k + iy] > NECK_Y)
    # The surface: the height below which 95% of the mass above the neck lies (a few grains or
    # drops left on the glass high up would make the highest particle meaningless).
    mass, level, seen = sum(m for _, m in above), NECK_Y, 0.0
    for y, m in above:
        seen += m
        level = y
        if seen >= 0.95 * mass:
            break
    return mass, level


def slope(t, m):
    n = len(t)
    mt, mm = sum(t) / n, sum(m) / n
    return sum((a - mt) * (b - mm) for a, b in zip(t, m)) / sum((a - mt) ** 2 for a in t)


def analyse(label, folder):
    files = sorted(glob.glob(os.path.join(folder, "particles", "*.ply")))
    if not files:
        sys.exit(f"{label}: no particle frames in {folder}/particles")
    times, masses, tops = [], [], []
    for f in files:
        frame = int(os.path.basename(f).rsplit("_", 1)[1].split(".")[0])
        mass, top = read_frame(f)
        times.append(frame / FPS)
        masses.append(mass)
        tops.append(top)
    m0 = masses[0]
    window = [i for i, m in enumerate(masses) if 0.2 * m0 <= m <= 0.8 * m0]
    print(f"{label}: {m0:.2f} kg above the neck at first, {masses[-1] / m0:.1%} at t = {times[-1]:.2f} s")
    if len(window) < 8 or masses[-1] > 0.2 * m0:
        print(f"  did not drain from 80% to 20% within the run (run it longer)")
        return None
    t = [times[i] for i in window]
    m = [masses[i] for i in window]
    mean = -slope(t, m)
    q = len(t) // 4
    quarters = [-slope(t[j * q:(j + 1) * q], m[j * q:(j + 1) * q]) for j in range(4)]
    spread = (max(quarters) - min(quarters)) / mean
    head80, head20 = tops[window[0]] - NECK_Y, tops[window[-1]] - NECK_Y
    print(f"  80% -> 20% from t = {t[0]:.2f} to {t[-1]:.2f} s: mean {mean:.2f} kg/s; quarters "
          + ", ".join(f"{r:.2f}" for r in quarters) + f" kg/s; spread {spread:.1%}")
    print(f"  head (95% mass level above the neck): {head80:.3f} m at 80%, {head20:.3f} m at 20%")
    return spread


def main():
    here = os.path.dirname(os.path.abspath(__file__))
    root = os.path.dirname(here)
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--msim", default=os.path.join(root, "build", "release", "bin", "msim"))
    parser.add_argument("--out", default=os.path.join(root, "out", "hourglass"))
    parser.add_argument("--no-run", action="store_true", help="analyse the runs already in --out")
    parser.add_argument("--duration-sand", type=float, default=16.0)
    parser.add_argument("--duration-liquid", type=float, default=12.0)
    args = parser.parse_args()
    runs = [("sand", "granular_hourglass", args.duration_sand),
            ("liquid", "granular_hourglass_liquid", args.duration_liquid)]
    spreads = {}
    for label, scene, duration in runs:
        folder = os.path.join(args.out, label)
        if not args.no_run:
            subprocess.run([args.msim, "run", os.path.join(root, "scenes", scene + ".json"), "--out", folder,
                            "--set", f"time.duration={duration}", "--set", "granular.render_points_per_particle=0"],
                           check=True)
        spreads[label] = analyse(label, folder)
    if None in spreads.values():
        return 1
    constant = spreads["sand"] <= 0.10 and spreads["liquid"] > 0.10
    print("sand constant within 10% and the liquid not: " + ("yes" if constant else "no"))
    return 0 if constant else 1


if __name__ == "__main__":
    sys.exit(main())
