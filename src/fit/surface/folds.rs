//! Folds of a least-squares surface, and the per-patch stiffness that removes them.
//!
//! Why: a patch that holds a few points along a line (the rim of a scan, the edge of a hole)
//! is pinned by the data across that line only, and the small thin-plate weight that suits the
//! dense parts lets it buckle: the surface's normal turns over between neighbouring samples.
//! On bun000.ply at the defaults the fitted surface folded in about 1 % of its area, mostly
//! beside the data, and a FEM mesh on it had 51 inverted elements of 20,000. A larger global β2
//! removes the folds but costs control points everywhere (1e-8: +19 % on bun000); stiffening
//! only the folded patches costs nothing where the surface is regular.

use super::patches::PatchGrid;
use crate::geom::Vec3;
use crate::spline::{BSplineSurface, MAX_DEGREE};

/// The weight factor of a stiffened patch. Measured on bun000.ply (FEM mesh of 20,000
/// elements on the fit): 512 left one inverted element, 4,096 none, 32,768 gave the same
/// surface as 4,096; in thin-plate terms 4,096 × the default β2 is about the global 1e-8 that
/// also removed every fold.
pub(crate) const STIFF: f64 = 4096.0;

/// What each further hold of a straying patch multiplies its factor by, from [`STIFF`] up to
/// [`HOLD_CAP`].
const HOLD_STEP: f64 = 8.0;

/// The largest factor a straying patch is held with.
const HOLD_CAP: f64 = STIFF * 4096.0;

/// What one step divides the stiffness of earlier steps by. Measured on bun000.ply: kept at
/// full weight for the rest of the fit, the stiffening pinned patches that folded only under
/// the first projection's parameters (a fixed 1,600-point grid ended at E_max 2.31 %, 0.92 %
/// without the guard); dropped after each step (nothing kept), the fit folded afresh in every
/// step and the grid ended at 1.85 %; divided by 8 per step it ends at 0.98 %, and the fixed
/// 6,400 grid at 0.68 % (1.67 % without the guard), with 1 inverted element in the FEM mesh
/// of 20,000 of the default adaptive fit (0 kept, 0 dropped; 51 without the guard).
const RELAX: f64 = 8.0;

/// Samples per span and direction in the fold check (its ends and two inner points). On
/// bun000.ply's FEM mesh at `--fem-size 0.01` two samples missed folds that left 2 inverted
/// elements; three and four left none.
const SAMPLES_PER_SPAN: usize = 3;

/// The stiffness factor of every patch, kept across knot insertions (a split patch's children
/// inherit its factor) and relaxed step by step.
#[derive(Clone, Debug, Default)]
pub(crate) struct Stiffness {
    /// Cell boundaries along u and v of the grid the factors belong to.
    u: Vec<f64>,
    v: Vec<f64>,
    /// Row-major over (u cell, v cell); empty while every factor is 1.
    factor: Vec<f64>,
    /// The factor each cell keeps through [`Stiffness::relax`], laid out as `factor`: set
    /// where the surface strayed from the data ([`Stiffness::hold_strays`]).
    floor: Vec<f64>,
}

impl Stiffness {
    /// Divides every factor by [`RELAX`], down to 1: called before each step's solve, so a
    /// patch stays stiff only while it keeps folding.
    pub(crate) fn relax(&mut self) {
        for (i, f) in self.factor.iter_mut().enumerate() {
            let floor = self.floor.get(i).copied().unwrap_or(1.0);
            *f = (*f / RELAX).max(floor).max(1.0);
        }
    }

    /// The factor of every patch of `surface`'s current grid, flat as [`PatchGrid::patch`].
    pub(crate) fn factors(&self, surface: &BSplineSurface, grid: &PatchGrid) -> Vec<f64> {
        self.on_grid(&self.factor, surface, grid)
    }

    /// `values` (one per stored cell, or none: all 1) on the patches of `surface`'s grid.
    fn on_grid(&self, values: &[f64], surface: &BSplineSurface, grid: &PatchGrid) -> Vec<f64> {
        let (cu, cv) = (centres(surface, grid, true), centres(surface, grid, false));
        if values.is_empty() {
            return vec![1.0; cu.len() * cv.len()];
        }
        let nv = self.v.len() - 1;
        let cell = |b: &[f64], t: f64| b.partition_point(|&x| x <= t).clamp(1, b.len() - 1) - 1;
        cu.iter()
            .flat_map(|&u| {
                let i = cell(&self.u, u);
                cv.iter().map(move |&v| values[i * nv + cell(&self.v, v)])
            })
            .collect()
    }

    /// Stores `factor` and `floor` (on `surface`'s current grid) as the new state.
    fn store(
        &mut self,
        surface: &BSplineSurface,
        grid: &PatchGrid,
        factor: Vec<f64>,
        floor: Vec<f64>,
    ) {
        self.u = boundaries(surface, grid, true);
        self.v = boundaries(surface, grid, false);
        self.factor = factor;
        self.floor = floor;
    }

    /// Stiffens, for the rest of the fit, the patches of `surface` that hold a parameter of
    /// `strays` (where the surface lies beyond the surface → data bound) and their eight
    /// neighbours: [`STIFF`] the first time, [`HOLD_STEP`] times more each time after, up to
    /// [`HOLD_CAP`]. Returns how many patches were raised: 0 means a new solve would change
    /// nothing there. As with folds, only patches with points of the fit (`held`: points per
    /// patch) in them or beside them are held: elsewhere the smoothing energy alone shapes the
    /// surface, whatever its weight (the folded sheets of a closed object fitted as one sheet).
    ///
    /// Why held and not relaxed like a fold: a patch strays where few points pin it (beside
    /// the rim of a scan, over a sparse strip); the smoothing weight that suits the dense parts
    /// lets it curl away, and relaxed again it curls back. Why escalating: one hold at
    /// [`STIFF`] took the page's range-scan sample (bun000-points.xyz, E_max 0.5 %) from
    /// E_back 1.32 to 1.26 % against a bound of 1 %; three more took it to 0.85 %.
    pub(crate) fn hold_strays(
        &mut self,
        surface: &BSplineSurface,
        grid: &PatchGrid,
        held: &[usize],
        strays: &[[f64; 2]],
    ) -> usize {
        let (nu, nv) = (grid.u.len(), grid.v.len());
        let near_data = |i: usize| neighbours(i, nu, nv).any(|k| held[k] > 0);
        let mut factor = self.factors(surface, grid);
        let mut floor = self.on_grid(&self.floor, surface, grid);
        let mut raised = 0;
        let mut seen = vec![false; factor.len()];
        for &[u, v] in strays {
            let at = grid.patch(surface, u, v);
            if !near_data(at) {
                continue;
            }
            for k in neighbours(at, nu, nv) {
                if seen[k] || floor[k] >= HOLD_CAP {
                    continue;
                }
                seen[k] = true;
                raised += 1;
                floor[k] = (floor[k] * HOLD_STEP).clamp(STIFF, HOLD_CAP);
                factor[k] = factor[k].max(floor[k]);
            }
        }
        if raised > 0 {
            self.store(surface, grid, factor, floor);
        }
        raised
    }

    /// Stiffens every folded patch of `surface` that has points of the fit in it or beside it
    /// (`held`: points per patch), and its eight neighbours. Returns how many folded patches
    /// were not stiff yet: 0 means a new solve would change nothing. A patch that folds while
    /// stiff folds with its data (a turn of more than a right angle within half a span) and
    /// is left so.
    ///
    /// Why not the others: where no point is near, the surface is the smoothing energy's
    /// minimiser alone, whatever its weight, so raising it changes nothing there. `c0` are the
    /// crease knot lines ([u, v]), where the normal may turn at once (see [`folded_patches`]).
    pub(crate) fn stiffen_folds(
        &mut self,
        surface: &BSplineSurface,
        grid: &PatchGrid,
        held: &[usize],
        c0: &[Vec<f64>; 2],
    ) -> usize {
        let (nu, nv) = (grid.u.len(), grid.v.len());
        let near_data = |i: usize| neighbours(i, nu, nv).any(|k| held[k] > 0);
        let mut folded = folded_patches(surface, grid, c0);
        for (i, f) in folded.iter_mut().enumerate() {
            *f = *f && near_data(i);
        }
        let mut factor = self.factors(surface, grid);
        let raisable = (0..factor.len())
            .filter(|&i| folded[i] && factor[i] < STIFF)
            .count();
        if raisable == 0 {
            return 0;
        }
        for (i, _) in folded.iter().enumerate().filter(|f| *f.1) {
            for k in neighbours(i, nu, nv) {
                factor[k] = STIFF;
            }
        }
        let floor = if self.floor.is_empty() {
            Vec::new()
        } else {
            self.on_grid(&self.floor, surface, grid)
        };
        self.store(surface, grid, factor, floor);
        raisable
    }
}

/// Patch `i` of an `nu` × `nv` grid and its (up to eight) neighbours.
fn neighbours(i: usize, nu: usize, nv: usize) -> impl Iterator<Item = usize> {
    let (a, b) = (i / nv, i % nv);
    (a.saturating_sub(1)..(a + 2).min(nu))
        .flat_map(move |x| (b.saturating_sub(1)..(b + 2).min(nv)).map(move |y| x * nv + y))
}

/// The distinct knots bounding the cells of one direction.
fn boundaries(surface: &BSplineSurface, grid: &PatchGrid, along_u: bool) -> Vec<f64> {
    let (kv, spans) = if along_u {
        (surface.knots_u(), &grid.u)
    } else {
        (surface.knots_v(), &grid.v)
    };
    let k = kv.knots();
    let mut b: Vec<f64> = (0..spans.len()).map(|c| k[spans.knot_index(c)]).collect();
    b.push(k[spans.knot_index(spans.len() - 1) + 1]);
    b
}

/// The middle of every cell of one direction.
fn centres(surface: &BSplineSurface, grid: &PatchGrid, along_u: bool) -> Vec<f64> {
    boundaries(surface, grid, along_u)
        .windows(2)
        .map(|w| 0.5 * (w[0] + w[1]))
        .collect()
}

/// Which patches fold: the normals S_u × S_v at two neighbouring samples (the corners and
/// middles of the spans) point against each other, or one of them vanishes. Two samples on
/// either side of (or on) a crease knot line of `c0` ([u values, v values]) are not compared:
/// there the surface is C0 on purpose, and a crease sharper than a right angle is not a fold.
pub(crate) fn folded_patches(
    surface: &BSplineSurface,
    grid: &PatchGrid,
    c0: &[Vec<f64>; 2],
) -> Vec<bool> {
    let lines = |along_u: bool| -> Vec<f64> {
        let b = boundaries(surface, grid, along_u);
        let mut t: Vec<f64> = b
            .windows(2)
            .flat_map(|w| {
                (0..SAMPLES_PER_SPAN)
                    .map(move |k| w[0] + (w[1] - w[0]) * k as f64 / SAMPLES_PER_SPAN as f64)
            })
            .collect();
        t.extend(b.last());
        t
    };
    let (us, vs) = (lines(true), lines(false));
    let normals = grid_normals(surface, &us, &vs);
    let (nu, nv, m) = (grid.u.len(), grid.v.len(), SAMPLES_PER_SPAN);
    let n = |i: usize, j: usize| normals[i * vs.len() + j];
    let mut folded = vec![false; nu * nv];
    let mut mark =
        |i: usize, j: usize| folded[(i / m).min(nu - 1) * nv + (j / m).min(nv - 1)] = true;
    let smooth = |t: &[f64], k: usize, lines: &[f64]| {
        k + 1 < t.len() && !lines.iter().any(|&c| t[k] <= c && c <= t[k + 1])
    };
    let (smooth_u, smooth_v): (Vec<bool>, Vec<bool>) = (
        (0..us.len()).map(|i| smooth(&us, i, &c0[0])).collect(),
        (0..vs.len()).map(|j| smooth(&vs, j, &c0[1])).collect(),
    );
    for i in 0..us.len() {
        for j in 0..vs.len() {
            let a = n(i, j);
            let turns = |b: Vec3| a.dot(b) <= 0.0;
            if (smooth_u[i] && turns(n(i + 1, j))) || (smooth_v[j] && turns(n(i, j + 1))) {
                mark(i, j);
            }
        }
    }
    folded
}

/// S_u × S_v at every (u, v) of `us` × `vs`, row-major in u.
///
/// Evaluated separably: the u-basis of each u line is applied to the control columns once
/// (S and S_u of the isocurve's control points), then each sample takes the v-basis of its
/// v line; about 40 times cheaper than evaluating every sample's derivatives on its own,
/// which was the fold check's whole cost. A rational surface is evaluated point by point.
fn grid_normals(surface: &BSplineSurface, us: &[f64], vs: &[f64]) -> Vec<Vec3> {
    if surface.weights().is_some() {
        return us
            .iter()
            .flat_map(|&u| {
                vs.iter().map(move |&v| {
                    let d = surface.derivs(u, v, 1);
                    d.skl[1][0].cross(d.skl[0][1])
                })
            })
            .collect();
    }
    let (ku, kv) = (surface.knots_u(), surface.knots_v());
    let (p, q) = (ku.degree(), kv.degree());
    let nv = surface.num_control().1;
    let ctrl = surface.control_points();
    let v_basis: Vec<(usize, [[f64; MAX_DEGREE + 1]; 2])> = vs
        .iter()
        .map(|&v| {
            let span = kv.find_span(v);
            let mut d = [[0.0; MAX_DEGREE + 1]; 2];
            kv.basis_ders(span, v, 1, &mut d);
            (span - q, d)
        })
        .collect();
    let mut out = Vec::with_capacity(us.len() * vs.len());
    // The isocurve at u: its control points (row `0`) and their u-derivatives (row `1`).
    let mut iso = [vec![Vec3::ZERO; nv], vec![Vec3::ZERO; nv]];
    for &u in us {
        let span = ku.find_span(u);
        let mut d = [[0.0; MAX_DEGREE + 1]; 2];
        ku.basis_ders(span, u, 1, &mut d);
        let first = span - p;
        for j in 0..nv {
            let (mut s, mut su) = (Vec3::ZERO, Vec3::ZERO);
            for r in 0..=p {
                let c = ctrl[(first + r) * nv + j];
                s += d[0][r] * c;
                su += d[1][r] * c;
            }
            iso[0][j] = s;
            iso[1][j] = su;
        }
        for (first_v, dv) in &v_basis {
            let (mut su, mut sv) = (Vec3::ZERO, Vec3::ZERO);
            for s in 0..=q {
                su += dv[0][s] * iso[1][first_v + s];
                sv += dv[1][s] * iso[0][first_v + s];
            }
            out.push(su.cross(sv));
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geom::Point3;
    use crate::spline::KnotVector;

    /// The plane z = 0 over [0, 1]², `n` × `n` cubic control points at their Greville
    /// abscissae, with the x of the control points in column `fold` (rows 2..5) moved back past
    /// the previous column when `fold` is given: the surface runs back over itself there.
    fn plane(n: usize, fold: Option<usize>) -> BSplineSurface {
        let kv = KnotVector::clamped_uniform(3, n).unwrap();
        let k = kv.knots().to_vec();
        let g = |i: usize| k[i + 1..=i + 3].iter().sum::<f64>() / 3.0;
        let control = (0..n * n)
            .map(|idx| {
                let (i, j) = (idx / n, idx % n);
                let x = match fold {
                    Some(f) if i == f && (2..5).contains(&j) => g(f - 2),
                    _ => g(i),
                };
                Point3::new(x, g(j), 0.0)
            })
            .collect();
        BSplineSurface::try_new(kv.clone(), kv, control).unwrap()
    }

    #[test]
    fn a_plane_has_no_fold_and_a_surface_running_back_over_itself_has() {
        let flat = plane(8, None);
        let grid = PatchGrid::of(&flat);
        assert!(folded_patches(&flat, &grid, &NONE).iter().all(|f| !f));
        let folded = plane(8, Some(4));
        let marks = folded_patches(&folded, &PatchGrid::of(&folded), &NONE);
        let count = marks.iter().filter(|f| **f).count();
        assert!(
            count > 0 && count < marks.len() / 4,
            "{count} of {}",
            marks.len()
        );
    }

    /// No crease knot lines.
    const NONE: [Vec<f64>; 2] = [Vec::new(), Vec::new()];

    #[test]
    fn a_crease_knot_line_sharper_than_a_right_angle_is_not_a_fold() {
        // z = 3 |x − 1/2| with a C0 knot line at u = 1/2: the normals on its two sides are
        // 143° apart. Exact, since the spline reproduces each linear side.
        let mut s = plane(8, None);
        for _ in 0..3 {
            s.insert_knot_u(0.5).unwrap();
        }
        let control: Vec<Point3> = s
            .control_points()
            .iter()
            .map(|c| Point3::new(c.x, c.y, 3.0 * (c.x - 0.5).abs()))
            .collect();
        s.set_control_points(&control).unwrap();
        let grid = PatchGrid::of(&s);
        assert!(folded_patches(&s, &grid, &NONE).iter().any(|f| *f));
        let c0 = [vec![0.5], Vec::new()];
        assert!(folded_patches(&s, &grid, &c0).iter().all(|f| !f));
    }

    #[test]
    fn grid_normals_match_pointwise_derivatives() {
        let mut s = plane(8, Some(4));
        s.insert_knot_u(0.37).unwrap();
        let control: Vec<Point3> = s
            .control_points()
            .iter()
            .map(|c| *c + Point3::new(0.0, 0.0, (3.0 * c.x).sin() * c.y))
            .collect();
        s.set_control_points(&control).unwrap();
        let (us, vs) = ([0.0, 0.2, 0.37, 0.5, 1.0], [0.0, 0.1, 0.55, 1.0]);
        let n = grid_normals(&s, &us, &vs);
        for (i, &u) in us.iter().enumerate() {
            for (j, &v) in vs.iter().enumerate() {
                let d = s.derivs(u, v, 1);
                let want = d.skl[1][0].cross(d.skl[0][1]);
                assert!((n[i * vs.len() + j] - want).length() < 1e-12, "{u} {v}");
            }
        }
    }

    #[test]
    fn strays_near_data_are_held_through_relaxing_and_escalate_to_the_cap() {
        let s = plane(8, None);
        let grid = PatchGrid::of(&s);
        let n = grid.len();
        let mut stiffness = Stiffness::default();
        let stray = [[0.5, 0.5]];
        // No points anywhere near: nothing to hold.
        assert_eq!(stiffness.hold_strays(&s, &grid, &vec![0; n], &stray), 0);
        let held = vec![1; n];
        assert_eq!(stiffness.hold_strays(&s, &grid, &held, &stray), 9);
        let at = grid.patch(&s, 0.5, 0.5);
        let first = stiffness.factors(&s, &grid);
        assert_eq!(first[at], STIFF);
        assert_eq!(first.iter().filter(|f| **f == STIFF).count(), 9);
        // Relaxing does not let a held patch go below its hold.
        stiffness.relax();
        assert_eq!(stiffness.factors(&s, &grid), first);
        // Each further hold raises it, up to the cap; then nothing is left to raise.
        let mut rounds = 1;
        while stiffness.hold_strays(&s, &grid, &held, &stray) > 0 {
            rounds += 1;
            assert!(rounds < 16, "the hold must end at its cap");
        }
        assert_eq!(stiffness.factors(&s, &grid)[at], HOLD_CAP);
        assert_eq!(rounds as f64, 1.0 + (HOLD_CAP / STIFF).log(HOLD_STEP));
    }

    #[test]
    fn folds_far_from_data_are_not_stiffened_and_split_patches_inherit() {
        let mut s = plane(8, Some(4));
        let grid = PatchGrid::of(&s);
        let mut stiffness = Stiffness::default();
        assert_eq!(
            stiffness.stiffen_folds(&s, &grid, &vec![0; grid.len()], &NONE),
            0
        );
        assert!(stiffness.factors(&s, &grid).iter().all(|f| *f == 1.0));
        let raised = stiffness.stiffen_folds(&s, &grid, &vec![1; grid.len()], &NONE);
        assert!(raised > 0);
        let before = stiffness.factors(&s, &grid);
        assert!(before.contains(&STIFF) && before.contains(&1.0));
        // Stiff already: a second check raises nothing; once relaxed, it raises them again.
        assert_eq!(
            stiffness.stiffen_folds(&s, &grid, &vec![1; grid.len()], &NONE),
            0
        );
        stiffness.relax();
        let relaxed = stiffness.factors(&s, &grid);
        for (r, b) in relaxed.iter().zip(&before) {
            assert_eq!(*r, (b / RELAX).max(1.0));
        }
        assert_eq!(
            stiffness.stiffen_folds(&s, &grid, &vec![1; grid.len()], &NONE),
            raised
        );
        assert_eq!(stiffness.factors(&s, &grid), before);
        // Splitting every u span in two: each child has its parent's factor.
        let mids: Vec<f64> = boundaries(&s, &grid, true)
            .windows(2)
            .map(|w| 0.5 * (w[0] + w[1]))
            .collect();
        for u in mids {
            s.insert_knot_u(u).unwrap();
        }
        let fine = PatchGrid::of(&s);
        let after = stiffness.factors(&s, &fine);
        let nv = grid.v.len();
        for (i, f) in after.iter().enumerate() {
            let (cu, cv) = (i / nv, i % nv);
            assert_eq!(*f, before[(cu / 2) * nv + cv], "patch {cu}, {cv}");
        }
    }
}
