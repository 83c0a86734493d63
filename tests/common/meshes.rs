//! Small control meshes for the subdivision tests.

use geofit::geom::Point3;
use geofit::mesh::PolyMesh;

/// Icosahedron: every vertex has valence 5 (all patches extraordinary).
pub fn icosahedron() -> PolyMesh {
    let t = (1.0 + 5f64.sqrt()) / 2.0;
    let p = vec![
        Point3::new(-1.0, t, 0.0),
        Point3::new(1.0, t, 0.0),
        Point3::new(-1.0, -t, 0.0),
        Point3::new(1.0, -t, 0.0),
        Point3::new(0.0, -1.0, t),
        Point3::new(0.0, 1.0, t),
        Point3::new(0.0, -1.0, -t),
        Point3::new(0.0, 1.0, -t),
        Point3::new(t, 0.0, -1.0),
        Point3::new(t, 0.0, 1.0),
        Point3::new(-t, 0.0, -1.0),
        Point3::new(-t, 0.0, 1.0),
    ];
    let f: Vec<[u32; 3]> = vec![
        [0, 11, 5],
        [0, 5, 1],
        [0, 1, 7],
        [0, 7, 10],
        [0, 10, 11],
        [1, 5, 9],
        [5, 11, 4],
        [11, 10, 2],
        [10, 7, 6],
        [7, 1, 8],
        [3, 9, 4],
        [3, 4, 2],
        [3, 2, 6],
        [3, 6, 8],
        [3, 8, 9],
        [4, 9, 5],
        [2, 4, 11],
        [6, 2, 10],
        [8, 6, 7],
        [9, 8, 1],
    ];
    PolyMesh::try_new(p, f).unwrap()
}

/// Octahedron: valence 4 everywhere. Its vertices are ±x, ±y, ±z; its faces go round the ring
/// x, y, −x, −y, first under +z, then (the other way) over −z.
pub fn octahedron() -> PolyMesh {
    let p = vec![
        Point3::X,
        Point3::NEG_X,
        Point3::Y,
        Point3::NEG_Y,
        Point3::Z,
        Point3::NEG_Z,
    ];
    let ring = [0, 2, 1, 3];
    let upper = (0..4).map(|i| [ring[i], ring[(i + 1) % 4], 4]);
    let lower = (0..4).map(|i| [ring[(i + 1) % 4], ring[i], 5]);
    let f: Vec<[u32; 3]> = upper.chain(lower).collect();
    PolyMesh::try_new(p, f).unwrap()
}

/// The (n + 1)² points (i, j, h(i, j)) of an n × n grid of unit squares, row by row.
fn grid_points(n: usize, h: impl Fn(f64, f64) -> f64) -> Vec<Point3> {
    let mut p = Vec::new();
    for j in 0..=n {
        for i in 0..=n {
            let (x, y) = (i as f64, j as f64);
            p.push(Point3::new(x, y, h(x, y)));
        }
    }
    p
}

/// The faces `cell([a, b, c, d])` of the squares of an n × n grid, row by row, where a, b, c, d
/// are the ids of the square's corners (i, j), (i + 1, j), (i + 1, j + 1), (i, j + 1) in
/// `grid_points`.
fn grid_faces<F, const K: usize>(n: usize, cell: impl Fn([u32; 4]) -> [F; K]) -> Vec<F> {
    let id = |i: usize, j: usize| (j * (n + 1) + i) as u32;
    let mut f = Vec::new();
    for j in 0..n {
        for i in 0..n {
            f.extend(cell([
                id(i, j),
                id(i + 1, j),
                id(i + 1, j + 1),
                id(i, j + 1),
            ]));
        }
    }
    f
}

/// An n × n grid of unit squares in the plane z = h(x, y), each split into two triangles along
/// the same diagonal (a regular triangulation: interior valence 6).
pub fn tri_grid(n: usize, h: impl Fn(f64, f64) -> f64) -> PolyMesh {
    let f = grid_faces(n, |[a, b, c, d]| [[a, b, d], [b, c, d]]);
    PolyMesh::try_new(grid_points(n, h), f).unwrap()
}

/// An n × n quad grid in the plane z = h(x, y).
pub fn quad_grid(n: usize, h: impl Fn(f64, f64) -> f64) -> PolyMesh {
    let f = grid_faces(n, |corners| [corners]);
    PolyMesh::try_new(grid_points(n, h), f).unwrap()
}

/// A cube of six quads (valence 3 everywhere).
pub fn cube() -> PolyMesh {
    let mut p = Vec::new();
    for z in [0.0, 1.0] {
        for y in [0.0, 1.0] {
            for x in [0.0, 1.0] {
                p.push(Point3::new(x, y, z));
            }
        }
    }
    let f: Vec<[u32; 4]> = vec![
        [0, 2, 3, 1],
        [4, 5, 7, 6],
        [0, 1, 5, 4],
        [2, 6, 7, 3],
        [0, 4, 6, 2],
        [1, 3, 7, 5],
    ];
    PolyMesh::try_new(p, f).unwrap()
}

/// A deterministic pseudo-random perturbation of every vertex by up to `amount`.
pub fn jitter(mesh: &PolyMesh, amount: f64, seed: u64) -> PolyMesh {
    let mut s = seed
        .wrapping_mul(6364136223846793005)
        .wrapping_add(1442695040888963407);
    let mut rnd = || {
        s = s
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        ((s >> 11) as f64 / (1u64 << 53) as f64) * 2.0 - 1.0
    };
    let p = mesh
        .positions()
        .iter()
        .map(|&q| q + Point3::new(rnd(), rnd(), rnd()) * amount)
        .collect();
    PolyMesh::try_new(p, mesh.faces()).unwrap()
}

/// Every triangle split 1 → 4 at its edge midpoints, `levels` times, without moving anything:
/// the same shape with finer facets.
pub fn refine_flat(mesh: &PolyMesh, levels: usize) -> PolyMesh {
    let mut pts = mesh.positions().to_vec();
    let mut tris = mesh.triangles();
    for _ in 0..levels {
        let mut mid = std::collections::HashMap::new();
        let mut m = |a: u32, b: u32, pts: &mut Vec<Point3>| {
            *mid.entry((a.min(b), a.max(b))).or_insert_with(|| {
                pts.push((pts[a as usize] + pts[b as usize]) * 0.5);
                pts.len() as u32 - 1
            })
        };
        let mut next = Vec::new();
        for [a, b, c] in tris {
            let (ab, bc, ca) = (m(a, b, &mut pts), m(b, c, &mut pts), m(c, a, &mut pts));
            next.extend([[a, ab, ca], [ab, b, bc], [ca, bc, c], [ab, bc, ca]]);
        }
        tris = next;
    }
    PolyMesh::try_new(pts, tris).expect("refined mesh")
}

/// How many crease edges (vertex pairs) each vertex of `edges` has.
pub fn crease_degrees(edges: &[[u32; 2]]) -> std::collections::HashMap<u32, usize> {
    let mut degree = std::collections::HashMap::new();
    for e in edges {
        for v in e {
            *degree.entry(*v).or_insert(0) += 1;
        }
    }
    degree
}

/// Whether `p` lies on an edge of the unit cube: two coordinates within `tol` of 0 or 1.
pub fn on_unit_cube_edge(p: Point3, tol: f64) -> bool {
    let at_face = |x: f64| x.abs() < tol || (x - 1.0).abs() < tol;
    [p.x, p.y, p.z].into_iter().filter(|&x| at_face(x)).count() >= 2
}
