//! What a `.pvtu` piece needs from the input that only rank 0 holds: the
//! location of every point of the piece in the input (the vertex parent
//! map), the input tet holding each tet's centroid (`parent`), and the
//! input's fields interpolated at the points and copied to the tets, as the
//! serial command computes them ([`tetrefine::locate_parents`],
//! [`tetrefine::locate_points`], [`super::transfer::transfer_fields`]).
//!
//! The ranks take turns: each sends its compacted piece (points, tets and
//! the `parent` hints) to rank 0, which rebuilds it, locates it with the
//! serial functions and sends the answer back. Rank 0 therefore holds, on
//! top of the input and its fields, one piece at a time: about 36 bytes per
//! tet and 24 per point on the wire, the rebuilt piece (the store's 91
//! bytes per tet), and the answer: 4 bytes per tet plus 8 per cell-field
//! component, 57 bytes per point plus 8 per point-field component. Every
//! rank keeps its own answer until its piece is written.

use tetrefine::distributed::{Comm, Part, Reader, Wire};
use tetrefine::io::{Field, MeshMeta};
use tetrefine::{MeshData, PointParent, TetMesh};

/// A piece located in the input.
#[derive(Debug, Default)]
pub struct Located {
    /// Per tet: the input tet holding its centroid.
    pub parents: Vec<u32>,
    /// Per point: where it lies in the input.
    pub locations: Vec<PointParent>,
    /// Per point: the vertices of its location's input tet.
    pub vertices: Vec<[u32; 4]>,
    /// The input's point fields at the piece's points (with transfer).
    pub point_fields: Vec<Field>,
    /// The input's cell fields at the piece's tets (with transfer).
    pub cell_fields: Vec<Field>,
}

/// Rank 0's input: the mesh, its fields and whether they are carried over.
pub struct Input<'a> {
    /// The input mesh (as the refinement started from it).
    pub mesh: &'a TetMesh,
    /// Its side table, with the `--fields` added.
    pub meta: &'a MeshMeta,
    /// Whether the fields are carried over.
    pub transfer: bool,
}

/// Locates every rank's compacted `mesh` in rank 0's `input` (`None` on the
/// other ranks) and sets each tet's `parent` to the input tet holding its
/// centroid, as the serial output does. A collective: one rank's failure
/// ends every rank with an error.
pub fn locate_pieces(
    comm: &Comm,
    input: Option<&Input<'_>>,
    mesh: &mut TetMesh,
) -> Result<Located, String> {
    let me = comm.rank;
    let root = comm.agree(match (me, input) {
        (0, None) => Err("rank 0 holds no input to locate the pieces in".to_string()),
        _ => Ok(()),
    });
    root?;
    let mut mine = None;
    for r in 1..comm.size {
        let mut out = vec![Vec::new(); comm.size as usize];
        if me == r {
            out[0] = request(mesh);
        }
        let got = comm.exchange(out)?;
        let answer = match input {
            Some(input) if me == 0 => Part::decode(&got[r as usize])
                .and_then(Part::build)
                .map(|(mut piece, _)| encode(&locate(input, &mut piece)))
                .map_err(|e| format!("rank 0: the piece of rank {r}: {e}")),
            _ => Ok(Vec::new()),
        };
        let answer = comm.agree(answer)?;
        let mut out = vec![Vec::new(); comm.size as usize];
        out[r as usize] = answer;
        let got = comm.exchange(out)?;
        if me == r {
            mine = Some(
                decode(&got[0], mesh)
                    .map_err(|e| format!("rank {me}: the locations from rank 0: {e}")),
            );
        }
    }
    let mine = match input {
        Some(input) if me == 0 => Ok(locate(input, mesh)),
        _ => mine.unwrap_or_else(|| Err(format!("rank {me}: no locations came"))),
    };
    let located = comm.agree(mine)?;
    for (t, &p) in located.parents.iter().enumerate() {
        mesh.set_parent(t as u32, p);
    }
    Ok(located)
}

/// A rank's piece as rank 0 rebuilds it: points, tets, regions and the
/// `parent` hints (no markers or features: location needs none).
fn request(mesh: &TetMesh) -> Vec<u8> {
    let ids: Vec<u32> = mesh.tet_ids().collect();
    Part {
        data: MeshData {
            points: mesh.points().iter().map(|p| p.to_array()).collect(),
            tets: ids.iter().map(|&t| mesh.tet(t)).collect(),
            tet_regions: ids.iter().map(|&t| mesh.region(t)).collect(),
            ..MeshData::default()
        },
        level: ids.iter().map(|&t| mesh.level(t)).collect(),
        parent: ids.iter().map(|&t| mesh.parent(t)).collect(),
        selected: Vec::new(),
        sizes: None,
    }
    .encode()
}

/// Rank 0: `piece` (compacted) located in the input as the serial
/// `write_output` locates its mesh.
fn locate(input: &Input<'_>, piece: &mut TetMesh) -> Located {
    tetrefine::locate_parents(input.mesh, piece);
    let locations = tetrefine::locate_points(input.mesh, piece);
    let (point_fields, cell_fields) = if input.transfer {
        super::transfer::transfer_fields(input.mesh, piece, input.meta, &locations)
    } else {
        (Vec::new(), Vec::new())
    };
    Located {
        parents: piece.tet_ids().map(|t| piece.parent(t)).collect(),
        vertices: locations.iter().map(|l| input.mesh.tet(l.tet)).collect(),
        locations,
        point_fields,
        cell_fields,
    }
}

fn encode(l: &Located) -> Vec<u8> {
    let mut w = Wire::default();
    w.u64(l.parents.len() as u64);
    l.parents.iter().for_each(|&p| w.u32(p));
    w.u64(l.locations.len() as u64);
    for (loc, v) in l.locations.iter().zip(&l.vertices) {
        w.u32(loc.tet);
        v.iter().for_each(|&x| w.u32(x));
        loc.bary.iter().for_each(|&b| w.f64(b));
        w.u32(u32::from(loc.outside));
    }
    for fields in [&l.point_fields, &l.cell_fields] {
        w.u64(fields.len() as u64);
        for f in fields {
            w.u64(f.name.len() as u64);
            w.0.extend_from_slice(f.name.as_bytes());
            w.u64(f.components as u64);
            w.u64(f.values.len() as u64);
            f.values.iter().for_each(|&x| w.f64(x));
        }
    }
    w.0
}

/// [`encode`]'s answer, checked against the piece `mesh` it is for.
fn decode(bytes: &[u8], mesh: &TetMesh) -> Result<Located, String> {
    let mut r = Reader { bytes, at: 0 };
    let count = |r: &mut Reader<'_>, what: &str, want: usize| -> Result<usize, String> {
        let n = r.u64()? as usize;
        if n != want {
            return Err(format!("{n} {what} for {want}"));
        }
        Ok(n)
    };
    let nt = count(&mut r, "parents", mesh.n_tets())?;
    let parents = (0..nt).map(|_| r.u32()).collect::<Result<Vec<_>, _>>()?;
    let np = count(&mut r, "point locations", mesh.n_points())?;
    let mut locations = Vec::with_capacity(np);
    let mut vertices = Vec::with_capacity(np);
    for _ in 0..np {
        let tet = r.u32()?;
        vertices.push([r.u32()?, r.u32()?, r.u32()?, r.u32()?]);
        let bary = [r.f64()?, r.f64()?, r.f64()?, r.f64()?];
        let outside = r.u32()? == 1;
        locations.push(PointParent { tet, bary, outside });
    }
    let mut fields = [Vec::new(), Vec::new()];
    for (k, out) in fields.iter_mut().enumerate() {
        let entries = if k == 0 { np } else { nt };
        let n = r.u64()?;
        for _ in 0..n {
            let len = r.u64()? as usize;
            let name = bytes
                .get(r.at..r.at.saturating_add(len))
                .ok_or("a field name past the end of the message")?;
            let name = String::from_utf8_lossy(name).into_owned();
            r.at += len;
            let components = r.u64()? as usize;
            let nv = count(&mut r, "field values", entries * components)?;
            let values = (0..nv).map(|_| r.f64()).collect::<Result<Vec<_>, _>>()?;
            out.push(Field {
                name,
                components,
                values,
            });
        }
    }
    if !r.done() {
        return Err("bytes after the end of the locations".into());
    }
    let [point_fields, cell_fields] = fields;
    Ok(Located {
        parents,
        locations,
        vertices,
        point_fields,
        cell_fields,
    })
}
