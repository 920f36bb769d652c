//! PolyMesh adjacency and validation: Euler characteristic and genus of
//! known surfaces, boundary loops, rings, and each kind of topology error.

use crate::shapes::*;
use glam::DVec3;
use tetrefine_surface::{PolyMesh, TopologyError};

#[test]
fn euler_characteristic_and_genus_of_known_surfaces() {
    // Sphere-like: χ = 2, genus 0; torus: χ = 0, genus 1; disc: χ = 1.
    for (mesh, chi, genus, loops) in [
        (cube(), 2, 0, 0),
        (octahedron(), 2, 0, 0),
        (icosahedron(), 2, 0, 0),
        (quad_torus(5, 4), 0, 1, 0),
        (tri_torus(4, 3), 0, 1, 0),
        (tri_grid(3, 2, |x, y| DVec3::new(x, y, 0.0)), 1, 0, 1),
    ] {
        assert_eq!(mesh.euler_characteristic(), chi);
        let comps = mesh.components().unwrap();
        assert_eq!(comps.len(), 1);
        assert_eq!(comps[0].euler, chi);
        assert_eq!(comps[0].genus, genus);
        assert_eq!(comps[0].boundary_loops, loops);
    }
}

#[test]
fn components_are_counted_separately() {
    // A cube and a torus side by side: two components, genus 0 and 1.
    let a = cube();
    let b = quad_torus(4, 4);
    let off = a.points.len() as u32;
    let mut points = a.points.clone();
    points.extend(b.points.iter().map(|p| *p + DVec3::new(10.0, 0.0, 0.0)));
    let mut faces = a.faces.clone();
    faces.extend(b.faces.iter().map(|f| f.iter().map(|v| v + off).collect()));
    let m = PolyMesh::new(points, faces);
    let mut genus: Vec<i64> = m.components().unwrap().iter().map(|c| c.genus).collect();
    genus.sort();
    assert_eq!(genus, vec![0, 1]);
    assert_eq!(m.euler_characteristic(), 2);
}

#[test]
fn boundary_edges_loops_and_rings() {
    // A 3 × 2 grid of squares cut in triangles: 2(3+2) = 10 boundary edges
    // in one loop; an interior vertex has 6 neighbours in counter-clockwise
    // order; a boundary vertex's ring starts and ends on the boundary.
    let m = tri_grid(3, 2, |x, y| DVec3::new(x, y, 0.0));
    assert_eq!(m.boundary_edges().len(), 10);
    let he = m.half_edges().unwrap();
    let loops = he.boundary_loops();
    assert_eq!(loops.len(), 1);
    assert_eq!(loops[0].len(), 10);
    // Vertex (1,1) has id 1*3+1 = 4.
    let (ring, boundary) = he.ring(4);
    assert!(!boundary);
    assert_eq!(ring.len(), 6);
    let c = m.points[4];
    let mut last: Option<f64> = None;
    for w in ring.iter().chain(ring.first()) {
        let d = m.points[*w as usize] - c;
        let a = d.y.atan2(d.x);
        if let Some(prev) = last {
            let step = (a - prev).rem_euclid(2.0 * std::f64::consts::PI);
            assert!(
                step > 0.0 && step < std::f64::consts::PI,
                "not counter-clockwise"
            );
        }
        last = Some(a);
    }
    // Corner (0,0): neighbours (1,0), (1,1), (0,1), boundary at both ends.
    let (ring, boundary) = he.ring(0);
    assert!(boundary);
    assert_eq!(ring, vec![3, 4, 1]);
    assert_eq!(he.valences()[4], 6);
}

#[test]
fn topology_errors_name_faces_and_vertices() {
    let p = |n: usize| {
        (0..n)
            .map(|i| DVec3::new(i as f64, (i * i) as f64, 0.0))
            .collect::<Vec<_>>()
    };
    // Three triangles on edge 0-1.
    let m = PolyMesh::new(p(5), vec![vec![0, 1, 2], vec![1, 0, 3], vec![0, 1, 4]]);
    assert!(matches!(
        m.validate(),
        Err(TopologyError::NonManifoldEdge {
            edge: [0, 1],
            faces: 3
        })
    ));
    // Two triangles running the same way along 0-1.
    let m = PolyMesh::new(p(4), vec![vec![0, 1, 2], vec![0, 1, 3]]);
    let e = m.validate().unwrap_err();
    assert_eq!(
        e,
        TopologyError::InconsistentOrientation {
            edge: [0, 1],
            faces: [0, 1]
        }
    );
    assert!(e.to_string().contains("orientations disagree"));
    // A bow tie: two triangles sharing only vertex 0.
    let m = PolyMesh::new(p(5), vec![vec![0, 1, 2], vec![0, 3, 4]]);
    assert!(matches!(
        m.validate(),
        Err(TopologyError::NonManifoldVertex { vertex: 0, fans: 2 })
    ));
    // Two closed octahedra glued at one vertex are non-manifold there too.
    let a = octahedron();
    let mut points = a.points.clone();
    points.extend(a.points.iter().map(|q| *q + DVec3::new(2.0, 0.0, 0.0)));
    let mut faces = a.faces.clone();
    // Second copy, with its vertex 1 (at −x) replaced by the first copy's vertex 0.
    faces.extend(
        a.faces
            .iter()
            .map(|f| f.iter().map(|&v| if v == 1 { 0 } else { v + 6 }).collect()),
    );
    let m = PolyMesh::new(points, faces);
    assert!(matches!(
        m.validate(),
        Err(TopologyError::NonManifoldVertex { vertex: 0, fans: 2 })
    ));
    // Bad faces.
    let m = PolyMesh::new(p(3), vec![vec![0, 1]]);
    assert_eq!(
        m.validate(),
        Err(TopologyError::FaceTooSmall { face: 0, len: 2 })
    );
    let m = PolyMesh::new(p(3), vec![vec![0, 1, 1]]);
    assert_eq!(
        m.validate(),
        Err(TopologyError::RepeatedVertex { face: 0, vertex: 1 })
    );
    let m = PolyMesh::new(p(3), vec![vec![0, 1, 9]]);
    assert_eq!(
        m.validate(),
        Err(TopologyError::IndexOutOfRange {
            face: 0,
            index: 9,
            points: 3
        })
    );
}
