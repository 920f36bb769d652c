//! A mesh read per rank (each rank its own pieces of a `.pvtu`) made into
//! the part the distributed step runs on: the boundary faces two ranks
//! share become partition faces, found by a rendezvous on their exact
//! coordinates (as the census matches the cut), so that the refinement runs
//! as after [`super::distribute`].

use super::comm::Comm;
use super::cut::{face_key_of, flat, gather_at_home};
use super::part::{FaceFate, MarkerSlots, Part, Reader, Wire};
use super::LocalMesh;
use crate::mesh::fasthash::FastHashMap;
use crate::mesh::{TetMesh, NO_ADJ};
use crate::refine::size::SizeMap;

/// Turns this rank's `mesh` (its pieces, merged, features detected) into its
/// part: every boundary face another rank also holds becomes a partition
/// face towards it, the user face markers of all ranks share one slot
/// table, and tet `i` gets `parent` `first_tet + i` (its global input id).
/// `size`, a size map over `mesh`'s points, becomes the part's
/// ([`LocalMesh::size`], over the part's points).
///
/// Feature edges on the shared faces' edges and corners at their vertices
/// are dropped: a rank sees only its side of them, so what it detected
/// there (the cut's own bends and rims look like creases) cannot be
/// trusted, and both sides must agree. Partition faces are never flipped
/// or moved, so the steps lose nothing by it; only the band optimised
/// after the cut moves sees those points without their tags.
///
/// An error on every rank when a face is held by more than two ranks'
/// tets, or twice by one rank (overlapping pieces).
pub fn assemble(
    comm: &Comm,
    mut mesh: TetMesh,
    first_tet: u32,
    size: Option<&SizeMap>,
) -> Result<LocalMesh, String> {
    let me = comm.rank;
    let boundary: Vec<(u32, usize)> = mesh
        .tet_ids()
        .flat_map(|t| {
            let adj = mesh.adj(t);
            (0..4)
                .filter(move |&f| adj[f] == NO_ADJ)
                .map(move |f| (t, f))
        })
        .collect();
    let keys: Vec<[u64; 9]> = boundary
        .iter()
        .map(|&(t, f)| flat(&face_key_of(&mesh, t, f)))
        .collect();
    // At each key's home rank: its holders; each of a pair learns the other.
    let holders = gather_at_home(comm, &keys)?;
    let mut out: Vec<Wire> = (0..comm.size).map(|_| Wire::default()).collect();
    let mut bad = 0usize;
    for (k, h) in &holders {
        match h.as_slice() {
            [_] => {}
            &[a, b] if a != b => {
                for (to, other) in [(a, b), (b, a)] {
                    let w = &mut out[to as usize];
                    k.iter().for_each(|&x| w.u64(x));
                    w.u32(other);
                }
            }
            _ => bad += 1,
        }
    }
    comm.agree(if bad > 0 {
        Err(format!(
            "rank {me}: {bad} faces are held by more than two tets of the pieces, or twice by one rank's (overlapping pieces)"
        ))
    } else {
        Ok(())
    })?;
    let got = comm.exchange(out.into_iter().map(|w| w.0).collect())?;
    let mut across: FastHashMap<[u64; 9], u32> = FastHashMap::default();
    for bytes in &got {
        let mut r = Reader { bytes, at: 0 };
        while !r.done() {
            let mut k = [0u64; 9];
            for x in &mut k {
                *x = r.u64()?;
            }
            across.insert(k, r.u32()?);
        }
    }
    let slots = shared_slots(comm, &mesh)?;
    let mut cut: FastHashMap<(u32, usize), u32> = FastHashMap::default();
    for (&(t, f), k) in boundary.iter().zip(&keys) {
        if let Some(&r) = across.get(k) {
            cut.insert((t, f), r);
            let fv = mesh.face_vertices(t, f);
            for i in 0..3 {
                mesh.set_feature_edge(fv[i], fv[(i + 1) % 3], None);
                mesh.set_corner(fv[i], false);
            }
        }
    }
    let ids: Vec<u32> = mesh.tet_ids().collect();
    let mut part = Part::from_tets(&mesh, &ids, &slots, None, |t, f| {
        if mesh.adj(t)[f] != NO_ADJ {
            FaceFate::Interior
        } else {
            cut.get(&(t, f))
                .map_or(FaceFate::Domain, |&r| FaceFate::Cut(r))
        }
    });
    part.parent = (0..ids.len() as u32).map(|i| first_tet + i).collect();
    if let Some(m) = size {
        part.attach_sizes(&mesh, &ids, m);
    }
    let size = part.sizes.take();
    drop(mesh);
    let built = part
        .build()
        .map(|(m, _)| m)
        .map_err(|e| format!("rank {me}: its part with the cut marked: {e}"));
    let mesh = comm.agree(built)?;
    Ok(LocalMesh { mesh, slots, size })
}

/// The user face markers of every rank's `mesh`, as one slot table.
fn shared_slots(comm: &Comm, mesh: &TetMesh) -> Result<MarkerSlots, String> {
    let local =
        comm.agree(MarkerSlots::of(mesh).map_err(|e| format!("rank {}: {e}", comm.rank)))?;
    let got = comm.exchange(vec![local.encode(); comm.size as usize])?;
    let mut markers = Vec::new();
    for bytes in &got {
        MarkerSlots::decode_into(bytes, &mut markers)?;
    }
    comm.agree(MarkerSlots::from_markers(markers).map_err(|e| format!("over the pieces: {e}")))
}
