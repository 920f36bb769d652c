//! Size-driven refinement over MPI: the serial size passes
//! ([`crate::size_pass`]) on every part, the cut's own long edges split by
//! agreement between the ranks holding them, then one cut move and passes
//! again so the band the cut froze for the optimize phase is improved too —
//! ParMmg's remesh / migrate / remesh iteration (Cirrottola–Froehly) with
//! the size loop in place of MMG's remesher.
//!
//! A long edge on a partition face is split only when every rank holding it
//! splits it in the same pass, at the same point (its midpoint, the same
//! bits on every rank): each pass first asks the holders whether the split
//! keeps their side's new tets above the floor, then, in one global order
//! (longest first, ties by coordinates), each rank picks the agreed edges
//! whose shells share no tet on its side, and the edges every holder picked
//! are split. The first agreed edge in the global order is picked by every
//! holder, so a pass that can split a cut edge splits at least one. The
//! serial passes then split the edges off the cut (they leave the cut's
//! alone). Each pass's quality floor is the worst tet of the union (a
//! minimum over the ranks), as the serial floor is the whole mesh's. The
//! optimize phase after each pass keeps the cut's points and faces where
//! they are (its operations refuse partition faces), which is what the cut
//! move is for.

use super::cut::{all_holders_agree, edge_coords};
use super::{
    census, global_stats, migrate_cut_layer, rebalance_and_say, Census, Comm, LocalMesh, CUT_LAYERS,
};
use crate::improve::ImproveOptions;
use crate::mesh::partition::PartitionMarker;
use crate::mesh::TetMesh;
use crate::refine::size::{
    size_pass, split_at_midpoint, split_quality, without_insertion, worst_metric_quality, SizeMap,
    SizeOptions, SPLIT_ABOVE,
};
use crate::report::MeshStats;
use crate::topo::{edge_key, TET_EDGES};
use std::collections::{HashMap, HashSet};

/// How often the cut moves in a size-driven run, each move followed by
/// the optimize phase and more passes.
const SIZE_CUT_MOVES: usize = 2;

/// Options of [`size_distributed`].
#[derive(Clone, Debug, Default)]
pub struct DistributedSizeOptions {
    /// Size passes before the cut moves; after it, at most as many again.
    pub passes: usize,
    /// Stop a round as soon as no edge off the cut is long, or nothing
    /// split anywhere (`--steps auto`).
    pub until_met: bool,
    /// The optimize phase after each pass's splits.
    pub improve: ImproveOptions,
}

/// One distributed size pass, summed over the ranks.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct SizePassReport {
    /// How often the cut had moved when the pass ran.
    pub cut_moves: usize,
    /// Long edges off the cut when the pass began.
    pub long_edges: u64,
    /// Edges split (each edge of the cut counted once).
    pub split: u64,
    /// Splits refused (a new tet inverted or below the floor).
    pub refused: u64,
    /// Edges off the cut still long after the pass.
    pub long_after: u64,
    /// Long edges on the cut after the pass (each counted once, by the
    /// lowest rank whose partition faces hold it).
    pub long_on_cut: u64,
}

/// Runs the distributed size loop on `local` (which must carry its size
/// map). `on_pass(pass, union_stats, report, seconds)` runs on every rank
/// after each pass. Returns the census and statistics of the final mesh
/// and the last pass's report.
pub fn size_distributed(
    comm: &Comm,
    local: &mut LocalMesh,
    opts: &DistributedSizeOptions,
    mut on_pass: impl FnMut(usize, &MeshStats, &SizePassReport, f64),
) -> Result<(Census, MeshStats, SizePassReport), String> {
    let has_map = local
        .size
        .as_ref()
        .is_some_and(|m| m.len() == local.mesh.n_points());
    comm.agree(if has_map {
        Ok(())
    } else {
        Err(format!("rank {}: its part has no size map", comm.rank))
    })?;
    let mut last = None;
    let mut pass = 0;
    for round in 0..=SIZE_CUT_MOVES {
        let after_cut_move = round > 0;
        if after_cut_move {
            if comm.size == 1 || !migrate_cut_layer(comm, local, CUT_LAYERS)? {
                break;
            }
            // The band the cut froze is improved before it is split: its
            // tets were never optimised, and splits judged on them against
            // the floor would be refused (tripod, --hsiz 1.5 on 2 ranks: 102
            // of 102 long edges refused after the move without this).
            crate::improve::improve(&mut local.mesh, &without_insertion(&opts.improve));
        }
        for _ in 0..opts.passes {
            pass += 1;
            let t = std::time::Instant::now();
            let size = local.size.as_mut().expect("checked above");
            let floor = comm.min(worst_metric_quality(&local.mesh, size));
            let sopts = SizeOptions {
                quality_floor: Some(floor),
                improve: opts.improve.clone(),
            };
            let cut_split = split_cut_edges(comm, &mut local.mesh, size, floor)?;
            let r = size_pass(&mut local.mesh, size, &sopts);
            let on_cut = long_cut_edges_owned(&local.mesh, size, comm.rank);
            let s = comm.sum(&[
                (r.long_edges - r.on_cut) as u64,
                r.split as u64 + cut_split,
                r.refused as u64,
                (r.long_after - r.on_cut) as u64,
                on_cut,
            ]);
            let report = SizePassReport {
                cut_moves: round,
                long_edges: s[0],
                split: s[1],
                refused: s[2],
                long_after: s[3],
                long_on_cut: s[4],
            };
            let c = census(comm, &local.mesh)?;
            let stats = global_stats(comm, &local.mesh, &c)?;
            on_pass(pass, &stats, &report, t.elapsed().as_secs_f64());
            let done = report.long_after + report.long_on_cut == 0 || report.split == 0;
            last = Some((c, stats, report));
            // After the move, passes that split nothing more only repeat
            // the optimize phase.
            if done && (opts.until_met || after_cut_move) {
                break;
            }
        }
    }
    if comm.size > 1 && rebalance_and_say(comm, local)? {
        if let Some(l) = last.as_mut() {
            l.0 = census(comm, &local.mesh)?;
            l.1 = global_stats(comm, &local.mesh, &l.0)?;
        }
    }
    match last {
        Some(l) => Ok(l),
        None => {
            let c = census(comm, &local.mesh)?;
            let stats = global_stats(comm, &local.mesh, &c)?;
            Ok((c, stats, SizePassReport::default()))
        }
    }
}

/// Splits the long edges of the cut that every rank holding them splits in
/// this pass (see the module documentation); returns how many of them this
/// rank counts (each edge once over the ranks, as [`lowest_neighbour`]
/// says).
fn split_cut_edges(
    comm: &Comm,
    mesh: &mut TetMesh,
    size: &mut SizeMap,
    floor: f64,
) -> Result<u64, String> {
    let lowest = lowest_neighbour(mesh);
    let mut long: Vec<(f64, [u64; 6], [u32; 2])> = lowest
        .keys()
        .filter_map(|&[a, b]| {
            let l = size.edge_length(a, b, mesh.point(a), mesh.point(b));
            (l > SPLIT_ABOVE).then(|| (l, edge_coords(mesh, a, b), [a, b]))
        })
        .collect();
    // The same order on every rank: lengths are the same bits on every
    // holder (same points, same sizes, sums taken in either order).
    long.sort_by(|x, y| y.0.total_cmp(&x.0).then(x.1.cmp(&y.1)));
    // A new tet's quality at or above the floor, and the floor above a sine
    // of 1e-6, is far from a zero volume: the exact orientation test in the
    // split cannot refuse what this accepted, on either side.
    let bar = floor.max(1e-6);
    // Every tet holding each long edge and each of their ends, by a scan:
    // after a cut move a rank may hold tets at a point of its cut that meet
    // only at that point or along the edge (the rank across fills the
    // gaps), and a split, which finds its tets through the ball of an end,
    // would split one fan of the edge and leave the other's faces whole.
    // An edge with such an end is not split.
    let mut holding: HashMap<[u32; 2], Vec<u32>> =
        long.iter().map(|&(_, _, e)| (e, Vec::new())).collect();
    let mut at_end: HashMap<u32, usize> = long
        .iter()
        .flat_map(|&(_, _, e)| e.map(|v| (v, 0)))
        .collect();
    for t in mesh.tet_ids() {
        let v = mesh.tet(t);
        for x in v {
            if let Some(n) = at_end.get_mut(&x) {
                *n += 1;
            }
        }
        for [i, j] in TET_EDGES {
            if let Some(h) = holding.get_mut(&edge_key(v[i], v[j])) {
                h.push(t);
            }
        }
    }
    let mut shell = Vec::new();
    let one_ball = |v: u32, shell: &mut Vec<u32>| {
        mesh.ball(v, shell);
        shell.len() == at_end[&v]
    };
    let votes: Vec<([u64; 6], bool)> = long
        .iter()
        .map(|&(_, k, [a, b])| {
            let whole = one_ball(a, &mut shell) && one_ball(b, &mut shell);
            let q = split_quality(mesh, size, a, b, &mut shell);
            (k, whole && q.is_some_and(|q| q >= bar))
        })
        .collect();
    let can = comm.agree(all_holders_agree(comm, &votes))?;
    // Edges with disjoint shells on this side: each split then sees the
    // tets it was judged on, whatever the order.
    let mut used: HashSet<u32> = HashSet::new();
    let picks: Vec<([u64; 6], bool)> = long
        .iter()
        .zip(&can)
        .map(|(&(_, k, [a, b]), &can)| {
            if !can {
                return (k, false);
            }
            let shell = &holding[&[a, b]];
            let free = shell.iter().all(|t| !used.contains(t));
            if free {
                used.extend(shell.iter().copied());
            }
            (k, free)
        })
        .collect();
    let go = comm.agree(all_holders_agree(comm, &picks))?;
    let (mut counted, mut failed) = (0u64, Vec::new());
    for (&(_, _, [a, b]), &go) in long.iter().zip(&go) {
        if !go {
            continue;
        }
        match split_at_midpoint(mesh, size, a, b) {
            Ok(()) => counted += u64::from(comm.rank < lowest[&[a, b]]),
            Err(e) => failed.push(format!("{} – {}: {e}", mesh.point(a), mesh.point(b))),
        }
    }
    comm.agree(if failed.is_empty() {
        Ok(counted)
    } else {
        Err(format!(
            "rank {}: {} edges of the cut could not be split where the rank across split them (the first: {})",
            comm.rank,
            failed.len(),
            failed[0]
        ))
    })
}

/// Every edge of `mesh`'s partition faces with the lowest rank across those
/// faces: the rank that counts the edge is the lowest of that one and
/// itself.
fn lowest_neighbour(mesh: &TetMesh) -> HashMap<[u32; 2], u32> {
    let mut lowest: HashMap<[u32; 2], u32> = HashMap::new();
    for (f, &m) in mesh.face_markers() {
        if let Some(pm) = PartitionMarker::decode(m) {
            for i in 0..3 {
                let l = lowest
                    .entry(edge_key(f[i], f[(i + 1) % 3]))
                    .or_insert(u32::MAX);
                *l = (*l).min(pm.neighbour);
            }
        }
    }
    lowest
}

/// The long edges on `mesh`'s partition faces that rank `me` counts (once
/// over the ranks; an edge two ranks share without a shared face would
/// count twice).
fn long_cut_edges_owned(mesh: &TetMesh, size: &SizeMap, me: u32) -> u64 {
    lowest_neighbour(mesh)
        .iter()
        .filter(|(&[a, b], &l)| {
            me < l && size.edge_length(a, b, mesh.point(a), mesh.point(b)) > SPLIT_ABOVE
        })
        .count() as u64
}
