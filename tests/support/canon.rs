//! Helpers shared by the I/O integration tests: a canonical, numbering-free
//! form of a mesh to compare meshes read from different files.

use std::path::Path;
use tetrefine::io::load_mesh;
use tetrefine::TetMesh;

/// A point as the bit patterns of its coordinates.
pub type P = [u64; 3];

fn bits(p: [f64; 3]) -> P {
    p.map(f64::to_bits)
}

/// A mesh described by coordinates only, so that two files that number the
/// same points differently still compare equal. Tets are positively oriented
/// in the store, so their vertex sets fix them up to even permutations.
#[derive(Debug, PartialEq)]
pub struct Canon {
    /// (sorted corner coordinates, region) per tet, sorted.
    pub tets: Vec<([P; 4], i32)>,
    /// (sorted corners, marker) per marked face, sorted.
    pub faces: Vec<([P; 3], i32)>,
    /// (sorted ends, marker) per feature edge, sorted.
    pub edges: Vec<([P; 2], i32)>,
    /// Corner coordinates, sorted.
    pub corners: Vec<P>,
}

/// The canonical form of a mesh.
pub fn canon(mesh: &TetMesh) -> Canon {
    let d = mesh.to_data();
    let pt = |v: u32| bits(d.points[v as usize]);
    let mut tets: Vec<([P; 4], i32)> = d
        .tets
        .iter()
        .enumerate()
        .map(|(t, v)| {
            let mut c = v.map(pt);
            c.sort_unstable();
            (c, d.region(t))
        })
        .collect();
    tets.sort_unstable();
    let mut faces: Vec<([P; 3], i32)> = d
        .triangles
        .iter()
        .map(|(f, m)| {
            let mut c = f.map(pt);
            c.sort_unstable();
            (c, *m)
        })
        .collect();
    faces.sort_unstable();
    let mut edges: Vec<([P; 2], i32)> = d
        .edges
        .iter()
        .map(|(e, m)| {
            let mut c = e.map(pt);
            c.sort_unstable();
            (c, *m)
        })
        .collect();
    edges.sort_unstable();
    let mut corners: Vec<P> = d.corners.iter().map(|&v| pt(v)).collect();
    corners.sort_unstable();
    Canon {
        tets,
        faces,
        edges,
        corners,
    }
}

/// Loads a mesh and fails the test on any error.
pub fn load(path: &Path) -> TetMesh {
    let (mesh, _report) =
        load_mesh(path).unwrap_or_else(|e| panic!("cannot load {}: {e}", path.display()));
    mesh
}

/// Path of a file in the repository's `meshes/` folder.
pub fn mesh_path(name: &str) -> std::path::PathBuf {
    super::path("meshes").join(name)
}

/// Tets per region, sorted by region.
pub fn region_sizes(mesh: &TetMesh) -> Vec<(i32, usize)> {
    let mut m = std::collections::BTreeMap::new();
    for t in mesh.tet_ids() {
        *m.entry(mesh.region(t)).or_insert(0usize) += 1;
    }
    m.into_iter().collect()
}
