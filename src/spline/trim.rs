//! The region of a surface's parameter domain that its data covers: a trim loop for CAD export
//! (a STEP face bound, an IGES trimmed surface) and a `contains` test for drawing and meshing.
//!
//! The outline is an alpha shape of the data's foot-point parameters: their Delaunay
//! triangulation (spade) without the triangles that have an edge longer than a few point
//! spacings, whose boundary loops are then simplified by Douglas–Peucker. The largest
//! counter-clockwise loop is the outer boundary; clockwise loops inside it enclosing more than a
//! few spacings² are holes. Smaller gaps are closed and islands apart from the main region
//! dropped, so a CAD face is one connected piece of surface.

use spade::{DelaunayTriangulation, HasPosition, Point2, Triangulation};
use std::collections::HashMap;
use thiserror::Error;

/// Why no trim region could be built from a set of parameters.
#[derive(Debug, Error, Clone, PartialEq)]
#[non_exhaustive]
pub enum TrimError {
    /// Fewer than three parameter pairs.
    #[error("a trim region needs at least 3 parameter pairs, {found} given")]
    TooFewPoints {
        /// Pairs given.
        found: usize,
    },
    /// A parameter is NaN or infinite.
    #[error("parameter pair {index} is not finite")]
    NotFinite {
        /// Its index.
        index: usize,
    },
    /// The parameters span no area (all on one line, or all equal).
    #[error("the {points} parameter pairs span no area (all on one line)")]
    Degenerate {
        /// Pairs given.
        points: usize,
    },
    /// A loop has fewer than three vertices or a vertex that is not finite.
    #[error("trim loop {what}: {reason}")]
    BadLoop {
        /// Which loop ("outer", "hole 2").
        what: String,
        /// What is wrong.
        reason: String,
    },
}

/// How the outline of the parameters is found. Lengths are multiples of the point spacing: the
/// median over the points of the distance in (u, v) to the nearest other point.
#[derive(Clone, Debug, PartialEq)]
#[non_exhaustive]
pub struct TrimOptions {
    /// Triangles with an edge longer than this many spacings are outside the region (default
    /// 4): gaps narrower than that are data, wider ones are outside or holes.
    pub edge_factor: f64,
    /// Holes are kept when their area exceeds (this many spacings)² (default 3).
    pub hole_factor: f64,
    /// Douglas–Peucker tolerance of the loops, in spacings (default 0.5).
    pub simplify_factor: f64,
}

impl Default for TrimOptions {
    fn default() -> Self {
        TrimOptions {
            edge_factor: 4.0,
            hole_factor: 3.0,
            simplify_factor: 0.5,
        }
    }
}

impl TrimOptions {
    /// Sets [`TrimOptions::edge_factor`].
    pub fn with_edge_factor(mut self, f: f64) -> Self {
        self.edge_factor = f;
        self
    }

    /// Sets [`TrimOptions::hole_factor`].
    pub fn with_hole_factor(mut self, f: f64) -> Self {
        self.hole_factor = f;
        self
    }

    /// Sets [`TrimOptions::simplify_factor`].
    pub fn with_simplify_factor(mut self, f: f64) -> Self {
        self.simplify_factor = f;
        self
    }
}

/// A region of the (u, v) plane: one outer loop, counter-clockwise, and hole loops inside it,
/// clockwise. Loops are closed implicitly (the last vertex connects to the first).
#[derive(Clone, Debug, PartialEq)]
pub struct TrimRegion {
    outer: Vec<[f64; 2]>,
    holes: Vec<Vec<[f64; 2]>>,
}

/// The outline of a set of parameters and the triangulation it bounds.
#[derive(Clone, Debug, PartialEq)]
pub struct Outline {
    /// The region.
    pub region: TrimRegion,
    /// The kept Delaunay triangles, as indices into the parameters (counter-clockwise in u, v):
    /// the data's triangulated region, for its area.
    pub triangles: Vec<[usize; 3]>,
    /// The point spacing in (u, v) the lengths were scaled by.
    pub spacing: f64,
    /// Loops left out: islands apart from the main region and holes below the size limit.
    pub dropped_loops: usize,
}

impl TrimRegion {
    /// A region from an outer loop and holes, each at least three finite vertices; loops are
    /// reoriented (outer counter-clockwise, holes clockwise). Whether the holes lie inside the
    /// outer loop and the loops are simple is the caller's to ensure.
    pub fn try_new(
        mut outer: Vec<[f64; 2]>,
        mut holes: Vec<Vec<[f64; 2]>>,
    ) -> Result<TrimRegion, TrimError> {
        check_loop("outer", &outer)?;
        if signed_area(&outer) < 0.0 {
            outer.reverse();
        }
        for (i, h) in holes.iter_mut().enumerate() {
            check_loop(&format!("hole {i}"), h)?;
            if signed_area(h) > 0.0 {
                h.reverse();
            }
        }
        Ok(TrimRegion { outer, holes })
    }

    /// The outer loop, counter-clockwise.
    pub fn outer(&self) -> &[[f64; 2]] {
        &self.outer
    }

    /// The holes, clockwise.
    pub fn holes(&self) -> &[Vec<[f64; 2]>] {
        &self.holes
    }

    /// Every loop, the outer first.
    pub fn loops(&self) -> impl Iterator<Item = &[[f64; 2]]> {
        std::iter::once(self.outer.as_slice()).chain(self.holes.iter().map(Vec::as_slice))
    }

    /// Whether (u, v) lies inside the outer loop and outside every hole (points on a loop may
    /// fall either way).
    pub fn contains(&self, u: f64, v: f64) -> bool {
        self.loops().filter(|l| crosses(l, u, v)).count() % 2 == 1
    }

    /// [`TrimRegion::contains`] at every node (us[i], vs[j]) of a grid, at `i * vs.len() + j`.
    ///
    /// Why: a test per node walks every loop edge, which made the inside tests of a 390K-node
    /// FEM mesh cost 0.5 s; here each v line's crossings with all loops are found once and
    /// sorted, and a node counts those beyond it by binary search: O(lines × edges + nodes ×
    /// log edges), the same answers (the same crossing arithmetic, and the parities of the
    /// loops add up to the parity of their sum).
    pub fn contains_grid(&self, us: &[f64], vs: &[f64]) -> Vec<bool> {
        let mut inside = vec![false; us.len() * vs.len()];
        let mut xs = Vec::new();
        for (j, &v) in vs.iter().enumerate() {
            xs.clear();
            xs.extend(self.loops().flat_map(|l| crossings(l, v)));
            xs.sort_unstable_by(f64::total_cmp);
            for (i, &u) in us.iter().enumerate() {
                let beyond = xs.len() - xs.partition_point(|&x| x <= u);
                inside[i * vs.len() + j] = beyond % 2 == 1;
            }
        }
        inside
    }

    /// Area in (u, v): the outer loop's less the holes'.
    pub fn area(&self) -> f64 {
        self.loops().map(signed_area).sum()
    }

    /// Number of loop vertices, all loops together.
    pub fn num_vertices(&self) -> usize {
        self.loops().map(<[_]>::len).sum()
    }

    /// The outline of `params` (foot-point parameters of the data), by the alpha shape
    /// described in the module docs.
    pub fn outline(params: &[[f64; 2]], options: &TrimOptions) -> Result<Outline, TrimError> {
        if params.len() < 3 {
            return Err(TrimError::TooFewPoints {
                found: params.len(),
            });
        }
        if let Some(index) = params
            .iter()
            .position(|p| !(p[0].is_finite() && p[1].is_finite()))
        {
            return Err(TrimError::NotFinite { index });
        }
        let degenerate = TrimError::Degenerate {
            points: params.len(),
        };
        let vertices: Vec<Param> = params
            .iter()
            .enumerate()
            .map(|(index, p)| Param {
                at: Point2::new(p[0], p[1]),
                index,
            })
            .collect();
        let dt: DelaunayTriangulation<Param> =
            DelaunayTriangulation::bulk_load(vertices).map_err(|_| degenerate.clone())?;
        if dt.num_inner_faces() == 0 {
            return Err(degenerate);
        }
        let spacing = spacing(&dt);
        let limit_sq = (options.edge_factor * spacing).powi(2);
        let kept: Vec<bool> = dt
            .inner_faces()
            .map(|f| f.adjacent_edges().iter().all(|e| e.length_2() <= limit_sq))
            .collect();
        let loops = boundary_loops(&dt, &kept);
        let triangles = dt
            .inner_faces()
            .filter(|f| kept[f.fix().index() - 1])
            .map(|f| f.vertices().map(|v| v.data().index))
            .collect();
        let (region, dropped_loops) = classify(loops, options, spacing).ok_or(degenerate)?;
        Ok(Outline {
            region,
            triangles,
            spacing,
            dropped_loops,
        })
    }
}

/// A parameter pair and its index, as a triangulation vertex.
#[derive(Clone, Copy, Debug)]
struct Param {
    at: Point2<f64>,
    index: usize,
}

impl HasPosition for Param {
    type Scalar = f64;

    fn position(&self) -> Point2<f64> {
        self.at
    }
}

fn check_loop(what: &str, l: &[[f64; 2]]) -> Result<(), TrimError> {
    let bad = |reason: String| {
        Err(TrimError::BadLoop {
            what: what.to_string(),
            reason,
        })
    };
    if l.len() < 3 {
        return bad(format!("{} vertices, at least 3 needed", l.len()));
    }
    if let Some(i) = l
        .iter()
        .position(|p| !(p[0].is_finite() && p[1].is_finite()))
    {
        return bad(format!("vertex {i} is not finite"));
    }
    if signed_area(l) == 0.0 {
        return bad("it encloses no area".into());
    }
    Ok(())
}

/// The median over the vertices of the shortest incident edge.
fn spacing(dt: &DelaunayTriangulation<Param>) -> f64 {
    let mut nearest: Vec<f64> = dt
        .vertices()
        .map(|v| {
            v.out_edges()
                .map(|e| e.length_2())
                .fold(f64::INFINITY, f64::min)
        })
        .filter(|d| d.is_finite())
        .collect();
    nearest.sort_by(f64::total_cmp);
    nearest.get(nearest.len() / 2).map_or(0.0, |d| d.sqrt())
}

/// The boundary of the kept faces as closed vertex loops with the region on their left. Where
/// two parts of the region touch at a vertex, each loop leaves by the first boundary edge
/// clockwise from the one it came by, so loops never cross.
fn boundary_loops(dt: &DelaunayTriangulation<Param>, kept: &[bool]) -> Vec<Vec<[f64; 2]>> {
    let is_kept = |f: Option<usize>| f.is_some_and(|i| kept[i - 1]);
    let mut out_of: HashMap<usize, Vec<usize>> = HashMap::new();
    for f in dt.inner_faces().filter(|f| kept[f.fix().index() - 1]) {
        for e in f.adjacent_edges() {
            if !is_kept(e.rev().face().as_inner().map(|g| g.fix().index())) {
                let (a, b) = (e.from().fix().index(), e.to().fix().index());
                out_of.entry(a).or_default().push(b);
            }
        }
    }
    let positions: Vec<[f64; 2]> = dt
        .vertices()
        .map(|v| [v.position().x, v.position().y])
        .collect();
    let mut starts: Vec<usize> = out_of.keys().copied().collect();
    starts.sort_unstable();
    let mut loops = Vec::new();
    for s in starts {
        while let Some(first) = out_of.get_mut(&s).and_then(Vec::pop) {
            let mut l = vec![s];
            let (mut prev, mut cur) = (s, first);
            while cur != s {
                l.push(cur);
                let Some(next) = next_edge(&positions, &mut out_of, prev, cur) else {
                    break;
                };
                (prev, cur) = (cur, next);
            }
            for simple in split_pinches(&l) {
                loops.push(simple.iter().map(|&i| positions[i]).collect());
            }
        }
    }
    loops
}

/// The simple loops a loop that visits some vertices more than once (where parts of the region
/// touch at a point) is made of, each of three vertices or more: CAD readers take a wire that
/// touches itself for a wrong one.
fn split_pinches(l: &[usize]) -> Vec<Vec<usize>> {
    let mut out = Vec::new();
    let mut stack: Vec<usize> = Vec::new();
    let mut at: HashMap<usize, usize> = HashMap::new();
    for &v in l {
        if let Some(&p) = at.get(&v) {
            let sub: Vec<usize> = stack.drain(p..).collect();
            for w in &sub {
                at.remove(w);
            }
            if sub.len() >= 3 {
                out.push(sub);
            }
        }
        at.insert(v, stack.len());
        stack.push(v);
    }
    if stack.len() >= 3 {
        out.push(stack);
    }
    out
}

/// Takes the boundary edge out of `cur` first clockwise from the direction back to `prev`.
fn next_edge(
    pos: &[[f64; 2]],
    out_of: &mut HashMap<usize, Vec<usize>>,
    prev: usize,
    cur: usize,
) -> Option<usize> {
    let outs = out_of.get_mut(&cur)?;
    let angle = |to: usize| {
        let d = |a: [f64; 2], b: [f64; 2]| libm::atan2(b[1] - a[1], b[0] - a[0]);
        let back = d(pos[cur], pos[prev]);
        (back - d(pos[cur], pos[to])).rem_euclid(std::f64::consts::TAU)
    };
    let k = (0..outs.len()).min_by(|&a, &b| angle(outs[a]).total_cmp(&angle(outs[b])))?;
    Some(outs.swap_remove(k))
}

/// The largest counter-clockwise loop as the outer boundary, with the clockwise loops inside it
/// larger than the hole limit, all simplified; and how many loops were left out.
fn classify(
    loops: Vec<Vec<[f64; 2]>>,
    options: &TrimOptions,
    spacing: f64,
) -> Option<(TrimRegion, usize)> {
    let total = loops.len();
    let (outers, inners): (Vec<_>, Vec<_>) = loops.into_iter().partition(|l| signed_area(l) > 0.0);
    let outer = outers
        .into_iter()
        .max_by(|a, b| signed_area(a).total_cmp(&signed_area(b)))?;
    let min_hole = (options.hole_factor * spacing).powi(2);
    let tol = options.simplify_factor * spacing;
    let simple_outer = simplify_loop(&outer, tol);
    // A hole touching the outer loop at a vertex, or whose simplified loop strays outside the
    // simplified outer one, would make the face's wires meet: it is filled instead.
    let holes: Vec<Vec<[f64; 2]>> = inners
        .into_iter()
        .filter(|h| -signed_area(h) > min_hole && inside(&outer, h))
        .filter(|h| !h.iter().any(|p| outer.contains(p)))
        .map(|h| simplify_loop(&h, tol))
        .filter(|h| h.iter().all(|p| crosses(&simple_outer, p[0], p[1])))
        .collect();
    let dropped = total - 1 - holes.len();
    let region = TrimRegion {
        outer: simple_outer,
        holes,
    };
    Some((region, dropped))
}

/// Whether most vertices of `h` lie inside `outer` (a hole may touch it at a vertex).
fn inside(outer: &[[f64; 2]], h: &[[f64; 2]]) -> bool {
    2 * h.iter().filter(|p| crosses(outer, p[0], p[1])).count() > h.len()
}

/// Shoelace area, positive for counter-clockwise loops.
fn signed_area(l: &[[f64; 2]]) -> f64 {
    let n = l.len();
    (0..n)
        .map(|i| {
            let (a, b) = (l[i], l[(i + 1) % n]);
            a[0] * b[1] - b[0] * a[1]
        })
        .sum::<f64>()
        / 2.0
}

/// Whether a ray from (u, v) towards +u crosses the loop an odd number of times.
fn crosses(l: &[[f64; 2]], u: f64, v: f64) -> bool {
    crossings(l, v).filter(|&x| u < x).count() % 2 == 1
}

/// The u of every crossing of loop `l` with the line at `v` (edges with one end above `v`
/// and one at or below): the ray of the even–odd rule runs from (u, v) towards +u, so a point
/// is inside a loop when an odd number of these lie beyond its u.
fn crossings(l: &[[f64; 2]], v: f64) -> impl Iterator<Item = f64> + '_ {
    let n = l.len();
    (0..n).filter_map(move |i| {
        let (a, b) = (l[i], l[(i + 1) % n]);
        ((a[1] > v) != (b[1] > v)).then(|| {
            let t = (v - a[1]) / (b[1] - a[1]);
            a[0] + t * (b[0] - a[0])
        })
    })
}

/// Douglas–Peucker on a closed loop, split at two extreme vertices (the one farthest from the
/// first vertex, and the one farthest from that), which any simplification keeps; loops that
/// would fall below three vertices stay as they are.
fn simplify_loop(l: &[[f64; 2]], tol: f64) -> Vec<[f64; 2]> {
    let dist_sq = |a: [f64; 2], b: [f64; 2]| (a[0] - b[0]).powi(2) + (a[1] - b[1]).powi(2);
    let farthest = |l: &[[f64; 2]]| {
        (0..l.len())
            .max_by(|&a, &b| dist_sq(l[0], l[a]).total_cmp(&dist_sq(l[0], l[b])))
            .unwrap_or(0)
    };
    let start = farthest(l);
    let l: Vec<[f64; 2]> = l[start..].iter().chain(&l[..start]).copied().collect();
    let far = farthest(&l);
    if far == 0 {
        return l;
    }
    let mut keep = vec![false; l.len()];
    keep[0] = true;
    keep[far] = true;
    let ring: Vec<[f64; 2]> = l.iter().chain(std::iter::once(&l[0])).copied().collect();
    douglas_peucker(&ring, 0, far, tol, &mut keep);
    douglas_peucker(&ring, far, l.len(), tol, &mut keep);
    let out: Vec<[f64; 2]> = (0..l.len()).filter(|&i| keep[i]).map(|i| l[i]).collect();
    if out.len() >= 3 {
        out
    } else {
        l
    }
}

/// Marks in `keep` the vertices of `p[a..=b]` that Douglas–Peucker keeps (iteratively).
fn douglas_peucker(p: &[[f64; 2]], a: usize, b: usize, tol: f64, keep: &mut [bool]) {
    let mut stack = vec![(a, b)];
    while let Some((a, b)) = stack.pop() {
        let (pa, pb) = (p[a], p[b]);
        let (dx, dy) = (pb[0] - pa[0], pb[1] - pa[1]);
        let len = libm::hypot(dx, dy);
        let dist = |q: [f64; 2]| {
            if len > 0.0 {
                ((q[0] - pa[0]) * dy - (q[1] - pa[1]) * dx).abs() / len
            } else {
                libm::hypot(q[0] - pa[0], q[1] - pa[1])
            }
        };
        let worst = (a + 1..b).max_by(|&i, &j| dist(p[i]).total_cmp(&dist(p[j])));
        if let Some(k) = worst.filter(|&k| dist(p[k]) > tol) {
            keep[k % keep.len()] = true;
            stack.push((a, k));
            stack.push((k, b));
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn grid_inside_tests_equal_pointwise_ones() {
        // A star-shaped outer loop with a square hole; grid lines through its vertices too.
        let outer: Vec<[f64; 2]> = (0..14)
            .map(|k| {
                let a = k as f64 * std::f64::consts::TAU / 14.0;
                let r = if k % 2 == 0 { 1.0 } else { 0.45 };
                [r * a.cos(), r * a.sin()]
            })
            .collect();
        let hole = vec![[-0.2, -0.2], [0.2, -0.2], [0.2, 0.2], [-0.2, 0.2]];
        let region = TrimRegion::try_new(outer, vec![hole]).unwrap();
        let lines = |n: usize| -> Vec<f64> {
            let mut t: Vec<f64> = (0..n)
                .map(|i| -1.1 + 2.2 * i as f64 / (n - 1) as f64)
                .collect();
            t.extend([-0.2, 0.2, 0.0, 1.0]);
            t
        };
        let (us, vs) = (lines(57), lines(43));
        let grid = region.contains_grid(&us, &vs);
        let mut inside = 0;
        for (i, &u) in us.iter().enumerate() {
            for (j, &v) in vs.iter().enumerate() {
                assert_eq!(
                    grid[i * vs.len() + j],
                    region.contains(u, v),
                    "at ({u}, {v})"
                );
                inside += usize::from(grid[i * vs.len() + j]);
            }
        }
        assert!(inside > 100 && inside < us.len() * vs.len() / 2, "{inside}");
        assert!(!region.contains(0.0, 0.0), "the hole is outside");
    }

    #[test]
    fn simplify_keeps_corners_of_a_sampled_square() {
        let mut l = Vec::new();
        for k in 0..10 {
            l.push([k as f64 / 10.0, 0.0]);
        }
        for k in 0..10 {
            l.push([1.0, k as f64 / 10.0]);
        }
        for k in 0..10 {
            l.push([1.0 - k as f64 / 10.0, 1.0]);
        }
        for k in 0..10 {
            l.push([0.0, 1.0 - k as f64 / 10.0]);
        }
        let s = simplify_loop(&l, 1e-3);
        assert_eq!(s.len(), 4, "{s:?}");
        assert!((signed_area(&s) - 1.0).abs() < 1e-12);
    }
}
