//! Creases of gridded data: the sections' multiple knots that matter at the tolerance, linked
//! across the sections into crease lines, and the rows' parameters aligned on them.

use super::{distinct, SectionsOptions};
use crate::fit::{FitError, KnotPlacementFitter};
use crate::geom::{Point3, Vec3};

/// A crease chain links a multiple knot to one in a section at most this many sections on
/// (the knot-placement test misses a crease that falls between two points of a section, whose
/// turn is shared by both: on a roof slanting across 41 rows it found the crease in 3 rows of
/// every 10).
const CHAIN_REACH: usize = 8;

/// ... and at most this many points along the section away, plus one per 4 sections crossed
/// (a crease that slants across the sections moves along them from one to the next).
const CHAIN_POINTS: usize = 2;

/// Multiple knots in a chain of fewer sections are noise: a crease crossing the sections shows
/// in each of them, noise in one section at a time. On bun000's range grid the rows have 257
/// "corners" (polyline turns over 30° between points 0.4 % of the diagonal apart with
/// 0.05 % of noise), about 2 per row of 160 points, before [`significant`] and this rule.
const CHAIN_MIN_SECTIONS: usize = 3;

/// A section's multiple knot.
#[derive(Clone, Copy, Debug, PartialEq)]
struct Feature {
    /// The point of the section the knot-placement test found it at.
    index: usize,
    multiplicity: usize,
    /// Where along the section (its parameter) the crease is: a corner's lies where the lines
    /// of the points on either side meet, between points; a curvature jump's at the point.
    param: f64,
}

/// One crease across the sections: its members (section, feature), one per section at most,
/// in section order, and its multiplicity (the highest of its members').
#[derive(Clone, Debug, PartialEq)]
struct Chain {
    members: Vec<(usize, Feature)>,
    multiplicity: usize,
}

/// The sections' multiple knots linked across the sections into creases; the chains of at
/// least [`CHAIN_MIN_SECTIONS`] sections, longest first.
fn chains(features: &[Vec<Feature>]) -> Vec<Chain> {
    let mut chains: Vec<Chain> = Vec::new();
    for (s, own) in features.iter().enumerate() {
        let mut taken = vec![false; chains.len()];
        for &f in own {
            let near = |c: &Chain| {
                let (ls, last) = c.members.last()?;
                let (gap, drift) = (s - ls, last.index.abs_diff(f.index));
                (gap <= CHAIN_REACH && drift <= CHAIN_POINTS + gap / 4).then_some((drift, gap))
            };
            let best = (0..taken.len())
                .filter(|&c| !taken[c])
                .filter_map(|c| near(&chains[c]).map(|d| (d, c)))
                .min();
            match best {
                Some((_, c)) => {
                    taken[c] = true;
                    chains[c].members.push((s, f));
                    chains[c].multiplicity = chains[c].multiplicity.max(f.multiplicity);
                }
                None => chains.push(Chain {
                    members: vec![(s, f)],
                    multiplicity: f.multiplicity,
                }),
            }
        }
    }
    chains.retain(|c| c.members.len() >= CHAIN_MIN_SECTIONS);
    chains.sort_by_key(|c| std::cmp::Reverse(c.members.len()));
    chains
}

/// The creases of a grid: chains of the rows' multiple knots (creases crossing the rows) and of
/// the data columns' (the i-th point of every row; creases running along the rows), each
/// multiple knot significant at the tolerance ([`significant`]).
#[derive(Clone, Debug)]
pub(super) struct GridFeatures {
    /// Across the rows, each at one u: the rows' parameters are aligned on it.
    rows: Vec<(f64, Chain)>,
    /// Along the rows; members' indices are rows.
    columns: Vec<Chain>,
}

impl GridFeatures {
    /// The creases of `points` cut into `rows` of equal length ([`check_rows`]) that matter at
    /// a tolerance of `tol` model units, and every point's u in data order: its chord
    /// parameter along its row, mapped piecewise linearly so that every crease crossing the
    /// rows lies at one u in all of them ([`align`]).
    pub(super) fn of(
        points: &[Point3],
        rows: &[std::ops::Range<usize>],
        normals: &[Vec3],
        options: &SectionsOptions,
        tol: f64,
    ) -> Result<(GridFeatures, Vec<f64>), FitError> {
        let (nr, nc) = (rows.len(), rows[0].len());
        let at = |r: usize, c: usize| points[rows[r].start + c];
        let normal = |r: usize, c: usize| normals[r * nc + c];
        let mut params = Vec::with_capacity(points.len());
        let mut row_features = Vec::with_capacity(nr);
        for (r, range) in rows.iter().enumerate() {
            let (p, f) = section_features(&points[range.clone()], |c| normal(r, c), options, tol)?;
            params.extend(p);
            row_features.push(f);
        }
        let columns = (0..nc)
            .map(|c| {
                let column: Vec<Point3> = (0..nr).map(|r| at(r, c)).collect();
                let normal = |r| normal(r, c);
                Ok(section_features(&distinct(&column), normal, options, tol)?.1)
            })
            .collect::<Result<Vec<_>, FitError>>()?;
        let row_chains = align(&mut params, nc, chains(&row_features));
        let features = GridFeatures {
            rows: row_chains,
            columns: chains(&columns),
        };
        Ok((features, params))
    }

    /// The knots (value, multiplicity) of the creases crossing the rows.
    pub(super) fn u_knots(&self) -> Vec<(f64, usize)> {
        self.rows
            .iter()
            .map(|(u, c)| (*u, c.multiplicity))
            .collect()
    }

    /// The knots of the creases along the rows, each at the mean of the parameters `v` of
    /// the rows it meets, of multiplicity at most `degree` − 1. A row has one v, so a crease
    /// slanting across the columns cannot be aligned as the rows' creases are: a knot per row
    /// it meets made bun000's columns C0 every other row (145 control points for 126 rows),
    /// and a C0 knot at its mean v kinked the surface where the crease is not (E_back 3.2 %
    /// against 0.16 % with C1 knots). The curvature jump lets the columns turn sharply
    /// there; the single knots placed to the tolerance follow the rest.
    pub(super) fn v_knots(&self, v: &[f64], degree: usize) -> Vec<(f64, usize)> {
        let mean = |c: &Chain| {
            let sum: f64 = c.members.iter().map(|(_, f)| v[f.index]).sum();
            sum / c.members.len() as f64
        };
        let smooth = |c: &Chain| c.multiplicity.min(degree.saturating_sub(1).max(1));
        self.columns.iter().map(|c| (mean(c), smooth(c))).collect()
    }
}

/// The unit normals of a grid of `rows` × `cols` points (`at(row, col)`), row by row: the
/// cross product of the steps to the neighbours along the row and across the rows (one-sided
/// at the edges); zero where they are parallel.
pub(super) fn grid_normals(
    rows: usize,
    cols: usize,
    at: impl Fn(usize, usize) -> Point3,
) -> Vec<Vec3> {
    let normal = |r: usize, c: usize| {
        let along = at(r, (c + 1).min(cols - 1)) - at(r, c.saturating_sub(1));
        let across = at((r + 1).min(rows - 1), c) - at(r.saturating_sub(1), c);
        along.cross(across).normalize_or_zero()
    };
    (0..rows)
        .flat_map(|r| (0..cols).map(move |c| (r, c)))
        .map(|(r, c)| normal(r, c))
        .collect()
}

/// Aligns the rows' parameters (`params`, rows of `per_row` points in data order) on the
/// creases crossing them: each chain gets the mean u of its members' creases, and every row's
/// chord parameters are mapped piecewise linearly through the (own u, mean) pairs of the
/// chains it meets, so one multiple knot makes the crease in every row it crosses — a crease
/// slanting across the rows would otherwise need a knot per row. In the rows between two
/// members of a chain the crease's own u is interpolated. A chain whose order would cross
/// another's in some row is dropped (shorter chains first). Returns the kept chains with
/// their u.
fn align(params: &mut [f64], per_row: usize, chains: Vec<Chain>) -> Vec<(f64, Chain)> {
    let rows = params.len() / per_row.max(1);
    // Anchors of each row: (own u, common u), both increasing.
    let mut anchors: Vec<Vec<(f64, f64)>> = vec![Vec::new(); rows];
    let mut kept = Vec::new();
    for chain in chains {
        let m = &chain.members;
        let mean = m.iter().map(|(_, f)| f.param).sum::<f64>() / m.len() as f64;
        let own: Vec<(usize, f64)> = m
            .windows(2)
            .flat_map(|w| {
                let ((r0, f0), (r1, f1)) = (w[0], w[1]);
                let step = (f1.param - f0.param) / (r1 - r0) as f64;
                (r0..r1).map(move |r| (r, f0.param + step * (r - r0) as f64))
            })
            .chain(m.last().map(|&(r, f)| (r, f.param)))
            .collect();
        let fits = own.iter().all(|&(r, t)| {
            let a = &anchors[r];
            let k = a.partition_point(|x| x.0 < t);
            let below = k.checked_sub(1).map_or((0.0, 0.0), |j| a[j]);
            let above = a.get(k).copied().unwrap_or((1.0, 1.0));
            below.0 < t && t < above.0 && below.1 < mean && mean < above.1
        });
        if fits {
            for (r, t) in own {
                let k = anchors[r].partition_point(|x| x.0 < t);
                anchors[r].insert(k, (t, mean));
            }
            kept.push((mean, chain));
        }
    }
    for (r, a) in anchors.iter().enumerate() {
        let row = &mut params[r * per_row..(r + 1) * per_row];
        let mut knots = vec![(0.0, 0.0)];
        knots.extend_from_slice(a);
        knots.push((1.0, 1.0));
        for t in row.iter_mut() {
            let k = knots
                .partition_point(|x| x.0 <= *t)
                .clamp(1, knots.len() - 1);
            let ((t0, u0), (t1, u1)) = (knots[k - 1], knots[k]);
            let w = if t1 > t0 { (*t - t0) / (t1 - t0) } else { 0.0 };
            *t = u0 + w * (u1 - u0);
        }
    }
    kept
}

/// The chord parameters of one section's points and its multiple knots: the knot-placement
/// curve fitter's test, and only where one smooth cubic cannot follow the points around
/// within `tol` along the surface's normal at the point (`normal(index)`, [`significant`]).
fn section_features(
    points: &[Point3],
    normal: impl Fn(usize) -> Vec3,
    options: &SectionsOptions,
    tol: f64,
) -> Result<(Vec<f64>, Vec<Feature>), FitError> {
    let fitter = KnotPlacementFitter::try_new(points, options.curve_options())?;
    let params = fitter.params();
    let knots = fitter.features().iter();
    let knots = knots.filter(|k| significant(points, params, k.index, normal(k.index), tol));
    let knots = knots.map(|k| Feature {
        index: k.index,
        multiplicity: k.multiplicity,
        param: if k.multiplicity >= options.degree {
            corner_param(points, params, k.index)
        } else {
            params[k.index]
        },
    });
    Ok((params.to_vec(), knots.collect()))
}

/// The parameter of a corner found at point `i` of a section: where the line through the two
/// points before it and the line through the two points after it come closest (a crease
/// between two samples turns the section at both), placed between the two points it lies
/// between in proportion to its distances from them.
fn corner_param(points: &[Point3], params: &[f64], i: usize) -> f64 {
    if i < 2 || i + 2 >= points.len() {
        return params[i];
    }
    let (a, da) = (points[i - 1], points[i - 1] - points[i - 2]);
    let (b, db) = (points[i + 1], points[i + 2] - points[i + 1]);
    // Closest points a + s·da and b + t·db of the two lines.
    let (w, aa, bb, ab) = (a - b, da.dot(da), db.dot(db), da.dot(db));
    let det = aa * bb - ab * ab;
    if det <= 1e-12 * aa * bb {
        return params[i];
    }
    let s = (ab * db.dot(w) - bb * da.dot(w)) / det;
    let t = (aa * db.dot(w) - ab * da.dot(w)) / det;
    let x = 0.5 * (a + da * s + b + db * t);
    let before = (x - points[i]).dot(points[i + 1] - points[i - 1]) < 0.0;
    let k = if before { i - 1 } else { i };
    let (to, from) = ((x - points[k]).length(), (points[k + 1] - x).length());
    let f = if to + from > 0.0 {
        to / (to + from)
    } else {
        0.5
    };
    params[k] + f * (params[k + 1] - params[k])
}

/// Points on either side of a feature that [`significant`] fits one cubic to.
const SIGNIFICANCE_REACH: usize = 4;

/// Whether the least-squares cubic (in the chord parameter `params`) through the points within
/// [`SIGNIFICANCE_REACH`] of point `i` misses one of them by more than `tol` along the
/// surface's unit `normal` there: a corner or curvature jump that a smooth surface cannot
/// follow within the tolerance. The knot-placement test compares cubics through 4 points on
/// either side, which noise turns by tens of degrees: bun000's depths are quantised to 0.095 %
/// of the diagonal and its grid's columns zigzag sideways by half a pixel (0.19 %, across the
/// column but within the surface), so it found a "corner" at nearly every point of the data's
/// columns. Along the normal only the quantisation is left.
fn significant(points: &[Point3], params: &[f64], i: usize, normal: Vec3, tol: f64) -> bool {
    let window =
        i.saturating_sub(SIGNIFICANCE_REACH)..(i + SIGNIFICANCE_REACH + 1).min(points.len());
    let (t0, t1) = (params[window.start], params[window.end - 1]);
    let scale = (t1 - t0).max(f64::MIN_POSITIVE);
    let powers = |t: f64| {
        let x = (t - params[i]) / scale;
        glam::DVec4::new(1.0, x, x * x, x * x * x)
    };
    let mut gram = glam::DMat4::ZERO;
    let mut rhs = [glam::DVec4::ZERO; 3];
    for k in window.clone() {
        let b = powers(params[k]);
        gram += glam::DMat4::from_cols(b * b.x, b * b.y, b * b.z, b * b.w);
        for (r, c) in rhs.iter_mut().zip(points[k].to_array()) {
            *r += b * c;
        }
    }
    if gram.determinant().abs() < 1e-12 {
        return true;
    }
    let inverse = gram.inverse();
    let coeffs = rhs.map(|r| inverse * r);
    window.into_iter().any(|k| {
        let b = powers(params[k]);
        let fitted = Point3::new(coeffs[0].dot(b), coeffs[1].dot(b), coeffs[2].dot(b));
        (points[k] - fitted).dot(normal).abs() > tol
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn corner(index: usize) -> Feature {
        Feature {
            index,
            multiplicity: 3,
            param: index as f64 / 40.0,
        }
    }

    #[test]
    fn a_crease_seen_in_some_sections_is_one_chain_and_noise_none() {
        // A crease found at points 18, 18, 19 … every few sections (it falls between points in
        // the others), and lone "corners" of noise.
        let mut features = vec![Vec::new(); 30];
        for s in [0, 1, 9, 10, 11, 19, 20, 21, 29] {
            features[s].push(corner(18 + s / 10));
        }
        features[4].push(corner(33));
        features[15].push(corner(5));
        features[16].push(corner(30));
        let found = chains(&features);
        assert_eq!(found.len(), 1, "{found:?}");
        assert_eq!(found[0].members.len(), 9);
    }

    #[test]
    fn aligned_rows_put_a_slanting_crease_at_one_parameter() {
        // Three rows of 41 points, a crease at u = 0.45, 0.5, 0.55 (the middle row's
        // interpolated): after alignment all three are at their mean, 0.5.
        let mut params: Vec<f64> = (0..3)
            .flat_map(|_| (0..41).map(|i| i as f64 / 40.0))
            .collect();
        let at = |u: f64| Feature {
            index: (u * 40.0) as usize,
            multiplicity: 3,
            param: u,
        };
        let chain = Chain {
            members: vec![(0, at(0.45)), (2, at(0.55))],
            multiplicity: 3,
        };
        let kept = align(&mut params, 41, vec![chain]);
        assert_eq!(kept.len(), 1);
        assert!((kept[0].0 - 0.5).abs() < 1e-12);
        // Row 0's point at 0.45 (index 18) and row 2's at 0.55 (index 22) both map to 0.5.
        assert!((params[18] - 0.5).abs() < 1e-12);
        assert!((params[2 * 41 + 22] - 0.5).abs() < 1e-12);
        assert!((params[41 + 20] - 0.5).abs() < 1e-12);
        assert!(params.windows(2).take(40).all(|w| w[0] < w[1]));
    }

    #[test]
    fn a_corner_between_two_points_is_found_where_its_sides_meet() {
        // z = |x − 0.4625| sampled at x = 0, 0.025, …: the crease lies between points 18 and 19.
        let points: Vec<Point3> = (0..41)
            .map(|i| {
                let x = i as f64 / 40.0;
                Point3::new(x, 0.0, (x - 0.4625).abs())
            })
            .collect();
        let params: Vec<f64> = {
            let mut acc = vec![0.0];
            for w in points.windows(2) {
                acc.push(acc[acc.len() - 1] + (w[1] - w[0]).length());
            }
            let total = acc[40];
            acc.iter().map(|a| a / total).collect()
        };
        let expected = params[18] + 0.5 * (params[19] - params[18]);
        for i in [18, 19] {
            let t = corner_param(&points, &params, i);
            assert!((t - expected).abs() < 1e-9, "{t} for {expected}");
        }
    }

    #[test]
    fn zigzag_within_the_surface_is_no_feature() {
        // A straight section along y whose points zigzag sideways in x (within the surface,
        // whose normal is z) by 10 tolerances, and one with a 1-tolerance dent in z.
        let tol = 1e-3;
        let zigzag: Vec<Point3> = (0..20)
            .map(|i| {
                Point3::new(
                    if i % 2 == 0 { 0.0 } else { 10.0 * tol },
                    i as f64 * 0.01,
                    0.0,
                )
            })
            .collect();
        let params: Vec<f64> = (0..20).map(|i| i as f64 / 19.0).collect();
        assert!(!significant(&zigzag, &params, 10, Vec3::Z, tol));
        let mut dent = zigzag.clone();
        dent[10].z = -3.0 * tol;
        assert!(significant(&dent, &params, 10, Vec3::Z, tol));
    }
}
