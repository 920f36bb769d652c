//! A self-contained set of tets as one rank sends it to another: its own
//! points, tags and per-tet data, with every face's fate on the receiving
//! rank written into its markers (interior, the domain's boundary, or a
//! partition face towards a named rank). The first distribution and every
//! migration build such parts; a rank's mesh is rebuilt by merging them,
//! points matched by their exact coordinates.
//!
//! Matching by coordinates is exact here: a point two ranks share is an
//! input point or was created on a partition face from its corners in a
//! canonical order ([`crate::canonical_centroid`]), and no phase moves a
//! point of a partition face, so both ranks hold the same bits.

use crate::mesh::fasthash::FastHashMap;
use crate::mesh::partition::PartitionMarker;
use crate::mesh::{edge_key, face_key, MeshData, TetMesh, NO_ADJ};
use crate::refine::size::SizeMap;
use crate::topo::{TET_EDGES, TET_FACES};
use glam::DVec3;
use std::collections::HashSet;

/// The exact coordinates of a point as a hashable key (`-0.0` taken as
/// `0.0`, so that the two zeros, equal as numbers, are one point).
pub type PointKey = [u64; 3];

/// A face as the sorted keys of its three corners.
pub type FaceCoords = [PointKey; 3];

/// The key of `p`.
pub fn point_key(p: DVec3) -> PointKey {
    p.to_array().map(|c| if c == 0.0 { 0 } else { c.to_bits() })
}

/// The key of the face with corners `p`.
pub fn face_coords(p: [DVec3; 3]) -> FaceCoords {
    let mut k = p.map(point_key);
    k.sort_unstable();
    k
}

/// Where a face of a sent tet ends up on its receiver.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum FaceFate {
    /// Inside the receiver's mesh (the tet on the other side goes there
    /// too, or stays there).
    Interior,
    /// On the domain's boundary.
    Domain,
    /// A partition face towards this rank.
    Cut(u32),
}

/// The distinct user face markers of a run, so that a partition face can
/// carry one ([`PartitionMarker::user_slot`]).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct MarkerSlots {
    /// Sorted distinct markers; slot `i + 1` is `markers[i]`.
    pub markers: Vec<i32>,
}

impl MarkerSlots {
    /// The table of every non-partition marker of `mesh`; an error when there
    /// are more than a partition marker can name.
    pub fn of(mesh: &TetMesh) -> Result<MarkerSlots, String> {
        MarkerSlots::from_markers(mesh.face_markers().values().copied().collect())
    }

    /// The table of `markers` (any order, repeats allowed); an error as for
    /// [`MarkerSlots::of`].
    pub fn from_markers(mut markers: Vec<i32>) -> Result<MarkerSlots, String> {
        markers.sort_unstable();
        markers.dedup();
        if let Some(m) = markers
            .iter()
            .find(|&&m| crate::mesh::partition::is_partition_marker(m))
        {
            return Err(format!(
                "face marker {m} lies in the range reserved for partition faces ({} and up, 2^30 values)",
                crate::mesh::partition::PARTITION_MARKER_BASE
            ));
        }
        if markers.len() + 1 > crate::mesh::partition::USER_SLOTS as usize {
            return Err(format!(
                "{} distinct face markers; distributed refinement carries at most {}",
                markers.len(),
                crate::mesh::partition::USER_SLOTS - 1
            ));
        }
        Ok(MarkerSlots { markers })
    }

    /// The table as a message ([`MarkerSlots::decode_into`] reads it).
    pub fn encode(&self) -> Vec<u8> {
        let mut w = Wire::default();
        self.markers.iter().for_each(|&m| w.i32(m));
        w.0
    }

    /// Appends the markers of a message [`MarkerSlots::encode`] made to
    /// `out`.
    pub fn decode_into(bytes: &[u8], out: &mut Vec<i32>) -> Result<(), String> {
        let mut r = Reader { bytes, at: 0 };
        while !r.done() {
            out.push(r.i32()?);
        }
        Ok(())
    }

    /// The slot of user marker `m` (0 for none).
    pub fn slot(&self, m: Option<i32>) -> u32 {
        m.and_then(|m| self.markers.binary_search(&m).ok())
            .map_or(0, |i| i as u32 + 1)
    }

    /// The user marker in `slot`.
    pub fn marker(&self, slot: u32) -> Option<i32> {
        (slot > 0).then(|| self.markers.get(slot as usize - 1).copied())?
    }

    /// The user marker a face with marker `m` carries (itself, or the one
    /// in its partition marker's slot).
    pub fn user_marker(&self, m: Option<i32>) -> Option<i32> {
        match m.map(|m| (m, PartitionMarker::decode(m))) {
            Some((_, Some(pm))) => self.marker(pm.user_slot),
            Some((m, None)) => Some(m),
            None => None,
        }
    }
}

/// Tets with their points and tags, ready to send.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Part {
    /// Points, tets (local ids), regions, marked faces (partition markers for
    /// cut faces), feature edges, corners and required vertices.
    pub data: MeshData,
    /// Refinement level per tet.
    pub level: Vec<u8>,
    /// Input tet per tet.
    pub parent: Vec<u32>,
    /// Per tet: selected for the first step (empty: uniform).
    pub selected: Vec<bool>,
    /// Per point: its entry of the run's size map (`None`: the run has
    /// none), so that a size-driven run's targets travel with the points.
    pub sizes: Option<SizeMap>,
}

impl Part {
    /// The tets `tets` of `mesh` with their points and tags; `fate(t, f)`
    /// says what face `f` of `t` becomes on the receiver, `selected` the
    /// first step's selection (per slot of `mesh`).
    pub fn from_tets(
        mesh: &TetMesh,
        tets: &[u32],
        slots: &MarkerSlots,
        selected: Option<&[bool]>,
        mut fate: impl FnMut(u32, usize) -> FaceFate,
    ) -> Part {
        let (out_tets, source, local) = local_numbering(mesh, tets);
        let points = source.iter().map(|&v| mesh.point(v).to_array()).collect();
        let has_markers = !mesh.face_markers().is_empty();
        let mut triangles = Vec::new();
        let mut seen_interior: HashSet<[u32; 3]> = HashSet::new();
        let mut edges = Vec::new();
        let mut seen_edges: HashSet<[u32; 2]> = HashSet::new();
        for (i, &t) in tets.iter().enumerate() {
            let v = mesh.tet(t);
            for (f, &h) in mesh.adj(t).iter().enumerate() {
                let fv = mesh.face_vertices(t, f);
                let marker = if has_markers {
                    mesh.face_marker(fv)
                } else {
                    None
                };
                let user = slots.user_marker(marker);
                let lf = TET_FACES[f].map(|j| out_tets[i][j]);
                match fate(t, f) {
                    FaceFate::Cut(rank) => {
                        let pm = PartitionMarker {
                            neighbour: rank,
                            user_slot: slots.slot(user),
                            hold: false,
                        };
                        triangles.push((lf, pm.encode().expect("rank in range")));
                    }
                    FaceFate::Domain => {
                        if let Some(m) = user {
                            triangles.push((lf, m));
                        }
                    }
                    FaceFate::Interior => {
                        // Listed once even when both tets are sent.
                        if let Some(m) = user {
                            if h == NO_ADJ || seen_interior.insert(face_key(fv)) {
                                triangles.push((lf, m));
                            }
                        }
                    }
                }
            }
            for [a, b] in TET_EDGES {
                if let Some(m) = mesh.feature_edge(v[a], v[b]) {
                    if seen_edges.insert(edge_key(v[a], v[b])) {
                        edges.push(([out_tets[i][a], out_tets[i][b]], m));
                    }
                }
            }
        }
        let mut corners: Vec<u32> = mesh
            .corners()
            .iter()
            .filter_map(|v| local.get(v).copied())
            .collect();
        corners.sort_unstable();
        let mut required: Vec<u32> = mesh
            .required_vertices()
            .iter()
            .filter_map(|v| local.get(v).copied())
            .collect();
        required.sort_unstable();
        Part {
            data: MeshData {
                points,
                tet_regions: tets.iter().map(|&t| mesh.region(t)).collect(),
                tets: out_tets,
                triangles,
                edges,
                corners,
                required_vertices: required,
                tet_lines: Vec::new(),
            },
            level: tets.iter().map(|&t| mesh.level(t)).collect(),
            parent: tets.iter().map(|&t| mesh.parent(t)).collect(),
            selected: selected.map_or_else(Vec::new, |s| {
                tets.iter()
                    .map(|&t| s.get(t as usize).copied().unwrap_or(false))
                    .collect()
            }),
            sizes: None,
        }
    }

    /// Gives the part built by [`Part::from_tets`] from `mesh`'s `tets` the
    /// entries of `size` (a size map over `mesh`'s points) of its points.
    pub fn attach_sizes(&mut self, mesh: &TetMesh, tets: &[u32], size: &SizeMap) {
        let (_, source, _) = local_numbering(mesh, tets);
        self.sizes = Some(size.gather(&source));
    }

    /// One part holding the tets of all `parts`, points with the same
    /// coordinates merged, each marked face and tagged edge once.
    pub fn merge(parts: Vec<Part>) -> Part {
        let mut out = Part::default();
        let mut index: FastHashMap<PointKey, u32> = FastHashMap::default();
        let mut faces: FastHashMap<[u32; 3], i32> = FastHashMap::default();
        let mut edges: FastHashMap<[u32; 2], i32> = FastHashMap::default();
        let mut corners = HashSet::new();
        let mut required = HashSet::new();
        let uniform = parts.iter().all(|p| p.selected.is_empty());
        // Sizes only when every part has a map of the same kind.
        let kind = |p: &Part| p.sizes.as_ref().map(SizeMap::components);
        out.sizes = parts
            .first()
            .filter(|first| kind(first).is_some() && parts.iter().all(|p| kind(p) == kind(first)))
            .and_then(|first| first.sizes.as_ref().map(SizeMap::empty_like));
        for p in parts {
            let ids: Vec<u32> = p
                .data
                .points
                .iter()
                .map(|&x| {
                    *index
                        .entry(point_key(DVec3::from_array(x)))
                        .or_insert_with(|| {
                            out.data.points.push(x);
                            out.data.points.len() as u32 - 1
                        })
                })
                .collect();
            if let (Some(to), Some(from)) = (out.sizes.as_mut(), p.sizes.as_ref()) {
                // A point's first part gives its size (both sides of a cut
                // carry the same entry).
                for (i, &id) in ids.iter().enumerate() {
                    if id as usize == to.len() {
                        to.push_entry(from, i);
                    }
                }
            }
            out.data
                .tets
                .extend(p.data.tets.iter().map(|t| t.map(|v| ids[v as usize])));
            out.data.tet_regions.extend(p.data.tet_regions);
            out.level.extend(p.level);
            out.parent.extend(p.parent);
            if !uniform {
                let n = p.data.tets.len();
                let mut s = p.selected;
                s.resize(n, false);
                out.selected.extend(s);
            }
            for (f, m) in p.data.triangles {
                faces.insert(face_key(f.map(|v| ids[v as usize])), m);
            }
            for (e, m) in p.data.edges {
                edges.insert(edge_key(ids[e[0] as usize], ids[e[1] as usize]), m);
            }
            corners.extend(p.data.corners.iter().map(|&v| ids[v as usize]));
            required.extend(p.data.required_vertices.iter().map(|&v| ids[v as usize]));
        }
        out.data.triangles = faces.into_iter().collect();
        out.data.triangles.sort_unstable();
        out.data.edges = edges.into_iter().collect();
        out.data.edges.sort_unstable();
        out.data.corners = corners.into_iter().collect();
        out.data.corners.sort_unstable();
        out.data.required_vertices = required.into_iter().collect();
        out.data.required_vertices.sort_unstable();
        out
    }

    /// The part as a mesh (validated by [`TetMesh::from_data`]) with its
    /// levels and parents, and its selection.
    pub fn build(self) -> Result<(TetMesh, Vec<bool>), String> {
        let (mut mesh, _) = TetMesh::from_data(&self.data).map_err(|e| e.to_string())?;
        for (t, (&l, &p)) in self.level.iter().zip(&self.parent).enumerate() {
            mesh.set_level(t as u32, l);
            mesh.set_parent(t as u32, p);
        }
        Ok((mesh, self.selected))
    }

    /// The part as bytes (little-endian, counts first).
    pub fn encode(&self) -> Vec<u8> {
        let mut w = Wire::default();
        let d = &self.data;
        w.u64(d.points.len() as u64);
        for p in &d.points {
            p.iter().for_each(|&c| w.f64(c));
        }
        w.u64(d.tets.len() as u64);
        for t in &d.tets {
            t.iter().for_each(|&v| w.u32(v));
        }
        for (i, _) in d.tets.iter().enumerate() {
            w.i32(d.region(i));
            w.u32(u32::from(self.level[i]));
            w.u32(self.parent[i]);
            w.u32(u32::from(self.selected.get(i).copied().unwrap_or(false)));
        }
        w.u32(u32::from(!self.selected.is_empty()));
        w.u64(d.triangles.len() as u64);
        for (f, m) in &d.triangles {
            f.iter().for_each(|&v| w.u32(v));
            w.i32(*m);
        }
        w.u64(d.edges.len() as u64);
        for (e, m) in &d.edges {
            e.iter().for_each(|&v| w.u32(v));
            w.i32(*m);
        }
        for list in [&d.corners, &d.required_vertices] {
            w.u64(list.len() as u64);
            list.iter().for_each(|&v| w.u32(v));
        }
        match &self.sizes {
            None => w.u32(0),
            Some(m) => {
                w.u32(m.components() as u32);
                (0..m.len()).for_each(|i| m.entry(i).iter().for_each(|&x| w.f64(x)));
            }
        }
        w.0
    }

    /// A part from [`Part::encode`]'s bytes; an error on a short or
    /// inconsistent message.
    pub fn decode(bytes: &[u8]) -> Result<Part, String> {
        let mut r = Reader { bytes, at: 0 };
        let np = r.count(24)?;
        let points = (0..np)
            .map(|_| Ok([r.f64()?, r.f64()?, r.f64()?]))
            .collect::<Result<Vec<_>, String>>()?;
        let nt = r.count(32)?;
        let tets = (0..nt)
            .map(|_| Ok([r.u32()?, r.u32()?, r.u32()?, r.u32()?]))
            .collect::<Result<Vec<_>, String>>()?;
        let (mut regions, mut level, mut parent, mut selected) =
            (Vec::new(), Vec::new(), Vec::new(), Vec::new());
        for _ in 0..nt {
            regions.push(r.i32()?);
            level.push(u8::try_from(r.u32()?).map_err(|_| "a level above 255".to_string())?);
            parent.push(r.u32()?);
            selected.push(r.u32()? == 1);
        }
        if r.u32()? == 0 {
            selected.clear();
        }
        let nf = r.count(16)?;
        let triangles = (0..nf)
            .map(|_| Ok(([r.u32()?, r.u32()?, r.u32()?], r.i32()?)))
            .collect::<Result<Vec<_>, String>>()?;
        let ne = r.count(12)?;
        let edges = (0..ne)
            .map(|_| Ok(([r.u32()?, r.u32()?], r.i32()?)))
            .collect::<Result<Vec<_>, String>>()?;
        let mut lists = Vec::new();
        for _ in 0..2 {
            let n = r.count(4)?;
            lists.push((0..n).map(|_| r.u32()).collect::<Result<Vec<_>, _>>()?);
        }
        let sizes = match r.u32()? {
            0 => None,
            c @ (1 | 6) => {
                let values = (0..np * c as usize)
                    .map(|_| r.f64())
                    .collect::<Result<Vec<_>, _>>()?;
                Some(SizeMap::from_values(c as usize, &values)?)
            }
            c => return Err(format!("a size map of {c} components")),
        };
        if r.at != bytes.len() {
            return Err(format!(
                "{} bytes after the end of a part",
                bytes.len() - r.at
            ));
        }
        let required_vertices = lists.pop().unwrap_or_default();
        let corners = lists.pop().unwrap_or_default();
        Ok(Part {
            data: MeshData {
                points,
                tets,
                tet_regions: regions,
                triangles,
                edges,
                corners,
                required_vertices,
                tet_lines: Vec::new(),
            },
            level,
            parent,
            selected,
            sizes,
        })
    }
}

/// `tets` of `mesh` renumbered for a part: each tet's local vertex ids, the
/// mesh's id of every local point (in order of first use), and the map
/// from the mesh's ids to the local ones.
fn local_numbering(
    mesh: &TetMesh,
    tets: &[u32],
) -> (Vec<[u32; 4]>, Vec<u32>, FastHashMap<u32, u32>) {
    let mut local: FastHashMap<u32, u32> = FastHashMap::default();
    let mut source = Vec::new();
    let out_tets = tets
        .iter()
        .map(|&t| {
            mesh.tet(t).map(|v| {
                *local.entry(v).or_insert_with(|| {
                    source.push(v);
                    source.len() as u32 - 1
                })
            })
        })
        .collect();
    (out_tets, source, local)
}

/// A little-endian byte writer.
#[derive(Default)]
pub struct Wire(pub Vec<u8>);

impl Wire {
    /// Appends a `u32`.
    pub fn u32(&mut self, x: u32) {
        self.0.extend_from_slice(&x.to_le_bytes());
    }
    /// Appends an `i32`.
    pub fn i32(&mut self, x: i32) {
        self.0.extend_from_slice(&x.to_le_bytes());
    }
    /// Appends a `u64`.
    pub fn u64(&mut self, x: u64) {
        self.0.extend_from_slice(&x.to_le_bytes());
    }
    /// Appends an `f64`.
    pub fn f64(&mut self, x: f64) {
        self.0.extend_from_slice(&x.to_le_bytes());
    }
    /// Appends a point key.
    pub fn key(&mut self, k: &PointKey) {
        k.iter().for_each(|&c| self.u64(c));
    }
}

/// Reads what [`Wire`] wrote; every read checks the length.
pub struct Reader<'a> {
    /// The message.
    pub bytes: &'a [u8],
    /// Read position.
    pub at: usize,
}

impl Reader<'_> {
    fn take<const N: usize>(&mut self) -> Result<[u8; N], String> {
        let end = self.at + N;
        let b = self
            .bytes
            .get(self.at..end)
            .ok_or_else(|| format!("a message ends after {} bytes", self.bytes.len()))?;
        self.at = end;
        Ok(b.try_into().expect("N bytes"))
    }
    /// Whether everything was read.
    pub fn done(&self) -> bool {
        self.at >= self.bytes.len()
    }
    /// Reads a `u32`.
    pub fn u32(&mut self) -> Result<u32, String> {
        self.take::<4>().map(u32::from_le_bytes)
    }
    /// Reads an `i32`.
    pub fn i32(&mut self) -> Result<i32, String> {
        self.take::<4>().map(i32::from_le_bytes)
    }
    /// Reads a `u64`.
    pub fn u64(&mut self) -> Result<u64, String> {
        self.take::<8>().map(u64::from_le_bytes)
    }
    /// Reads an `f64`.
    pub fn f64(&mut self) -> Result<f64, String> {
        self.take::<8>().map(f64::from_le_bytes)
    }
    /// Reads a point key.
    pub fn key(&mut self) -> Result<PointKey, String> {
        Ok([self.u64()?, self.u64()?, self.u64()?])
    }
    /// Reads a count of items of at least `item` bytes each, refusing one
    /// the rest of the message cannot hold.
    fn count(&mut self, item: usize) -> Result<usize, String> {
        let n = self.u64()? as usize;
        if n.saturating_mul(item) > self.bytes.len() - self.at {
            return Err(format!("a count of {n} does not fit the message"));
        }
        Ok(n)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::partition::partition_marker;

    #[test]
    fn a_part_survives_encoding_and_a_split_cube_merges_back() {
        let (mesh, _) = TetMesh::from_data(&crate::cube_grid(2)).unwrap();
        let slots = MarkerSlots::of(&mesh).unwrap();
        let n = mesh.n_tets() as u32;
        let half = |t: u32| u32::from(mesh.tet_points(t).iter().map(|p| p.x).sum::<f64>() > 2.0);
        let mut parts = Vec::new();
        for r in 0..2 {
            let tets: Vec<u32> = (0..n).filter(|&t| half(t) == r).collect();
            let p = Part::from_tets(&mesh, &tets, &slots, None, |t, f| {
                let h = mesh.adj(t)[f];
                if h == NO_ADJ {
                    FaceFate::Domain
                } else if half(h >> 2) != r {
                    FaceFate::Cut(half(h >> 2))
                } else {
                    FaceFate::Interior
                }
            });
            assert_eq!(Part::decode(&p.encode()).unwrap(), p);
            // Every cut face is marked toward the other half.
            assert!(p
                .data
                .triangles
                .iter()
                .all(|&(_, m)| m == partition_marker(1 - r)));
            parts.push(p);
        }
        // Sizes travel with the points: a size per point from its
        // coordinates comes back at every point of the merged part.
        let h = |p: [f64; 3]| 1.0 + p[0] + 10.0 * p[1] + 100.0 * p[2];
        let size = SizeMap::Iso(mesh.points().iter().map(|p| h(p.to_array())).collect());
        let mut sized = Vec::new();
        for (r, p) in parts.iter().enumerate() {
            let tets: Vec<u32> = (0..n).filter(|&t| half(t) == r as u32).collect();
            let mut q = p.clone();
            q.attach_sizes(&mesh, &tets, &size);
            assert_eq!(Part::decode(&q.encode()).unwrap(), q);
            sized.push(q);
        }
        let merged = Part::merge(sized);
        let got = merged.sizes.expect("every part had sizes");
        assert_eq!(got.len(), merged.data.points.len());
        for (i, p) in merged.data.points.iter().enumerate() {
            assert_eq!(got.entry(i), &[h(*p)]);
        }
        let cut = parts[0].data.triangles.len();
        assert_eq!(cut, parts[1].data.triangles.len());
        assert!(cut > 0);
        let merged = Part::merge(parts);
        assert_eq!(merged.data.points.len(), mesh.n_points());
        // Both sides listed the cut faces: as markers they are one each.
        assert_eq!(merged.data.triangles.len(), cut);
        assert!(Part::decode(&[1, 2, 3]).is_err());
    }
}
