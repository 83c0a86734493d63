//! What a repair changed: counts per kind, the first few places of each, and a one-line summary.

use serde::Serialize;

/// How many places of one kind were found, with the first few of them (input indices).
#[derive(Clone, Debug, Default, PartialEq, Eq, Serialize)]
pub struct Found<T> {
    /// How many.
    pub count: usize,
    /// The first [`Found::SHOWN`] of them, in the order they were met.
    pub first: Vec<T>,
}

impl<T> Found<T> {
    /// How many places a report lists by index.
    pub const SHOWN: usize = 5;

    /// Counts `item`, and keeps it if fewer than [`Found::SHOWN`] are kept.
    pub(crate) fn add(&mut self, item: T) {
        self.count += 1;
        if self.first.len() < Self::SHOWN {
            self.first.push(item);
        }
    }
}

/// The connected components of the repaired mesh (faces joined across shared edges).
#[derive(Clone, Debug, Default, PartialEq, Eq, Serialize)]
#[non_exhaustive]
pub struct Components {
    /// Number of components with faces, the data-only ones included.
    pub count: usize,
    /// Face counts of the largest components, largest first (at most [`Found::SHOWN`]).
    pub largest_faces: Vec<usize>,
    /// Components so small that their faces were dropped and their vertices left to the data
    /// only (see [`RepairOptions::data_only_faces`](super::RepairOptions::data_only_faces));
    /// `first` holds an input face of each.
    pub data_only: Found<usize>,
    /// Faces of the data-only components.
    pub data_only_faces: usize,
}

/// What [`repair`](super::repair) found and changed. Face indices are the input's faces,
/// vertex indices the input's vertices.
#[derive(Clone, Debug, Default, PartialEq, Eq, Serialize)]
#[non_exhaustive]
pub struct RepairReport {
    /// One line for people: `"repaired: 3 non-manifold vertices split, 12 degenerate faces
    /// dropped"`, or `"nothing to repair"`.
    pub summary: String,
    /// Vertices whose faces formed several fans; each fan got its own copy of the vertex.
    pub non_manifold_vertices: Found<usize>,
    /// Vertices added by those splits.
    pub vertices_added: usize,
    /// Edges shared by more than two faces (as input vertex pairs).
    pub non_manifold_edges: Found<[u32; 2]>,
    /// Faces beyond two on such an edge, detached from it onto their own vertex copies.
    pub detached_faces: Found<usize>,
    /// Faces beyond two that could not be detached (their fans join elsewhere), dropped.
    pub dropped_faces: Found<usize>,
    /// Faces that use a vertex twice (or have fewer than three distinct vertices), dropped.
    pub degenerate_faces: Found<usize>,
    /// Faces of zero area (collinear or coincident corners), dropped.
    pub zero_area_faces: Found<usize>,
    /// Faces with the same vertices as an earlier face, dropped.
    pub duplicate_faces: Found<usize>,
    /// Faces turned over so that each component is consistently oriented (the orientation of
    /// the majority of a component's faces is kept).
    pub flipped_faces: Found<usize>,
    /// Components that cannot be oriented (Möbius-like); each was cut open along edges
    /// (listed in `cut_edges`) until it could be.
    pub non_orientable_components: usize,
    /// Edges cut open to orient non-orientable components (as input vertex pairs).
    pub cut_edges: Found<[u32; 2]>,
    /// Vertices in no face: kept, as data points.
    pub unreferenced_vertices: Found<usize>,
    /// Faces with more than three corners (kept as they are).
    pub polygons: usize,
    /// The components.
    pub components: Components,
}

impl RepairReport {
    /// Whether the repair changed the mesh (vertices in no face and polygons are not changes).
    pub fn changed(&self) -> bool {
        self.vertices_added > 0
            || self.dropped_faces.count
                + self.degenerate_faces.count
                + self.zero_area_faces.count
                + self.duplicate_faces.count
                + self.flipped_faces.count
                + self.detached_faces.count
                + self.cut_edges.count
                + self.components.data_only_faces
                > 0
    }

    /// Sets [`RepairReport::summary`] from the counts.
    pub(crate) fn summarise(&mut self) {
        let parts: Vec<String> = [
            (
                self.non_manifold_vertices.count,
                "non-manifold vertices split",
            ),
            (
                self.detached_faces.count,
                "faces detached from non-manifold edges",
            ),
            (
                self.dropped_faces.count,
                "faces dropped at non-manifold edges",
            ),
            (self.degenerate_faces.count, "degenerate faces dropped"),
            (self.zero_area_faces.count, "zero-area faces dropped"),
            (self.duplicate_faces.count, "duplicate faces dropped"),
            (
                self.flipped_faces.count,
                "faces flipped to a consistent orientation",
            ),
            (
                self.cut_edges.count,
                "edges cut to orient non-orientable parts",
            ),
            (
                self.components.data_only_faces,
                "faces of tiny components left to the data only",
            ),
        ]
        .into_iter()
        .filter(|(n, _)| *n > 0)
        .map(|(n, what)| format!("{n} {what}"))
        .collect();
        let mut line = if parts.is_empty() {
            "nothing to repair".to_string()
        } else {
            format!("repaired: {}", parts.join(", "))
        };
        if self.unreferenced_vertices.count > 0 {
            line += &format!(
                "; {} vertices in no face kept as data points",
                self.unreferenced_vertices.count
            );
        }
        self.summary = line;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn summary_lists_what_changed_or_says_nothing_did() {
        let mut r = RepairReport::default();
        r.summarise();
        assert_eq!(r.summary, "nothing to repair");
        assert!(!r.changed());
        for v in 0..7 {
            r.non_manifold_vertices.add(v);
        }
        r.degenerate_faces.add(4);
        r.unreferenced_vertices.add(9);
        r.summarise();
        assert_eq!(
            r.summary,
            "repaired: 7 non-manifold vertices split, 1 degenerate faces dropped; \
             1 vertices in no face kept as data points"
        );
        assert_eq!(r.non_manifold_vertices.first, vec![0, 1, 2, 3, 4]);
        assert!(r.changed());
    }
}
