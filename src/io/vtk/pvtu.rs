//! The `.pvtu` (VTK's parallel unstructured grid) as an input: the list of
//! its `.vtu` pieces.

use super::xml::{child_element, parse_xml};
use crate::io::IoError;
use std::path::{Path, PathBuf};

/// The `.vtu` pieces a `.pvtu` lists (`<Piece Source="…"/>`), in its order,
/// each resolved against the `.pvtu`'s folder as ParaView resolves them. An
/// error names the file: not VTK XML, not a `PUnstructuredGrid`, or no piece.
pub fn read_pvtu_pieces(path: &Path) -> Result<Vec<PathBuf>, IoError> {
    let text = std::fs::read_to_string(path).map_err(|e| IoError::os(path, None, e))?;
    let elems = parse_xml(path, &text)?;
    let root = &elems[0];
    if root.name != "VTKFile" || root.attr("type") != Some("PUnstructuredGrid") {
        return Err(IoError::at(
            path,
            root.line,
            "not a VTK parallel unstructured grid (<VTKFile type=\"PUnstructuredGrid\">)",
        ));
    }
    let grid = child_element(&elems, root, "PUnstructuredGrid")
        .ok_or_else(|| IoError::at(path, root.line, "no <PUnstructuredGrid> element"))?;
    let dir = path.parent().unwrap_or(Path::new(""));
    let mut pieces = Vec::new();
    for p in grid.children.iter().map(|&i| &elems[i]) {
        if p.name != "Piece" {
            continue;
        }
        match p.attr("Source") {
            Some(s) if !s.is_empty() => pieces.push(dir.join(s)),
            _ => return Err(IoError::at(path, p.line, "a <Piece> without a Source")),
        }
    }
    if pieces.is_empty() {
        return Err(IoError::file(path, "lists no <Piece Source=\"…\"/>"));
    }
    Ok(pieces)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn pieces_resolve_beside_the_pvtu_and_a_bad_file_is_named() {
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("a.pvtu");
        std::fs::write(
            &p,
            "<?xml version=\"1.0\"?>\n<VTKFile type=\"PUnstructuredGrid\">\n<PUnstructuredGrid GhostLevel=\"0\">\n<PPoints/>\n<Piece Source=\"a_0.vtu\"/>\n<Piece Source=\"sub/a_1.vtu\"/>\n</PUnstructuredGrid>\n</VTKFile>\n",
        )
        .unwrap();
        assert_eq!(
            read_pvtu_pieces(&p).unwrap(),
            vec![dir.path().join("a_0.vtu"), dir.path().join("sub/a_1.vtu")]
        );
        std::fs::write(&p, "<VTKFile type=\"UnstructuredGrid\"></VTKFile>").unwrap();
        let e = read_pvtu_pieces(&p).unwrap_err().to_string();
        assert!(
            e.contains("a.pvtu") && e.contains("PUnstructuredGrid"),
            "{e}"
        );
    }
}
