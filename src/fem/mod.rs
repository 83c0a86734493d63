//! Quadrilateral meshes of fitted surfaces for finite-element analysis (SPEC §2: "a quad mesh
//! of the fitted surface for FEM").
//!
//! - **B-spline surface** ([`mesh_bspline`]): a structured mesh of u and v parameter lines. The
//!   lines are placed by equidistributing ∫ ds / h along each direction, h the local element
//!   size (see [`FemOptions::grading`]): the flat-size part the largest over the other
//!   direction so no element is longer than L, the curvature part its mean; elements follow the parameter lines, and since the lines
//!   increase strictly no element inverts in the parameter plane. An optional inside test on
//!   (u, v) trims the mesh to the data: an element is kept when at least one of its corners is
//!   inside, dropped when all four are outside.
//! - **Catmull–Clark limit surface** ([`mesh_limit`]): every control quad is a patch, meshed
//!   with a k_u × k_v grid of its limit surface; nodes on control edges and vertices are shared
//!   between patches. Opposite edges of a quad must have the same count, so the counts are
//!   chosen per strip of quads (edges linked through opposite sides of quads), the largest any
//!   quad of the strip asks for.
//!
//! Element size comes from a target edge length L or an element count N
//! ([`FemSize`]); the mesh is written as OBJ quads or Gmsh MSH 4.1
//! ([`io::write_msh`](crate::io::write_msh)) from [`FemMesh::mesh`], and its quality is
//! [`FemQuality`].
//!
//! ```
//! use geofit::fem::{mesh_bspline, FemOptions};
//! use geofit::geom::Point3;
//! use geofit::spline::{BSplineSurface, KnotVector};
//!
//! // A bilinear 2 × 1 rectangle, meshed with elements of about 0.25.
//! let k = || KnotVector::clamped_uniform(1, 2);
//! let ctrl = vec![Point3::ZERO, Point3::Y, Point3::new(2.0, 0.0, 0.0), Point3::new(2.0, 1.0, 0.0)];
//! let s = BSplineSurface::try_new(k()?, k()?, ctrl)?;
//! let fem = mesh_bspline(&s, &FemOptions::default().with_edge(0.25), None)?;
//! assert_eq!(fem.quality().elements, 8 * 4);
//! assert_eq!(fem.quality().inverted, 0);
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

mod bspline;
mod grading;
mod limit;
mod quality;

pub use bspline::mesh_bspline;
pub use grading::MAX_REFINEMENT;
pub use limit::mesh_limit;
pub use quality::FemQuality;

use crate::fit::{outline_on, Fitter, Spline};
use crate::geom::{Point3, Vec3};
use crate::mesh::{MeshError, PolyMesh};
use crate::spline::{BSplineSurface, TrimOptions, TrimRegion};
use thiserror::Error;

/// The most elements a FEM mesh may have (about 0.5 GB of nodes and quads): a size or count
/// that asks for more is an error, not an allocation failure.
pub const MAX_ELEMENTS: usize = 10_000_000;

/// How large the elements are.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum FemSize {
    /// Target edge length L in model units: the element size where the surface is flat.
    Edge(f64),
    /// About this many elements (the size L is found for it).
    Count(usize),
}

/// What the FEM mesher does.
#[derive(Clone, Copy, Debug, PartialEq)]
#[non_exhaustive]
pub struct FemOptions {
    /// Element size; default 10,000 elements.
    pub size: FemSize,
    /// Curvature grading g ≥ 0: the local element size is h = L / (1 + g κ L) (at least
    /// L / [`MAX_REFINEMENT`]) with κ the
    /// largest principal curvature, so where the radius of curvature is far below L there are
    /// about g elements per radian of turning. 0 gives uniform elements; default 4.
    pub grading: f64,
    /// A fitted B-spline surface is meshed only over its data's outline, the region its STEP
    /// and IGES exports are trimmed to (default on): past the data the surface is
    /// extrapolation, and it folds there more often than anywhere.
    pub trim: bool,
}

impl Default for FemOptions {
    fn default() -> Self {
        FemOptions {
            size: FemSize::Count(10_000),
            grading: 4.0,
            trim: true,
        }
    }
}

impl FemOptions {
    /// Elements of edge length about `length` (model units) where the surface is flat.
    pub fn with_edge(mut self, length: f64) -> Self {
        self.size = FemSize::Edge(length);
        self
    }

    /// About `count` elements.
    pub fn with_count(mut self, count: usize) -> Self {
        self.size = FemSize::Count(count);
        self
    }

    /// The curvature grading g (0: uniform).
    pub fn with_grading(mut self, grading: f64) -> Self {
        self.grading = grading;
        self
    }

    /// Whether a fitted B-spline surface is trimmed to its data ([`FemOptions::trim`]).
    pub fn with_trim(mut self, trim: bool) -> Self {
        self.trim = trim;
        self
    }

    /// Checks the size, count and grading.
    pub fn validate(&self) -> Result<(), FemError> {
        match self.size {
            FemSize::Edge(l) if !l.is_finite() || l <= 0.0 => {
                return Err(FemError::Invalid {
                    what: "element size",
                    expected: "a positive finite length",
                    value: l,
                })
            }
            FemSize::Count(n) if n == 0 || n > MAX_ELEMENTS => {
                return Err(FemError::Invalid {
                    what: "element count",
                    expected: "between 1 and 10,000,000",
                    value: n as f64,
                })
            }
            _ => {}
        }
        if !self.grading.is_finite() || self.grading < 0.0 {
            return Err(FemError::Invalid {
                what: "grading",
                expected: "a finite number ≥ 0",
                value: self.grading,
            });
        }
        Ok(())
    }
}

/// Why a FEM mesh could not be made.
///
/// ```
/// use geofit::fem::{FemError, FemOptions};
/// let err = FemOptions::default().with_edge(-1.0).validate().unwrap_err();
/// assert_eq!(err.to_string(), "FEM element size must be a positive finite length, got -1");
/// ```
#[derive(Debug, Error, Clone, PartialEq)]
#[non_exhaustive]
pub enum FemError {
    /// An option is out of range.
    #[error("FEM {what} must be {expected}, got {value}")]
    Invalid {
        /// Which option.
        what: &'static str,
        /// What it must be.
        expected: &'static str,
        /// What was given.
        value: f64,
    },
    /// The size asks for more than [`MAX_ELEMENTS`] elements.
    #[error(
        "the FEM mesh would have about {estimated:.3e} elements, more than the {max} allowed; \
         give a larger element size or a smaller count"
    )]
    TooMany {
        /// Elements the size asks for.
        estimated: f64,
        /// The limit.
        max: usize,
    },
    /// A control face of a Catmull–Clark surface is not a quad.
    #[error("control face {face} has {sides} sides; the FEM mesh of a limit surface needs quads")]
    NotQuad {
        /// The face.
        face: u32,
        /// Its number of sides.
        sides: usize,
    },
    /// The surface has no FEM mesh (a curve, a Loop or Doo–Sabin surface).
    #[error("{what}")]
    Unsupported {
        /// What was asked for and why it cannot be given.
        what: String,
    },
    /// The inside test keeps no element.
    #[error("the trim keeps no element of the FEM mesh")]
    Empty,
    /// The nodes are not a valid mesh (a surface point beyond the coordinate range).
    #[error(transparent)]
    Mesh(#[from] MeshError),
}

/// A FEM quad mesh and its quality.
#[derive(Clone, Debug)]
pub struct FemMesh {
    mesh: PolyMesh,
    quality: FemQuality,
}

impl FemMesh {
    /// The nodes and quadrilaterals (counter-clockwise seen from the side the surface normal
    /// S_u × S_v points to), for [`io::write_obj`](crate::io::write_obj) and
    /// [`io::write_msh`](crate::io::write_msh).
    pub fn mesh(&self) -> &PolyMesh {
        &self.mesh
    }

    /// The element quality.
    pub fn quality(&self) -> &FemQuality {
        &self.quality
    }

    /// The mesh of `quads` over the nodes they use (the others are dropped and the rest
    /// renumbered in order), with `normals` the unit surface normal per node.
    fn assemble(
        nodes: Vec<Point3>,
        normals: Vec<Vec3>,
        mut quads: Vec<[u32; 4]>,
    ) -> Result<FemMesh, FemError> {
        if quads.is_empty() {
            return Err(FemError::Empty);
        }
        let mut map = vec![u32::MAX; nodes.len()];
        for q in &quads {
            for &v in q {
                map[v as usize] = 0;
            }
        }
        let (mut kept, mut kept_normals) = (Vec::new(), Vec::new());
        for (i, m) in map.iter_mut().enumerate() {
            if *m == 0 {
                *m = kept.len() as u32;
                kept.push(nodes[i]);
                kept_normals.push(normals[i]);
            }
        }
        for q in &mut quads {
            *q = q.map(|v| map[v as usize]);
        }
        let quality = quality::measure(&kept, &kept_normals, &quads);
        Ok(FemMesh {
            mesh: PolyMesh::try_new(kept, &quads)?,
            quality,
        })
    }
}

/// The FEM mesh of a fit's surface: its B-spline surface, or its Catmull–Clark limit surface.
pub fn mesh_fit(fit: &dyn Fitter, options: &FemOptions) -> Result<FemMesh, FemError> {
    if let Some(Spline::Surface { surface, params }) = fit.spline() {
        let region = options.trim.then(|| data_region(surface, params)).flatten();
        return mesh_bspline(surface, options, region.as_ref());
    }
    match fit.subdiv_surface() {
        Some(surface) => mesh_limit(surface, options),
        None => Err(FemError::Unsupported {
            what: "a FEM quad mesh needs a surface (B-spline or Catmull–Clark); a curve has none"
                .into(),
        }),
    }
}

/// The outline of the data's parameters on `surface`, as the exports trim to; `None` where the
/// data give no region (too few points, all in a line), and the mesh is then untrimmed as the
/// exports are.
fn data_region(surface: &BSplineSurface, params: &[[f64; 2]]) -> Option<TrimRegion> {
    outline_on(surface, params, &TrimOptions::default())
        .ok()
        .map(|o| o.region)
}
