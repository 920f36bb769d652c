//! Geometry: exact orientation predicates and tetrahedron quality measures.

pub(crate) mod closest;
pub(crate) mod exact;
pub(crate) mod predicates;
pub(crate) mod quality;

pub use closest::{closest_on_segment, closest_point_on_triangle, distance_to_triangle};
pub use exact::{orient2d_exact, orient3d_exact};
pub use predicates::{
    all_positive, is_positive, orient3d, orient3d_sign, positive_in_doubles, Orientation,
};
pub use quality::{dihedral_angles, tet_min_sine, tet_quality, tet_volume, TetQuality};
