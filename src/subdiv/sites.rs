//! Where Doo–Sabin's patches sit: one per corner of the extended control mesh (the mesh with
//! its ring of ghost faces), with what evaluation and walking across patch edges need.

use super::doo_sabin::{extend, Extended};
use super::topo::{Topo, NO};

/// Doo–Sabin's patches: one per corner of the extended mesh (control mesh with its ghost ring)
/// at a vertex that is not a ghost copy, with what walking across patch edges needs.
pub(crate) struct DooSabinSites {
    /// The extended mesh.
    pub ext: Extended,
    /// (extended face, extended vertex) of every patch.
    pub sites: Vec<(u32, u32)>,
    /// Patch of every corner of the extended mesh (`NO` at ghost copies).
    pub corner_patch: Vec<u32>,
}

impl DooSabinSites {
    pub(crate) fn new(topo: &Topo) -> DooSabinSites {
        let ext = extend(topo);
        let t = &ext.topo;
        let mut sites = Vec::new();
        let mut corner_patch = vec![NO; t.face_verts.len()];
        for f in 0..t.num_faces() as u32 {
            let s = t.face_starts[f as usize] as usize;
            for (i, &v) in t.face(f).iter().enumerate() {
                if !ext.ghost[v as usize] {
                    corner_patch[s + i] = sites.len() as u32;
                    sites.push((f, v));
                }
            }
        }
        DooSabinSites {
            ext,
            sites,
            corner_patch,
        }
    }

    /// (control face, control vertex) of every patch: a ghost face reports the control face on
    /// whose cut edge it sits.
    pub(crate) fn control_sites(&self) -> Vec<(u32, u32)> {
        let e = &self.ext;
        self.sites
            .iter()
            .map(|&(f, v)| {
                let face = if (f as usize) < e.real_faces {
                    f
                } else {
                    e.ghost_of[f as usize - e.real_faces]
                };
                (face, e.owner[v as usize])
            })
            .collect()
    }
}
