#!/usr/bin/env python3
"""Closed-curve fitting benchmark on the bunny section (615 points): geofit (geometric iteration
and knot placement) against SciPy splprep (periodic) and Open CASCADE GeomAPI_PointsToBSpline,
all at E_max <= 0.01 % of the bounding-box diagonal, in one run on one machine.

E_max is measured the same way for every curve: distance of each data point to a polyline of
200,000 samples of the curve. Times are one fit call at the final setting (the search for
SciPy's smoothing factor and OCC's tolerance is not timed, as a user would know them).

Usage: python scripts/bench_curve.py [SECTION.xyz] [--tol PCT]
"""
import json
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

# One BLAS thread: geofit runs on one core, and on a loaded machine OpenBLAS's spinning threads
# made SciPy's Delaunay transforms 50× slower (25 s instead of 0.5 s).
os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")
os.environ.setdefault("OMP_NUM_THREADS", "1")

import numpy as np
from scipy.interpolate import BSpline, splev, splprep
from scipy.spatial import cKDTree

REPO = Path(__file__).resolve().parents[1]


def point_to_polyline(points, poly):
    """Distance of each point to the closed polyline `poly` (nearest vertex, then its two
    segments)."""
    tree = cKDTree(poly)
    _, idx = tree.query(points)
    n = len(poly)
    best = np.full(len(points), np.inf)
    for off in (-1, 0):
        a = poly[(idx + off) % n]
        b = poly[(idx + off + 1) % n]
        ab = b - a
        t = np.clip(((points - a) * ab).sum(1) / np.maximum((ab * ab).sum(1), 1e-300), 0, 1)
        d = np.linalg.norm(points - (a + t[:, None] * ab), axis=1)
        best = np.minimum(best, d)
    return best


def emax_pct(points, poly, diag):
    return point_to_polyline(points, poly).max() / diag * 100


def scipy_fit(points, diag, tol):
    x, y = points[:, 0], points[:, 1]
    u_dense = np.linspace(0, 1, 200_000)

    def fit(s):
        t0 = time.perf_counter()
        tck, _ = splprep([x, y], s=s, per=1, k=3, quiet=1)
        dt = time.perf_counter() - t0
        poly = np.array(splev(u_dense, tck)).T
        ctrl = len(tck[1][0]) - 3  # periodic: the last k coefficients repeat the first
        return ctrl, emax_pct(points, poly, diag), dt

    # Largest smoothing factor that still meets the tolerance (fewest control points).
    lo, hi = 0.0, len(points) * (tol / 100 * diag) ** 2
    best = fit(lo)
    for _ in range(40):
        mid = 0.5 * (lo + hi)
        r = fit(mid)
        if r[1] <= tol:
            lo, best = mid, r
        else:
            hi = mid
    final = fit(lo)
    return final[0], final[1], final[2], "splprep per=1 k=3"


def occ_fit(points, diag, tol):
    from OCP.GeomAPI import GeomAPI_PointsToBSpline
    from OCP.GeomAbs import GeomAbs_C2
    from OCP.collections import Array1_gp_Pnt
    from OCP.gp import gp_Pnt

    def fit(tol3d):
        arr = Array1_gp_Pnt(1, len(points) + 1)
        for i, p in enumerate(list(points) + [points[0]]):
            arr.SetValue(i + 1, gp_Pnt(float(p[0]), float(p[1]), 0.0))
        t0 = time.perf_counter()
        curve = GeomAPI_PointsToBSpline(arr, 3, 8, GeomAbs_C2, tol3d).Curve()
        dt = time.perf_counter() - t0
        a, b = curve.FirstParameter(), curve.LastParameter()
        us = np.linspace(a, b, 200_000)
        poly = np.array([[curve.Value(u).X(), curve.Value(u).Y()] for u in us])
        return curve.NbPoles(), emax_pct(points, poly, diag), dt, curve.Degree()

    tol3d = tol / 100 * diag
    r = fit(tol3d)
    while r[1] > tol and tol3d > 1e-6 * tol / 100 * diag:
        tol3d *= 0.7
        r = fit(tol3d)
    return r[0], r[1], r[2], f"PointsToBSpline C2 deg {r[3]} Tol3D {tol3d:.3g} (open, seam point repeated)"


def corner_jumps(spline, knots, degree):
    """Angle (degrees) between the one-sided tangents at every interior knot of multiplicity
    `degree` (a C0 corner knot): a corner kept sharp turns by about the data's angle."""
    t = np.array(knots)
    a, b = t[degree], t[-degree - 1]
    values, counts = np.unique(t[(t > a) & (t < b)], return_counts=True)
    d = spline.derivative()
    eps = 1e-9 * (b - a)
    out = []
    for u in values[counts >= degree]:
        t1, t2 = d(u - eps), d(u + eps)
        cos = np.dot(t1, t2) / (np.linalg.norm(t1) * np.linalg.norm(t2))
        out.append(float(np.degrees(np.arccos(np.clip(cos, -1, 1)))))
    return out


def geofit_fit(section, method, diag, points, tol):
    exe = Path(os.environ.get("CARGO_TARGET_DIR") or REPO / "target") / "release" / "geofit"
    if not exe.exists():
        subprocess.run(["cargo", "build", "--release", "--bin", "geofit"], cwd=REPO, check=True)
    with tempfile.TemporaryDirectory() as tmp:
        out = Path(tmp) / "r.json"
        subprocess.run([str(exe), "fit", str(section), "--scheme", "bspline-curve", "--quiet", "--closed", "--method", method,
                        "--tol-max", str(tol), "--json", str(out)], check=True)
        r = json.loads(out.read_text())
    c = r["clamped"]
    ctrl = np.array(c["control_points"])[:, :2]
    spline = BSpline(np.array(c["knots"]), ctrl, c["degree"])
    a, b = c["knots"][c["degree"]], c["knots"][-c["degree"] - 1]
    poly = spline(np.linspace(a, b, 200_000))
    note = f"{r['iterations']} iterations, own E_max {r['e_max_pct']:.5f} %"
    if method == "knots":
        note += f", {r['corners']} corner / {r['features']} multiple knots"
        jumps = corner_jumps(spline, c["knots"], c["degree"])
        if jumps:
            note += f", tangent turns {min(jumps):.1f}–{max(jumps):.1f}° at the corner knots"
    return r["control_points"], emax_pct(points, poly, diag), r["fit_s"], note


def main():
    args = [a for a in sys.argv[1:] if not a.startswith("--")]
    tol = 0.01
    if "--tol" in sys.argv:
        tol = float(sys.argv[sys.argv.index("--tol") + 1])
    section = Path(args[0]) if args else REPO / "tests" / "data" / "bunny_section.xyz"
    points = np.loadtxt(section)[:, :2]
    diag = np.linalg.norm(points.max(0) - points.min(0))
    rows = [
        ("geofit geometric",) + geofit_fit(section, "geometric", diag, points, tol),
        ("geofit knots",) + geofit_fit(section, "knots", diag, points, tol),
        ("SciPy splprep",) + scipy_fit(points, diag, tol),
        ("Open CASCADE",) + occ_fit(points, diag, tol),
    ]
    print(f"{section.name}: {len(points)} points, closed, target E_max {tol} % of diagonal {diag:.6g}")
    print(f"| method | control points | E_max % | time ms | notes |")
    print(f"|---|---|---|---|---|")
    for name, ctrl, e, t, note in rows:
        print(f"| {name} | {ctrl} | {e:.5f} | {t * 1e3:.1f} | {note} |")


if __name__ == "__main__":
    main()
