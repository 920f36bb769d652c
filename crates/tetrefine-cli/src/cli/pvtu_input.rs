//! A `.pvtu` input of a distributed `refine`: every rank reads its own
//! pieces (the pieces in contiguous blocks: with K pieces on P ranks, rank
//! r reads pieces ⌊rK/P⌋ to ⌊(r+1)K/P⌋ − 1; fewer pieces than ranks is an
//! error), merges them (shared points by `GlobalPointIds` when every piece
//! carries them, else by exact coordinates), detects its features, and
//! [`tetrefine::distributed::assemble`] turns the faces it shares with other
//! ranks into partition faces. No rank ever holds the whole input.

use super::refine::Args;
use std::path::PathBuf;
use tetrefine::distributed::{self as dist, Comm, LocalMesh, Reader, Wire};
use tetrefine::MeshData;

/// The options a `.pvtu` input cannot serve yet, refused by name: those
/// that need the whole input on one rank (a gathered output, the parent
/// map, the fields, a selection, an edge list in input numbering).
pub fn refuse_unsupported(a: &Args) -> super::CliResult {
    if !super::distributed::is_pvtu(&a.output) {
        return Err(format!(
            "{}: a .pvtu input is read piece by piece on every rank and refined into a .pvtu output; give -o OUT.pvtu",
            a.input.display()
        ));
    }
    let refused = [
        ("--parent-map", a.parent_map.is_some()),
        ("--fields", !a.fields.is_empty()),
        ("--transfer", a.transfer),
        ("--indicator", a.indicator.is_some()),
        ("--mark", !a.marks.is_empty()),
        ("--region", a.region.is_some()),
        ("--box", a.select_box.is_some()),
        ("--sphere", a.sphere.is_some()),
        (
            "--features FILE",
            !matches!(a.features.as_str(), "auto" | "none"),
        ),
    ];
    match refused.iter().find(|(_, on)| *on) {
        Some((name, _)) => Err(format!(
            "{name} is not available with a .pvtu input (no rank holds the whole input); refine the pieces uniformly, or give a single-file input"
        )),
        None => Ok(()),
    }
}

/// Every rank's share of the `.pvtu` input `a.input`, with its cut faces
/// marked. A collective: a bad piece (missing, corrupt, an inverted tet,
/// `GlobalPointIds` that disagree) ends every rank with an error naming
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
    let r = u64::from(comm.rank);
    let mine: Vec<(usize, &PathBuf)> = all
        .iter()
        .enumerate()
        .skip((r * k / p) as usize)
        .take(((r + 1) * k / p - r * k / p) as usize)
        .collect();
    let read = merge_pieces(&mine);
    let (data, ids) = comm.agree(read)?;
    check_point_ids(comm, &all, &data, &ids)?;
    let built = tetrefine::TetMesh::from_data(&data)
        .map_err(|e| format!("{}: {e}", names(&mine)))
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
    dist::assemble(comm, mesh, first as u32)
}

/// The names of `pieces`, for a message.
fn names(pieces: &[(usize, &PathBuf)]) -> String {
    pieces
        .iter()
        .map(|(_, p)| p.display().to_string())
        .collect::<Vec<_>>()
        .join(", ")
}

/// Per merged point: its `GlobalPointIds` value (when the pieces carry
/// them) and the index of the piece it was first read from.
type PointIds = Vec<(Option<u64>, usize)>;

/// This rank's pieces as one mesh: points shared by `GlobalPointIds` when
/// every piece has them (and by exact coordinates: equal coordinates are
/// one point), else by exact coordinates alone. A piece that cannot be
/// read, holds an inverted tet, or gives one id to two points is an error
/// naming it.
fn merge_pieces(pieces: &[(usize, &PathBuf)]) -> Result<(MeshData, PointIds), String> {
    let mut read = Vec::with_capacity(pieces.len());
    for &(i, path) in pieces {
        let (d, meta) = tetrefine::io::read_mesh_with_meta(path).map_err(|e| e.to_string())?;
        let gids = match meta
            .point_fields
            .iter()
            .find(|f| f.name == "GlobalPointIds")
        {
            Some(f) if f.components == 1 => Some(
                f.values
                    .iter()
                    .map(|&g| {
                        (g >= 0.0 && g.fract() == 0.0)
                            .then_some(g as u64)
                            .ok_or_else(|| {
                                format!("{}: GlobalPointIds holds {g}, not an id", path.display())
                            })
                    })
                    .collect::<Result<Vec<u64>, String>>()?,
            ),
            Some(_) => {
                return Err(format!(
                    "{}: GlobalPointIds has more than one component",
                    path.display()
                ))
            }
            None => None,
        };
        if let Some(t) = d.tets.iter().position(|t| {
            let q = t.map(|v| glam::DVec3::from_array(d.points[v as usize]));
            tetrefine::geom::tet_volume(&q) < 0.0
        }) {
            return Err(format!(
                "{}: tetrahedron {} is inverted (negative volume): a corrupt piece",
                path.display(),
                t + 1
            ));
        }
        read.push((i, path, d, gids));
    }
    let by_id = read.iter().all(|r| r.3.is_some());
    let mut out = MeshData::default();
    let mut ids: PointIds = Vec::new();
    let mut by_gid: std::collections::HashMap<u64, u32> = Default::default();
    let mut by_key: std::collections::HashMap<[u64; 3], u32> = Default::default();
    let key = |p: [f64; 3]| dist::point_key(glam::DVec3::from_array(p));
    for (i, path, d, gids) in read {
        let mut map = Vec::with_capacity(d.points.len());
        for (v, &x) in d.points.iter().enumerate() {
            let g = gids.as_ref().map(|g| g[v]);
            let next = out.points.len() as u32;
            let at = match (by_id, g) {
                (true, Some(g)) => match by_gid.get(&g) {
                    Some(&at) if out.points[at as usize] != x => {
                        let other = pieces
                            .iter()
                            .find(|(j, _)| *j == ids[at as usize].1)
                            .map_or_else(
                                || "this piece".to_string(),
                                |(_, p)| p.display().to_string(),
                            );
                        return Err(format!(
                            "{}: GlobalPointIds {g} names {x:?} here and {:?} in {other}",
                            path.display(),
                            out.points[at as usize]
                        ));
                    }
                    Some(&at) => at,
                    None => {
                        // Equal coordinates are one point even under two
                        // ids: a point two ranks share without a shared
                        // face (a pinch) gets an id from each.
                        let at = *by_key.entry(key(x)).or_insert(next);
                        by_gid.insert(g, at);
                        at
                    }
                },
                _ => *by_key.entry(key(x)).or_insert(next),
            };
            if at == next {
                out.points.push(x);
                ids.push((g, i));
            }
            map.push(at);
        }
        out.tets
            .extend(d.tets.iter().map(|t| t.map(|v| map[v as usize])));
        out.tet_regions
            .extend((0..d.tets.len()).map(|t| d.region(t)));
        out.triangles.extend(
            d.triangles
                .iter()
                .map(|&(f, m)| (f.map(|v| map[v as usize]), m)),
        );
        out.edges.extend(
            d.edges
                .iter()
                .map(|&(e, m)| (e.map(|v| map[v as usize]), m)),
        );
        out.corners
            .extend(d.corners.iter().map(|&v| map[v as usize]));
        out.required_vertices
            .extend(d.required_vertices.iter().map(|&v| map[v as usize]));
    }
    out.corners.sort_unstable();
    out.corners.dedup();
    out.required_vertices.sort_unstable();
    out.required_vertices.dedup();
    Ok((out, ids))
}

/// Across ranks: every `GlobalPointIds` value names one point. Each
/// (id, point) pair goes to the rank its id names (modulo the rank count);
/// there, an id seen with two different points is an error naming the
/// pieces that disagree. (Two ids for one point are not an error: a point
/// two ranks share without a shared face gets one from each.)
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
