//! A `.pvtu` input of a distributed `refine` with a `.pvtu` output (see
//! [`per_rank`]): every rank reads its own pieces (the pieces in contiguous blocks: with K pieces on P ranks, rank
//! r reads pieces ⌊rK/P⌋ to ⌊(r+1)K/P⌋ − 1; fewer pieces than ranks is an
//! error), merges them (shared points by `GlobalPointIds` when every piece
//! carries them, else by exact coordinates), detects its features, and
//! [`tetrefine::distributed::assemble`] turns the faces it shares with other
//! ranks into partition faces. No rank ever holds the whole input.

use super::refine::Args;
use std::path::PathBuf;
use tetrefine::distributed::{self as dist, Comm, LocalMesh, Reader, Wire};
use tetrefine::io::MeshMeta;
use tetrefine::MeshData;

/// Whether a distributed run reads its `.pvtu` input per rank: with a
/// `.pvtu` output and none of the options that need the whole input on one
/// rank (a gathered output, `--parent-map`, `--fields`, `--transfer`, a
/// selection, `--features FILE`); otherwise rank 0 reads every piece and
/// METIS partitions, as for any input.
pub fn per_rank(a: &Args) -> bool {
    super::distributed::is_pvtu(&a.input)
        && super::distributed::is_pvtu(&a.output)
        && a.parent_map.is_none()
        && a.fields.is_empty()
        && !a.transfer
        && a.indicator.is_none()
        && a.marks.is_empty()
        && a.region.is_none()
        && a.select_box.is_none()
        && a.sphere.is_none()
        && matches!(a.features.as_str(), "auto" | "none")
}

/// Every rank's share of the `.pvtu` input `a.input`, with its cut faces
/// marked and its size map (`--hsiz`/`--hmax`, or `--size-array NAME`: the
/// point array NAME of its pieces). A collective: a bad piece (missing,
/// corrupt, an inverted or degenerate tet, `GlobalPointIds` that disagree,
/// a size array missing or not a size) ends every rank with an error naming
/// the file.
pub fn load_pieces(comm: &Comm, a: &Args) -> Result<LocalMesh, String> {
    let all = comm.agree(tetrefine::io::read_pvtu_pieces(&a.input).map_err(|e| e.to_string()))?;
    let (k, p) = (all.len() as u64, u64::from(comm.size));
    comm.agree(if k < p && comm.rank == 0 {
        Err(format!(
            "{}: {k} pieces for {p} ranks: every rank reads whole pieces; run on at most {k} ranks",
            a.input.display()
        ))
    } else {
        Ok(())
    })?;
    let mine = own_pieces(comm, &all);
    let size_array = a.size_array.as_deref();
    let read = super::pvtu_merge::merge_pieces(&mine, size_array);
    let (data, ids, fields) = comm.agree(read)?;
    if let Some(name) = size_array {
        same_components(comm, a, name, &fields)?;
    }
    // A rank holds its own pieces only: it could not interpolate their
    // fields at points that the cut move brings from another rank. (The
    // size array is no field of the output: its values travel with the
    // points as the size map.)
    let names: Vec<&str> = fields
        .point_fields
        .iter()
        .chain(&fields.cell_fields)
        .map(|f| f.name.as_str())
        .filter(|n| Some(*n) != size_array)
        .collect();
    let with_fields = comm.sum(&[u64::from(!names.is_empty())])[0] > 0;
    comm.agree(if with_fields && !a.no_transfer && comm.rank == 0 {
        Err(format!(
            "{}: the pieces carry fields ({}) that a per-rank read does not carry over: give --no-transfer to drop them, or a single-file -o (rank 0 then reads every piece and carries them over)",
            a.input.display(),
            if names.is_empty() { "on other ranks".to_string() } else { names.join(", ") }
        ))
    } else {
        Ok(())
    })?;
    check_point_ids(comm, &all, &data, &ids)?;
    let built = tetrefine::TetMesh::from_data(&data)
        .map_err(|e| format!("{}: {e}", super::pvtu_merge::names(&mine)))
        .map(|(mut mesh, _)| {
            // Quietly: a rank's counts are not the input's (the step
            // table's input row gives the union's).
            if a.features == "none" {
                mesh.clear_features();
            } else {
                tetrefine::detect_features_for(&mut mesh, a.feature_angle, a.interfaces);
            }
            mesh
        });
    let mesh = comm.agree(built)?;
    // `--hsiz`/`--hmax`, or `--size-array` from the pieces' point data
    // (`--size FILE.sol` is refused before: it numbers one whole mesh).
    let size = super::size::size_map(None, size_array, a.hsiz, a.hmax, &mesh, &fields)
        .map_err(|e| format!("{}: {e}", super::pvtu_merge::names(&mine)));
    let size = comm.agree(size)?;
    let counts = comm.all_gather(mesh.n_tets() as u64);
    let first: u64 = counts[..comm.rank as usize].iter().sum();
    let total: u64 = counts.iter().sum();
    comm.agree(if total > u64::from(u32::MAX) {
        Err(format!(
            "{}: {total} tets; input tet ids are 32-bit",
            a.input.display()
        ))
    } else {
        Ok(())
    })?;
    if comm.rank == 0 {
        eprintln!(
            "{}: {k} pieces read on {p} ranks, {total} tets",
            a.input.display()
        );
    }
    dist::assemble(comm, mesh, first as u32, size.as_ref())
}

/// Across ranks: the size array `name` has one number of components in
/// every rank's pieces (a length everywhere, or a metric everywhere: the
/// size map's points travel between ranks when the cut moves).
fn same_components(comm: &Comm, a: &Args, name: &str, fields: &MeshMeta) -> super::CliResult {
    let own = fields
        .point_fields
        .iter()
        .find(|f| f.name == name)
        .map_or(0, |f| f.components as u64);
    let all = comm.all_gather(own);
    comm.agree(if comm.rank == 0 && all.iter().any(|&c| c != all[0]) {
        let each: Vec<String> = all
            .iter()
            .enumerate()
            .map(|(r, c)| format!("{c} on rank {r}"))
            .collect();
        Err(format!(
            "{}: --size-array {name} has different numbers of components in the pieces of different ranks ({}): give every piece lengths (1) or every piece metrics (6)",
            a.input.display(),
            each.join(", ")
        ))
    } else {
        Ok(())
    })
}

/// The pieces (index, path) rank `comm.rank` reads of `all`: a contiguous
/// block, ⌊rK/P⌋ to ⌊(r+1)K/P⌋ − 1 (none when there are fewer pieces than
/// ranks and this rank's block is empty).
pub fn own_pieces<'a>(comm: &Comm, all: &'a [PathBuf]) -> Vec<(usize, &'a PathBuf)> {
    let (k, p, r) = (all.len() as u64, u64::from(comm.size), u64::from(comm.rank));
    all.iter()
        .enumerate()
        .skip((r * k / p) as usize)
        .take(((r + 1) * k / p - r * k / p) as usize)
        .collect()
}

/// Across ranks: every `GlobalPointIds` value names one point. Each
/// (id, point) pair goes to the rank its id names (modulo the rank count);
/// there, an id seen with two different points is an error naming the
/// pieces that disagree. (Two ids for one point are not an error: pieces
/// written before [`tetrefine::distributed::global_point_ids`] matched
/// every boundary point gave a point two ranks share without a shared face
/// one id from each, and the points are joined by coordinates too.)
fn check_point_ids(
    comm: &Comm,
    all: &[PathBuf],
    data: &MeshData,
    ids: &[(Option<u64>, usize)],
) -> super::CliResult {
    let mut out: Vec<Wire> = (0..comm.size).map(|_| Wire::default()).collect();
    for (x, &(g, piece)) in data.points.iter().zip(ids) {
        let Some(g) = g else { continue };
        let w = &mut out[(g % u64::from(comm.size)) as usize];
        w.u64(g);
        w.key(&dist::point_key(glam::DVec3::from_array(*x)));
        w.u64(piece as u64);
    }
    let got = comm.exchange(out.into_iter().map(|w| w.0).collect())?;
    let mut seen: std::collections::HashMap<u64, ([u64; 3], u64)> = Default::default();
    let mut bad = None;
    for bytes in &got {
        let mut r = Reader { bytes, at: 0 };
        while !r.done() && bad.is_none() {
            let (g, k, piece) = (r.u64()?, r.key()?, r.u64()?);
            let (k0, p0) = *seen.entry(g).or_insert((k, piece));
            if k0 != k {
                bad = Some((g, p0, piece));
            }
        }
    }
    let piece = |i: u64| {
        all.get(i as usize)
            .map_or_else(|| format!("piece {i}"), |p| p.display().to_string())
    };
    comm.agree(match bad {
        Some((g, a, b)) if a == b => Err(format!(
            "{}: GlobalPointIds {g} names two different points",
            piece(a)
        )),
        Some((g, a, b)) => Err(format!(
            "{} and {}: GlobalPointIds {g} names two different points",
            piece(a),
            piece(b)
        )),
        None => Ok(()),
    })
}
