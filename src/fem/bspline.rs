//! The FEM mesh of a B-spline surface: a structured grid of u and v parameter lines, graded by
//! curvature, optionally trimmed by an inside test.

use super::grading::{equidistribute, intervals, max_curvature, resolve_size};
use super::{quality, FemError, FemMesh, FemOptions, FemSize, MAX_ELEMENTS};
use crate::geom::{Aabb, Point3, Vec3};
use crate::spline::{BSplineSurface, KnotVector, TrimRegion, MAX_DEGREE};

/// The FEM quad mesh of `surface` (see the [module](super) docs). `trim`, when given, trims
/// it: elements whose four corners are all outside the region are dropped, and so are the
/// elements across its outline that are inverted (part of them lies past the data, where the
/// surface extrapolates and folds most often; an inverted element there is a fold the data
/// never held, and leaving it out keeps the mesh valid). A count asks for that
/// many elements inside: the lines are laid out once for the whole domain, then once more with
/// the count scaled by the share of elements the trim kept (a second pass only when it dropped
/// some), so a trimmed mesh is about as fine as the count says, not coarser by the trim.
pub fn mesh_bspline(
    surface: &BSplineSurface,
    options: &FemOptions,
    trim: Option<&TrimRegion>,
) -> Result<FemMesh, FemError> {
    options.validate()?;
    let field = SizeField::sample(surface);
    let grid = Grid::lay_out(surface, &field, options, options.size)?;
    let inside = grid.inside(trim);
    let (kept, total) = grid.quads(inside.as_deref());
    let share = kept.len() as f64 / total.max(1) as f64;
    let (mut grid, mut inside, mut quads) = match options.size {
        FemSize::Count(n) if share > 0.0 && share < 1.0 => {
            let scaled = ((n as f64 / share).round() as usize).min(MAX_ELEMENTS);
            let grid = Grid::lay_out(surface, &field, options, FemSize::Count(scaled))?;
            let inside = grid.inside(trim);
            let (quads, _) = grid.quads(inside.as_deref());
            (grid, inside, quads)
        }
        _ => (grid, inside, kept),
    };
    let (mut nodes, mut normals) = eval_grid(surface, &grid.us, &grid.vs);
    for _ in 0..MEND_ROUNDS {
        if !grid.split_inverted(surface, &nodes, &normals, &quads) {
            break;
        }
        inside = grid.inside(trim);
        quads = grid.quads(inside.as_deref()).0;
        (nodes, normals) = eval_grid(surface, &grid.us, &grid.vs);
    }
    if let Some(inside) = inside {
        quads.retain(|q| {
            q.iter().all(|&c| inside[c as usize])
                || !quality::inverted(q.map(|k| nodes[k as usize]), q.map(|k| normals[k as usize]))
        });
    }
    FemMesh::assemble(nodes, normals, quads)
}

/// Rounds of [`Grid::split_inverted`]. Measured on the B-spline fits (defaults) of nine data
/// and corpus files at 20,000 elements, inverted elements off folds in all (mending only
/// those): 131 without, 113 after one round, 100 after two, 92 after three (bun000,
/// rocker-arm, teapot and homer at 0; spot 24 → 6), 95 after five; what is left (fandisk 60,
/// cow 32) lies beside folds the corner normals do not see, and more rounds only add elements
/// there. Mending also the elements across sharp bends ([`Grid::mendable`]): 105 off folds,
/// bun000 at 10,000 elements 1 inverted instead of 2.
const MEND_ROUNDS: usize = 3;

/// [`Grid::split_inverted`] adds at most one element per this many in each direction and round.
const MEND_SHARE: usize = 40;

/// The u and v lines of a FEM mesh.
struct Grid {
    us: Vec<f64>,
    vs: Vec<f64>,
}

impl Grid {
    /// The lines for `size` over the whole domain, graded by `field`.
    fn lay_out(
        surface: &BSplineSurface,
        field: &SizeField,
        options: &FemOptions,
        size: FemSize,
    ) -> Result<Grid, FemError> {
        let g = options.grading;
        let scale = Aabb::from_points(surface.control_points()).map_or(1.0, |b| b.diagonal());
        let scale = if scale > 0.0 { scale } else { 1.0 };
        let l = resolve_size(size, scale, |l| {
            let (wu, wv) = field.weights(l, g);
            intervals(integral(&field.u, &wu)) as f64 * intervals(integral(&field.v, &wv)) as f64
        })?;
        let (wu, wv) = field.weights(l, g);
        Ok(Grid {
            us: equidistribute(&field.u, &wu, intervals(integral(&field.u, &wu))),
            vs: equidistribute(&field.v, &wv, intervals(integral(&field.v, &wv))),
        })
    }

    /// Which nodes lie inside `trim` (node `(i, j)` at `i * vs.len() + j`); `None` without one.
    fn inside(&self, trim: Option<&TrimRegion>) -> Option<Vec<bool>> {
        trim.map(|r| r.contains_grid(&self.us, &self.vs))
    }

    /// The quads with a node `inside` (all without a mask; node `(i, j)` is
    /// `i * vs.len() + j`), and how many there are in all.
    fn quads(&self, inside: Option<&[bool]>) -> (Vec<[u32; 4]>, usize) {
        let nv = self.vs.len();
        let id = |i: usize, j: usize| (i * nv + j) as u32;
        let total = (self.us.len() - 1) * (nv - 1);
        let mut quads = Vec::with_capacity(total);
        for i in 0..self.us.len() - 1 {
            for j in 0..nv - 1 {
                let q = [id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j + 1)];
                if inside.is_none_or(|k| q.iter().any(|&c| k[c as usize])) {
                    quads.push(q);
                }
            }
        }
        (quads, total)
    }
}

impl Grid {
    /// Whether an inverted element with first node `c` and corner normals `n` can be mended by
    /// smaller elements: the surface does not fold within it. Its corner normals may turn by
    /// more than a right angle where the surface curves sharply (the rim of a scan) without a
    /// fold; then each still turns by less than one from the normal at the element's centre.
    fn mendable(&self, surface: &BSplineSurface, c: usize, n: &[Vec3; 4]) -> bool {
        if !quality::across_fold(n) {
            return true;
        }
        let nv = self.vs.len();
        let (i, j) = (c / nv, c % nv);
        let (u, v) = (
            0.5 * (self.us[i] + self.us[i + 1]),
            0.5 * (self.vs[j] + self.vs[j + 1]),
        );
        let d = surface.derivs(u, v, 1);
        let centre = d.skl[1][0].cross(d.skl[0][1]);
        n.iter().all(|m| m.dot(centre) > 0.0)
    }

    /// Halves, in both directions, the elements of `quads` that invert where the surface does
    /// not fold (see [`quality::inverted_off_fold`]): the intervals holding most of them, each
    /// direction adding at most 1/[`MEND_SHARE`] of the elements (one interval at least).
    /// Returns whether any was split.
    ///
    /// Why: the lines follow the parameterisation, and where it shears hard within one
    /// element the element's corners no longer span a convex quad in the tangent plane; half
    /// the parameter step brings the element back to the surface's tangent plane. A new line
    /// runs through the whole grid, so the mesh stays structured and conforming; the cap keeps
    /// a surface with many such places (beside its folds) near the element count asked for.
    fn split_inverted(
        &mut self,
        surface: &BSplineSurface,
        nodes: &[Point3],
        normals: &[Vec3],
        quads: &[[u32; 4]],
    ) -> bool {
        let nv = self.vs.len();
        // Per interval of each direction: (inverted elements, elements) among `quads`.
        let (mut cu, mut cv) = (vec![(0, 0); self.us.len()], vec![(0, 0); nv]);
        for q in quads {
            let (p, n) = (q.map(|k| nodes[k as usize]), q.map(|k| normals[k as usize]));
            let c = q[0] as usize;
            let bad = usize::from(quality::inverted(p, n) && self.mendable(surface, c, &n));
            for x in [&mut cu[c / nv], &mut cv[c % nv]] {
                *x = (x.0 + bad, x.1 + 1);
            }
        }
        let budget = quads.len() / MEND_SHARE;
        let split = |t: &mut Vec<f64>, count: &[(usize, usize)]| -> bool {
            let mut worst: Vec<usize> = (0..count.len()).filter(|&i| count[i].0 > 0).collect();
            worst.sort_by_key(|&i| (std::cmp::Reverse(count[i].0), i));
            let mut at = vec![false; t.len()];
            let mut added = 0;
            for i in worst {
                if added > 0 && added + count[i].1 > budget {
                    break;
                }
                at[i] = true;
                added += count[i].1;
            }
            let mut out = Vec::with_capacity(t.len() + 1);
            for (i, w) in t.windows(2).enumerate() {
                out.push(w[0]);
                if at[i] {
                    out.push(0.5 * (w[0] + w[1]));
                }
            }
            out.extend(t.last());
            let any = out.len() > t.len();
            *t = out;
            any
        };
        let u = split(&mut self.us, &cu);
        let v = split(&mut self.vs, &cv);
        u || v
    }
}

/// ∫ w dt over the samples (trapezoid rule).
fn integral(t: &[f64], w: &[f64]) -> f64 {
    t.windows(2)
        .zip(w.windows(2))
        .map(|(t, w)| 0.5 * (w[0] + w[1]) * (t[1] - t[0]))
        .sum()
}

/// Speeds |S_u|, |S_v| and curvature on a sample grid of the domain.
struct SizeField {
    u: Vec<f64>,
    v: Vec<f64>,
    /// Per sample (i along u, j along v, at `i * v.len() + j`): (|S_u|, |S_v|, κ).
    at: Vec<(f64, f64, f64)>,
}

impl SizeField {
    /// Samples 8 per knot span in each direction (33 to 257 samples).
    fn sample(s: &BSplineSurface) -> SizeField {
        let ((u0, u1), (v0, v1)) = s.domain();
        let samples = |k: &KnotVector, a: f64, b: f64| {
            let spans = k.num_basis() - k.degree();
            let n = (8 * spans + 1).clamp(33, 257);
            (0..n)
                .map(|i| a + (b - a) * i as f64 / (n - 1) as f64)
                .collect::<Vec<f64>>()
        };
        let (u, v) = (samples(s.knots_u(), u0, u1), samples(s.knots_v(), v0, v1));
        let mut at = Vec::with_capacity(u.len() * v.len());
        for &a in &u {
            for &b in &v {
                let d = s.derivs(a, b, 2).skl;
                let k = max_curvature(d[1][0], d[0][1], d[2][0], d[1][1], d[0][2]);
                at.push((d[1][0].length(), d[0][1].length(), k));
            }
        }
        SizeField { u, v, at }
    }

    /// The elements per unit parameter along u at each u sample and along v at each v sample,
    /// for size `l` and grading `g`: the size part |S_u| / L the largest over the other
    /// direction's samples (no element longer than L), the curvature part |S_u| (1 / h − 1 / L)
    /// their mean, so curvature that runs along a line refines it and a lone spike (a noisy
    /// fit's wrinkle) does not refine the whole line.
    fn weights(&self, l: f64, g: f64) -> (Vec<f64>, Vec<f64>) {
        let (nu, nv) = (self.u.len(), self.v.len());
        let (mut size_u, mut size_v) = (vec![0.0_f64; nu], vec![0.0_f64; nv]);
        let (mut curv_u, mut curv_v) = (vec![0.0_f64; nu], vec![0.0_f64; nv]);
        for (idx, &(su, sv, k)) in self.at.iter().enumerate() {
            let extra = super::grading::density(l, k, g) - 1.0 / l;
            let (i, j) = (idx / nv, idx % nv);
            size_u[i] = size_u[i].max(su / l);
            size_v[j] = size_v[j].max(sv / l);
            curv_u[i] += su * extra / nv as f64;
            curv_v[j] += sv * extra / nu as f64;
        }
        let add = |a: Vec<f64>, b: Vec<f64>| a.iter().zip(&b).map(|(x, y)| x + y).collect();
        (add(size_u, curv_u), add(size_v, curv_v))
    }
}

/// The non-zero basis values and first derivatives at one parameter.
struct Basis {
    first: usize,
    ders: [[f64; MAX_DEGREE + 1]; 2],
}

fn basis(k: &KnotVector, t: f64) -> Basis {
    let span = k.find_span(t);
    let mut ders = [[0.0; MAX_DEGREE + 1]; 2];
    k.basis_ders(span, t, 1, &mut ders);
    Basis {
        first: span - k.degree(),
        ders,
    }
}

/// Positions and unit normals at every (us[i], vs[j]), at `i * vs.len() + j`. The basis of each
/// line is computed once, so a node costs one (p + 1)(q + 1) sum.
fn eval_grid(s: &BSplineSurface, us: &[f64], vs: &[f64]) -> (Vec<Point3>, Vec<Vec3>) {
    let bu: Vec<Basis> = us.iter().map(|&u| basis(s.knots_u(), u)).collect();
    let bv: Vec<Basis> = vs.iter().map(|&v| basis(s.knots_v(), v)).collect();
    let (p, q) = (s.knots_u().degree(), s.knots_v().degree());
    let nv = s.num_control().1;
    let (ctrl, weights) = (s.control_points(), s.weights());
    let mut nodes = Vec::with_capacity(us.len() * vs.len());
    let mut normals = Vec::with_capacity(us.len() * vs.len());
    for a in &bu {
        for b in &bv {
            // Homogeneous sums (w = 1 without weights): value, ∂u and ∂v of Σ w P and of Σ w.
            let (mut s0, mut su, mut sv) = (Vec3::ZERO, Vec3::ZERO, Vec3::ZERO);
            let (mut w0, mut wu, mut wv) = (0.0, 0.0, 0.0);
            for r in 0..=p {
                let row = (a.first + r) * nv + b.first;
                let (mut c0, mut cv, mut cw0, mut cwv) = (Vec3::ZERO, Vec3::ZERO, 0.0, 0.0);
                for t in 0..=q {
                    let w = weights.map_or(1.0, |w| w[row + t]);
                    let wp = ctrl[row + t] * w;
                    c0 += b.ders[0][t] * wp;
                    cv += b.ders[1][t] * wp;
                    cw0 += b.ders[0][t] * w;
                    cwv += b.ders[1][t] * w;
                }
                let (n0, n1) = (a.ders[0][r], a.ders[1][r]);
                s0 += n0 * c0;
                su += n1 * c0;
                sv += n0 * cv;
                w0 += n0 * cw0;
                wu += n1 * cw0;
                wv += n0 * cwv;
            }
            let point = s0 / w0;
            let (du, dv) = ((su - wu * point) / w0, (sv - wv * point) / w0);
            nodes.push(point);
            normals.push(du.cross(dv).normalize_or_zero());
        }
    }
    (nodes, normals)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A bicubic surface with a 5 × 5 control grid at `f(s, t)`, s and t in [−1, 1].
    fn surface(f: impl Fn(f64, f64) -> Point3) -> BSplineSurface {
        let k = || KnotVector::clamped_uniform(3, 5).unwrap();
        let at = |i: usize| -1.0 + 0.5 * i as f64;
        let ctrl = (0..5)
            .flat_map(|i| (0..5).map(move |j| (at(i), at(j))))
            .map(|(s, t)| f(s, t))
            .collect();
        BSplineSurface::try_new(k(), k(), ctrl).unwrap()
    }

    /// `mendable` for the one element over the whole domain.
    fn one_element_mendable(s: &BSplineSurface) -> bool {
        let grid = Grid {
            us: vec![0.0, 1.0],
            vs: vec![0.0, 1.0],
        };
        let (_, normals) = eval_grid(s, &grid.us, &grid.vs);
        let n = [0, 2, 3, 1].map(|k| normals[k]);
        grid.mendable(s, 0, &n)
    }

    #[test]
    fn inverted_elements_across_the_trim_outline_are_dropped() {
        // The sheet of the test below that runs out along x and back, folded at u = 1/2,
        // trimmed to u < 1/2: the elements across the outline hold the fold (6 of them invert
        // when kept).
        let folded = surface(|s, t| Point3::new(1.0 - s * s, t, 0.0));
        let options = FemOptions::default().with_count(400).with_grading(0.0);
        let whole = mesh_bspline(&folded, &options, None).unwrap();
        assert!(whole.quality().inverted > 0, "{:?}", whole.quality());
        let outline = vec![[0.0, 0.0], [0.5, 0.0], [0.5, 1.0], [0.0, 1.0]];
        let region = TrimRegion::try_new(outline, Vec::new()).unwrap();
        let trimmed = mesh_bspline(&folded, &options, Some(&region)).unwrap();
        let q = trimmed.quality();
        assert_eq!(q.inverted, 0, "{q:?}");
        assert!(q.elements > 150, "{q:?}");
    }

    #[test]
    fn sharp_bends_are_mendable_and_folds_are_not() {
        // A plane: no fold.
        assert!(one_element_mendable(&surface(|s, t| Point3::new(
            s, t, 0.0
        ))));
        // A cap of the unit sphere, ±70° of longitude and latitude: normals at opposite corners
        // point against each other, and each is within a right angle of the centre's.
        let cap = surface(|s, t| {
            let (a, b) = (1.2 * s, 1.2 * t);
            Point3::new(a.cos() * b.cos(), a.sin() * b.cos(), b.sin())
        });
        assert!(one_element_mendable(&cap));
        // A hairpin bend, out along x and back 0.2 above: the normal turns by 180° through
        // −x, so the surface bends without folding.
        let hairpin = surface(|s, t| Point3::new(1.0 - s * s, t, 0.1 * s));
        assert!(one_element_mendable(&hairpin));
        // The same flattened into the plane: a fold, the normal +z on the way out, −z on the
        // way back and zero at the turn in the middle.
        let folded = surface(|s, t| Point3::new(1.0 - s * s, t, 0.0));
        assert!(!one_element_mendable(&folded));
    }
}
