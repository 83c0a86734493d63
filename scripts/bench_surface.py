#!/usr/bin/env python3
"""bun000.ply as one B-spline surface: geofit against SciPy and Open CASCADE, in one run.

Every surface (geofit's, SciPy's z(x, y) spline, OCC's) is turned into the same plain form
(degrees, clamped knots, control grid) and measured the same way: the distance of every data
point to the surface by closest point — the 4 nearest samples of a dense sampling (6 per knot
span and direction, so as fine on a 40,000- as on a 400-control-point surface) and the fit's own
parameters of the point (geofit's foot points; for SciPy's and OCC's z(x, y) surfaces the
parameters above the point) seed damped Newton descents, and the nearest foot point wins — in %
of the data's bounding-box diagonal. geofit's rows also show the fit's own report
(warm-started Newton from its parameters), which this measure must match or undercut. Times are wall-clock and CPU seconds of the fit itself (geofit: the whole
process, reading the file included, on one thread like the peers, and its wall time on all
cores in the note; OCC: resampling to its grid plus its fit).

    pip install -r scripts/bench-requirements.txt
    cargo build --release
    python3 scripts/bench_surface.py [--data ../shared/data/bun000.ply] [--counts 400,1600,6400]
        [--tols 0.1,0.05] [--json out.json]
"""

import argparse
import json
import os
import resource
import subprocess
import sys
import tempfile
import time

# One BLAS thread: geofit runs on one core, and on a loaded machine OpenBLAS's spinning threads
# made SciPy's Delaunay transforms 50× slower (25 s instead of 0.5 s).
os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")
os.environ.setdefault("OMP_NUM_THREADS", "1")

import numpy as np
from scipy.interpolate import LSQBivariateSpline, NdBSpline, SmoothBivariateSpline
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

    def sample_params(self, t, k, lo, hi, per_span):
        """`per_span` parameters in every non-empty knot span (both ends included), so that
        the sampling is as fine, relative to the surface's detail, on a 400- as on a
        40,000-control-point surface."""
        br = np.unique(t[k : len(t) - k])
        inner = np.linspace(0.0, 1.0, per_span + 1)[:-1]
        out = (br[:-1, None] + (br[1:] - br[:-1])[:, None] * inner[None, :]).ravel()
        return np.clip(np.append(out, hi), lo, hi)

    def distances(self, pts, seeds=None, per_span=6, starts=4, iters=10):
        """Distance of every point to the surface: the `starts` nearest of a dense sampling
        (`per_span` samples per knot span and direction, through a k-d tree), and the fit's own
        parameters of the points (`seeds`, when known), seed damped Newton descents on the
        squared distance (clamped to the domain); the nearest foot point wins. Returns
        (distances, (u, v) of the foot points)."""
        us = self.sample_params(self.tu, self.p, self.u0, self.u1, per_span)
        vs = self.sample_params(self.tv, self.q, self.v0, self.v1, per_span)
        grid = np.stack(np.meshgrid(us, vs, indexing="ij"), -1).reshape(-1, 2)
        tree = cKDTree(self.ev(grid))
        _, idx = tree.query(pts, k=starts)
        idx = idx.reshape(len(pts), -1)
        inits = [grid[idx[:, s]] for s in range(idx.shape[1])]
        if seeds is not None:
            lo, hi = np.array([self.u0, self.v0]), np.array([self.u1, self.v1])
            inits.append(np.clip(np.asarray(seeds, float), lo, hi))
        best_d = np.full(len(pts), np.inf)
        best_uv = np.zeros((len(pts), 2))
        for init in inits:
            uv, d = self.newton(pts, init.copy(), iters)
            better = d < best_d
            best_d = np.where(better, d, best_d)
            best_uv[better] = uv[better]
        return best_d, best_uv

    def graph_seeds(self, pts):
        """For a z(x, y) surface (x depending on u only, y on v only, both increasing): the
        parameters (u, v) straight above each point — the parameters that such a fit used."""
        us = self.sample_params(self.tu, self.p, self.u0, self.u1, 16)
        vs = self.sample_params(self.tv, self.q, self.v0, self.v1, 16)
        vm, um = 0.5 * (self.v0 + self.v1), 0.5 * (self.u0 + self.u1)
        xs = self.ev(np.stack([us, np.full_like(us, vm)], 1))[:, 0]
        ys = self.ev(np.stack([np.full_like(vs, um), vs], 1))[:, 1]
        if not (np.all(np.diff(xs) > 0) and np.all(np.diff(ys) > 0)):
            return None
        return np.stack([np.interp(pts[:, 0], xs, us), np.interp(pts[:, 1], ys, vs)], 1)

    def newton(self, pts, uv, iters):
        """Damped Newton on |S(u, v) − p|² from `uv`, clamped to the domain; (uv, distance)."""
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
        return uv, np.sqrt(((self.ev(uv) - pts) ** 2).sum(1))


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


def run_geofit(binary, data, extra, threads=1):
    """One `geofit fit` process on `threads` threads (None: geofit's default, all cores)."""
    env = dict(os.environ)
    env.pop("GEOFIT_THREADS", None)
    if threads is not None:
        env["GEOFIT_THREADS"] = str(threads)
    with tempfile.TemporaryDirectory() as tmp:
        sj = os.path.join(tmp, "s.json")
        rj = os.path.join(tmp, "r.json")
        cmd = [binary, "fit", data, "--scheme", "bspline-surface", "--quiet", "--json", rj,
               "--surface-json", sj] + extra
        before = resource.getrusage(resource.RUSAGE_CHILDREN)
        w = time.perf_counter()
        out = subprocess.run(cmd, capture_output=True, text=True, env=env)
        wall = time.perf_counter() - w
        after = resource.getrusage(resource.RUSAGE_CHILDREN)
        if out.returncode != 0:
            raise RuntimeError(out.stderr.strip())
        report = json.load(open(rj))
        s = json.load(open(sj))
    ctrl = np.array(s["control_points"]).reshape(s["control_points_u"], s["control_points_v"], 3)
    surf = Surface(s["knots_u"], s["knots_v"], s["degree_u"], s["degree_v"], ctrl)
    surf.seeds = np.array(s["parameters"])
    cpu = (after.ru_utime + after.ru_stime) - (before.ru_utime + before.ru_stime)
    return surf, report, wall, cpu


class Resampler:
    """z(x, y) of the scan on regular grids, as Open CASCADE needs: linear interpolation on the
    Delaunay triangulation of (x, y), holes and the outside of the hull filled with the nearest
    point's z. Built once (triangulation, k-d tree); each grid is then one vectorised call."""

    def __init__(self, pts):
        from scipy.interpolate import LinearNDInterpolator
        from scipy.spatial import Delaunay

        self.pts = pts
        tri = Delaunay(pts[:, :2])
        self.lin = LinearNDInterpolator(tri, pts[:, 2])
        # Half-planes of the convex hull: grid nodes outside it skip the triangle search
        # (which falls back to a brute-force scan per outside node: seconds on big grids).
        hull = tri.convex_hull
        a, b = pts[hull[:, 0], :2], pts[hull[:, 1], :2]
        normal = np.stack([b[:, 1] - a[:, 1], a[:, 0] - b[:, 0]], 1)
        inward = np.sign(((pts[:, :2].mean(0) - a) * normal).sum(1))
        self.planes = (normal * inward[:, None], (a * normal).sum(1) * inward)
        self.tree = cKDTree(pts[:, :2])

    def grid(self, n):
        xs = np.linspace(self.pts[:, 0].min(), self.pts[:, 0].max(), n)
        ys = np.linspace(self.pts[:, 1].min(), self.pts[:, 1].max(), n)
        q = np.stack(np.meshgrid(xs, ys, indexing="ij"), -1).reshape(-1, 2)
        normal, offset = self.planes
        scale = np.abs(offset).max()
        inside = (q @ normal.T - offset >= -1e-12 * scale).all(1)
        z = np.full(len(q), np.nan)
        z[inside] = self.lin(q[inside])
        holes = np.isnan(z)
        z[holes] = self.pts[self.tree.query(q[holes])[1], 2]
        return xs, ys, z.reshape(n, n)


def occ_surface(s):
    """An OCP Geom_BSplineSurface as a plain Surface."""
    tu = [s.UKnot(i) for i in range(1, s.NbUKnots() + 1) for _ in range(s.UMultiplicity(i))]
    tv = [s.VKnot(i) for i in range(1, s.NbVKnots() + 1) for _ in range(s.VMultiplicity(i))]
    ctrl = np.array(
        [[[s.Pole(i, j).X(), s.Pole(i, j).Y(), s.Pole(i, j).Z()] for j in range(1, s.NbVPoles() + 1)]
         for i in range(1, s.NbUPoles() + 1)]
    )
    return Surface(tu, tv, s.UDegree(), s.VDegree(), ctrl)


def occ_fit(resampler, diag, count, mode):
    """Open CASCADE GeomAPI_PointsToBSplineSurface on a regular z(x, y) grid sized to `count`
    control points. `mode` "interpolate": a (√count − 2)² grid, interpolated by a bicubic C2
    surface (exactly `count` poles); "approximate": a √count² grid approximated with degree 3,
    C2, Tol3D 0.01 % (OCC then keeps about one pole per grid point). Returns (surface, grid
    side, resample s wall, fit s wall, CPU s of both); the triangulation of the resampler is
    built once per run and timed separately."""
    from OCP.GeomAPI import GeomAPI_PointsToBSplineSurface
    from OCP.GeomAbs import GeomAbs_C2
    from OCP.collections import Array2_double

    side = int(round(np.sqrt(count)))
    n = side - 2 if mode == "interpolate" else side
    (xs, ys, z), rw, rc = timed(lambda: resampler.grid(n))

    def fit():
        arr = Array2_double(1, n, 1, n)
        for i in range(n):
            for j in range(n):
                arr.SetValue(i + 1, j + 1, float(z[i, j]))
        api = GeomAPI_PointsToBSplineSurface()
        x0, dx, y0, dy = float(xs[0]), float(xs[1] - xs[0]), float(ys[0]), float(ys[1] - ys[0])
        if mode == "interpolate":
            api.Interpolate(arr, x0, dx, y0, dy)
        else:
            api.Init(arr, x0, dx, y0, dy, 3, 3, GeomAbs_C2, 1e-4 * diag)
        return api.Surface()

    s, fw, fc = timed(fit)
    return occ_surface(s), n, rw, fw, rc + fc


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--data", default=default_data())
    target_dir = os.environ.get("CARGO_TARGET_DIR") or os.path.join(ROOT, "target")
    ap.add_argument("--geofit", default=os.path.join(target_dir, "release", "geofit"))
    ap.add_argument("--counts", default="400,1600,6400")
    ap.add_argument("--tols", default="0.1,0.05", help="tolerances (%%) of the adaptive geofit runs")
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
        seeds = getattr(surf, "seeds", None)
        if seeds is None:
            seeds = surf.graph_seeds(pts)
        emax, erms, eavg = stats(surf.distances(pts, seeds)[0], diag)
        rows.append((name, ctrl, emax, erms, eavg, wall, cpu, note))
        print(f"{name:34s} {ctrl:6d}  E_max {emax:6.3f}  E_rms {erms:6.4f}  E_avg {eavg:6.4f}  "
              f"{wall:7.2f} s / {cpu:6.2f} s  {note}", flush=True)

    def geofit(name, extra):
        # Timed on one thread, as the peers run; then once more on all cores (geofit's
        # default), whose wall time goes into the note.
        s, rep, w, c = run_geofit(args.geofit, args.data, extra, threads=1)
        _, rep_all, w_all, _ = run_geofit(args.geofit, args.data, extra, threads=None)
        if rep_all["final_control_points"] != rep["final_control_points"]:
            raise RuntimeError(f"{name}: a different fit on {os.cpu_count()} threads")
        note = (f"{rep['iterations']} iterations, converged {rep['converged']}, own E_max "
                f"{rep['e_max_pct']:.3f} E_rms {rep['e_rms_pct']:.4f}; "
                f"{w_all:.2f} s wall on {os.cpu_count()} threads")
        row(name, rep["final_control_points"], s, w, c, note)
        return rep["final_control_points"]

    resampler = None

    def occ(n):
        nonlocal resampler
        try:
            import OCP  # noqa: F401
        except ImportError as e:
            print(f"Open CASCADE not available ({e}); pip install cadquery-ocp")
            return
        if resampler is None:
            resampler, tw, tc = timed(lambda: Resampler(pts))
            resampler.setup = (tw, tc)
            print(f"# OCC resampling: triangulation of (x, y) once, {tw:.2f} s wall / {tc:.2f} s CPU, "
                  "added to every OCC row's time", flush=True)
        tw, tc = resampler.setup
        for mode in ("interpolate", "approximate"):
            s, grid_n, rw, fw, c = occ_fit(resampler, diag, n, mode)
            row(f"OCC PointsToBSplineSurface {mode}", s.ctrl.shape[0] * s.ctrl.shape[1], s,
                tw + rw + fw, tc + c,
                f"grid {grid_n}², triangulation {tw:.2f} s + grid {rw:.2f} s + fit {fw:.2f} s")

    counts = [int(c) for c in args.counts.split(",") if c]
    x, y, zz = pts[:, 0], pts[:, 1], pts[:, 2]
    for n in counts:
        side = int(round(np.sqrt(n)))
        if not args.peers_only:
            geofit("geofit least-squares (fixed)", ["--ctrl", str(n)])
            geofit("geofit geometric (fixed)", ["--ctrl", str(n), "--method", "geometric"])
        inner = side - 4
        tx = np.linspace(x.min(), x.max(), inner + 2)[1:-1]
        ty = np.linspace(y.min(), y.max(), inner + 2)[1:-1]
        try:
            sp, w, c = timed(lambda: LSQBivariateSpline(x, y, zz, tx, ty, kx=3, ky=3))
            row("scipy LSQBivariateSpline", n, scipy_surface(sp), w, c)
        except Exception as e:  # noqa: BLE001 - report what the peer does
            print(f"scipy LSQBivariateSpline {n}: failed: {e}")
        occ(n)
    tols = [float(t) for t in args.tols.split(",") if t]
    for tol in () if args.peers_only else tols:
        for method in ("least-squares", "geometric"):
            n = geofit(f"geofit {method} tol {tol} noisy",
                       ["--tol-max", str(tol), "--tol-mode", "noisy", "--method", method])
            occ(n)
    if not args.skip_smooth:
        try:
            sp, w, c = timed(lambda: SmoothBivariateSpline(x, y, zz, kx=3, ky=3))
            nc = len(sp.get_coeffs())
            row("scipy SmoothBivariateSpline", nc, scipy_surface(sp), w, c, "default s")
        except Exception as e:  # noqa: BLE001
            print(f"scipy SmoothBivariateSpline: failed: {e}")
    equal_accuracy(rows)
    if args.json:
        keys = ("method", "control_points", "e_max_pct", "e_rms_pct", "e_avg_pct", "wall_s", "cpu_s", "note")
        with open(args.json, "w") as f:
            json.dump([dict(zip(keys, r)) for r in rows], f, indent=1)

def equal_accuracy(rows):
    """For every peer surface, the cheapest geofit surface (CPU s, one thread) at least as
    accurate on both E_max and E_rms: the time each takes to reach the peer's accuracy."""
    fits = [r for r in rows if r[0].startswith("geofit")]
    print("\n# equal accuracy: the cheapest geofit fit with E_max and E_rms at most the peer's")
    for name, ctrl, emax, erms, _, _, cpu, _ in rows:
        if name.startswith("geofit"):
            continue
        good = [f for f in fits if f[2] <= emax and f[3] <= erms]
        if not good:
            print(f"{name:40s} {ctrl:6d}  E_max {emax:6.3f} E_rms {erms:6.4f} {cpu:6.2f} s  <- no geofit fit")
            continue
        best = min(good, key=lambda f: f[6])
        print(f"{name:40s} {ctrl:6d}  E_max {emax:6.3f} E_rms {erms:6.4f} {cpu:6.2f} s  <- "
              f"{best[0]} {best[1]}: E_max {best[2]:.3f} E_rms {best[3]:.4f} {best[6]:.2f} s "
              f"({cpu / max(best[6], 1e-9):.1f}x)")


if __name__ == "__main__":
    main()
