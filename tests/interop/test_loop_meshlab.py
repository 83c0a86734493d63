#!/usr/bin/env python3
"""geofit's Loop subdivision is Loop's (1987) scheme, as MeshLab implements it (pymeshlab).

Refines meshes two levels with `geofit subdiv --scheme loop` and with MeshLab's Loop filter
(weights 'Loop', threshold 0 so every edge is split), and checks that every geofit vertex has a
MeshLab vertex within 1e-12 of the bounding-box diagonal, and the counts agree. The meshes: a
closed coarse spot with vertex valences 3 to 10, an open bunny patch (boundary rules), and the
1,219-triangle bunny with valences up to 17.

Run: python tests/interop/test_loop_meshlab.py   (exit status 1 on any failure)
Uses $GEOFIT_BIN, else target/release/geofit (built with cargo if missing).
"""
import os
import subprocess
import sys
import tempfile
from collections import Counter
from pathlib import Path

import numpy as np
import pymeshlab
from scipy.spatial import cKDTree

from geofit_cli import REPO, geofit_bin

DATA = REPO / "tests" / "data" / "subdiv"
TOL = 1e-12



def read_vertices(path):
    with open(path) as f:
        return np.array([[float(x) for x in l.split()[1:4]] for l in f if l.startswith("v ")])


def valences(faces):
    edges = {tuple(sorted((f[i], f[(i + 1) % 3]))) for f in faces for i in range(3)}
    degree = Counter(v for e in edges for v in e)
    return min(degree.values()), max(degree.values())


def check(exe, name, tmp):
    src = DATA / name
    ms = pymeshlab.MeshSet()
    ms.load_new_mesh(str(src))
    low, high = valences(ms.current_mesh().face_matrix().tolist())
    ms.meshing_surface_subdivision_loop(loopweight="Loop", iterations=2,
                                        threshold=pymeshlab.PercentageValue(0))
    ref = ms.current_mesh()
    out = Path(tmp) / "ours.obj"
    subprocess.run([exe, "subdiv", str(src), "--scheme", "loop", "--levels", "2", "-o", str(out)],
                   check=True, capture_output=True)
    ours = read_vertices(out)
    refv = ref.vertex_matrix()
    diag = np.linalg.norm(refv.max(0) - refv.min(0))
    dist, _ = cKDTree(refv).query(ours)
    worst = dist.max() / diag
    ok = len(ours) == len(refv) and worst < TOL
    print(f"{'PASS' if ok else 'FAIL'} {name} (valences {low}-{high}): {len(ours)} vertices "
          f"(MeshLab {len(refv)}), worst deviation {worst:.2e} of the diagonal")
    return ok


def main():
    exe = geofit_bin()
    results = []
    with tempfile.TemporaryDirectory() as tmp:
        for name in ["spot_coarse.obj", "bunny_patch.obj", "bunny_coarse.obj"]:
            results.append(check(exe, name, tmp))
    passed = sum(results)
    print(f"{passed} passed, {len(results) - passed} failed")
    return 0 if all(results) else 1


if __name__ == "__main__":
    sys.exit(main())
