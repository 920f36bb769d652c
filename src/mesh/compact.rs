//! [`TetMesh::compact`]: the one place where ids move.

use super::fasthash::{FastHashMap, FastHashSet};
use super::{TetMesh, DEAD, NO_ADJ};

/// Where ids went in a [`TetMesh::compact`]: `old → new`, [`DEAD`] for removed.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct Remap {
    /// New id of each old point slot.
    pub points: Vec<u32>,
    /// New id of each old tet slot.
    pub tets: Vec<u32>,
}

impl TetMesh {
    /// Removes dead tet slots and points no live tet uses, keeping the order of
    /// what remains, and renumbers adjacency and tags. Tags on removed points
    /// are dropped.
    pub fn compact(&mut self) -> Remap {
        let nt = self.tets.len();
        let mut tet_map = vec![DEAD; nt];
        let mut next = 0u32;
        for (t, m) in tet_map.iter_mut().enumerate() {
            if self.tets[t][0] != DEAD {
                *m = next;
                next += 1;
            }
        }
        let mut used = vec![false; self.points.len()];
        for v in self.tets.iter().filter(|v| v[0] != DEAD) {
            for &x in v {
                used[x as usize] = true;
            }
        }
        let mut point_map = vec![DEAD; self.points.len()];
        let mut np = 0u32;
        for (p, m) in point_map.iter_mut().enumerate() {
            if used[p] {
                *m = np;
                np += 1;
            }
        }

        let keep = |t: usize| tet_map[t] != DEAD;
        let mut w = 0;
        for t in 0..nt {
            if !keep(t) {
                continue;
            }
            let v = self.tets[t].map(|x| point_map[x as usize]);
            let a = self.adj[t].map(|h| {
                if h == NO_ADJ {
                    NO_ADJ
                } else {
                    4 * tet_map[(h >> 2) as usize] + (h & 3)
                }
            });
            self.tets[w] = v;
            self.adj[w] = a;
            self.generation[w] = 0;
            self.region[w] = self.region[t];
            self.level[w] = self.level[t];
            self.parent[w] = self.parent[t];
            w += 1;
        }
        self.tets.truncate(w);
        self.adj.truncate(w);
        self.generation.truncate(w);
        self.region.truncate(w);
        self.level.truncate(w);
        self.parent.truncate(w);
        self.free.clear();

        let mut pw = 0;
        for (p, &u) in used.iter().enumerate() {
            if u {
                self.points[pw] = self.points[p];
                pw += 1;
            }
        }
        self.points.truncate(pw);
        self.rebuild_v2t();

        let pm = |v: u32| point_map[v as usize];
        self.face_markers = self
            .face_markers
            .drain()
            .filter(|(k, _)| k.iter().all(|&v| pm(v) != DEAD))
            .map(|(k, m)| (super::face_key(k.map(pm)), m))
            .collect::<FastHashMap<_, _>>();
        self.feature_edges = self
            .feature_edges
            .drain()
            .filter(|(k, _)| k.iter().all(|&v| pm(v) != DEAD))
            .map(|(k, m)| (super::edge_key(pm(k[0]), pm(k[1])), m))
            .collect::<FastHashMap<_, _>>();
        self.corners = self
            .corners
            .iter()
            .map(|&v| pm(v))
            .filter(|&v| v != DEAD)
            .collect::<FastHashSet<_>>();
        self.required = self
            .required
            .iter()
            .map(|&v| pm(v))
            .filter(|&v| v != DEAD)
            .collect::<FastHashSet<_>>();
        Remap {
            points: point_map,
            tets: tet_map,
        }
    }
}
