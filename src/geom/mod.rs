//! Geometry: exact orientation predicates and tetrahedron quality measures.

pub mod predicates;
pub mod quality;

pub use predicates::{orient3d, orient3d_sign, Orientation};
pub use quality::{
    dihedral_angles, tet_min_sine, tet_quality, tet_volume, TetQuality, TET_EDGES,
    TET_EDGE_OPPOSITE, TET_FACES,
};
