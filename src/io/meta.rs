//! What a mesh file carries besides the mesh: Gmsh's physical names and the
//! full physical tag lists of its entities, and the point and cell arrays a
//! solver attached (fields). [`MeshData`](crate::mesh::MeshData) and
//! [`TetMesh`](crate::TetMesh) keep one integer per tet (the region), per
//! marked face and per feature edge; this side table says what those integers
//! stand for, so that a writer can give back what a reader was handed.
//!
//! Values are keyed by the integer the mesh stores: `(dim, value)` with dim 3
//! for regions, 2 for face markers and 1 for edge markers. Refinement keeps
//! those integers on every child, so the table survives it unchanged; point
//! fields do not (the points change) and are carried over by
//! [`crate::io::fields`].

use std::collections::BTreeMap;

/// A named array over points or cells: `components` values per entry.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Field {
    /// The array's name (the `.vtu` array name, the Gmsh view name, or
    /// `sol` / `sol_<i>` for a Medit solution).
    pub name: String,
    /// Values per point or cell (1 for a scalar, 3 for a vector, …).
    pub components: usize,
    /// `components` values per entry, entry after entry.
    pub values: Vec<f64>,
}

impl Field {
    /// Number of entries (points or cells) the field covers.
    pub fn len(&self) -> usize {
        self.values.len() / self.components.max(1)
    }

    /// Whether the field covers no entry.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// The values of entry `i`.
    pub fn entry(&self, i: usize) -> &[f64] {
        &self.values[i * self.components..(i + 1) * self.components]
    }
}

/// The side table of a mesh file (see the module documentation).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct MeshMeta {
    /// Gmsh `$PhysicalNames`: `(dim, physical tag) → name`.
    pub physical_names: BTreeMap<(i32, i32), String>,
    /// The physical tags of the entity behind a stored value, when they are
    /// not just `[value]`: `(dim, value) → tags` (an entity in several
    /// physical groups, or one whose first tag was taken by another entity).
    pub tag_sets: BTreeMap<(i32, i32), Vec<i32>>,
    /// Physical tags of point entities (Gmsh point elements), keyed by the
    /// point's coordinates: corners never move, and their ids may change.
    pub point_tags: Vec<([f64; 3], Vec<i32>)>,
    /// Arrays over the points, in point order.
    pub point_fields: Vec<Field>,
    /// Arrays over the tets, in tet order.
    pub cell_fields: Vec<Field>,
}

impl MeshMeta {
    /// The physical tags behind the stored value `value` of dimension `dim`.
    pub fn physical_tags(&self, dim: i32, value: i32) -> Vec<i32> {
        self.tag_sets
            .get(&(dim, value))
            .cloned()
            .unwrap_or_else(|| vec![value])
    }

    /// The physical tags of the point at `p`, if the file gave it any.
    pub fn point_physical_tags(&self, p: [f64; 3]) -> Option<&[i32]> {
        self.point_tags
            .iter()
            .find(|(q, _)| *q == p)
            .map(|(_, t)| t.as_slice())
    }

    /// Whether the table holds nothing.
    pub fn is_empty(&self) -> bool {
        *self == MeshMeta::default()
    }
}

/// Gives every distinct list of physical tags of one dimension the integer the
/// mesh will store for it: its first tag, unless another list (or `reserved`,
/// the entity tags used by elements without a physical tag) has it already;
/// then a fresh integer above every tag in use. Lists in first-seen order.
pub(crate) fn assign_values(
    lists: &[Vec<i32>],
    reserved: &std::collections::BTreeSet<i32>,
) -> Vec<i32> {
    let mut taken: std::collections::BTreeSet<i32> = reserved.clone();
    let mut out = vec![None; lists.len()];
    for (i, l) in lists.iter().enumerate() {
        if let Some(&first) = l.first() {
            if taken.insert(first) {
                out[i] = Some(first);
            }
        }
    }
    let mut next = lists
        .iter()
        .flatten()
        .chain(taken.iter())
        .copied()
        .max()
        .unwrap_or(0)
        .saturating_add(1);
    out.into_iter()
        .map(|v| {
            v.unwrap_or_else(|| {
                let f = next;
                next = next.saturating_add(1);
                f
            })
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn first_tags_are_kept_and_collisions_get_fresh_values() {
        let lists = vec![vec![10, 20], vec![11, 20], vec![10], vec![5]];
        let reserved = [5].into_iter().collect();
        assert_eq!(assign_values(&lists, &reserved), vec![10, 11, 21, 22]);
    }
}
