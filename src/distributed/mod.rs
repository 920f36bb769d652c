//! Distributed √3 refinement over MPI (feature `mpi`), in the manner of
//! ParMmg (Cirrottola–Froehly): the mesh is cut into parts, each rank
//! refines its part with the serial step while the cut stays frozen, then
//! the cut moves and the band that was frozen is improved.
//!
//! 1. **Partition.** Rank 0 holds the input; METIS cuts its dual graph
//!    ([`partition_dual_graph`]), each tet weighted by the tets it will
//!    become (a selected tet of an adaptive run weighs
//!    [`GROWTH_PER_STEP`] to the power of the steps). Each rank receives
//!    its tets as a self-contained part: points, tags, regions, `level`,
//!    `parent` (global input ids), and its cut faces as partition faces
//!    ([`crate::PartitionMarker`]) naming the rank across.
//! 2. **Refine.** The serial step runs on every part. A partition face is
//!    refined like a linear interface — split at its canonical centroid,
//!    never flipped, never moved — so both sides create the same points
//!    without talking. In an adaptive step the ranks first tell each other,
//!    face by face, whether the tet on their side is refined; a face whose
//!    other side is not stays whole (held), as a serial interface does.
//! 3. **Improve across the cut.** Once every step is done, the tets within
//!    three layers of the cut move to the lowest rank holding one of their
//!    vertices, so the old cut lies inside a part with a free layer before
//!    the new cut, and the optimize phase runs again over the band the old
//!    cut froze, with only the new cut frozen, including a long-edge round
//!    for the old cut's edges that the steps' rounds left whole. Then ranks
//!    above the mean share give whole layers to neighbours below it (the
//!    rebalance).
//! 4. **Census.** After each step the ranks check that the cut conforms
//!    (every partition face held by exactly two ranks), reduce the
//!    statistics of the union ([`global_stats`]) and, at the end, number
//!    the points globally ([`global_point_ids`]).
//!
//! A `.pvtu` input skips step 1: each rank reads its own pieces and
//! [`assemble`] finds the faces two ranks share, which become partition
//! faces.
//!
//! Every collective is preceded by an agreement ([`Comm::agree`]): one
//! rank's failure ends every rank with an error, never a hang.

mod assemble;
mod comm;
mod cut;
mod part;
mod partition;
mod size;

pub use assemble::assemble;
pub use comm::{failure_printed, Comm, OTHER_RANK_FAILED};
pub use cut::{census, global_point_ids, global_stats, Census};
pub use part::{point_key, MarkerSlots, Part, PointKey, Reader, Wire};
pub use partition::partition_dual_graph;
pub use size::{size_distributed, DistributedSizeOptions, SizePassReport};

use crate::mesh::partition::PartitionMarker;
use crate::mesh::TetMesh;
use crate::refine::size::SizeMap;
use crate::refine::step::descendants_of_last_step;
use crate::report::MeshStats;
use crate::{RefineOptions, StepReport};
use cut::{across_faces, face_key_of, partition_faces};
use part::FaceFate;

/// The partition weight of a refined tet per step: about the tets one
/// default √3 step makes of it (on the shipped meshes 8.9 to 13.1 with the
/// two long-edge rounds). The weight was 6 before the second round; an
/// adaptive two-step run on the tripod then ended 28 % heavier on one of
/// two ranks.
pub const GROWTH_PER_STEP: i32 = 10;

/// A rank's share of a distributed refinement.
pub struct LocalMesh {
    /// This rank's tets; its cut faces carry partition markers.
    pub mesh: TetMesh,
    /// The user markers partition faces carry, by slot.
    pub slots: MarkerSlots,
    /// The size map over this rank's points, in a size-driven run.
    pub size: Option<SizeMap>,
}

/// How often the cut moves after the last step, each move followed by the
/// optimize phase over the band it froze.
const CUT_MOVES: usize = 1;
/// Layers of tets each move carries across: the band along the old cut
/// keeps free layers between it and the new cut (one layer and one ring
/// left mmg_cube's average on 2 ranks at 43.00° against the serial 44.06°,
/// three layers and two rings at 43.29°).
const CUT_LAYERS: usize = 3;
/// A rank holding more tets than this times the mean after the cut has
/// moved gives some to its neighbours ([`rebalance`]).
const REBALANCE_ABOVE: f64 = 1.05;
/// Rings of tets around the old cut's points the optimize phase runs over
/// after a move: two, so that the vertices next to the frozen ones move
/// with their whole balls.
const BAND_RINGS: usize = 2;

/// Options of [`refine_distributed`].
#[derive(Clone, Debug)]
pub struct DistributedOptions {
    /// The serial step's options; `selection` is rank 0's, per input tet.
    pub refine: RefineOptions,
    /// Number of √3 steps.
    pub steps: usize,
    /// Move the cut after the last step and improve the band it froze.
    pub improve_across_cut: bool,
}

/// Splits rank 0's `input` into one part per rank, METIS on the dual graph
/// weighted by the work each tet brings; every rank gets its part, with its
/// points' entries of rank 0's `size` map when there is one.
pub fn distribute(
    comm: &Comm,
    input: Option<&TetMesh>,
    selection: Option<&[bool]>,
    size: Option<&SizeMap>,
    steps: usize,
) -> Result<(LocalMesh, Option<Vec<bool>>), String> {
    let prepared = match input {
        Some(mesh) if comm.rank == 0 => prepare_parts(comm.size, mesh, selection, size, steps),
        _ if comm.rank == 0 => Err("rank 0 holds no input mesh".to_string()),
        _ => Ok((Vec::new(), MarkerSlots::default())),
    };
    let (messages, slots) = comm.agree(prepared)?;
    let slot_bytes = comm.broadcast(slots.encode());
    let mut markers = Vec::new();
    MarkerSlots::decode_into(&slot_bytes, &mut markers)?;
    let slots = MarkerSlots { markers };
    let out = if comm.rank == 0 {
        messages
    } else {
        vec![Vec::new(); comm.size as usize]
    };
    let got = comm.exchange(out)?;
    let built = Part::decode(&got[0])
        .and_then(|mut p| {
            let size = p.sizes.take();
            p.build().map(|(m, s)| (m, s, size))
        })
        .map_err(|e| format!("rank {}: its part: {e}", comm.rank));
    let (mesh, selected, size) = comm.agree(built)?;
    // Only rank 0 knows whether the run is adaptive.
    let adaptive = comm.sum(&[u64::from(comm.rank == 0 && selection.is_some())])[0] > 0;
    let selected = adaptive.then_some(selected);
    Ok((LocalMesh { mesh, slots, size }, selected))
}

/// Rank 0's side of [`distribute`]: one encoded part per rank.
fn prepare_parts(
    ranks: u32,
    mesh: &TetMesh,
    selection: Option<&[bool]>,
    size: Option<&SizeMap>,
    steps: usize,
) -> Result<(Vec<Vec<u8>>, MarkerSlots), String> {
    let slots = MarkerSlots::of(mesh)?;
    let ids: Vec<u32> = mesh.tet_ids().collect();
    // A refined tet weighs what it grows into, but METIS sums the weights
    // in 32 bits: the growth is capped so that the total stays below half
    // of `i32::MAX` (20 size passes on 15k tets overflowed it, and METIS
    // left a rank empty).
    let cap = (i64::from(i32::MAX) / 2 / ids.len().max(1) as i64).max(1);
    let grow = i64::from(GROWTH_PER_STEP.saturating_pow(steps.min(8) as u32)).min(cap) as i32;
    let weight: Vec<i32> = ids
        .iter()
        .map(|&t| match selection {
            Some(s) if !s.get(t as usize).copied().unwrap_or(false) => 1,
            _ => grow,
        })
        .collect();
    let part_of_dense = partition_dual_graph(mesh, ranks, &weight)?;
    let mut part_of = vec![0u32; mesh.n_tet_slots()];
    for (i, &t) in ids.iter().enumerate() {
        part_of[t as usize] = part_of_dense[i];
    }
    let mut by_rank: Vec<Vec<u32>> = vec![Vec::new(); ranks as usize];
    for &t in &ids {
        by_rank[part_of[t as usize] as usize].push(t);
    }
    if let Some(r) = by_rank.iter().position(Vec::is_empty) {
        return Err(format!(
            "METIS left rank {r} without tetrahedra; run on fewer ranks"
        ));
    }
    Ok((
        by_rank
            .iter()
            .enumerate()
            .map(|(r, tets)| {
                let mut p = Part::from_tets(mesh, tets, &slots, selection, |t, f| {
                    let h = mesh.adj(t)[f];
                    if h == crate::NO_ADJ {
                        FaceFate::Domain
                    } else if part_of[(h >> 2) as usize] as usize != r {
                        FaceFate::Cut(part_of[(h >> 2) as usize])
                    } else {
                        FaceFate::Interior
                    }
                });
                // The input tet's own id: the `parent` of every descendant.
                p.parent = tets.clone();
                if let Some(m) = size {
                    p.attach_sizes(mesh, tets, m);
                }
                p.encode()
            })
            .collect(),
        slots,
    ))
}

/// Refines every rank's part `opts.steps` times, then (with
/// `improve_across_cut`) moves the cut and improves the band it froze.
/// `on_step(step, union_stats, this_rank_report)` runs on every rank after
/// each step with the statistics of the union; `progress` hears this
/// rank's phases (the command line shows rank 0's). Returns the census and
/// the union's statistics of the final mesh.
pub fn refine_distributed(
    comm: &Comm,
    local: &mut LocalMesh,
    first_selection: Option<Vec<bool>>,
    opts: &DistributedOptions,
    progress: &dyn crate::Progress,
    mut on_step: impl FnMut(usize, &MeshStats, &StepReport),
) -> Result<(Census, MeshStats), String> {
    let adaptive = first_selection.is_some();
    // The census and statistics of the mesh as it stands, so that the end
    // reuses the last ones instead of taking them again.
    let mut last = None;
    let mut step_opts = opts.refine.clone();
    step_opts.selection = first_selection;
    for s in 1..=opts.steps {
        if s > 1 && adaptive {
            step_opts.selection = Some(descendants_of_last_step(&local.mesh, s - 1));
        }
        if adaptive {
            hold_faces_across_unrefined_tets(comm, &mut local.mesh, &step_opts)?;
        }
        let report =
            crate::refine::refine_step_with_progress(&mut local.mesh, s, &step_opts, progress);
        release_held_faces(&mut local.mesh);
        let c = census(comm, &local.mesh)?;
        let stats = global_stats(comm, &local.mesh, &c)?;
        on_step(s, &stats, &report);
        last = Some((c, stats));
    }
    // No step, no cut move: `--steps 0` hands the input on as it came.
    if opts.improve_across_cut && comm.size > 1 && opts.steps > 0 {
        let mut o = opts.refine.clone();
        o.selection = None;
        let mut changed = false;
        for k in 1..=CUT_MOVES {
            let t0 = std::time::Instant::now();
            let frozen = cut_point_keys(&local.mesh);
            if !migrate_cut_layer(comm, local, CUT_LAYERS)? {
                break;
            }
            changed = true;
            let t1 = std::time::Instant::now();
            let zone = band_zone(
                &local.mesh,
                &frozen,
                opts.refine.smooth_refined_only,
                opts.steps,
            );
            let band = zone.1.iter().filter(|&&b| b).count() as u64;
            crate::refine::step::optimize_phase(
                &mut local.mesh,
                opts.steps,
                &o,
                false,
                Some(zone),
                0.0,
            );
            let band = comm.sum(&[band])[0];
            if comm.rank == 0 {
                eprintln!(
                    "cut move {k}/{CUT_MOVES}: {band} tets in the band, migration {:.2} s, optimize {:.2} s (rank 0)",
                    (t1 - t0).as_secs_f64(),
                    t1.elapsed().as_secs_f64()
                );
            }
        }
        changed |= rebalance_and_say(comm, local)?;
        // The census and statistics of the mesh as the moves and the
        // rebalance leave it, taken once.
        if changed {
            let c = census(comm, &local.mesh)?;
            last = Some((c, global_stats(comm, &local.mesh, &c)?));
        }
    }
    match last {
        Some(l) => Ok(l),
        None => {
            let c = census(comm, &local.mesh)?;
            Ok((c, global_stats(comm, &local.mesh, &c)?))
        }
    }
}

/// The exact coordinates of every point on a partition face.
fn cut_point_keys(mesh: &TetMesh) -> std::collections::HashSet<part::PointKey> {
    partition_faces(mesh)
        .into_iter()
        .flat_map(|(t, f, _)| mesh.face_vertices(t, f))
        .map(|v| part::point_key(mesh.point(v)))
        .collect()
}

/// The band a cut froze, once it has moved: the tets with a vertex at one
/// of `frozen`'s points, and their vertices (per point, per tet slot). With
/// `refined_only` (`--smooth refined`), only the tets refined in the last
/// step count.
fn band_zone(
    mesh: &TetMesh,
    frozen: &std::collections::HashSet<part::PointKey>,
    refined_only: bool,
    step: usize,
) -> (Vec<bool>, Vec<bool>) {
    let on_cut: Vec<bool> = mesh
        .points()
        .iter()
        .map(|&p| frozen.contains(&part::point_key(p)))
        .collect();
    let refined = refined_only.then(|| descendants_of_last_step(mesh, step));
    mesh.grow_zone(on_cut, BAND_RINGS, |t| {
        refined.as_ref().is_none_or(|r| r[t as usize])
    })
}

/// Before an adaptive step: a partition face whose tet on the other rank
/// is not refined is held (not split), as the serial step leaves an
/// interface face whole unless both its tets are split.
fn hold_faces_across_unrefined_tets(
    comm: &Comm,
    mesh: &mut TetMesh,
    opts: &RefineOptions,
) -> Result<(), String> {
    let sel = opts.selection.as_deref().unwrap_or(&[]);
    let selected = |t: u32| u32::from(sel.get(t as usize).copied().unwrap_or(false));
    let across = across_faces(comm, mesh, selected)?;
    for (t, f, pm) in partition_faces(mesh) {
        if across.get(&face_key_of(mesh, t, f)) == Some(&0) {
            let held = PartitionMarker { hold: true, ..pm };
            mesh.set_face_marker(mesh.face_vertices(t, f), held.encode());
        }
    }
    Ok(())
}

/// After a step: every held face is an ordinary partition face again.
fn release_held_faces(mesh: &mut TetMesh) {
    let held: Vec<([u32; 3], PartitionMarker)> = mesh
        .face_markers()
        .iter()
        .filter_map(|(f, &m)| {
            PartitionMarker::decode(m)
                .filter(|p| p.hold)
                .map(|p| (*f, p))
        })
        .collect();
    for (f, pm) in held {
        let free = PartitionMarker { hold: false, ..pm };
        mesh.set_face_marker(f, free.encode());
    }
}

/// Moves every tet within `layers` layers of the cut to the lowest rank
/// holding one of its vertices (as far as the partition faces at its
/// vertices tell), and rebuilds each rank's mesh: the old cut is then
/// inside a part.
///
/// Returns whether the cut moved.
fn migrate_cut_layer(comm: &Comm, local: &mut LocalMesh, layers: usize) -> Result<bool, String> {
    let mesh = &local.mesh;
    let me = comm.rank;
    let mut lowest = vec![u32::MAX; mesh.n_points()];
    for (t, f, pm) in partition_faces(mesh) {
        for v in mesh.face_vertices(t, f) {
            let l = &mut lowest[v as usize];
            *l = (*l).min(pm.neighbour);
        }
    }
    let mut dest = vec![me; mesh.n_tet_slots()];
    for layer in 0..layers {
        if layer > 0 {
            // The next layer: the lowest destination of a tet at each point.
            for t in mesh.tet_ids() {
                for v in mesh.tet(t) {
                    let l = &mut lowest[v as usize];
                    *l = (*l).min(dest[t as usize]);
                }
            }
        }
        for t in mesh.tet_ids() {
            for v in mesh.tet(t) {
                dest[t as usize] = dest[t as usize].min(lowest[v as usize]);
            }
        }
    }
    migrate(comm, local, dest)
}

/// Sends every tet of this rank to rank `dest[t]` (per tet slot) and
/// rebuilds each rank's mesh from what it keeps and receives; faces between
/// tets that end on different ranks become partition faces. Returns false,
/// with nothing moved, when a rank would be left without tets.
fn migrate(comm: &Comm, local: &mut LocalMesh, dest: Vec<u32>) -> Result<bool, String> {
    let mesh = &local.mesh;
    let me = comm.rank;
    let across = across_faces(comm, mesh, |t| dest[t as usize])?;
    let mut by_rank: Vec<Vec<u32>> = vec![Vec::new(); comm.size as usize];
    for t in mesh.tet_ids() {
        by_rank[dest[t as usize] as usize].push(t);
    }
    // A rank whose every tet touches the cut would be left empty: then the
    // cut stays where it is (every rank learns it from the same sum).
    let after = comm.sum(&by_rank.iter().map(|b| b.len() as u64).collect::<Vec<_>>());
    if after.contains(&0) {
        return Ok(false);
    }
    let mut unmatched = 0usize;
    let mut parts: Vec<Part> = by_rank
        .iter()
        .map(|tets| {
            let mut part = Part::from_tets(mesh, tets, &local.slots, None, |t, f| {
                let h = mesh.adj(t)[f];
                let other = if h == crate::NO_ADJ {
                    let fv = mesh.face_vertices(t, f);
                    let is_cut = mesh
                        .face_marker(fv)
                        .is_some_and(crate::mesh::partition::is_partition_marker);
                    if !is_cut {
                        return FaceFate::Domain;
                    }
                    match across.get(&face_key_of(mesh, t, f)) {
                        Some(&o) => o,
                        None => {
                            unmatched += 1;
                            return FaceFate::Domain;
                        }
                    }
                } else {
                    dest[(h >> 2) as usize]
                };
                if other == dest[t as usize] {
                    FaceFate::Interior
                } else {
                    FaceFate::Cut(other)
                }
            });
            if let Some(m) = &local.size {
                part.attach_sizes(mesh, tets, m);
            }
            part
        })
        .collect();
    comm.agree(if unmatched > 0 {
        Err(format!(
            "rank {me}: {unmatched} partition faces unmatched before migration"
        ))
    } else {
        Ok(())
    })?;
    let out: Vec<Vec<u8>> = parts
        .iter()
        .enumerate()
        .map(|(r, p)| {
            if r as u32 == me || p.data.tets.is_empty() {
                Vec::new()
            } else {
                p.encode()
            }
        })
        .collect();
    // The old mesh is in the parts now: free it before the rebuild, which
    // would otherwise hold both.
    local.mesh = TetMesh::default();
    let got = comm.exchange(out)?;
    // In rank order (the own part at its own rank), so the rebuilt mesh is
    // the same whatever the message timing.
    let mut all = Vec::with_capacity(got.len());
    for (r, bytes) in got.iter().enumerate() {
        if r as u32 == me {
            all.push(std::mem::take(&mut parts[r]));
        } else if !bytes.is_empty() {
            all.push(Part::decode(bytes).map_err(|e| format!("rank {me}: from rank {r}: {e}"))?);
        }
    }
    all.retain(|p| !p.data.tets.is_empty());
    let mut merged = Part::merge(all);
    local.size = merged.sizes.take();
    let rebuilt = merged.build().map(|(m, _)| m);
    local.mesh = comm.agree(rebuilt)?;
    Ok(true)
}

/// [`rebalance`], with a line from rank 0 saying what moved. Returns
/// whether tets moved (the caller's census and statistics are then stale).
pub(crate) fn rebalance_and_say(comm: &Comm, local: &mut LocalMesh) -> Result<bool, String> {
    let t0 = std::time::Instant::now();
    let Some(r) = rebalance(comm, local)? else {
        return Ok(false);
    };
    if comm.rank == 0 {
        let list = |v: &[u64]| v.iter().map(u64::to_string).collect::<Vec<_>>().join(" / ");
        eprintln!(
            "rebalanced: tets per rank {} -> {} ({} moved, {:.2} s)",
            list(&r.before),
            list(&r.after),
            r.moved,
            t0.elapsed().as_secs_f64()
        );
    }
    Ok(true)
}

/// The shares of tets per rank before and after [`rebalance`].
#[derive(Clone, Debug, PartialEq, Eq)]
pub(crate) struct Rebalanced {
    /// Tets per rank before.
    pub(crate) before: Vec<u64>,
    /// Tets per rank after.
    pub(crate) after: Vec<u64>,
    /// Tets that changed rank.
    pub(crate) moved: u64,
}

/// Evens out the ranks' shares once the cut has moved. Every move carries
/// its layers to the lower rank, so the low ranks grow (gmsh_t16, one step
/// on 3 ranks, ended at 62,258 / 42,478 / 18,704 tets): a rank above the
/// mean gives tets to each neighbouring rank below it, whole layers from
/// their common cut (the tets with a vertex on it, then those with a
/// vertex on a tet given), in one migration, in the manner of a
/// diffusion load balancer (Cybenko's first-order scheme, one round). Each
/// neighbour's deficit is shared among the ranks bordering it in
/// proportion to their surpluses, and no rank gives more than its own
/// surplus. The tets that cross were inside a part when the band was
/// improved, so the new cut runs through improved tets. Returns `None`,
/// moving nothing, when no rank holds more than [`REBALANCE_ABOVE`] times
/// the mean.
pub(crate) fn rebalance(comm: &Comm, local: &mut LocalMesh) -> Result<Option<Rebalanced>, String> {
    let p = comm.size as usize;
    let before = comm.all_gather(local.mesh.n_tets() as u64);
    let mean = before.iter().sum::<u64>() as f64 / p as f64;
    if before.iter().all(|&n| n as f64 <= REBALANCE_ABOVE * mean) {
        return Ok(None);
    }
    let me = comm.rank as usize;
    let mesh = &local.mesh;
    let faces = partition_faces(mesh);
    // Who borders whom: this rank fills its own row.
    let mut row = vec![0u64; p * p];
    for (_, _, pm) in &faces {
        row[me * p + pm.neighbour as usize] = 1;
    }
    let borders = comm.sum(&row);
    let surplus = |r: usize| (before[r] as f64 - mean).max(0.0);
    let deficit = |r: usize| (mean - before[r] as f64).max(0.0);
    let mut quota = vec![0.0f64; p];
    if surplus(me) > 0.0 {
        for (j, q) in quota.iter_mut().enumerate() {
            if borders[me * p + j] == 0 || deficit(j) == 0.0 {
                continue;
            }
            let givers: f64 = (0..p)
                .filter(|&k| borders[k * p + j] > 0)
                .map(surplus)
                .sum();
            *q = deficit(j) * surplus(me) / givers;
        }
        let total: f64 = quota.iter().sum();
        if total > surplus(me) {
            let scale = surplus(me) / total;
            quota.iter_mut().for_each(|q| *q *= scale);
        }
    }
    let mut dest = vec![comm.rank; mesh.n_tet_slots()];
    for (j, &q) in quota.iter().enumerate() {
        let mut left = q as usize;
        if left == 0 {
            continue;
        }
        let mut reached = vec![false; mesh.n_points()];
        for (t, f, pm) in &faces {
            if pm.neighbour as usize == j {
                for v in mesh.face_vertices(*t, *f) {
                    reached[v as usize] = true;
                }
            }
        }
        while left > 0 {
            let layer: Vec<u32> = mesh
                .tet_ids()
                .filter(|&t| {
                    dest[t as usize] == comm.rank
                        && mesh.tet(t).iter().any(|&v| reached[v as usize])
                })
                .collect();
            // Whole layers only (the last one when at least half of it is
            // wanted): a layer cut short in id order leaves a ragged cut
            // (gmsh_t16 on 3 ranks: 8,471 partition faces against 5,101
            // before the rebalance).
            if layer.is_empty() || 2 * left < layer.len() {
                break;
            }
            left = left.saturating_sub(layer.len());
            for t in layer {
                dest[t as usize] = j as u32;
                for v in mesh.tet(t) {
                    reached[v as usize] = true;
                }
            }
        }
    }
    // A dead slot keeps this rank: only live tets were given.
    let moved = comm.sum(&[dest.iter().filter(|&&d| d != comm.rank).count() as u64])[0];
    if moved == 0 || !migrate(comm, local, dest)? {
        return Ok(None);
    }
    let after = comm.all_gather(local.mesh.n_tets() as u64);
    Ok(Some(Rebalanced {
        before,
        after,
        moved,
    }))
}

/// Starts MPI (the returned universe finalises it when dropped; keep it
/// until the last collective) and wraps its world communicator.
pub fn init() -> Result<(mpi::environment::Universe, Comm), String> {
    let universe =
        mpi::initialize().ok_or_else(|| "MPI was initialised twice in one process".to_string())?;
    let comm = Comm::new(universe.world());
    Ok((universe, comm))
}

/// Every partition face of `local` gets its own user marker back (or
/// none): what a piece or a gathered file carries.
pub fn strip_partition_markers(local: &mut LocalMesh) {
    let cut: Vec<([u32; 3], PartitionMarker)> = local
        .mesh
        .face_markers()
        .iter()
        .filter_map(|(f, &m)| PartitionMarker::decode(m).map(|p| (*f, p)))
        .collect();
    for (f, pm) in cut {
        local
            .mesh
            .set_face_marker(f, local.slots.marker(pm.user_slot));
    }
}

/// Gathers every rank's mesh on rank 0 as one mesh (points on the cut
/// merged, partition faces interior again); `None` on the other ranks.
pub fn gather(comm: &Comm, local: &LocalMesh) -> Result<Option<TetMesh>, String> {
    let mesh = &local.mesh;
    let tets: Vec<u32> = mesh.tet_ids().collect();
    let part = Part::from_tets(mesh, &tets, &local.slots, None, |t, f| {
        if mesh.adj(t)[f] != crate::NO_ADJ {
            return FaceFate::Interior;
        }
        let cut = mesh
            .face_marker(mesh.face_vertices(t, f))
            .is_some_and(crate::mesh::partition::is_partition_marker);
        if cut {
            FaceFate::Interior
        } else {
            FaceFate::Domain
        }
    });
    let mut out = vec![Vec::new(); comm.size as usize];
    out[0] = part.encode();
    let got = comm.exchange(out)?;
    let merged = if comm.rank == 0 {
        got.iter()
            .map(|b| Part::decode(b))
            .collect::<Result<Vec<_>, _>>()
            .and_then(|parts| Part::merge(parts).build())
            .map(|(m, _)| Some(m))
    } else {
        Ok(None)
    };
    comm.agree(merged)
}
