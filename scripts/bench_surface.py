#!/usr/bin/env python3
"""bun000.ply as one B-spline surface: geofit against SciPy and Open CASCADE, in one run.

Every surface (geofit's, SciPy's z(x, y) spline, OCC's) is turned into the same plain form
(degrees, clamped knots, control grid) and measured the same way: the distance of every data
point to the surface by closest point (seeded from a dense sample grid through a k-d tree,
then vectorised Newton on the squared distance with clamping), in % of the data's bounding-box
diagonal. Times are wall-clock and CPU seconds of the fit itself (geofit: the whole process,
reading the file included).

    pip install -r scripts/bench-requirements.txt
    cargo build --release
    python3 scripts/bench_surface.py [--data ../shared/data/bun000.ply] [--counts 400,1600,6400]
"""

import argparse
import json
import os
import resource
import subprocess
import sys
import tempfile
import time

import numpy as np
from scipy.interpolate import LSQBivariateSpline, NdBSpline, SmoothBivariateSpline, griddata
from scipy.spatial import cKDTree

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


def default_data():
    for d in (os.environ.get("GEOFIT_DATA"), os.path.join(ROOT, "..", "shared", "data"), "/work/shared/data"):
        if d and os.path.exists(os.path.join(d, "bun000.ply")):
            return os.path.join(d, "bun000.ply")
    return "bun000.ply"


def read_ascii_ply_vertices(path):
    with open(path, "rb") as f:
        n = None
        while True:
            line = f.readline().decode("ascii", "replace").strip()
            if line.startswith("element vertex"):
                n = int(line.split()[2])
            if line == "end_header":
                break
        pts = np.loadtxt(f, max_rows=n, usecols=(0, 1, 2))
    return pts


class Surface:
    """A clamped tensor-product B-spline surface: knots, degrees, control grid (nu, nv, 3)."""

    def __init__(self, tu, tv, p, q, ctrl):
        self.tu, self.tv, self.p, self.q = np.asarray(tu, float), np.asarray(tv, float), p, q
        self.ctrl = np.asarray(ctrl, float)
        self.spl = NdBSpline((self.tu, self.tv), self.ctrl, (p, q))
        self.u0, self.u1 = self.tu[p], self.tu[-p - 1]
        self.v0, self.v1 = self.tv[q], self.tv[-q - 1]

    def ev(self, uv, du=0, dv=0):
        return self.spl(uv, nu=(du, dv))

    def distances(self, pts, samples=300, iters=12):
        us = np.linspace(self.u0, self.u1, samples)
        vs = np.linspace(self.v0, self.v1, samples)
        grid = np.stack(np.meshgrid(us, vs, indexing="ij"), -1).reshape(-1, 2)
        tree = cKDTree(self.ev(grid))
        _, idx = tree.query(pts)
        uv = grid[idx].copy()
        lo = np.array([self.u0, self.v0])
        hi = np.array([self.u1, self.v1])
        for _ in range(iters):
            s, su, sv = self.ev(uv), self.ev(uv, 1, 0), self.ev(uv, 0, 1)
            suu, suv, svv = self.ev(uv, 2, 0), self.ev(uv, 1, 1), self.ev(uv, 0, 2)
            r = s - pts
            g = np.stack([(su * r).sum(1), (sv * r).sum(1)], 1)
            a = (su * su).sum(1) + (suu * r).sum(1)
            b = (su * sv).sum(1) + (suv * r).sum(1)
            c = (sv * sv).sum(1) + (svv * r).sum(1)
            det = a * c - b * b
            bad = (a <= 0) | (det <= 1e-300)
            # Gauss-Newton where the full Hessian is not positive definite.
            a = np.where(bad, (su * su).sum(1), a)
            b = np.where(bad, (su * sv).sum(1), b)
            c = np.where(bad, (sv * sv).sum(1), c)
            det = np.where(np.abs(a * c - b * b) > 1e-300, a * c - b * b, 1e-300)
            step = -np.stack([(c * g[:, 0] - b * g[:, 1]) / det, (a * g[:, 1] - b * g[:, 0]) / det], 1)
            d_old = (r * r).sum(1)
            for _half in range(6):
                trial = np.clip(uv + step, lo, hi)
                d_new = ((self.ev(trial) - pts) ** 2).sum(1)
                ok = d_new <= d_old
                uv = np.where(ok[:, None], trial, uv)
                if ok.all():
                    break
                step = np.where(ok[:, None], 0.0, step * 0.5)
        return np.sqrt(((self.ev(uv) - pts) ** 2).sum(1))


def greville(t, k, n):
    return np.array([t[i + 1 : i + k + 1].mean() for i in range(n)])


def scipy_surface(spline):
    # get_knots() gives the full clamped knot vectors (ends repeated k + 1 times).
    tu, tv = (np.asarray(t, float) for t in spline.get_knots())
    kx, ky = spline.degrees
    nu, nv = len(tu) - kx - 1, len(tv) - ky - 1
    c = spline.get_coeffs().reshape(nu, nv)
    gx, gy = greville(tu, kx, nu), greville(tv, ky, nv)
    ctrl = np.stack(np.broadcast_arrays(gx[:, None], gy[None, :], c), -1)
    return Surface(tu, tv, kx, ky, ctrl)


def timed(fn):
    w, c = time.perf_counter(), time.process_time()
    out = fn()
    return out, time.perf_counter() - w, time.process_time() - c


def stats(d, diag):
    d = np.abs(d)
    return 100 * d.max() / diag, 100 * np.sqrt((d * d).mean()) / diag, 100 * d.mean() / diag


def run_geofit(binary, data, extra):
    with tempfile.TemporaryDirectory() as tmp:
        sj = os.path.join(tmp, "s.json")
        cmd = [binary, "fit", data, "--scheme", "bspline", "--surface-json", sj] + extra
        before = resource.getrusage(resource.RUSAGE_CHILDREN)
        w = time.perf_counter()
        out = subprocess.run(cmd, capture_output=True, text=True)
        wall = time.perf_counter() - w
        after = resource.getrusage(resource.RUSAGE_CHILDREN)
        if out.returncode != 0:
            raise RuntimeError(out.stderr.strip())
        report = json.loads(out.stdout)
        s = json.load(open(sj))
    ctrl = np.array(s["control_points"]).reshape(s["control_points_u"], s["control_points_v"], 3)
    surf = Surface(s["knots_u"], s["knots_v"], s["degree_u"], s["degree_v"], ctrl)
    cpu = (after.ru_utime + after.ru_stime) - (before.ru_utime + before.ru_stime)
    return surf, report, wall, cpu


def occ_fit(pts, diag, grid_n, tol_pct):
    """OCC needs a complete regular grid: resample z(x, y) linearly, fill holes by nearest."""
    from OCP.GeomAPI import GeomAPI_PointsToBSplineSurface
    from OCP.GeomAbs import GeomAbs_C2
    try:
        from OCP.collections import Array2_gp_Pnt as TColgp_Array2OfPnt
    except ImportError:
        from OCP.TColgp import TColgp_Array2OfPnt
    from OCP.gp import gp_Pnt

    def resample():
        xs = np.linspace(pts[:, 0].min(), pts[:, 0].max(), grid_n)
        ys = np.linspace(pts[:, 1].min(), pts[:, 1].max(), grid_n)
        gx, gy = np.meshgrid(xs, ys, indexing="ij")
        z = griddata(pts[:, :2], pts[:, 2], (gx, gy), method="linear")
        holes = np.isnan(z)
        z[holes] = griddata(pts[:, :2], pts[:, 2], (gx[holes], gy[holes]), method="nearest")
        return gx, gy, z

    (gx, gy, z), rw, rc = timed(resample)

    def approx():
        arr = TColgp_Array2OfPnt(1, grid_n, 1, grid_n)
        for i in range(grid_n):
            for j in range(grid_n):
                arr.SetValue(i + 1, j + 1, gp_Pnt(gx[i, j], gy[i, j], z[i, j]))
        api = GeomAPI_PointsToBSplineSurface(arr, 3, 3, GeomAbs_C2, tol_pct / 100 * diag)
        return api.Surface()

    s, aw, ac = timed(approx)
    tu = [s.UKnot(i) for i in range(1, s.NbUKnots() + 1) for _ in range(s.UMultiplicity(i))]
    tv = [s.VKnot(i) for i in range(1, s.NbVKnots() + 1) for _ in range(s.VMultiplicity(i))]
    ctrl = np.array(
        [[[s.Pole(i, j).X(), s.Pole(i, j).Y(), s.Pole(i, j).Z()] for j in range(1, s.NbVPoles() + 1)] for i in range(1, s.NbUPoles() + 1)]
    )
    return Surface(tu, tv, s.UDegree(), s.VDegree(), ctrl), rw, aw, rc + ac


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--data", default=default_data())
    ap.add_argument("--geofit", default=os.path.join(ROOT, "target", "release", "geofit"))
    ap.add_argument("--counts", default="400,1600,6400")
    ap.add_argument("--json", help="also write the table as JSON to this file")
    ap.add_argument("--skip-smooth", action="store_true", help="skip SciPy SmoothBivariateSpline")
    ap.add_argument("--peers-only", action="store_true", help="skip the geofit runs")
    args = ap.parse_args()
    pts = read_ascii_ply_vertices(args.data)
    diag = float(np.linalg.norm(pts.max(0) - pts.min(0)))
    print(f"# {args.data}: {len(pts)} points, bbox diagonal {diag:.6g}; errors in % of it; "
          f"times wall / CPU s; machine: {os.cpu_count()} cores, load {os.getloadavg()[0]:.1f}")
    rows = []

    def row(name, ctrl, surf, wall, cpu, note=""):
        emax, erms, eavg = stats(surf.distances(pts), diag)
        rows.append((name, ctrl, emax, erms, eavg, wall, cpu, note))
        print(f"{name:34s} {ctrl:6d}  E_max {emax:6.3f}  E_rms {erms:6.4f}  E_avg {eavg:6.4f}  "
              f"{wall:7.2f} s / {cpu:6.2f} s  {note}", flush=True)

    counts = [int(c) for c in args.counts.split(",")]
    x, y, zz = pts[:, 0], pts[:, 1], pts[:, 2]
    for n in counts:
        side = int(round(np.sqrt(n)))
        if not args.peers_only:
            s, rep, w, c = run_geofit(args.geofit, args.data, ["--ctrl", str(n), "--solves", "4"])
            row("geofit least-squares (fixed)", n, s, w, c, f"internal {rep['total_s']:.2f} s, {rep['folded_points']} folded")
            s, rep, w, c = run_geofit(args.geofit, args.data, ["--ctrl", str(n), "--method", "geometric"])
            row("geofit geometric (fixed)", n, s, w, c, f"{rep['iterations']} iterations")
        inner = side - 4
        tx = np.linspace(x.min(), x.max(), inner + 2)[1:-1]
        ty = np.linspace(y.min(), y.max(), inner + 2)[1:-1]
        try:
            sp, w, c = timed(lambda: LSQBivariateSpline(x, y, zz, tx, ty, kx=3, ky=3))
            row("scipy LSQBivariateSpline", n, scipy_surface(sp), w, c)
        except Exception as e:  # noqa: BLE001 - report what the peer does
            print(f"scipy LSQBivariateSpline {n}: failed: {e}")
    for tol in () if args.peers_only else (0.1, 0.05):
        for method in ("least-squares", "geometric"):
            s, rep, w, c = run_geofit(args.geofit, args.data, ["--tol-max", str(tol), "--tol-mode", "noisy", "--method", method])
            row(f"geofit {method} tol {tol} noisy", rep["final_control_points"], s, w, c,
                f"converged {rep['converged']}, {rep['iterations']} iterations")
    if not args.skip_smooth:
        try:
            sp, w, c = timed(lambda: SmoothBivariateSpline(x, y, zz, kx=3, ky=3))
            nc = len(sp.get_coeffs())
            row("scipy SmoothBivariateSpline", nc, scipy_surface(sp), w, c, "default s")
        except Exception as e:  # noqa: BLE001
            print(f"scipy SmoothBivariateSpline: failed: {e}")
    try:
        for grid_n, tol in ((100, 0.05), (150, 0.02)):
            s, rw, aw, c = occ_fit(pts, diag, grid_n, tol)
            nc = s.ctrl.shape[0] * s.ctrl.shape[1]
            row(f"OCC PointsToBSplineSurface", nc, s, rw + aw, c,
                f"grid {grid_n}², tol {tol} %, resample {rw:.2f} s + approx {aw:.2f} s")
    except ImportError as e:
        print(f"Open CASCADE not available ({e}); pip install cadquery-ocp")
    if args.json:
        keys = ("method", "control_points", "e_max_pct", "e_rms_pct", "e_avg_pct", "wall_s", "cpu_s", "note")
        with open(args.json, "w") as f:
            json.dump([dict(zip(keys, r)) for r in rows], f, indent=1)

if __name__ == "__main__":
    main()
