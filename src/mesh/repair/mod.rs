//! Repair on intake: any polygon soup becomes an oriented 2-manifold with boundary, which
//! [`ControlMesh::try_new`](crate::mesh::ControlMesh::try_new) accepts, with a report of what
//! was changed.
//!
//! Real meshes have vertices where two surfaces touch, edges shared by three faces, repeated
//! and degenerate faces, several pieces and faces that disagree on orientation. Every fit goes
//! through [`repair`] first, so none of these is a reason to refuse a mesh:
//!
//! 1. faces with fewer than three distinct corners, or of zero area, are dropped;
//! 2. the sides of faces are paired along their edges; a face that repeats the vertices of an
//!    earlier one is dropped; on an edge with more than two faces two are kept together (a
//!    pair running opposite ways if there is one) and the others are detached from it;
//! 3. each connected component is oriented consistently (the majority of its faces keep
//!    theirs); a non-orientable component is cut open where its orientation clashes;
//! 4. every vertex is split into its fans, one copy per fan, so each vertex has one fan;
//! 5. a detached face whose fans still meet at both ends of its edge is dropped (a second
//!    round checks the result), and components of very few faces are left to the data only.
//!
//! Vertices keep their indices (copies are appended, and [`Repaired::vertex_origin`] maps
//! every vertex to the input's), so the data points stay the original ones; vertices in no
//! face are kept. Polygons are kept as they are.
//!
//! ```
//! use geofit::geom::Point3;
//! use geofit::mesh::{repair, ControlMesh, PolyMesh};
//!
//! // Two triangles touching at vertex 0 (a bow tie), one of them repeated.
//! let pos = vec![
//!     Point3::ZERO,
//!     Point3::new(1.0, 0.0, 0.0),
//!     Point3::new(1.0, 1.0, 0.0),
//!     Point3::new(-1.0, 0.0, 0.0),
//!     Point3::new(-1.0, -1.0, 0.0),
//! ];
//! let soup = PolyMesh::try_new(pos, [[0, 1, 2], [0, 3, 4], [0, 1, 2]])?;
//! assert!(ControlMesh::try_new(&soup).is_err());
//! let fixed = repair(&soup)?;
//! assert_eq!(
//!     fixed.report.summary,
//!     "repaired: 1 non-manifold vertices split, 1 duplicate faces dropped"
//! );
//! assert_eq!(fixed.vertex_origin, vec![0, 1, 2, 3, 4, 0]);
//! ControlMesh::try_new(&fixed.mesh)?;
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

pub(crate) mod clean;
mod edges;
mod fans;
mod orient;
mod report;
mod soup;

pub use report::{Components, Found, RepairReport};

use super::{MeshError, PolyMesh};
use crate::geom::Point3;
use crate::progress::{self, Phase};
use orient::Orientation;
use soup::Soup;

/// Settings of [`repair_with`]. Build with `RepairOptions::default()` and the `with_*` setters.
#[derive(Clone, Debug, PartialEq, Eq)]
#[non_exhaustive]
pub struct RepairOptions {
    /// Components with at most this many faces, when a larger component exists, have their
    /// faces dropped and their vertices left to the data only (they are still data points, but
    /// get no control points of their own: scan debris would otherwise cost three or four
    /// control vertices per speck). Default 4; 0 keeps every component.
    pub data_only_faces: usize,
}

impl Default for RepairOptions {
    fn default() -> RepairOptions {
        RepairOptions { data_only_faces: 4 }
    }
}

impl RepairOptions {
    /// Sets [`RepairOptions::data_only_faces`].
    pub fn with_data_only_faces(mut self, faces: usize) -> RepairOptions {
        self.data_only_faces = faces;
        self
    }
}

/// A repaired mesh, where each of its vertices came from, and what was done.
#[derive(Clone, Debug, PartialEq)]
pub struct Repaired {
    /// An oriented 2-manifold with boundary (possibly several components, possibly with
    /// vertices in no face).
    pub mesh: PolyMesh,
    /// Input vertex of every vertex of `mesh`: vertex `i` of the input stays vertex `i`, and the
    /// copies made by splits follow, each naming the vertex it was split from.
    pub vertex_origin: Vec<u32>,
    /// What was found and changed.
    pub report: RepairReport,
}

/// Repairs `mesh` with default options; see [`repair_with`].
pub fn repair(mesh: &PolyMesh) -> Result<Repaired, MeshError> {
    repair_with(mesh, &RepairOptions::default())
}

/// Turns `mesh` into an oriented 2-manifold with boundary (see the [module docs](self)).
///
/// Coordinates are finite and indices in range by [`PolyMesh`]'s own checks, so the only error
/// is [`MeshError::TooLarge`], when the vertex copies overflow `u32` indexing. Deterministic:
/// the same mesh gives the same result.
pub fn repair_with(mesh: &PolyMesh, options: &RepairOptions) -> Result<Repaired, MeshError> {
    let mut report = RepairReport::default();
    progress::report(Phase::Repair, 0.0);
    let soup = clean::clean(mesh, &mut report);
    progress::report(Phase::Repair, 0.3);
    let mut work = Work {
        soup,
        positions: mesh.positions().to_vec(),
        origin: (0..mesh.num_vertices() as u32).collect(),
        report,
    };
    let orientation = work.make_manifold()?;
    progress::report(Phase::Repair, 0.8);
    work.leave_tiny_components(&orientation, options.data_only_faces);
    let repaired = work.finish();
    progress::report(Phase::Repair, 1.0);
    Ok(repaired)
}

/// The state of a repair between its steps.
struct Work {
    soup: Soup,
    positions: Vec<Point3>,
    /// Input vertex of every current vertex.
    origin: Vec<u32>,
    report: RepairReport,
}

impl Work {
    /// Rounds of pairing, orienting and fan splitting until a round finds nothing to cut.
    /// Returns the last round's components.
    ///
    /// The first round detaches the extra faces of crowded edges and cuts clashing glue; a
    /// later round that still finds a crowded edge drops the extra faces instead, and from the
    /// third round on clashing glue drops a face too, so every round either ends the loop or
    /// removes a face: the loop ends.
    fn make_manifold(&mut self) -> Result<Orientation, MeshError> {
        let mut round = 0;
        loop {
            let pairing = edges::pair(&self.soup, self.positions.len());
            if !pairing.duplicates.is_empty() {
                self.drop_faces(&pairing.duplicates, Kind::Duplicate);
                continue;
            }
            let crowded = !pairing.crowded.is_empty();
            if crowded && round > 0 {
                self.drop_faces(&self.faces_of(&pairing.unpaired), Kind::Crowded);
                continue;
            }
            self.record_crowded(&pairing);
            let mut twin = pairing.twin;
            let orientation = orient::orient(&self.soup, &mut twin);
            if !orientation.cut.is_empty() && round > 1 {
                self.drop_faces(&self.faces_of(&orientation.cut), Kind::Crowded);
                continue;
            }
            self.record_orientation(&orientation);
            self.split_fans(&twin, &orientation)?;
            if !crowded && orientation.cut.is_empty() {
                return Ok(orientation);
            }
            round += 1;
        }
    }

    /// The faces of `corners`, deduplicated and in order.
    fn faces_of(&self, corners: &[u32]) -> Vec<u32> {
        let mut faces: Vec<u32> = corners
            .iter()
            .map(|&c| self.soup.face_of(c as usize) as u32)
            .collect();
        faces.sort_unstable();
        faces.dedup();
        faces
    }

    /// Drops `faces` of the soup, counting them as `kind`.
    fn drop_faces(&mut self, faces: &[u32], kind: Kind) {
        let mut drop = vec![false; self.soup.faces()];
        for &f in faces {
            drop[f as usize] = true;
            let input = self.soup.origin[f as usize] as usize;
            match kind {
                Kind::Duplicate => self.report.duplicate_faces.add(input),
                Kind::Crowded => self.report.dropped_faces.add(input),
            }
        }
        self.soup = self.soup.without(&drop);
    }

    /// The input vertex pair of edge `[a, b]`.
    fn input_edge(&self, [a, b]: [u32; 2]) -> [u32; 2] {
        let (a, b) = (self.origin[a as usize], self.origin[b as usize]);
        [a.min(b), a.max(b)]
    }

    fn record_crowded(&mut self, pairing: &edges::Pairing) {
        for &e in &pairing.crowded {
            let edge = self.input_edge(e);
            self.report.non_manifold_edges.add(edge);
        }
        for f in self.faces_of(&pairing.unpaired) {
            let input = self.soup.origin[f as usize] as usize;
            self.report.detached_faces.add(input);
        }
    }

    fn record_orientation(&mut self, o: &Orientation) {
        for (f, _) in o.flip.iter().enumerate().filter(|(_, &x)| x) {
            self.report.flipped_faces.add(self.soup.origin[f] as usize);
        }
        for &c in &o.cut {
            let c = c as usize;
            let edge = [self.soup.idx[c], self.soup.idx[self.soup.next(c)]];
            let edge = self.input_edge(edge);
            self.report.cut_edges.add(edge);
        }
        self.report.non_orientable_components += o.non_orientable;
    }

    /// Gives every fan its own vertex and turns the flipped faces over.
    fn split_fans(&mut self, twin: &[u32], o: &Orientation) -> Result<(), MeshError> {
        let fans = fans::split(&self.soup, twin, self.positions.len());
        if u32::try_from(self.positions.len() + fans.copy_of.len()).is_err() {
            return Err(MeshError::TooLarge {
                what: "vertex count after splitting non-manifold vertices",
            });
        }
        for &v in &fans.split {
            self.report
                .non_manifold_vertices
                .add(self.origin[v as usize] as usize);
        }
        self.report.vertices_added += fans.copy_of.len();
        for &v in &fans.copy_of {
            self.positions.push(self.positions[v as usize]);
            self.origin.push(self.origin[v as usize]);
        }
        self.soup.idx = fans.corner_vertex;
        for (f, _) in o.flip.iter().enumerate().filter(|(_, &x)| x) {
            self.soup.reverse(f);
        }
        Ok(())
    }

    /// Drops the faces of components with at most `max_faces` faces when a larger one exists.
    fn leave_tiny_components(&mut self, o: &Orientation, max_faces: usize) {
        let largest = o.sizes.iter().copied().max().unwrap_or(0);
        let tiny = |c: u32| o.sizes[c as usize] <= max_faces && o.sizes[c as usize] < largest;
        let mut seen = vec![false; o.sizes.len()];
        let mut drop = vec![false; self.soup.faces()];
        for (f, &c) in o.component.iter().enumerate() {
            if tiny(c) {
                drop[f] = true;
                self.report.components.data_only_faces += 1;
                if !std::mem::replace(&mut seen[c as usize], true) {
                    let input = self.soup.origin[f] as usize;
                    self.report.components.data_only.add(input);
                }
            }
        }
        let mut sizes = o.sizes.clone();
        sizes.sort_unstable_by(|a, b| b.cmp(a));
        sizes.truncate(Found::<usize>::SHOWN);
        self.report.components.count = o.sizes.len();
        self.report.components.largest_faces = sizes;
        if self.report.components.data_only_faces > 0 {
            self.soup = self.soup.without(&drop);
        }
    }

    /// The repaired mesh, with the vertices in no face and the polygons counted.
    fn finish(mut self) -> Repaired {
        let mut used = vec![false; self.positions.len()];
        for &v in &self.soup.idx {
            used[v as usize] = true;
        }
        for (v, _) in used.iter().enumerate().filter(|(_, &u)| !u) {
            self.report
                .unreferenced_vertices
                .add(self.origin[v] as usize);
        }
        self.report.polygons = (0..self.soup.faces())
            .filter(|&f| self.soup.face(f).len() > 3)
            .count();
        self.report.summarise();
        let (starts, idx) = self.soup.into_parts();
        Repaired {
            mesh: PolyMesh::from_parts_unchecked(self.positions, starts, idx),
            vertex_origin: self.origin,
            report: self.report,
        }
    }
}

/// Why faces are dropped.
#[derive(Clone, Copy)]
enum Kind {
    Duplicate,
    Crowded,
}
