//! Medit / MMG `.mesh` ASCII (the format of MMG, Gamma's libMeshb in text form).
//!
//! Read: `Vertices` (the vertex ref is ignored), `Tetrahedra` (ref → region),
//! `Triangles` (ref → face marker), `Edges` (→ feature edges; every listed edge
//! is a feature, as MMG writes ridges and required edges there), `Ridges`,
//! `RequiredEdges`, `Corners`, `RequiredVertices`. Sections of other element
//! kinds and attribute tables are skipped; so are keywords of other tools
//! (`TetrahedraP2`, `Identifier`, `SubDomainFromGeom`, `AngleOfCorner`, …)
//! after `MeshVersionFormatted`, with one note on stderr naming them. A
//! malformed known section is still an error at its line. Written: the same
//! sections. Binary `.meshb` is [`super::meshb`].
//! [`read_surface`] reads a triangles-only file as a surface to mesh.

use super::plc::Plc;
use super::text::{as_text, Tokens};
use super::{read_bytes, write_atomic, IoError};
use crate::mesh::{MeshData, TetMesh};
use std::io::Write;
use std::path::Path;

/// Number of tokens per entry of the sections we skip.
fn skipped_section_width(keyword: &str) -> Option<usize> {
    Some(match keyword {
        "Quadrilaterals" => 5,
        "Hexahedra" => 9,
        "Prisms" => 7,
        "Pyramids" => 6,
        "Normals" | "Tangents" => 3,
        "NormalAtVertices" | "TangentAtVertices" => 2,
        "RequiredTriangles" | "RequiredTetrahedra" | "RequiredQuadrilaterals" => 1,
        "ParallelTriangles" | "ParallelVertices" | "ParallelEdges" => 1,
        _ => return None,
    })
}

/// Reads a Medit `.mesh` ASCII file.
pub fn read(path: &Path) -> Result<MeshData, IoError> {
    let data = parse(path)?;
    if data.tets.is_empty() {
        return Err(IoError::file(
            path,
            "no Tetrahedra section: not a volume mesh",
        ));
    }
    Ok(data)
}

/// Reads a Medit `.mesh` file that describes a closed surface by its
/// `Triangles` (their refs become facet markers) as a [`Plc`] to mesh.
pub fn read_surface(path: &Path) -> Result<Plc, IoError> {
    let data = parse(path)?;
    if !data.tets.is_empty() {
        return Err(IoError::file(
            path,
            "holds Tetrahedra: a surface to mesh must hold Triangles only",
        ));
    }
    if data.triangles.is_empty() {
        return Err(IoError::file(
            path,
            "no Triangles section: there is no surface to mesh",
        ));
    }
    Ok(Plc::from_triangles(data.points, &data.triangles))
}

/// Reads every section of a Medit file, without requiring tetrahedra.
fn parse(path: &Path) -> Result<MeshData, IoError> {
    let bytes = read_bytes(path)?;
    let text = as_text(path, &bytes)?;
    let mut tok = Tokens::new(path, text, true);
    let mut data = MeshData::default();
    let mut raw_edges: Vec<([u32; 2], i32)> = Vec::new();
    let mut saw_vertices = false;
    let mut saw_any = false;
    let mut saw_version = false;
    let mut skipped: Vec<String> = Vec::new();
    while let Some(kw) = tok.next() {
        saw_any = true;
        match kw {
            "MeshVersionFormatted" => {
                read_version(&mut tok)?;
                saw_version = true;
            }
            "Dimension" => {
                let d: i64 = tok.parse("the dimension")?;
                if d != 3 {
                    return Err(tok.error(format!("Dimension {d}: only 3-D meshes are supported")));
                }
            }
            "Vertices" => {
                let n = count(&mut tok, "vertex count")?;
                // A count larger than the file could hold is caught as a
                // truncation below; do not let it reserve memory first.
                data.points.reserve(n.min(text.len() / 8));
                for _ in 0..n {
                    let x = tok.coord("an x coordinate")?;
                    let y = tok.coord("a y coordinate")?;
                    let z = tok.coord("a z coordinate")?;
                    let _ref: i64 = tok.parse("a vertex reference")?;
                    data.points.push([x, y, z]);
                }
                saw_vertices = true;
            }
            "Tetrahedra" => {
                need_vertices(&tok, saw_vertices, "Tetrahedra")?;
                let n = count(&mut tok, "tetrahedron count")?;
                let np = data.points.len();
                let cap = n.min(text.len() / 10);
                data.tets.reserve(cap);
                data.tet_regions.reserve(cap);
                data.tet_lines.reserve(cap);
                for _ in 0..n {
                    let a = tok.index1("vertex index", np)?;
                    let line = tok.line() as u32;
                    let b = tok.index1("vertex index", np)?;
                    let c = tok.index1("vertex index", np)?;
                    let d = tok.index1("vertex index", np)?;
                    let r: i32 = tok.parse("a tetrahedron reference")?;
                    data.tets.push([a, b, c, d]);
                    data.tet_regions.push(r);
                    data.tet_lines.push(line);
                }
            }
            "Triangles" => {
                need_vertices(&tok, saw_vertices, "Triangles")?;
                let n = count(&mut tok, "triangle count")?;
                let np = data.points.len();
                for _ in 0..n {
                    let a = tok.index1("vertex index", np)?;
                    let b = tok.index1("vertex index", np)?;
                    let c = tok.index1("vertex index", np)?;
                    let r: i32 = tok.parse("a triangle reference")?;
                    data.triangles.push(([a, b, c], r));
                }
            }
            "Edges" => {
                need_vertices(&tok, saw_vertices, "Edges")?;
                let n = count(&mut tok, "edge count")?;
                let np = data.points.len();
                for _ in 0..n {
                    let a = tok.index1("vertex index", np)?;
                    let b = tok.index1("vertex index", np)?;
                    let r: i32 = tok.parse("an edge reference")?;
                    raw_edges.push(([a, b], r));
                }
            }
            "Ridges" | "RequiredEdges" => {
                // Every listed edge is already a feature: only check the
                // numbers name edges that exist.
                let n = count(&mut tok, "edge count")?;
                for _ in 0..n {
                    let e: i64 = tok.parse("an edge number")?;
                    if e < 1 || e as usize > raw_edges.len() {
                        return Err(tok.error(format!(
                            "{kw} names edge {e} but {} edges were listed before",
                            raw_edges.len()
                        )));
                    }
                }
            }
            "Corners" | "RequiredVertices" => {
                need_vertices(&tok, saw_vertices, kw)?;
                let n = count(&mut tok, "vertex count")?;
                let np = data.points.len();
                for _ in 0..n {
                    let v = tok.index1("vertex index", np)?;
                    if kw == "Corners" {
                        data.corners.push(v);
                    } else {
                        data.required_vertices.push(v);
                    }
                }
            }
            // `End` is optional in practice (many writers omit it).
            "End" => break,
            other => match skipped_section_width(other) {
                Some(w) => {
                    let n = count(&mut tok, "entry count")?;
                    for _ in 0..n * w {
                        if tok.next().is_none() {
                            return Err(
                                tok.error(format!("file ends inside section {other} (truncated?)"))
                            );
                        }
                    }
                }
                None if !saw_version => {
                    return Err(tok.error(format!(
                        "unknown keyword '{}' before MeshVersionFormatted (not a Medit .mesh file)",
                        other.chars().take(32).collect::<String>()
                    )))
                }
                None => {
                    // Another tool's keyword (TetrahedraP2, Identifier,
                    // AngleOfCorner, …): skipped up to the next keyword, as
                    // libMeshb itself finds keywords (a token that starts
                    // with a letter); quoted strings are skipped whole.
                    let name = other.chars().take(32).collect::<String>();
                    if !skipped.contains(&name) {
                        skipped.push(name);
                    }
                    while let Some(t) = tok.peek() {
                        if t.starts_with(|c: char| c.is_ascii_alphabetic()) {
                            break;
                        }
                        let t = tok.next().unwrap_or_default();
                        if t.starts_with('"') && !(t.len() > 1 && t.ends_with('"')) {
                            while let Some(u) = tok.next() {
                                if u.ends_with('"') {
                                    break;
                                }
                            }
                        }
                    }
                }
            },
        }
    }
    if !saw_any {
        return Err(IoError::file(path, "empty file"));
    }
    if !skipped.is_empty() {
        eprintln!(
            "note: {}: skipped sections tetrefine does not use: {}",
            path.display(),
            skipped.join(", ")
        );
    }
    data.edges = raw_edges;
    Ok(data)
}

/// Reads the number after `MeshVersionFormatted` (shared with the `.sol`
/// reader): 1 to 4 are the versions of the libMeshb family.
pub(crate) fn read_version(tok: &mut Tokens) -> Result<(), IoError> {
    let v: i64 = tok.parse("a format version")?;
    if !(1..=4).contains(&v) {
        return Err(tok.error(format!("unsupported MeshVersionFormatted {v}")));
    }
    Ok(())
}

fn count(tok: &mut Tokens, what: &str) -> Result<usize, IoError> {
    let n: i64 = tok.parse(what)?;
    if n < 0 || n > u32::MAX as i64 / 4 {
        return Err(tok.error(format!("{what} {n} is not valid")));
    }
    Ok(n as usize)
}

fn need_vertices(tok: &Tokens, saw: bool, section: &str) -> Result<(), IoError> {
    if saw {
        Ok(())
    } else {
        Err(tok.error(format!("section {section} comes before Vertices")))
    }
}

/// Writes `mesh` as Medit `.mesh` ASCII (through a temporary file).
pub fn write(path: &Path, mesh: &TetMesh) -> Result<(), IoError> {
    write_data(path, &mesh.to_data())
}

/// Writes plain mesh data as Medit `.mesh` ASCII.
pub fn write_data(path: &Path, d: &MeshData) -> Result<(), IoError> {
    write_atomic(path, |w| {
        writeln!(
            w,
            "MeshVersionFormatted 2\n\nDimension 3\n\nVertices\n{}",
            d.points.len()
        )?;
        for p in &d.points {
            writeln!(w, "{:?} {:?} {:?} 0", p[0], p[1], p[2])?;
        }
        if !d.triangles.is_empty() {
            writeln!(w, "\nTriangles\n{}", d.triangles.len())?;
            for (f, m) in &d.triangles {
                writeln!(w, "{} {} {} {}", f[0] + 1, f[1] + 1, f[2] + 1, m)?;
            }
        }
        if !d.edges.is_empty() {
            writeln!(w, "\nEdges\n{}", d.edges.len())?;
            for (e, m) in &d.edges {
                writeln!(w, "{} {} {}", e[0] + 1, e[1] + 1, m)?;
            }
            writeln!(w, "\nRidges\n{}", d.edges.len())?;
            for i in 0..d.edges.len() {
                writeln!(w, "{}", i + 1)?;
            }
        }
        if !d.corners.is_empty() {
            writeln!(w, "\nCorners\n{}", d.corners.len())?;
            for v in &d.corners {
                writeln!(w, "{}", v + 1)?;
            }
        }
        if !d.required_vertices.is_empty() {
            writeln!(w, "\nRequiredVertices\n{}", d.required_vertices.len())?;
            for v in &d.required_vertices {
                writeln!(w, "{}", v + 1)?;
            }
        }
        writeln!(w, "\nTetrahedra\n{}", d.tets.len())?;
        for (t, v) in d.tets.iter().enumerate() {
            writeln!(
                w,
                "{} {} {} {} {}",
                v[0] + 1,
                v[1] + 1,
                v[2] + 1,
                v[3] + 1,
                d.region(t)
            )?;
        }
        writeln!(w, "\nEnd")
    })
}
