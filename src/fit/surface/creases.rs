//! Crease lines of the data as C0 knot lines of a B-spline surface (issue: sharp features,
//! seed 004's multiple knots at second-derivative jumps, carried from curves to surfaces).
//!
//! A tensor-product surface can only be C0 along whole parameter lines: a knot of multiplicity
//! p at u = c makes every point of the line u = c a possible kink. So a crease of the data is
//! representable exactly when it runs along such a line in the fit's parameterisation: its
//! points' u lie within the tolerance's reach of one value c (measured in model units, |Δu| ×
//! |S_u|). Those lines get the multiple knot before the first solve; the others are reported
//! and left to the adaptive splitting, which buys them back with control points as before.
//! Away from the crease the kink is free, not forced: the data on both sides pin the surface,
//! and the smoothing energies, integrated span by span, do not see the C0 line.

use crate::geom::{quantile, Point3};
use crate::mesh::FeatureLine;
use crate::spline::BSplineSurface;
use serde::Serialize;

/// One crease line of the data made a knot line of the surface.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct CreaseKnot {
    /// Indices into the detected lines ([`crate::mesh::Features::lines`]) that the knot line
    /// represents (two lines within the tolerance of one parameter share it).
    pub lines: Vec<usize>,
    /// The parameter direction the knot is in: "u" (the crease runs along v) or "v".
    pub direction: &'static str,
    /// The knot's value.
    pub at: f64,
}

/// Which crease lines a B-spline surface fit made knot lines, and how many it could not.
#[derive(Clone, Debug, Default, PartialEq, Serialize)]
pub struct CreaseKnots {
    /// The knot lines inserted, each with multiplicity = the degree (C0).
    pub knots: Vec<CreaseKnot>,
    /// Crease lines that do not run along a parameter line (or lie on the domain's border).
    pub unaligned: usize,
}

impl CreaseKnots {
    /// One line for people: "2 of 3 crease lines as C0 knot lines (u = 0.5000, v = 0.2500)".
    pub fn summary(&self) -> String {
        let represented: usize = self.knots.iter().map(|k| k.lines.len()).sum();
        let at: Vec<String> = self
            .knots
            .iter()
            .map(|k| format!("{} = {:.4}", k.direction, k.at))
            .collect();
        let list = if at.is_empty() {
            String::new()
        } else {
            format!(" ({})", at.join(", "))
        };
        format!(
            "{represented} of {} crease lines as C0 knot lines{list}",
            represented + self.unaligned
        )
    }
}

/// Where the crease `lines` (vertex chains; vertex = data point index) run along a parameter
/// line of `surface` at the points' parameters `uv` (`points`: their positions), within `tol`
/// (model units), with data on both sides ([`two_sided`]): the knot lines to insert, merged
/// where two lie within `tol` of each other.
pub(crate) fn find_crease_knots(
    surface: &BSplineSurface,
    lines: &[FeatureLine],
    (uv, points): (&[[f64; 2]], &[Point3]),
    tol: f64,
) -> CreaseKnots {
    let mut out = CreaseKnots::default();
    let ((u0, u1), (v0, v1)) = surface.domain();
    for (index, line) in lines.iter().enumerate() {
        let on_line: Vec<([f64; 2], Point3)> = line
            .vertices
            .iter()
            .filter_map(|&i| Some((*uv.get(i as usize)?, *points.get(i as usize)?)))
            .collect();
        let params: Vec<[f64; 2]> = on_line.iter().map(|x| x.0).collect();
        let along = [(0, "u", (u0, u1)), (1, "v", (v0, v1))]
            .into_iter()
            .filter_map(|(d, name, (lo, hi))| {
                let c = lower_median(&params.iter().map(|p| p[d]).collect::<Vec<_>>())?;
                let inside = c > lo + 1e-9 * (hi - lo) && c < hi - 1e-9 * (hi - lo);
                let off = reach(surface, &params, d, c);
                (inside && off <= tol && two_sided(surface, &on_line, (uv, points), d, c, tol))
                    .then_some((off, d, name, c))
            })
            .min_by(|a, b| a.0.total_cmp(&b.0));
        let Some((_, d, direction, at)) = along else {
            out.unaligned += 1;
            continue;
        };
        let apart = |k: &CreaseKnot| {
            let mid = [0.5 * (u0 + u1), 0.5 * (v0 + v1)];
            let mut p = mid;
            p[d] = k.at;
            reach(surface, &[p], d, at)
        };
        match out
            .knots
            .iter_mut()
            .find(|k| k.direction == direction && apart(k) <= tol)
        {
            Some(k) => k.lines.push(index),
            None => out.knots.push(CreaseKnot {
                lines: vec![index],
                direction,
                at,
            }),
        }
    }
    out
}

/// Band on each side of a candidate knot line, in tolerances, in which [`two_sided`] counts
/// the points.
const SIDE_BAND: f64 = 20.0;

/// A side holding less than this share of the other's points in the band, or fewer than
/// [`MIN_SIDE`] points, is empty.
const SIDE_SHARE: f64 = 0.25;

/// See [`SIDE_SHARE`].
const MIN_SIDE: usize = 3;

/// Whether the crease (`line`, its points' parameters and positions) runs at least
/// [`SIDE_BAND`] tolerances along the line t_d = c and the data lie on both sides of it:
/// within [`SIDE_BAND`] tolerances of it in (u, v) and in
/// space (so the other layer of a closed surface's projection does not count), over the
/// crease's extent in the other direction, each side holds at least [`SIDE_SHARE`] of the
/// other's points.
///
/// Why: where a closed mesh's projection turns from its front to its back (the outline of the
/// parameter domain) the detector sees a crease that runs along a parameter line, but the data
/// beside it all lie on one side of it in (u, v); a C0 line there only frees the surface's
/// rim. Of fandisk's 34 lines two ran along such a line, one at u = 0.001; with them its fit
/// took 39,820 control points instead of 35,904.
fn two_sided(
    surface: &BSplineSurface,
    line: &[([f64; 2], Point3)],
    data: (&[[f64; 2]], &[Point3]),
    d: usize,
    c: f64,
    tol: f64,
) -> bool {
    let e = 1 - d;
    let mut along: Vec<(f64, Point3)> = line.iter().map(|(t, p)| (t[e], *p)).collect();
    along.sort_by(|a, b| a.0.total_cmp(&b.0));
    let (lo, hi) = match (along.first(), along.last()) {
        (Some(a), Some(b)) => (a.0, b.0),
        _ => return false,
    };
    // The crease point nearest to t_e = x in space, of the two around it along the line.
    let near = |x: f64, p: Point3| {
        let k = along.partition_point(|a| a.0 < x);
        [k.saturating_sub(1), k.min(along.len() - 1)]
            .iter()
            .map(|&i| (along[i].1 - p).length())
            .fold(f64::INFINITY, f64::min)
    };
    let mut at = [0.5, 0.5];
    at[d] = c;
    at[e] = 0.5 * (lo + hi);
    let der = surface.derivs(at[0], at[1], 1);
    let (su, sv) = (der.skl[1][0].length(), der.skl[0][1].length());
    let (speed, along_speed) = if d == 0 { (su, sv) } else { (sv, su) };
    // A line shorter than the band (two corners an edge apart) runs along any direction.
    if speed.is_nan() || speed <= 0.0 || (hi - lo) * along_speed < SIDE_BAND * tol {
        return false;
    }
    let (band, gap) = (SIDE_BAND * tol / speed, tol / speed);
    let (mut below, mut above) = (0usize, 0usize);
    let (uv, points) = data;
    for (t, p) in uv.iter().zip(points) {
        let off = t[d] - c;
        if t[e] < lo || t[e] > hi || off.abs() <= gap || off.abs() >= band {
            continue;
        }
        if near(t[e], *p) > 2.0 * SIDE_BAND * tol {
            continue;
        }
        if off < 0.0 {
            below += 1;
        } else {
            above += 1;
        }
    }
    let (few, many) = (below.min(above) as f64, below.max(above) as f64);
    few >= MIN_SIDE as f64 && few >= SIDE_SHARE * many
}

/// How far, in model units, the points at `params` lie from the parameter line where
/// coordinate `d` equals `c`: the largest |t_d − c| × |∂S/∂t_d| over them.
fn reach(surface: &BSplineSurface, params: &[[f64; 2]], d: usize, c: f64) -> f64 {
    params
        .iter()
        .map(|p| {
            let der = surface.derivs(p[0], p[1], 1);
            let speed = if d == 0 { der.skl[1][0] } else { der.skl[0][1] }.length();
            (p[d] - c).abs() * speed
        })
        .fold(0.0, f64::max)
}

/// The median of `values` (the lower one of an even count); `None` when empty or not finite.
fn lower_median(values: &[f64]) -> Option<f64> {
    let finite = !values.is_empty() && values.iter().all(|x| x.is_finite());
    finite.then(|| quantile(values, 0.5))
}

/// Inserts every knot of `knots` into `surface` until it has multiplicity = the degree there
/// (C0). Returns the knot values per direction ([u, v]), for the fold check to leave alone.
pub(crate) fn insert_crease_knots(
    surface: &mut BSplineSurface,
    knots: &CreaseKnots,
) -> [Vec<f64>; 2] {
    let (mut us, mut vs) = (Vec::new(), Vec::new());
    for k in &knots.knots {
        let along_u = k.direction == "u";
        let kv = if along_u {
            surface.knots_u()
        } else {
            surface.knots_v()
        };
        let have = kv.knots().iter().filter(|&&x| x == k.at).count();
        for _ in have..kv.degree() {
            let inserted = if along_u {
                surface.insert_knot_u(k.at)
            } else {
                surface.insert_knot_v(k.at)
            };
            if inserted.is_err() {
                break;
            }
        }
        if along_u { &mut us } else { &mut vs }.push(k.at);
    }
    [us, vs]
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::spline::KnotVector;

    /// The square [0, 2] × [0, 1] as a bicubic surface over [0, 1]² (|S_u| = 2, |S_v| = 1).
    fn plane() -> BSplineSurface {
        let k = || KnotVector::clamped_uniform(3, 4).unwrap();
        let ctrl = (0..16)
            .map(|i| Point3::new(2.0 * (i / 4) as f64 / 3.0, (i % 4) as f64 / 3.0, 0.0))
            .collect();
        BSplineSurface::try_new(k(), k(), ctrl).unwrap()
    }

    fn line(vertices: std::ops::Range<u32>) -> FeatureLine {
        FeatureLine {
            vertices: vertices.collect(),
            closed: false,
            length: 1.0,
        }
    }

    /// Points of a 41 × 21 grid over the u range `u`, on `s`, lifted by `lift` in z.
    fn grid(s: &BSplineSurface, u: (f64, f64), lift: f64) -> Vec<([f64; 2], Point3)> {
        (0..41)
            .flat_map(|i| (0..21).map(move |j| (i, j)))
            .map(|(i, j)| {
                let t = [u.0 + (u.1 - u.0) * i as f64 / 40.0, j as f64 / 20.0];
                (t, s.eval(t[0], t[1]) + Point3::new(0.0, 0.0, lift))
            })
            .collect()
    }

    /// Lines made of the parameters `lines` (each after the data `data`, on `s`).
    fn with_lines(
        s: &BSplineSurface,
        mut data: Vec<([f64; 2], Point3)>,
        lines: &[Vec<[f64; 2]>],
    ) -> (Vec<[f64; 2]>, Vec<Point3>, Vec<FeatureLine>) {
        let mut out = Vec::new();
        for l in lines {
            let first = data.len() as u32;
            data.extend(l.iter().map(|&t| (t, s.eval(t[0], t[1]))));
            out.push(line(first..data.len() as u32));
        }
        let (uv, points) = data.into_iter().unzip();
        (uv, points, out)
    }

    #[test]
    fn lines_along_parameter_lines_become_knots_and_others_do_not() {
        // Line 0: u = 0.3 ± 0.001 (± 0.002 in model units) along v; line 1 the same at
        // u = 0.3005 (merged); line 2 along u at v = 0.6; line 3 a diagonal; line 4 two points
        // (a corner to corner edge) along v.
        let t = |k: usize| 0.1 + 0.08 * k as f64;
        let line0 = (0..10)
            .map(|k| [0.3 + if k % 2 == 0 { 0.001 } else { -0.001 }, t(k)])
            .collect();
        let lines = [
            line0,
            (0..10).map(|k| [0.3005, t(k)]).collect(),
            (0..10).map(|k| [t(k), 0.6]).collect(),
            (0..10).map(|k| [t(k), t(k)]).collect(),
            vec![[0.7, 0.5], [0.7, 0.51]],
        ];
        let s = plane();
        let (uv, points, lines) = with_lines(&s, grid(&s, (0.0, 1.0), 0.0), &lines);
        let found = find_crease_knots(&s, &lines, (&uv, &points), 0.005);
        assert_eq!(found.unaligned, 2, "{found:?}");
        assert_eq!(found.knots.len(), 2, "{found:?}");
        assert_eq!(found.knots[0].lines, [0, 1]);
        assert_eq!(found.knots[0].direction, "u");
        assert!((found.knots[0].at - 0.3).abs() < 0.0015);
        assert_eq!((found.knots[1].direction, found.knots[1].at), ("v", 0.6));
        assert_eq!(
            found.summary().split(" (").next(),
            Some("3 of 5 crease lines as C0 knot lines")
        );
        // Within a tolerance below the first line's spread (0.002 × 2 = 0.004) it is not aligned.
        let strict = find_crease_knots(&s, &lines[..1], (&uv, &points), 0.003);
        assert_eq!((strict.knots.len(), strict.unaligned), (0, 1));
        // Inserted, each knot line is C0: multiplicity 3 in a cubic.
        let mut s = plane();
        let [us, vs] = insert_crease_knots(&mut s, &found);
        assert_eq!((us.len(), vs.len()), (1, 1));
        let count = |k: &[f64], x: f64| k.iter().filter(|&&y| y == x).count();
        assert_eq!(count(s.knots_u().knots(), us[0]), 3);
        assert_eq!(count(s.knots_v().knots(), 0.6), 3);
        assert_eq!(s.num_control(), (7, 7));
    }

    #[test]
    fn a_line_with_data_on_one_side_only_is_not_a_knot_line() {
        // The data end at u = 0.5, where the line runs (the outline of a projection); a second
        // layer beyond it lies 1 unit above (the back of a closed surface): one-sided still.
        let s = plane();
        let line: Vec<[f64; 2]> = (0..10).map(|k| [0.5, 0.1 + 0.08 * k as f64]).collect();
        let mut data = grid(&s, (0.0, 0.5), 0.0);
        let (uv, points, lines) = with_lines(&s, data.clone(), std::slice::from_ref(&line));
        let found = find_crease_knots(&s, &lines, (&uv, &points), 0.005);
        assert_eq!((found.knots.len(), found.unaligned), (0, 1));
        data.extend(grid(&s, (0.5, 1.0), 1.0));
        let (uv, points, lines) = with_lines(&s, data.clone(), std::slice::from_ref(&line));
        let found = find_crease_knots(&s, &lines, (&uv, &points), 0.005);
        assert_eq!((found.knots.len(), found.unaligned), (0, 1));
        // The same layer beyond it: two-sided, a knot line.
        data.extend(grid(&s, (0.5, 1.0), 0.0));
        let (uv, points, lines) = with_lines(&s, data, &[line]);
        let found = find_crease_knots(&s, &lines, (&uv, &points), 0.005);
        assert_eq!((found.knots.len(), found.unaligned), (1, 0));
    }
}
