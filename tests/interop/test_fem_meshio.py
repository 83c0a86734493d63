#!/usr/bin/env python3
"""geofit's FEM quad mesh (`geofit fit --fem out.msh`) reads back with meshio as Gmsh 4.1.

Fits bun000 (a range scan) with one B-spline surface and spot with Catmull–Clark, writes each
FEM mesh as MSH (by element size and by count) and as OBJ quads, reads them with meshio, and
checks the node and element counts the CLI printed, that every element is a 4-node quad, that
the OBJ holds the same mesh, and that every element has positive area (the norm of half the
cross product of its diagonals). bun000's fitted surface folds in places, so elements across
its folds are counted apart; spot's must all be non-inverted against their neighbours.

Run: python tests/interop/test_fem_meshio.py   (exit status 1 on any failure)
Uses $GEOFIT_BIN, else target/release/geofit (built with cargo if missing).
"""
import re
import subprocess
import sys
import tempfile
from pathlib import Path

import meshio
import numpy as np

from geofit_cli import REPO, geofit_bin

DATA = REPO.parent / "shared" / "data"
if not DATA.exists():
    DATA = Path("/work/shared/data")

QUALITY = re.compile(r"FEM mesh: (\d+) quads, (\d+) nodes .* (\d+) inverted")


def fem(scan, scheme, out, *size):
    """Runs the fit with --fem; returns (quads, nodes, inverted) from its quality line."""
    cmd = [geofit_bin(), "fit", str(DATA / scan), "--scheme", scheme, "-q", "--fem", str(out), *size]
    text = subprocess.run(cmd, check=True, capture_output=True, text=True).stdout
    m = QUALITY.search(text)
    assert m, text
    return tuple(int(x) for x in m.groups())


def quads_of(mesh):
    blocks = [c for c in mesh.cells if c.type == "quad"]
    others = [c.type for c in mesh.cells if c.type != "quad"]
    assert not others, f"non-quad cells {others}"
    return np.concatenate([c.data for c in blocks])


def areas(points, quads):
    p = points[quads]
    return 0.5 * np.linalg.norm(np.cross(p[:, 2] - p[:, 0], p[:, 3] - p[:, 1]), axis=1)


def check(scan, scheme, size, tmp):
    name = f"{Path(scan).stem}-{scheme}-{size[0][2:]}"
    msh, obj = tmp / f"{name}.msh", tmp / f"{name}.obj"
    quads, nodes, inverted = fem(scan, scheme, msh, *size)
    assert fem(scan, scheme, obj, *size) == (quads, nodes, inverted), "OBJ and MSH differ"
    m = meshio.read(msh)
    q = quads_of(m)
    assert len(m.points) == nodes, f"{len(m.points)} nodes read, {nodes} written"
    assert len(q) == quads, f"{len(q)} quads read, {quads} written"
    assert np.isfinite(m.points).all()
    a = areas(m.points, q)
    assert (a > 0).all(), f"{(a <= 0).sum()} elements without area"
    o = meshio.read(obj)
    assert np.array_equal(quads_of(o), q), "OBJ elements differ"
    assert np.allclose(o.points, m.points, rtol=0, atol=1e-12), "OBJ nodes differ"
    print(f"ok  {name}: {quads} quads, {nodes} nodes, min area {a.min():.3e}, {inverted} inverted")
    return inverted


def main():
    cases = [
        ("bun000.ply", "bspline", ["--fem-size", "0.01"]),
        ("bun000.ply", "bspline", ["--fem-count", "50000"]),
        ("spot.obj", "catmull-clark", ["--fem-count", "20000"]),
    ]
    passed = failed = 0
    with tempfile.TemporaryDirectory() as d:
        for scan, scheme, size in cases:
            try:
                inverted = check(scan, scheme, size, Path(d))
                assert scheme != "catmull-clark" or inverted == 0, f"{inverted} inverted on spot"
                passed += 1
            except (AssertionError, subprocess.CalledProcessError) as e:
                print(f"FAIL {scan} {scheme} {size}: {e}")
                failed += 1
    print(f"{passed} passed, {failed} failed")
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
