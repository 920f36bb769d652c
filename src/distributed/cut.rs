//! What the ranks learn about their common cut: which ranks hold each
//! shared point, edge and face (by a rendezvous: every key goes to the rank
//! its hash names, which sees all holders at once), the conformity check
//! that follows from it, global point ids, statistics of the union, and the
//! face-to-face exchange with the rank across each partition face.

use super::comm::Comm;
use super::part::{face_coords, point_key, FaceCoords, PointKey, Reader, Wire};
use crate::mesh::fasthash::FastHashMap;
use crate::mesh::partition::PartitionMarker;
use crate::mesh::{TetMesh, NO_ADJ};
use crate::report::MeshStats;
use std::collections::BTreeMap;

/// The partition faces of `mesh`: tet, local face, decoded marker.
pub fn partition_faces(mesh: &TetMesh) -> Vec<(u32, usize, PartitionMarker)> {
    if mesh.face_markers().is_empty() {
        return Vec::new();
    }
    let mut out = Vec::new();
    for t in mesh.tet_ids() {
        for (f, &h) in mesh.adj(t).iter().enumerate() {
            if h == NO_ADJ {
                if let Some(pm) = mesh
                    .face_marker(mesh.face_vertices(t, f))
                    .and_then(PartitionMarker::decode)
                {
                    out.push((t, f, pm));
                }
            }
        }
    }
    out
}

/// The key of face `f` of `t`.
pub fn face_key_of(mesh: &TetMesh, t: u32, f: usize) -> FaceCoords {
    face_coords(mesh.face_vertices(t, f).map(|v| mesh.point(v)))
}

/// Sends `value(t)` for every partition face to the rank across it and
/// returns, per face key, what that rank sent for its side. An error names
/// a face whose other side sent nothing (the cut does not match).
pub fn across_faces(
    comm: &Comm,
    mesh: &TetMesh,
    value: impl Fn(u32) -> u32,
) -> Result<FastHashMap<FaceCoords, u32>, String> {
    let faces = partition_faces(mesh);
    let mut out: Vec<Wire> = (0..comm.size).map(|_| Wire::default()).collect();
    for &(t, f, pm) in &faces {
        let w = out
            .get_mut(pm.neighbour as usize)
            .ok_or_else(|| format!("a partition face names rank {}", pm.neighbour))?;
        face_key_of(mesh, t, f).iter().for_each(|k| w.key(k));
        w.u32(value(t));
    }
    let got = comm.exchange(out.into_iter().map(|w| w.0).collect())?;
    let mut map = FastHashMap::default();
    for bytes in &got {
        let mut r = Reader { bytes, at: 0 };
        while !r.done() {
            let k = [r.key()?, r.key()?, r.key()?];
            map.insert(k, r.u32()?);
        }
    }
    let missing = faces
        .iter()
        .filter(|&&(t, f, _)| !map.contains_key(&face_key_of(mesh, t, f)))
        .count();
    comm.agree(if missing > 0 {
        Err(format!(
            "rank {}: {missing} partition faces have no match on the rank across them",
            comm.rank
        ))
    } else {
        Ok(())
    })?;
    Ok(map)
}

/// The rank that gathers key `k`: a fixed hash (FNV-1a over the bits), so
/// the same on every rank and every run.
pub(super) fn home<const N: usize>(k: &[u64; N], size: u32) -> usize {
    let mut h: u64 = 0xcbf2_9ce4_8422_2325;
    for &x in k {
        for b in x.to_le_bytes() {
            h ^= u64::from(b);
            h = h.wrapping_mul(0x0100_0000_01b3);
        }
    }
    (h % u64::from(size)) as usize
}

/// Sends each key of `keys` to its home rank; there, the holders of every
/// key (ranks in increasing order) by key.
pub(super) fn gather_at_home<const N: usize>(
    comm: &Comm,
    keys: &[[u64; N]],
) -> Result<BTreeMap<[u64; N], Vec<u32>>, String> {
    let mut out: Vec<Wire> = (0..comm.size).map(|_| Wire::default()).collect();
    for k in keys {
        let w = &mut out[home(k, comm.size)];
        k.iter().for_each(|&x| w.u64(x));
    }
    let got = comm.exchange(out.into_iter().map(|w| w.0).collect())?;
    let mut holders: BTreeMap<[u64; N], Vec<u32>> = BTreeMap::new();
    for (rank, bytes) in got.iter().enumerate() {
        let mut r = Reader { bytes, at: 0 };
        while !r.done() {
            let mut k = [0u64; N];
            for x in &mut k {
                *x = r.u64()?;
            }
            holders.entry(k).or_default().push(rank as u32);
        }
    }
    Ok(holders)
}

/// What a rank can share with another, as keys the same on every rank: the
/// points and edges of its boundary faces (the domain's and the cut's, so
/// those two ranks share at a pinch, without a face between them, are in),
/// with the points of the partition faces apart, and the partition faces.
struct CutKeys {
    /// Points of every boundary face.
    points: Vec<PointKey>,
    /// Per point: is it a corner?
    corner: Vec<bool>,
    /// Points of the partition faces only (each must have another holder).
    cut_points: Vec<PointKey>,
    /// Edges of every boundary face.
    edges: Vec<[u64; 6]>,
    /// Per edge: is it a feature edge?
    feature: Vec<bool>,
    faces: Vec<[u64; 9]>,
}

fn cut_keys(mesh: &TetMesh) -> CutKeys {
    let mut pts = std::collections::BTreeSet::new();
    let mut cut_pts = std::collections::BTreeSet::new();
    let mut edges = std::collections::BTreeSet::new();
    for fv in boundary_faces(mesh) {
        pts.extend(fv);
        for i in 0..3 {
            let (a, b) = (fv[i], fv[(i + 1) % 3]);
            edges.insert(if a < b { [a, b] } else { [b, a] });
        }
    }
    let faces = partition_faces(mesh);
    let mut face_keys = Vec::with_capacity(faces.len());
    for &(t, f, _) in &faces {
        cut_pts.extend(mesh.face_vertices(t, f));
        face_keys.push(flat(&face_key_of(mesh, t, f)));
    }
    let key = |&v: &u32| point_key(mesh.point(v));
    CutKeys {
        points: pts.iter().map(key).collect(),
        corner: pts.iter().map(|&v| mesh.is_corner(v)).collect(),
        cut_points: cut_pts.iter().map(key).collect(),
        edges: edges
            .iter()
            .map(|&[a, b]| edge_coords(mesh, a, b))
            .collect(),
        feature: edges
            .iter()
            .map(|&[a, b]| mesh.is_feature_edge(a, b))
            .collect(),
        faces: face_keys,
    }
}

/// Edge `(a, b)` as the sorted keys of its ends: the same on every rank.
pub(super) fn edge_coords(mesh: &TetMesh, a: u32, b: u32) -> [u64; 6] {
    let mut k = [point_key(mesh.point(a)), point_key(mesh.point(b))];
    k.sort_unstable();
    [k[0][0], k[0][1], k[0][2], k[1][0], k[1][1], k[1][2]]
}

/// For each `(key, yes)` a rank lists, whether every rank listing the key
/// said yes (in the order of `votes`): the votes meet at the key's home
/// rank, which sends the verdict back to each voter.
pub(super) fn all_holders_agree<const N: usize>(
    comm: &Comm,
    votes: &[([u64; N], bool)],
) -> Result<Vec<bool>, String> {
    let mut out: Vec<Wire> = (0..comm.size).map(|_| Wire::default()).collect();
    for (k, yes) in votes {
        let w = &mut out[home(k, comm.size)];
        k.iter().for_each(|&x| w.u64(x));
        w.u32(u32::from(*yes));
    }
    let got = comm.exchange(out.into_iter().map(|w| w.0).collect())?;
    let mut tally: BTreeMap<[u64; N], (bool, Vec<u32>)> = BTreeMap::new();
    for (rank, bytes) in got.iter().enumerate() {
        let mut r = Reader { bytes, at: 0 };
        while !r.done() {
            let mut k = [0u64; N];
            for x in &mut k {
                *x = r.u64()?;
            }
            let yes = r.u32()? == 1;
            let e = tally.entry(k).or_insert((true, Vec::new()));
            e.0 &= yes;
            e.1.push(rank as u32);
        }
    }
    let mut back: Vec<Wire> = (0..comm.size).map(|_| Wire::default()).collect();
    for (k, (yes, voters)) in &tally {
        for &v in voters {
            k.iter().for_each(|&x| back[v as usize].u64(x));
            back[v as usize].u32(u32::from(*yes));
        }
    }
    let got = comm.exchange(back.into_iter().map(|w| w.0).collect())?;
    let mut verdict: FastHashMap<[u64; N], bool> = FastHashMap::default();
    for bytes in &got {
        let mut r = Reader { bytes, at: 0 };
        while !r.done() {
            let mut k = [0u64; N];
            for x in &mut k {
                *x = r.u64()?;
            }
            verdict.insert(k, r.u32()? == 1);
        }
    }
    votes
        .iter()
        .map(|(k, _)| {
            verdict
                .get(k)
                .copied()
                .ok_or_else(|| format!("rank {}: a vote came back without a verdict", comm.rank))
        })
        .collect()
}

pub(super) fn flat(k: &FaceCoords) -> [u64; 9] {
    let mut out = [0u64; 9];
    for (i, p) in k.iter().enumerate() {
        out[3 * i..3 * i + 3].copy_from_slice(p);
    }
    out
}

/// How much the ranks' sums over-count the union, from the cut.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Census {
    /// Points counted by more than one rank, over-count.
    pub extra_points: u64,
    /// Edges likewise.
    pub extra_edges: u64,
    /// Feature edges likewise.
    pub extra_feature_edges: u64,
    /// Corners likewise.
    pub extra_corners: u64,
    /// Partition faces, summed over the ranks (each is a boundary face of
    /// two ranks' meshes and of none in the union).
    pub partition_faces: u64,
}

/// The cut's census, and its conformity check: every partition face must be
/// held by exactly two ranks and every shared point by two or more. An
/// error (on every rank) names how many do not match.
pub fn census(comm: &Comm, mesh: &TetMesh) -> Result<Census, String> {
    let keys = cut_keys(mesh);
    let face_holders = gather_at_home(comm, &keys.faces)?;
    let bad_faces = face_holders.values().filter(|h| h.len() != 2).count();
    let cut_point_holders = gather_at_home(comm, &keys.cut_points)?;
    let lonely = cut_point_holders.values().filter(|h| h.len() < 2).count();
    comm.agree(if bad_faces + lonely > 0 {
        Err(format!(
            "rank {}: the parts do not conform: {bad_faces} partition faces not held by exactly two ranks, {lonely} shared points held by one",
            comm.rank
        ))
    } else {
        Ok(())
    })?;
    // Over-counts come from every boundary point and edge, pinches included.
    let point_holders = gather_at_home(comm, &keys.points)?;
    let edge_holders = gather_at_home(comm, &keys.edges)?;
    // Flags travel as separate key sets: a corner (feature edge) is one of
    // the shared points (edges) that some rank calls so.
    let corner_keys: Vec<PointKey> = keys
        .points
        .iter()
        .zip(&keys.corner)
        .filter(|(_, &c)| c)
        .map(|(k, _)| *k)
        .collect();
    let corner_holders = gather_at_home(comm, &corner_keys)?;
    let feature_keys: Vec<[u64; 6]> = keys
        .edges
        .iter()
        .zip(&keys.feature)
        .filter(|(_, &c)| c)
        .map(|(k, _)| *k)
        .collect();
    let feature_holders = gather_at_home(comm, &feature_keys)?;
    let extra = |n: usize| n as u64 - 1;
    let local = [
        point_holders.values().map(|h| extra(h.len())).sum::<u64>(),
        edge_holders.values().map(|h| extra(h.len())).sum(),
        feature_holders.values().map(|h| extra(h.len())).sum(),
        corner_holders.values().map(|h| extra(h.len())).sum(),
        keys.faces.len() as u64,
    ];
    let s = comm.sum(&local);
    Ok(Census {
        extra_points: s[0],
        extra_edges: s[1],
        extra_feature_edges: s[2],
        extra_corners: s[3],
        partition_faces: s[4],
    })
}

/// Statistics of the union of every rank's mesh (the same on every rank).
/// Exact but for the valence maximum, which is the largest any rank sees
/// (a point on the cut has edges on several ranks).
pub fn global_stats(comm: &Comm, mesh: &TetMesh, census: &Census) -> Result<MeshStats, String> {
    let mut s = MeshStats::compute(mesh);
    let local_tets = s.tets as u64;
    let sums = comm.sum(&[
        s.nodes as u64,
        s.edges as u64,
        local_tets,
        s.boundary_faces as u64,
        s.inverted as u64,
        s.feature_edges as u64,
        s.corners as u64,
    ]);
    let tets = sums[2].max(1) as f64;
    // Float sums through every rank's value, in rank order.
    let min_sum = gather_f64(comm, s.min_dihedral_deg.avg * local_tets as f64)?;
    let max_sum = gather_f64(comm, s.max_dihedral_deg.avg * local_tets as f64)?;
    let volume = gather_f64(comm, s.volume)?;
    s.nodes = (sums[0] - census.extra_points) as usize;
    s.edges = (sums[1] - census.extra_edges) as usize;
    s.tets = sums[2] as usize;
    s.boundary_faces = (sums[3] - census.partition_faces) as usize;
    s.interior_faces = (4 * s.tets - s.boundary_faces) / 2;
    s.inverted = sums[4] as usize;
    s.feature_edges = (sums[5] - census.extra_feature_edges) as usize;
    s.corners = (sums[6] - census.extra_corners) as usize;
    s.min_dihedral_deg.worst = comm.min(s.min_dihedral_deg.worst);
    s.min_dihedral_deg.best = comm.max(s.min_dihedral_deg.best);
    s.min_dihedral_deg.avg = min_sum / tets;
    s.max_dihedral_deg.worst = comm.max(s.max_dihedral_deg.worst);
    s.max_dihedral_deg.avg = max_sum / tets;
    s.volume = volume;
    s.valence.max = comm.max(f64::from(s.valence.max)) as u32;
    s.valence.avg = if s.nodes > 0 {
        2.0 * s.edges as f64 / s.nodes as f64
    } else {
        0.0
    };
    s.histogram.counts = comm.sum(&s.histogram.counts);
    // Regions: every rank's (id, count) list to every rank.
    let mut w = Wire::default();
    for (k, &n) in &s.regions {
        w.i32(k.parse::<i32>().unwrap_or(0));
        w.u64(n as u64);
    }
    let got = comm.exchange(vec![w.0; comm.size as usize])?;
    let mut regions: BTreeMap<i32, usize> = BTreeMap::new();
    for bytes in &got {
        let mut r = Reader { bytes, at: 0 };
        while !r.done() {
            let k = r.i32()?;
            *regions.entry(k).or_default() += r.u64()? as usize;
        }
    }
    s.regions = regions
        .into_iter()
        .map(|(k, n)| (k.to_string(), n))
        .collect();
    Ok(s)
}

/// The sum over the ranks of `x`, added in rank order (so the same bits on
/// every rank and every run).
fn gather_f64(comm: &Comm, x: f64) -> Result<f64, String> {
    let all = comm.all_gather(x.to_bits());
    Ok(all.into_iter().map(f64::from_bits).sum())
}

/// The keys of the points on `mesh`'s boundary faces (the domain's and the
/// cut's), each once: the only points another rank can hold too (an
/// interior point has its whole ball of tets in this part). They include
/// the points two ranks share without sharing a face (a pinch: where a
/// non-manifold input, or a cut meeting itself, touches another part at a
/// point or an edge only), which no partition face names.
fn boundary_point_keys(mesh: &TetMesh) -> Vec<PointKey> {
    let pts: std::collections::BTreeSet<u32> = boundary_faces(mesh).flatten().collect();
    pts.iter().map(|&v| point_key(mesh.point(v))).collect()
}

/// The vertices of every face of `mesh` without a neighbour (the domain's
/// boundary and the cut).
fn boundary_faces(mesh: &TetMesh) -> impl Iterator<Item = [u32; 3]> + '_ {
    mesh.tet_ids().flat_map(move |t| {
        (0..4)
            .filter(move |&f| mesh.adj(t)[f] == NO_ADJ)
            .map(move |f| mesh.face_vertices(t, f))
    })
}

/// Global point ids: each shared point belongs to the lowest rank holding
/// it, every rank numbers the points it owns after those of the ranks
/// before it, and the owners' ids reach the other holders through the
/// points' home ranks. Shared points are found by their exact coordinates
/// among every boundary point of every part (not only the cut's), so a
/// point two ranks share without a face between them gets one id too. Per
/// local point, its id; points no tet uses get `u64::MAX`.
pub fn global_point_ids(comm: &Comm, mesh: &TetMesh) -> Result<Vec<u64>, String> {
    let keys = boundary_point_keys(mesh);
    let holders = gather_at_home(comm, &keys)?;
    // Home tells each holder the owner.
    let mut out: Vec<Wire> = (0..comm.size).map(|_| Wire::default()).collect();
    for (k, hs) in &holders {
        for &r in hs {
            out[r as usize].key(k);
            out[r as usize].u32(hs[0]);
        }
    }
    let got = comm.exchange(out.into_iter().map(|w| w.0).collect())?;
    let mut owner: FastHashMap<PointKey, u32> = FastHashMap::default();
    for bytes in &got {
        let mut r = Reader { bytes, at: 0 };
        while !r.done() {
            let k = r.key()?;
            owner.insert(k, r.u32()?);
        }
    }
    let n = mesh.n_points();
    let mut used = vec![false; n];
    for t in mesh.tet_ids() {
        for v in mesh.tet(t) {
            used[v as usize] = true;
        }
    }
    let mine = |v: usize| {
        used[v]
            && owner
                .get(&point_key(mesh.point(v as u32)))
                .is_none_or(|&o| o == comm.rank)
    };
    let owned = (0..n).filter(|&v| mine(v)).count() as u64;
    let counts = comm.all_gather(owned);
    let mut next: u64 = counts[..comm.rank as usize].iter().sum();
    let mut ids = vec![u64::MAX; n];
    for (v, id) in ids.iter_mut().enumerate() {
        if mine(v) {
            *id = next;
            next += 1;
        }
    }
    // Owners send their shared points' ids home; home forwards to holders.
    let mut out: Vec<Wire> = (0..comm.size).map(|_| Wire::default()).collect();
    let index: FastHashMap<PointKey, u32> = (0..n as u32)
        .filter(|&v| used[v as usize])
        .map(|v| (point_key(mesh.point(v)), v))
        .collect();
    for k in &keys {
        if owner.get(k) == Some(&comm.rank) {
            let w = &mut out[home(k, comm.size)];
            w.key(k);
            w.u64(ids[index[k] as usize]);
        }
    }
    let got = comm.exchange(out.into_iter().map(|w| w.0).collect())?;
    let mut out: Vec<Wire> = (0..comm.size).map(|_| Wire::default()).collect();
    for bytes in &got {
        let mut r = Reader { bytes, at: 0 };
        while !r.done() {
            let k = r.key()?;
            let id = r.u64()?;
            for &h in holders.get(&k).map(Vec::as_slice).unwrap_or(&[]) {
                out[h as usize].key(&k);
                out[h as usize].u64(id);
            }
        }
    }
    let got = comm.exchange(out.into_iter().map(|w| w.0).collect())?;
    for bytes in &got {
        let mut r = Reader { bytes, at: 0 };
        while !r.done() {
            let k = r.key()?;
            let id = r.u64()?;
            if let Some(&v) = index.get(&k) {
                ids[v as usize] = id;
            }
        }
    }
    let unset = (0..n).filter(|&v| used[v] && ids[v] == u64::MAX).count();
    comm.agree(if unset > 0 {
        Err(format!(
            "rank {}: {unset} shared points got no global id",
            comm.rank
        ))
    } else {
        Ok(())
    })?;
    Ok(ids)
}
