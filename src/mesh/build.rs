//! Building a [`TetMesh`] from [`MeshData`]: validation, orientation and face
//! adjacency by bucketing half-faces on their smallest vertex (parallel).

use super::fasthash::{FastHashMap, FastHashSet};
use super::{
    edge_key, edges_present, face_key, faces_present, EdgeKey, FaceKey, MeshData, TetMesh, NO_ADJ,
};
use crate::geom::{orient3d_sign, Orientation};
use crate::topo::scatter::Shared;
use crate::topo::TET_FACES;
use glam::DVec3;
use rayon::prelude::*;
use std::fmt;
use std::sync::atomic::{AtomicU32, Ordering};

/// Why a mesh could not be built. Tet and point numbers in messages are
/// 1-based, as in Medit, Gmsh and most solver files; `line` is the file line
/// when the reader knew it.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum MeshError {
    /// The mesh has no tetrahedra.
    #[error("the mesh has no tetrahedra")]
    Empty,
    /// A coordinate is NaN or infinite.
    #[error("point {point} has a non-finite coordinate {coords:?}")]
    NonFinite {
        /// 1-based point number.
        point: usize,
        /// The coordinates as read.
        coords: [f64; 3],
    },
    /// A tet refers to a point that does not exist.
    #[error("{at}refers to point {index} but the mesh has {n_points} points")]
    IndexOutOfRange {
        /// Where (tet and line).
        at: Where,
        /// The 1-based index found.
        index: u64,
        /// Number of points.
        n_points: usize,
    },
    /// A tet repeats a vertex.
    #[error("{at}repeats a vertex {vertices:?}")]
    RepeatedVertex {
        /// Where (tet and line).
        at: Where,
        /// Its 1-based vertices.
        vertices: [u64; 4],
    },
    /// A tet has zero volume (exact predicate).
    #[error("{at}has zero volume: its four points are coplanar")]
    ZeroVolume {
        /// Where (tet and line).
        at: Where,
    },
    /// Two tets have the same four vertices.
    #[error("{at}duplicates tetrahedron {other}")]
    DuplicateTet {
        /// Where (tet and line).
        at: Where,
        /// 1-based number of the earlier tet.
        other: usize,
    },
    /// More than two tets share one face.
    #[error("{at}shares face {face:?} with {count} tetrahedra in all (a face may have at most two): the mesh is not manifold")]
    NonManifoldFace {
        /// Where (one of the tets and its line).
        at: Where,
        /// 1-based vertex numbers of the face.
        face: [u64; 3],
        /// How many tets hold it.
        count: usize,
    },
    /// Two tets that share a face lie on the same side of it (overlap).
    #[error("{at}overlaps its neighbour across face {face:?}: both lie on the same side of it")]
    Overlap {
        /// Where.
        at: Where,
        /// 1-based face vertices.
        face: [u64; 3],
    },
    /// A tag refers to a point that does not exist.
    #[error("a {what} refers to point {index} but the mesh has {n_points} points")]
    TagOutOfRange {
        /// Which kind of tag (triangle, edge, corner).
        what: &'static str,
        /// 1-based index.
        index: u64,
        /// Number of points.
        n_points: usize,
    },
    /// Region list length does not match tets.
    #[error("{regions} region values for {tets} tetrahedra")]
    RegionCount {
        /// Number of region values.
        regions: usize,
        /// Number of tets.
        tets: usize,
    },
}

/// A position for error messages: 1-based tet number and, if known, file line.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Where {
    /// 1-based tet number.
    pub tet: usize,
    /// 1-based line of the file, if known.
    pub line: Option<u32>,
}

impl fmt::Display for Where {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        // The line, when known, is reported by the caller (as `file:line:`).
        write!(f, "tetrahedron {} ", self.tet)
    }
}

impl MeshError {
    /// The file line the error concerns, if known.
    pub fn line(&self) -> Option<u32> {
        match self {
            MeshError::IndexOutOfRange { at, .. }
            | MeshError::RepeatedVertex { at, .. }
            | MeshError::ZeroVolume { at }
            | MeshError::DuplicateTet { at, .. }
            | MeshError::NonManifoldFace { at, .. }
            | MeshError::Overlap { at, .. } => at.line,
            _ => None,
        }
    }
}

/// What building changed or dropped, for the user to know.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct BuildReport {
    /// Tets given with negative orientation and turned around.
    pub reoriented: usize,
    /// Points no tet uses (kept, but not counted as nodes).
    pub unreferenced_points: usize,
    /// Marked triangles that are not a face of any tet (dropped).
    pub dropped_triangles: usize,
    /// Tagged edges that are not an edge of any tet (dropped).
    pub dropped_edges: usize,
}

fn one_based3(f: [u32; 3]) -> [u64; 3] {
    [f[0] as u64 + 1, f[1] as u64 + 1, f[2] as u64 + 1]
}

impl TetMesh {
    /// Builds the store from plain data, validating everything.
    ///
    /// Negatively oriented tets are turned around (counted in the report);
    /// zero-volume tets, repeated or out-of-range vertices, duplicate tets,
    /// faces shared by more than two tets and non-finite coordinates are
    /// errors. Half-faces are matched by a parallel counting sort on their
    /// smallest vertex.
    pub fn from_data(data: &MeshData) -> Result<(TetMesh, BuildReport), MeshError> {
        let n_points = data.points.len();
        let nt = data.tets.len();
        if nt == 0 {
            return Err(MeshError::Empty);
        }
        if !data.tet_regions.is_empty() && data.tet_regions.len() != nt {
            return Err(MeshError::RegionCount {
                regions: data.tet_regions.len(),
                tets: nt,
            });
        }
        let at = |t: usize| Where {
            tet: t + 1,
            line: data.tet_lines.get(t).copied(),
        };
        if let Some((i, p)) = data
            .points
            .iter()
            .enumerate()
            .find(|(_, p)| !p.iter().all(|c| c.is_finite()))
        {
            return Err(MeshError::NonFinite {
                point: i + 1,
                coords: *p,
            });
        }
        let points: Vec<DVec3> = data.points.iter().map(|p| DVec3::from_array(*p)).collect();

        // Indices, repeated vertices and orientation, in parallel; the first
        // error in tet order wins so that messages are deterministic.
        let oriented: Vec<Result<([u32; 4], bool), MeshError>> = data
            .tets
            .par_iter()
            .enumerate()
            .map(|(t, &v)| {
                if let Some(&bad) = v.iter().find(|&&x| x as usize >= n_points) {
                    return Err(MeshError::IndexOutOfRange {
                        at: at(t),
                        index: bad as u64 + 1,
                        n_points,
                    });
                }
                if v[0] == v[1]
                    || v[0] == v[2]
                    || v[0] == v[3]
                    || v[1] == v[2]
                    || v[1] == v[3]
                    || v[2] == v[3]
                {
                    return Err(MeshError::RepeatedVertex {
                        at: at(t),
                        vertices: v.map(|x| x as u64 + 1),
                    });
                }
                let p = v.map(|x| points[x as usize]);
                match orient3d_sign(p[0], p[1], p[2], p[3]) {
                    Orientation::Positive => Ok((v, false)),
                    Orientation::Negative => Ok(([v[1], v[0], v[2], v[3]], true)),
                    Orientation::Zero => Err(MeshError::ZeroVolume { at: at(t) }),
                }
            })
            .collect();
        let mut tets = Vec::with_capacity(nt);
        let mut reoriented = 0;
        for r in oriented {
            let (v, flipped) = r?;
            reoriented += flipped as usize;
            tets.push(v);
        }

        // Duplicate tets: sort the sorted quadruples.
        let mut quads: Vec<([u32; 4], u32)> = tets
            .par_iter()
            .enumerate()
            .map(|(t, v)| {
                let mut s = *v;
                s.sort_unstable();
                (s, t as u32)
            })
            .collect();
        quads.par_sort_unstable();
        if let Some(w) = quads.windows(2).find(|w| w[0].0 == w[1].0) {
            return Err(MeshError::DuplicateTet {
                at: at(w[1].1 as usize),
                other: w[0].1 as usize + 1,
            });
        }
        drop(quads);

        // Face adjacency: half-faces matched by sorted key.
        let adj = match match_half_faces(&tets, n_points) {
            Ok(adj) => adj,
            Err((h, face, count)) => {
                return Err(MeshError::NonManifoldFace {
                    at: at((h >> 2) as usize),
                    face: one_based3(face),
                    count,
                })
            }
        };

        // Two positive tets sharing a face must lie on opposite sides of it: the
        // neighbour's opposite vertex must be on the side our outward-oriented
        // face points to.
        // Face `f` of `t` has a neighbour on the wrong side of it.
        let overlaps = |t: usize, f: usize| {
            let h = adj[t][f];
            h != NO_ADJ && {
                let l = TET_FACES[f];
                let v = tets[t];
                let o = tets[(h >> 2) as usize][(h & 3) as usize];
                orient3d_sign(
                    points[v[l[0]] as usize],
                    points[v[l[1]] as usize],
                    points[v[l[2]] as usize],
                    points[o as usize],
                ) != Orientation::Positive
            }
        };
        // Each shared face is tested once, from its lower tet.
        let overlap = (0..nt).into_par_iter().find_first(|&t| {
            (0..4).any(|f| adj[t][f] != NO_ADJ && ((adj[t][f] >> 2) as usize) > t && overlaps(t, f))
        });
        if let Some(t) = overlap {
            let f = (0..4)
                .find(|&f| overlaps(t, f))
                .expect("find_first picked t for one of its faces");
            let l = TET_FACES[f];
            let v = tets[t];
            return Err(MeshError::Overlap {
                at: at(t),
                face: one_based3([v[l[0]], v[l[1]], v[l[2]]]),
            });
        }

        let mut referenced = vec![false; n_points];
        for v in &tets {
            for &x in v {
                referenced[x as usize] = true;
            }
        }
        let unreferenced_points = referenced.iter().filter(|&&r| !r).count();

        let mut mesh = TetMesh {
            points,
            region: if data.tet_regions.is_empty() {
                vec![0; nt]
            } else {
                data.tet_regions.clone()
            },
            level: vec![0; nt],
            parent: (0..nt as u32).collect(),
            generation: vec![0; nt],
            tets,
            adj,
            ..Default::default()
        };
        mesh.rebuild_v2t();
        let mut report = BuildReport {
            reoriented,
            unreferenced_points,
            ..Default::default()
        };
        mesh.attach_tags(data, &mut report)?;
        Ok((mesh, report))
    }

    /// Copies the tags of `data` onto the mesh, dropping (and counting) those
    /// that name no face or edge of it.
    fn attach_tags(&mut self, data: &MeshData, report: &mut BuildReport) -> Result<(), MeshError> {
        let n = self.points.len();
        let check = |what: &'static str, v: u32| {
            if v as usize >= n {
                Err(MeshError::TagOutOfRange {
                    what,
                    index: v as u64 + 1,
                    n_points: n,
                })
            } else {
                Ok(())
            }
        };
        for (f, _) in &data.triangles {
            for &v in f {
                check("triangle", v)?;
            }
        }
        for (e, _) in &data.edges {
            for &v in e {
                check("edge", v)?;
            }
        }
        for &v in data.corners.iter().chain(&data.required_vertices) {
            check("vertex tag", v)?;
        }
        if !data.triangles.is_empty() {
            let wanted: FastHashSet<FaceKey> =
                data.triangles.iter().map(|&(f, _)| face_key(f)).collect();
            let faces = faces_present(&self.tets, &wanted);
            for &(f, m) in &data.triangles {
                let k = face_key(f);
                if faces.contains(&k) {
                    self.face_markers.insert(k, m);
                } else {
                    report.dropped_triangles += 1;
                }
            }
        }
        if !data.edges.is_empty() {
            let wanted: FastHashSet<EdgeKey> = data
                .edges
                .iter()
                .map(|&([a, b], _)| edge_key(a, b))
                .collect();
            let edges = edges_present(&self.tets, &wanted);
            let mut tagged = FastHashMap::default();
            for &([a, b], m) in &data.edges {
                let k = edge_key(a, b);
                if edges.contains(&k) {
                    tagged.insert(k, m);
                } else {
                    report.dropped_edges += 1;
                }
            }
            self.feature_edges = tagged;
        }
        self.corners = data.corners.iter().copied().collect();
        self.required = data.required_vertices.iter().copied().collect();
        Ok(())
    }

    /// The mesh as plain data: live tets in id order, every point slot, tags.
    /// Call [`TetMesh::compact`] first for a dense numbering.
    pub fn to_data(&self) -> MeshData {
        let ids: Vec<u32> = self.tet_ids().collect();
        let mut triangles: Vec<([u32; 3], i32)> =
            self.face_markers.iter().map(|(k, &m)| (*k, m)).collect();
        // Boundary faces are written with their outward orientation, as Medit
        // and Gmsh expect; interface faces keep their sorted order.
        let outward: FastHashMap<[u32; 3], [u32; 3]> = ids
            .iter()
            .flat_map(|&t| {
                (0..4)
                    .filter(move |&f| self.adj[t as usize][f] == NO_ADJ)
                    .map(move |f| {
                        let fv = self.face_vertices(t, f);
                        (face_key(fv), fv)
                    })
            })
            .collect();
        for (f, _) in triangles.iter_mut() {
            if let Some(o) = outward.get(f) {
                *f = *o;
            }
        }
        triangles.sort_unstable_by_key(|(f, m)| (face_key(*f), *m));
        let mut edges: Vec<([u32; 2], i32)> =
            self.feature_edges.iter().map(|(k, &m)| (*k, m)).collect();
        edges.sort_unstable();
        let mut corners: Vec<u32> = self.corners.iter().copied().collect();
        corners.sort_unstable();
        let mut required_vertices: Vec<u32> = self.required.iter().copied().collect();
        required_vertices.sort_unstable();
        MeshData {
            points: self.points.iter().map(|p| p.to_array()).collect(),
            tets: ids.iter().map(|&t| self.tets[t as usize]).collect(),
            tet_regions: ids.iter().map(|&t| self.region[t as usize]).collect(),
            triangles,
            edges,
            corners,
            required_vertices,
            tet_lines: Vec::new(),
        }
    }
}

/// The face adjacency of `tets` (positively oriented, vertices below
/// `n_points`): `adj[t][f]` is the half-face `4u + g` glued to face `f` of
/// `t`, or [`NO_ADJ`]. A face held by more than two tets is returned as
/// `(first half-face, sorted face, count)`, the first such face in the order
/// of sorted keys, and in it the lowest half-face.
///
/// Half-faces are bucketed by their smallest vertex (a counting sort with
/// atomic cursors), and each bucket, about 20 half-faces, is sorted by the
/// other two vertices and the half-face id: the same order as sorting every
/// half-face by its packed key, so the same first error, but 12 bytes per
/// half-face instead of 32 and no sort of the whole array (on a 14M-tet
/// `.vtu` the global sort held 1.8 GB and took a fifth of the read).
fn match_half_faces(
    tets: &[[u32; 4]],
    n_points: usize,
) -> Result<Vec<[u32; 4]>, (u32, [u32; 3], usize)> {
    let key = |t: usize, f: usize| {
        let v = tets[t];
        let l = TET_FACES[f];
        face_key([v[l[0]], v[l[1]], v[l[2]]])
    };
    let cursor: Vec<AtomicU32> = (0..n_points + 1)
        .into_par_iter()
        .map(|_| AtomicU32::new(0))
        .collect();
    tets.par_iter().enumerate().for_each(|(t, _)| {
        for f in 0..4 {
            cursor[key(t, f)[0] as usize + 1].fetch_add(1, Ordering::Relaxed);
        }
    });
    // Exclusive prefix sums: bucket `k` is `start[k]..start[k + 1]`.
    let mut start: Vec<u32> = Vec::with_capacity(n_points + 1);
    let mut sum = 0u32;
    for c in &cursor {
        sum += c.load(Ordering::Relaxed);
        start.push(sum);
    }
    for (c, &s0) in cursor.iter().zip(&start) {
        c.store(s0, Ordering::Relaxed);
    }
    let mut entries = vec![[0u32; 3]; 4 * tets.len()];
    {
        let out = Shared::new(&mut entries);
        tets.par_iter().enumerate().for_each(|(t, _)| {
            for f in 0..4 {
                let k = key(t, f);
                let at = cursor[k[0] as usize].fetch_add(1, Ordering::Relaxed);
                // Each cursor hands out every slot of its bucket once: one
                // writer per entry.
                out.set(at as usize, [k[1], k[2], (4 * t + f) as u32]);
            }
        });
    }
    drop(cursor);
    // Runs of whole buckets, about equal in size, one task each.
    let parts = (rayon::current_num_threads() * 8).max(1);
    let per = entries.len().div_ceil(parts).max(1);
    let mut runs: Vec<(usize, &mut [[u32; 3]])> = Vec::with_capacity(parts + 1);
    let mut rest: &mut [[u32; 3]] = &mut entries;
    let (mut k, mut done) = (0usize, 0usize);
    while k < n_points {
        let first = k;
        while k < n_points && (start[k + 1] as usize) - done < per {
            k += 1;
        }
        k = (k + 1).min(n_points);
        let end = start[k] as usize;
        let (run, tail) = std::mem::take(&mut rest).split_at_mut(end - done);
        runs.push((first, run));
        rest = tail;
        done = end;
    }
    let mut adj = vec![[NO_ADJ; 4]; tets.len()];
    let first_error = {
        let adj_w = Shared::new(&mut adj);
        let start = &start;
        runs.into_par_iter()
            .map(|(first, run)| {
                let base = start[first] as usize;
                let mut b = first;
                while start[b] as usize - base < run.len() {
                    let lo = start[b] as usize - base;
                    let hi = start[b + 1] as usize - base;
                    let bucket = &mut run[lo..hi];
                    bucket.sort_unstable();
                    let mut i = 0;
                    while i < bucket.len() {
                        let mut j = i + 1;
                        while j < bucket.len() && bucket[j][..2] == bucket[i][..2] {
                            j += 1;
                        }
                        match j - i {
                            1 => {}
                            2 => {
                                let (x, y) = (bucket[i][2], bucket[i + 1][2]);
                                // Every half-face is in one group only, so
                                // its adjacency entry has one writer.
                                adj_w.set_lane((x >> 2) as usize, (x & 3) as usize, y);
                                adj_w.set_lane((y >> 2) as usize, (y & 3) as usize, x);
                            }
                            count => {
                                let face = [b as u32, bucket[i][0], bucket[i][1]];
                                return Some((bucket[i][2], face, count));
                            }
                        }
                        i = j;
                    }
                    b += 1;
                }
                None
            })
            .find_first(|e| e.is_some())
            .flatten()
    };
    match first_error {
        Some(e) => Err(e),
        None => Ok(adj),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::generate::cube_grid;
    use std::collections::HashMap;

    /// Adjacency by a hash map from sorted face to its half-faces: the
    /// plain definition `match_half_faces` must agree with.
    fn by_hash(tets: &[[u32; 4]]) -> HashMap<[u32; 3], Vec<u32>> {
        let mut faces: HashMap<[u32; 3], Vec<u32>> = HashMap::new();
        for (t, v) in tets.iter().enumerate() {
            for (f, l) in TET_FACES.iter().enumerate() {
                faces
                    .entry(face_key([v[l[0]], v[l[1]], v[l[2]]]))
                    .or_default()
                    .push((4 * t + f) as u32);
            }
        }
        faces
    }

    /// A cube grid with tets and points in a scrambled (seeded) order.
    fn scrambled_grid(n: usize) -> (Vec<[u32; 4]>, usize) {
        let data = cube_grid(n);
        let np = data.points.len();
        let mut state = 0x2545_f491_4f6c_dd1du64;
        let mut next = move |m: usize| {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            (state % m as u64) as usize
        };
        let mut relabel: Vec<u32> = (0..np as u32).collect();
        for i in (1..np).rev() {
            relabel.swap(i, next(i + 1));
        }
        let mut tets: Vec<[u32; 4]> = data
            .tets
            .iter()
            .map(|v| v.map(|x| relabel[x as usize]))
            .collect();
        for i in (1..tets.len()).rev() {
            tets.swap(i, next(i + 1));
        }
        (tets, np)
    }

    #[test]
    fn half_faces_match_as_the_plain_definition_says() {
        let (tets, np) = scrambled_grid(7);
        let adj = match_half_faces(&tets, np).expect("a grid is manifold");
        let faces = by_hash(&tets);
        let mut glued = 0;
        for hs in faces.values() {
            match hs[..] {
                [h] => assert_eq!(adj[(h >> 2) as usize][(h & 3) as usize], NO_ADJ),
                [a, b] => {
                    assert_eq!(adj[(a >> 2) as usize][(a & 3) as usize], b);
                    assert_eq!(adj[(b >> 2) as usize][(b & 3) as usize], a);
                    glued += 1;
                }
                _ => panic!("a grid face is held by {} tets", hs.len()),
            }
        }
        // 6·7³ tets, 4 faces each; the boundary has 6·2·7² triangles.
        assert_eq!(2 * glued + 6 * 2 * 49, 4 * 6 * 343);
    }

    #[test]
    fn the_first_non_manifold_face_in_key_order_is_reported() {
        let (mut tets, np) = scrambled_grid(3);
        // Two extra tets on two faces of the grid, each making a face held by
        // three tets; the reported one is the lower sorted face, with its
        // lowest half-face.
        let faces = by_hash(&tets);
        let mut inner: Vec<[u32; 3]> = faces
            .iter()
            .filter(|(_, hs)| hs.len() == 2)
            .map(|(k, _)| *k)
            .collect();
        inner.sort_unstable();
        let (lo, hi) = (inner[3], inner[inner.len() - 5]);
        let apex = |f: [u32; 3]| {
            (0..np as u32)
                .find(|x| !f.contains(x))
                .expect("a fourth point")
        };
        tets.push([hi[0], hi[1], hi[2], apex(hi)]);
        tets.push([lo[0], lo[1], lo[2], apex(lo)]);
        let err = match_half_faces(&tets, np).expect_err("three tets on one face");
        let first = by_hash(&tets)[&lo][0];
        assert_eq!(err, (first, lo, 3));
    }

    #[test]
    fn matching_does_not_depend_on_threads() {
        let (tets, np) = scrambled_grid(9);
        let run = |n: usize| {
            rayon::ThreadPoolBuilder::new()
                .num_threads(n)
                .build()
                .expect("a thread pool")
                .install(|| match_half_faces(&tets, np))
        };
        assert_eq!(run(1), run(3));
    }
}
