//! Partition faces: the faces where a distributed mesh is cut between two
//! ranks, carried as face markers in a reserved range so that every
//! renumbering, split and compaction that keeps markers keeps them too.
//!
//! A partition face is refined like a linear interface by every phase of the
//! √3 step: split 1-3 at its centroid (computed from its corners in a
//! canonical order, so both ranks create bit-identical points), its edges
//! never flipped nor trisected, its points never moved. On one rank it is a
//! boundary face of the local mesh; in a serial run the same face may be an
//! interior face carrying the marker, and the step then does exactly what the
//! two ranks do together (the distributed tests compare the counts).
//!
//! Encoding, from [`PARTITION_MARKER_BASE`] = `i32::MIN + 1` upwards
//! (`i32::MIN` itself is the improvement passes' "no marker"):
//!
//! ```text
//!   marker = BASE + 2 * (neighbour * USER_SLOTS + user_slot) + hold
//! ```
//!
//! `neighbour` is the rank on the other side, `user_slot` the 1-based index
//! of the face's own marker in a table the driver keeps (0: none), and `hold`
//! says the other side's tet is not refined in this step, so the face must
//! stay whole. Markers in `[BASE, BASE + 2^30)` are reserved; the distributed
//! driver refuses input files that use them.

use glam::DVec3;

/// The lowest partition marker.
pub const PARTITION_MARKER_BASE: i32 = i32::MIN + 1;
/// How many markers above [`PARTITION_MARKER_BASE`] are reserved.
const RESERVED: i64 = 1 << 30;
/// User markers a cut face can carry besides its partition (slot 0: none).
pub const USER_SLOTS: u32 = 1024;

/// A decoded partition marker.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct PartitionMarker {
    /// The rank on the other side of the face.
    pub neighbour: u32,
    /// 1-based slot of the face's own marker in the driver's table, 0 for
    /// none.
    pub user_slot: u32,
    /// The face must not be split in this step (the other side's tet is not
    /// refined).
    pub hold: bool,
}

impl PartitionMarker {
    /// The marker value, or `None` when the neighbour or slot is out of the
    /// encodable range.
    pub fn encode(self) -> Option<i32> {
        if self.user_slot >= USER_SLOTS {
            return None;
        }
        let code = 2
            * (i64::from(self.neighbour) * i64::from(USER_SLOTS) + i64::from(self.user_slot))
            + i64::from(self.hold);
        (code < RESERVED).then(|| (i64::from(PARTITION_MARKER_BASE) + code) as i32)
    }

    /// Decodes `m`, or `None` when it is an ordinary marker.
    pub fn decode(m: i32) -> Option<PartitionMarker> {
        let code = i64::from(m) - i64::from(PARTITION_MARKER_BASE);
        if !(0..RESERVED).contains(&code) {
            return None;
        }
        let slots = i64::from(USER_SLOTS);
        Some(PartitionMarker {
            neighbour: (code / 2 / slots) as u32,
            user_slot: (code / 2 % slots) as u32,
            hold: code % 2 == 1,
        })
    }
}

/// The marker of a plain partition face towards rank `neighbour` (no user
/// marker, not held).
pub fn partition_marker(neighbour: u32) -> i32 {
    PartitionMarker {
        neighbour,
        user_slot: 0,
        hold: false,
    }
    .encode()
    .expect("rank within the reserved range")
}

/// Whether `m` is a partition marker.
#[inline]
pub fn is_partition_marker(m: i32) -> bool {
    PartitionMarker::decode(m).is_some()
}

/// The edges of every partition face of `mesh` (none when no marker is a
/// partition marker): the edges no operation may split, flip or trisect,
/// since the rank across would not do the same.
pub(crate) fn partition_edges(mesh: &super::TetMesh) -> std::collections::HashSet<[u32; 2]> {
    use crate::topo::edge_key;
    mesh.face_markers()
        .iter()
        .filter(|(_, &m)| is_partition_marker(m))
        .flat_map(|(f, _)| {
            [
                edge_key(f[0], f[1]),
                edge_key(f[1], f[2]),
                edge_key(f[0], f[2]),
            ]
        })
        .collect()
}

/// The centroid of a triangle computed from its corners sorted by their
/// coordinates: the same bits whichever order the caller lists them in
/// (floating-point addition is commutative but not associative, so
/// `(a + b) + c` and `(b + c) + a` may differ in the last bit). Two ranks
/// splitting the same partition face thus create the same point.
pub fn canonical_centroid(p: [DVec3; 3]) -> DVec3 {
    let mut q = p.map(|x| x.to_array());
    q.sort_by(|a, b| {
        a.iter()
            .zip(b)
            .map(|(x, y)| x.total_cmp(y))
            .find(|o| o.is_ne())
            .unwrap_or(std::cmp::Ordering::Equal)
    });
    let [a, b, c] = q.map(DVec3::from_array);
    (a + b + c) / 3.0
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn markers_round_trip_and_ordinary_markers_are_not_partitions() {
        for (neighbour, user_slot, hold) in [(0, 0, false), (1, 3, true), (524_287, 1023, true)] {
            let m = PartitionMarker {
                neighbour,
                user_slot,
                hold,
            };
            let code = m.encode().unwrap();
            assert_eq!(PartitionMarker::decode(code), Some(m));
            assert!(is_partition_marker(code));
        }
        assert!(PartitionMarker {
            neighbour: 524_288,
            user_slot: 0,
            hold: false
        }
        .encode()
        .is_none());
        for m in [i32::MIN, -1_073_741_823, -1, 0, 1, 7, i32::MAX] {
            assert!(!is_partition_marker(m), "{m}");
        }
    }

    #[test]
    fn the_canonical_centroid_does_not_depend_on_the_order() {
        // Three points whose sums round differently in different orders.
        let p = [
            DVec3::new(0.1, 1e16, 0.3),
            DVec3::new(0.7, 1.0, -0.2),
            DVec3::new(0.2, -1e16, 0.9),
        ];
        let c = canonical_centroid(p);
        for perm in [
            [0, 1, 2],
            [0, 2, 1],
            [1, 0, 2],
            [1, 2, 0],
            [2, 0, 1],
            [2, 1, 0],
        ] {
            let q = perm.map(|i| p[i]);
            assert_eq!(canonical_centroid(q).to_array(), c.to_array());
        }
        // and the naive sum differs for some order: the reason for sorting.
        let naive = |q: [DVec3; 3]| (q[0] + q[1] + q[2]) / 3.0;
        assert_ne!(
            naive([p[0], p[1], p[2]]).y,
            naive([p[0], p[2], p[1]]).y,
            "the fixture must exercise rounding"
        );
    }
}
