//! Reading a `.pvtu`'s pieces into one mesh: the serial command's `.pvtu`
//! input (every piece), and each rank's share in a distributed run.

use std::path::PathBuf;
use tetrefine::io::{Field, MeshMeta};
use tetrefine::MeshData;

/// The pieces' own arrays of a distributed run, not fields of the mesh.
pub const RUN_POINT_ARRAYS: [&str; 1] = ["GlobalPointIds"];
/// See [`RUN_POINT_ARRAYS`].
pub const RUN_CELL_ARRAYS: [&str; 1] = ["rank"];

/// Whether `p` names a `.pvtu`.
pub fn is_pvtu(p: &std::path::Path) -> bool {
    p.extension()
        .and_then(|e| e.to_str())
        .is_some_and(|e| e.eq_ignore_ascii_case("pvtu"))
}

/// The names of `pieces`, for a message.
#[cfg(feature = "mpi")]
pub fn names(pieces: &[(usize, &PathBuf)]) -> String {
    pieces
        .iter()
        .map(|(_, p)| p.display().to_string())
        .collect::<Vec<_>>()
        .join(", ")
}

/// Reads every piece of the `.pvtu` `path` as one mesh with the fields all
/// pieces carry (point fields at the joined points, cell fields piece after
/// piece; `GlobalPointIds` and `rank` left out).
pub fn read_pvtu(path: &std::path::Path) -> Result<(MeshData, MeshMeta), String> {
    let all = tetrefine::io::read_pvtu_pieces(path).map_err(|e| e.to_string())?;
    let pieces: Vec<(usize, &PathBuf)> = all.iter().enumerate().collect();
    let (data, _, meta) = merge_pieces(&pieces, None)?;
    Ok((data, meta))
}

/// The fields every piece carries (same name and components), gathered as
/// the points and tets are joined.
struct FieldMerge {
    points: Vec<Field>,
    cells: Vec<Field>,
}

impl FieldMerge {
    /// The fields of the first piece that every piece has.
    fn new(metas: &[&MeshMeta]) -> FieldMerge {
        let common = |pick: fn(&MeshMeta) -> &Vec<Field>, skip: &[&str]| -> Vec<Field> {
            let Some(first) = metas.first() else {
                return Vec::new();
            };
            pick(first)
                .iter()
                .filter(|f| !skip.contains(&f.name.as_str()))
                .filter(|f| {
                    metas.iter().all(|m| {
                        pick(m)
                            .iter()
                            .any(|g| g.name == f.name && g.components == f.components)
                    })
                })
                .map(|f| Field {
                    name: f.name.clone(),
                    components: f.components,
                    values: Vec::new(),
                })
                .collect()
        };
        FieldMerge {
            points: common(|m| &m.point_fields, &RUN_POINT_ARRAYS),
            cells: common(|m| &m.cell_fields, &RUN_CELL_ARRAYS),
        }
    }

    /// Appends point `v` of the piece with `meta`.
    fn point(&mut self, meta: &MeshMeta, v: usize) {
        for f in &mut self.points {
            if let Some(g) = meta.point_fields.iter().find(|g| g.name == f.name) {
                let c = f.components;
                f.values.extend_from_slice(&g.values[v * c..(v + 1) * c]);
            }
        }
    }

    /// Appends every tet's values of the piece with `meta`.
    fn cells(&mut self, meta: &MeshMeta) {
        for f in &mut self.cells {
            if let Some(g) = meta.cell_fields.iter().find(|g| g.name == f.name) {
                f.values.extend_from_slice(&g.values);
            }
        }
    }

    fn finish(self) -> MeshMeta {
        MeshMeta {
            point_fields: self.points,
            cell_fields: self.cells,
            ..MeshMeta::default()
        }
    }
}

/// Every tet of the piece at `path` (read as `d`) has four distinct points
/// and a positive volume (the exact orientation test the mesh builder
/// uses). A piece is written oriented: an inverted or degenerate tet is a
/// corrupt piece, named with the tet's number (1-based, in the piece's own
/// order), its points (0-based, as a one-piece `.vtu`'s connectivity has them) and
/// the line of the connectivity. Checked piece by piece, before the points
/// of several pieces are joined (which would renumber them).
fn check_tets(path: &std::path::Path, d: &MeshData) -> Result<(), String> {
    use tetrefine::geom::{orient3d_sign, Orientation};
    for (t, v) in d.tets.iter().enumerate() {
        let distinct = (0..4).all(|i| (i + 1..4).all(|j| v[i] != v[j]));
        let problem = if distinct {
            let q = v.map(|x| glam::DVec3::from_array(d.points[x as usize]));
            match orient3d_sign(q[0], q[1], q[2], q[3]) {
                Orientation::Positive => continue,
                Orientation::Negative => "is inverted (negative volume)",
                Orientation::Zero => "is degenerate (zero volume: its four points are coplanar)",
            }
        } else {
            "is degenerate (it repeats a point)"
        };
        let line = d
            .tet_lines
            .get(t)
            .map_or_else(String::new, |l| format!(", connectivity at line {l}"));
        return Err(format!(
            "{}: tetrahedron {} (points {} {} {} {}{line}) {problem}: a corrupt piece",
            path.display(),
            t + 1,
            v[0],
            v[1],
            v[2],
            v[3]
        ));
    }
    Ok(())
}

/// The point array `name` of the piece at `path` (read as `d` with `meta`)
/// is a size map: there, 1 (a length) or 6 (a metric) components, one entry
/// per point, each a positive finite length or a positive-definite metric.
/// Returns its number of components; an error names the piece, the array
/// and the problem (for a bad value, the point, 1-based in the piece).
pub fn check_size_array(
    path: &std::path::Path,
    d: &MeshData,
    meta: &MeshMeta,
    name: &str,
) -> Result<usize, String> {
    let f =
        meta.point_fields
            .iter()
            .find(|f| f.name == name)
            .ok_or_else(|| {
                let names: Vec<&str> = meta
                    .point_fields
                    .iter()
                    .map(|f| f.name.as_str())
                    .filter(|n| !RUN_POINT_ARRAYS.contains(n))
                    .collect();
                format!(
                "{}: --size-array {name}: the piece has no point array of that name (it has: {})",
                path.display(),
                if names.is_empty() { "none".to_string() } else { names.join(", ") }
            )
            })?;
    let n = d.points.len();
    if f.values.len() != n * f.components {
        return Err(format!(
            "{}: --size-array {name}: {} values for {n} points of {} components",
            path.display(),
            f.values.len(),
            f.components
        ));
    }
    tetrefine::SizeMap::from_values(f.components, &f.values)
        .map_err(|e| format!("{}: --size-array {name}: {e}", path.display()))?;
    Ok(f.components)
}

/// Per merged point: its `GlobalPointIds` value (when the pieces carry
/// them) and the index of the piece it was first read from.
pub type PointIds = Vec<(Option<u64>, usize)>;

/// This rank's pieces as one mesh: points shared by `GlobalPointIds` when
/// every piece has them (and by exact coordinates: equal coordinates are
/// one point), else by exact coordinates alone. A piece that cannot be
/// read, holds an inverted or degenerate tet, or gives one id to two points is an error
/// naming it. With `size_array` (`--size-array NAME`), every piece must
/// carry the point array NAME as a size map (see [`check_size_array`]),
/// with one number of components in all of them.
pub fn merge_pieces(
    pieces: &[(usize, &PathBuf)],
    size_array: Option<&str>,
) -> Result<(MeshData, PointIds, MeshMeta), String> {
    let mut read = Vec::with_capacity(pieces.len());
    let mut size_components: Option<(usize, &PathBuf)> = None;
    for &(i, path) in pieces {
        let (d, meta) = tetrefine::io::read_mesh_with_meta(path).map_err(|e| e.to_string())?;
        if let Some(name) = size_array {
            let c = check_size_array(path, &d, &meta, name)?;
            match size_components {
                Some((c0, first)) if c0 != c => {
                    return Err(format!(
                        "{}: --size-array {name} has {c} components here and {c0} in {}",
                        path.display(),
                        first.display()
                    ))
                }
                Some(_) => {}
                None => size_components = Some((c, path)),
            }
        }
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
        check_tets(path, &d)?;
        read.push((i, path, d, gids, meta));
    }
    let by_id = read.iter().all(|r| r.3.is_some());
    let mut out = MeshData::default();
    let mut ids: PointIds = Vec::new();
    let mut by_gid: std::collections::HashMap<u64, u32> = Default::default();
    let mut by_key: std::collections::HashMap<[u64; 3], u32> = Default::default();
    let key = |p: [f64; 3]| p.map(|c| if c == 0.0 { 0 } else { c.to_bits() });
    let mut fields = FieldMerge::new(&read.iter().map(|r| &r.4).collect::<Vec<_>>());
    for (i, path, d, gids, meta) in read {
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
                        // ids: in pieces written by an earlier version, a
                        // point two ranks share without a shared face (a
                        // pinch) has an id from each.
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
                fields.point(&meta, v);
            }
            map.push(at);
        }
        fields.cells(&meta);
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
    Ok((out, ids, fields.finish()))
}
