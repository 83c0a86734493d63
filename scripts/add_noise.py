#!/usr/bin/env python3
"""Adds Gaussian noise to the vertex positions of an OBJ file: standard deviation SIGMA_PCT % of
the vertices' bounding-box diagonal, on each coordinate, from a fixed seed. Every other line
(faces, comments) is copied as it is. Standard library only, and reproducible across Python
versions: the normal deviates are made by Box–Muller from `random.Random(seed).random()`, the one
sequence Python promises not to change for a given integer seed.

    python3 scripts/add_noise.py IN.obj OUT.obj [--sigma-pct 0.002] [--seed 17]
"""

import argparse
import math
import random


def main():
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("input")
    p.add_argument("output")
    p.add_argument("--sigma-pct", type=float, default=0.002)
    p.add_argument("--seed", type=int, default=17)
    args = p.parse_args()

    lo = [math.inf] * 3
    hi = [-math.inf] * 3
    with open(args.input) as fh:
        for line in fh:
            if line.startswith("v "):
                for k, t in enumerate(line.split()[1:4]):
                    x = float(t)
                    lo[k] = min(lo[k], x)
                    hi[k] = max(hi[k], x)
    diag = math.sqrt(sum((b - a) ** 2 for a, b in zip(lo, hi)))
    sigma = args.sigma_pct / 100.0 * diag

    rng = random.Random(args.seed)
    spare = []

    def normal():
        if spare:
            return spare.pop()
        u1 = 1.0 - rng.random()  # (0, 1]: log is finite
        u2 = rng.random()
        r = math.sqrt(-2.0 * math.log(u1))
        spare.append(r * math.sin(2.0 * math.pi * u2))
        return r * math.cos(2.0 * math.pi * u2)

    n = 0
    with open(args.input) as src, open(args.output, "w") as dst:
        for line in src:
            if line.startswith("v "):
                xyz = [float(t) + sigma * normal() for t in line.split()[1:4]]
                dst.write(f"v {xyz[0]!r} {xyz[1]!r} {xyz[2]!r}\n")
                n += 1
            else:
                dst.write(line)
    print(f"{args.output}: {n} vertices, noise sigma {sigma:.6g} ({args.sigma_pct} % of the diagonal {diag:.6g}), seed {args.seed}")


if __name__ == "__main__":
    main()
