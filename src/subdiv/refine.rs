//! Refinement of whole control meshes: one step of a scheme, several steps, and the conversion
//! of any polygon mesh into quads for the quad schemes.

use super::topo::Topo;
use super::{Scheme, SubdivError};
use crate::geom::Point3;
use crate::mesh::ControlMesh;

/// One refinement step of `scheme`. Loop needs triangles; Catmull–Clark and Doo–Sabin take any
/// polygons. Boundary edges follow the curve rules (cubic B-spline for Loop and Catmull–Clark,
/// Chaikin's quadratic for Doo–Sabin, by its ghost ring); sharp edges follow the crease rules and
/// stay sharp.
pub fn refine(scheme: Scheme, mesh: &ControlMesh) -> Result<ControlMesh, SubdivError> {
    if scheme == Scheme::Loop {
        if let Some(f) = (0..mesh.num_faces() as u32).find(|&f| mesh.face_len(f) != 3) {
            return Err(SubdivError::WrongFaceSize {
                face: f as usize,
                len: mesh.face_len(f),
                scheme,
            });
        }
    }
    let topo = Topo::of_control_mesh(mesh);
    let refined = match scheme {
        Scheme::DooSabin => super::doo_sabin::refine_control(&topo),
        _ => super::step::refine_step(&topo, scheme),
    };
    let old = mesh.positions();
    let positions = refined
        .points
        .iter()
        .map(|s| {
            s.as_ref()
                .map(|s| s.iter().map(|&(i, w)| old[i as usize] * w).sum::<Point3>())
                .ok_or(SubdivError::Unevaluable { patch: 0 })
        })
        .collect::<Result<Vec<_>, _>>()?;
    rebuild(positions, &refined.topo)
}

/// `levels` refinement steps.
pub fn refine_levels(
    scheme: Scheme,
    mesh: &ControlMesh,
    levels: usize,
) -> Result<ControlMesh, SubdivError> {
    let mut m = mesh.clone();
    for _ in 0..levels {
        m = refine(scheme, &m)?;
    }
    Ok(m)
}

/// Exact limit positions of the vertices of `mesh` under `scheme` (limit masks), without
/// building an evaluator. For Doo–Sabin the limit point of a vertex is the centroid of its
/// vertex face (kept by every step; at boundaries and creases the vertex face of the mesh with
/// its ghost ring, see [`refine`]).
pub fn limit_positions(scheme: Scheme, mesh: &ControlMesh) -> Result<Vec<Point3>, SubdivError> {
    let topo = Topo::of_control_mesh(mesh);
    let p = mesh.positions();
    let doo_sabin = (scheme == Scheme::DooSabin).then(|| super::doo_sabin::vertex_limits(&topo));
    let stencils = topo.limit_stencils(scheme, mesh.num_vertices(), doo_sabin);
    stencils
        .into_iter()
        .map(|s| {
            let s = s.ok_or(SubdivError::Unevaluable { patch: 0 })?;
            Ok(s.iter().map(|&(i, w)| p[i as usize] * w).sum())
        })
        .collect()
}

/// A quad mesh from any polygon mesh by one Catmull–Clark step (each n-gon gives n quads).
pub fn quadrangulate(mesh: &ControlMesh) -> Result<ControlMesh, SubdivError> {
    refine(Scheme::CatmullClark, mesh)
}

fn rebuild(positions: Vec<Point3>, topo: &Topo) -> Result<ControlMesh, SubdivError> {
    let faces = (0..topo.num_faces() as u32).map(|f| topo.face(f).to_vec());
    let mut mesh = ControlMesh::from_faces(positions, faces).map_err(|e| match e {
        crate::mesh::ControlMeshError::Mesh(m) => SubdivError::Mesh(m),
        crate::mesh::ControlMeshError::Topology(t) => SubdivError::Topology(t),
    })?;
    for (e, &[a, b]) in topo.edges.iter().enumerate() {
        let tag = topo.edge_tags[e];
        if tag.sharp && !tag.open {
            mesh.set_sharp(a, b, true)?;
        }
    }
    Ok(mesh)
}
