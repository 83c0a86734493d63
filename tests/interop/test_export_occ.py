#!/usr/bin/env python3
"""Interoperability of geofit's IGES and STEP export with Open CASCADE (cadquery-ocp).

Runs `geofit export-samples` (open, closed and rational curves, B-spline and NURBS surfaces)
and `geofit fit --scheme bspline-curve` on the bunny section (both methods), reads every exported file back with
OCC's IGES and STEP readers, and checks that OCC evaluates the geometry at geofit's sample
parameters to within 1e-9 of the bounding-box diagonal.

Run: python tests/interop/test_export_occ.py   (exit status 1 on any failure)
Uses $GEOFIT_BIN, else target/release/geofit (built with cargo if missing).
"""
import json
import os
import subprocess
import sys
import tempfile
from pathlib import Path

from OCP.BRep import BRep_Tool
from OCP.IFSelect import IFSelect_RetDone
from OCP.IGESControl import IGESControl_Reader
from OCP.STEPControl import STEPControl_Reader
from OCP.TopAbs import TopAbs_EDGE, TopAbs_FACE
from OCP.TopExp import TopExp_Explorer
from OCP.TopoDS import TopoDS

from geofit_cli import REPO, geofit_bin

REL_TOL = 1e-9



def read_shape(path):
    reader = IGESControl_Reader() if path.suffix == ".igs" else STEPControl_Reader()
    if reader.ReadFile(str(path)) != IFSelect_RetDone:
        raise RuntimeError(f"OCC cannot read {path.name}")
    if reader.TransferRoots() == 0:
        raise RuntimeError(f"OCC transferred nothing from {path.name}")
    return reader.OneShape()


def occ_curve(shape):
    """An evaluator over every edge of the shape. OCC's IGES reader splits a B-spline curve at
    its C0 knots (a corner knot of the knot method, the double knots of a NURBS circle) into
    edges that keep their original parameter ranges, so a parameter is evaluated on the edge
    whose range holds it."""
    curves = []
    exp = TopExp_Explorer(shape, TopAbs_EDGE)
    while exp.More():
        curves.append(BRep_Tool.Curve_s(TopoDS.Edge(exp.Current()), 0.0, 0.0))
        exp.Next()
    if not curves:
        raise RuntimeError("no edge in the file")

    def value(u):
        for c in curves:
            if c.FirstParameter() - 1e-12 <= u <= c.LastParameter() + 1e-12:
                return c.Value(u)
        raise RuntimeError(f"parameter {u} is on no edge")

    return value


def occ_surface(shape):
    exp = TopExp_Explorer(shape, TopAbs_FACE)
    if not exp.More():
        raise RuntimeError("no face in the file")
    return BRep_Tool.Surface_s(TopoDS.Face(exp.Current()))


def diagonal(points):
    lo = [min(p[k] for p in points) for k in range(3)]
    hi = [max(p[k] for p in points) for k in range(3)]
    return sum((h - l) ** 2 for h, l in zip(hi, lo)) ** 0.5


def worst(samples, evaluate, nparams):
    pts = [s[nparams:] for s in samples]
    diag = diagonal(pts)
    err = 0.0
    for s in samples:
        p = evaluate(*s[:nparams])
        err = max(err, sum((a - b) ** 2 for a, b in zip((p.X(), p.Y(), p.Z()), s[nparams:])) ** 0.5)
    return err / diag


class Tally:
    def __init__(self):
        self.passed = 0
        self.failed = 0

    def check(self, name, fn):
        try:
            rel = fn()
            ok = rel <= REL_TOL
            detail = f"max deviation {rel:.2e} of the diagonal"
        except Exception as exc:  # a reader failure is a test failure, reported by name
            ok, detail = False, f"{type(exc).__name__}: {exc}"
        print(f"{'PASS' if ok else 'FAIL'} {name}: {detail}")
        if ok:
            self.passed += 1
        else:
            self.failed += 1


def main():
    exe = geofit_bin()
    tally = Tally()
    with tempfile.TemporaryDirectory() as tmp:
        out = Path(tmp)
        subprocess.run([exe, "export-samples", str(out)], check=True)
        meta = json.loads((out / "samples.json").read_text())
        for c in meta["curves"]:
            for key in ("iges", "step"):
                path = out / c[key]
                tally.check(f"{path.name}", lambda: worst(
                    c["samples"], occ_curve(read_shape(path)), 1))
        for s in meta["surfaces"]:
            for key in ("iges", "step"):
                path = out / s[key]
                tally.check(f"{path.name}", lambda: worst(
                    s["samples"], lambda u, v: occ_surface(read_shape(path)).Value(u, v), 2))
        section = REPO / "tests" / "data" / "bunny_section.xyz"
        for method in ("geometric", "knots"):
            stem = out / f"bunny_{method}"
            subprocess.run([exe, "fit", str(section), "--scheme", "bspline-curve", "--quiet", "--closed", "--method", method,
                            "--tol-max", "0.01", "--json", f"{stem}.json",
                            "--iges", f"{stem}.igs", "--step", f"{stem}.stp"], check=True)
            report = json.loads(Path(f"{stem}.json").read_text())
            for ext in ("igs", "stp"):
                path = Path(f"{stem}.{ext}")
                tally.check(f"fit-curve {method} {path.name}", lambda: worst(
                    report["samples"], occ_curve(read_shape(path)), 1))
    print(f"{tally.passed} passed, {tally.failed} failed")
    return 1 if tally.failed else 0


if __name__ == "__main__":
    sys.exit(main())
