//! Gmsh `.msh`: MSH 2.2 (ASCII and binary) and MSH 4.1 (ASCII and binary) read,
//! MSH 4.1 ASCII written. The layouts follow the "MSH file format" chapter of
//! the Gmsh reference manual (C. Geuzaine, J.-F. Remacle, gmsh.info).
//!
//! Tags: a tetrahedron's physical tag is its region, a triangle's its face
//! marker, a line's its feature-edge marker; a point element makes its node a
//! corner. An element without a physical tag gets its elementary (entity) tag,
//! which is what Gmsh saves when no physical group was defined. Quadratic
//! elements (10-node tets, 6-node triangles, 3-node lines) keep their corner
//! nodes; the mid-side nodes are then dropped. Every other element type is
//! skipped. Node tags may be sparse and in any order: they are mapped to dense
//! indices in the order of the file.
//!
//! The writer puts every region in its own volume entity with that region as
//! physical tag, every face marker in a surface entity, every edge marker in a
//! curve entity and every corner in a point entity (physical tag 1), so that
//! Gmsh and meshio read the tags back.

use super::{drop_unused_points, read_bytes, write_atomic, IoError};
use crate::mesh::{MeshData, TetMesh};
use std::collections::{BTreeMap, HashMap};
use std::io::Write;
use std::path::Path;

/// Number of nodes of a Gmsh element type, for the types one may meet in a
/// linear or quadratic tet mesh and the other common ones (so that they can be
/// skipped in binary files, where no line ends show the way).
fn nodes_of_type(t: i64) -> Option<usize> {
    Some(match t {
        1 => 2,
        2 => 3,
        3 => 4,
        4 => 4,
        5 => 8,
        6 => 6,
        7 => 5,
        8 => 3,
        9 => 6,
        10 => 9,
        11 => 10,
        12 => 27,
        13 => 18,
        14 => 14,
        15 => 1,
        16 => 8,
        17 => 20,
        18 => 15,
        19 => 13,
        20 => 9,
        21 => 10,
        22 => 12,
        23 => 15,
        24 => 15,
        25 => 21,
        26 => 4,
        27 => 5,
        28 => 6,
        29 => 20,
        30 => 35,
        31 => 56,
        92 => 64,
        93 => 125,
        _ => return None,
    })
}

/// What an element becomes in [`MeshData`].
#[derive(Clone, Copy, PartialEq, Eq)]
enum Role {
    Tet,
    Triangle,
    Edge,
    Corner,
    Skip,
}

fn role_of_type(t: i64) -> Role {
    match t {
        4 | 11 => Role::Tet,
        2 | 9 => Role::Triangle,
        1 | 8 => Role::Edge,
        15 => Role::Corner,
        _ => Role::Skip,
    }
}

/// A byte cursor over a `.msh` file: whitespace-separated ASCII tokens with
/// line numbers, and little- or big-endian binary values.
struct Cursor<'a> {
    path: &'a Path,
    b: &'a [u8],
    pos: usize,
    line: usize,
    /// Line (ASCII) or byte offset (binary) of the item read last.
    last_line: usize,
    last_pos: usize,
    /// Binary values follow; errors then name byte offsets.
    binary: bool,
    swap: bool,
    size_t: usize,
}

impl<'a> Cursor<'a> {
    fn new(path: &'a Path, b: &'a [u8]) -> Cursor<'a> {
        Cursor {
            path,
            b,
            pos: 0,
            line: 1,
            last_line: 1,
            last_pos: 0,
            binary: false,
            swap: false,
            size_t: 8,
        }
    }

    fn error(&self, message: impl Into<String>) -> IoError {
        if self.binary {
            IoError::file(
                self.path,
                format!("at byte {}: {}", self.last_pos, message.into()),
            )
        } else {
            IoError::at(self.path, self.last_line, message)
        }
    }

    /// An error about the item read at `line` / `pos` (a section header).
    fn error_at(&self, line: usize, pos: usize, message: impl Into<String>) -> IoError {
        if self.binary {
            IoError::file(self.path, format!("at byte {pos}: {}", message.into()))
        } else {
            IoError::at(self.path, line, message)
        }
    }

    fn eof_error(&self, what: &str) -> IoError {
        let message = format!("file ends where {what} was expected (truncated?)");
        if self.binary {
            IoError::file(self.path, format!("at byte {}: {message}", self.b.len()))
        } else {
            IoError::at(self.path, self.line, message)
        }
    }

    fn skip_space(&mut self) {
        while self.pos < self.b.len() {
            match self.b[self.pos] {
                b'\n' => {
                    self.line += 1;
                    self.pos += 1;
                }
                c if c.is_ascii_whitespace() => self.pos += 1,
                _ => break,
            }
        }
    }

    /// The next whitespace-separated token.
    fn token(&mut self, what: &str) -> Result<&'a str, IoError> {
        self.skip_space();
        if self.pos >= self.b.len() {
            return Err(self.eof_error(what));
        }
        let start = self.pos;
        while self.pos < self.b.len() && !self.b[self.pos].is_ascii_whitespace() {
            self.pos += 1;
        }
        self.last_line = self.line;
        self.last_pos = start;
        std::str::from_utf8(&self.b[start..self.pos]).map_err(|_| {
            self.error(format!(
                "expected {what}, found binary data (corrupt or not a Gmsh file)"
            ))
        })
    }

    /// The next token, or `None` at the end of the file.
    fn maybe_token(&mut self) -> Result<Option<&'a str>, IoError> {
        self.skip_space();
        if self.pos >= self.b.len() {
            return Ok(None);
        }
        self.token("a section").map(Some)
    }

    fn parse<T: std::str::FromStr>(&mut self, what: &str) -> Result<T, IoError> {
        let t = self.token(what)?;
        t.parse::<T>()
            .map_err(|_| self.error(format!("expected {what}, found '{}'", shorten(t))))
    }

    /// Skips the rest of the current line, including its end.
    fn skip_line(&mut self) {
        while self.pos < self.b.len() && self.b[self.pos] != b'\n' {
            self.pos += 1;
        }
        if self.pos < self.b.len() {
            self.pos += 1;
            self.line += 1;
        }
    }

    /// Whether nothing but blanks is left on the current line.
    fn rest_of_line_blank(&self) -> bool {
        self.b[self.pos..]
            .iter()
            .take_while(|&&c| c != b'\n')
            .all(|c| c.is_ascii_whitespace())
    }

    /// Consumes the line end that precedes binary data.
    fn line_end(&mut self) -> Result<(), IoError> {
        while self.pos < self.b.len() && matches!(self.b[self.pos], b' ' | b'\t' | b'\r') {
            self.pos += 1;
        }
        if self.pos < self.b.len() && self.b[self.pos] == b'\n' {
            self.pos += 1;
            self.line += 1;
            Ok(())
        } else {
            Err(self.error("expected a line end before binary data"))
        }
    }

    fn bytes<const N: usize>(&mut self, what: &str) -> Result<[u8; N], IoError> {
        if self.pos + N > self.b.len() {
            return Err(self.eof_error(what));
        }
        self.last_pos = self.pos;
        let mut a = [0u8; N];
        a.copy_from_slice(&self.b[self.pos..self.pos + N]);
        if self.swap {
            a.reverse();
        }
        self.pos += N;
        Ok(a)
    }

    /// An `int`: a 4-byte integer in binary files, a token in ASCII ones.
    fn int(&mut self, what: &str) -> Result<i64, IoError> {
        if self.binary {
            Ok(i32::from_le_bytes(self.bytes::<4>(what)?) as i64)
        } else {
            self.parse(what)
        }
    }

    /// A `size_t` (count or tag): `size_t` bytes in binary files.
    fn size(&mut self, what: &str) -> Result<u64, IoError> {
        if self.binary {
            if self.size_t == 4 {
                Ok(u32::from_le_bytes(self.bytes::<4>(what)?) as u64)
            } else {
                Ok(u64::from_le_bytes(self.bytes::<8>(what)?))
            }
        } else {
            self.parse(what)
        }
    }

    /// A count, checked against what the rest of the file could hold (each
    /// entry takes at least `min_bytes`), so that a corrupt count is an error
    /// and not an attempt to allocate the impossible.
    fn count(&mut self, what: &str, min_bytes: usize) -> Result<usize, IoError> {
        let n = if self.binary {
            self.size(what)?
        } else {
            let t = self.token(what)?;
            match t.parse::<i64>() {
                Ok(n) if n < 0 => return Err(self.error(format!("{what} {n} is negative"))),
                Ok(n) => n as u64,
                Err(_) => {
                    return Err(self.error(format!("expected {what}, found '{}'", shorten(t))))
                }
            }
        };
        let left = (self.b.len() - self.pos) as u64;
        if n > left / min_bytes.max(1) as u64 + 1 {
            return Err(self.error(format!(
                "{what} {n} is more than the rest of the file can hold (corrupt or truncated)"
            )));
        }
        Ok(n as usize)
    }

    /// A `double`.
    fn double(&mut self, what: &str) -> Result<f64, IoError> {
        if self.binary {
            Ok(f64::from_le_bytes(self.bytes::<8>(what)?))
        } else {
            self.parse(what)
        }
    }

    /// A coordinate: a finite `double`.
    fn coord(&mut self, what: &str) -> Result<f64, IoError> {
        let x = self.double(what)?;
        if !x.is_finite() {
            return Err(self.error(format!("{what} is {x}, not a finite number")));
        }
        Ok(x)
    }

    /// Expects the keyword `kw` next.
    fn expect(&mut self, kw: &str) -> Result<(), IoError> {
        let t = self.token(kw)?;
        if t == kw {
            Ok(())
        } else {
            Err(self.error(format!("expected {kw}, found '{}'", shorten(t))))
        }
    }

    /// Skips an unknown section up to and including its `$End…` line.
    fn skip_section(&mut self, name: &str) -> Result<(), IoError> {
        let end = format!("$End{}", &name[1..]);
        let needle = end.as_bytes();
        let hay = &self.b[self.pos..];
        match hay.windows(needle.len()).position(|w| w == needle) {
            Some(i) => {
                self.line += hay[..i].iter().filter(|&&c| c == b'\n').count();
                self.pos += i + needle.len();
                Ok(())
            }
            None => Err(self.error(format!("section {name} has no {end} (truncated?)"))),
        }
    }
}

fn shorten(s: &str) -> String {
    if s.chars().count() > 24 {
        format!("{}…", s.chars().take(24).collect::<String>())
    } else {
        s.to_string()
    }
}

/// Node tags to dense indices.
enum NodeIndex {
    /// Tags `first..first + n` in file order.
    Dense { first: u64, n: u64 },
    /// Anything else.
    Map(HashMap<u64, u32>),
}

impl NodeIndex {
    fn build(c: &Cursor, tags: &[u64]) -> Result<NodeIndex, IoError> {
        if let Some(&first) = tags.first() {
            if tags.iter().enumerate().all(|(i, &t)| t == first + i as u64) {
                return Ok(NodeIndex::Dense {
                    first,
                    n: tags.len() as u64,
                });
            }
        }
        let mut map = HashMap::with_capacity(tags.len());
        for (i, &t) in tags.iter().enumerate() {
            if map.insert(t, i as u32).is_some() {
                return Err(c.error(format!("node tag {t} is defined twice")));
            }
        }
        Ok(NodeIndex::Map(map))
    }

    fn get(&self, tag: u64) -> Option<u32> {
        match self {
            NodeIndex::Dense { first, n } => {
                if tag >= *first && tag - first < *n {
                    Some((tag - first) as u32)
                } else {
                    None
                }
            }
            NodeIndex::Map(m) => m.get(&tag).copied(),
        }
    }
}

/// Collects the elements of a file into [`MeshData`].
struct Collector {
    data: MeshData,
    nodes: Option<NodeIndex>,
    quadratic: bool,
    node_buf: Vec<u32>,
}

impl Collector {
    fn new() -> Collector {
        Collector {
            data: MeshData::default(),
            nodes: None,
            quadratic: false,
            node_buf: Vec::with_capacity(16),
        }
    }

    /// Reads `k` node tags of one element with `read` and maps them.
    fn read_nodes(
        &mut self,
        c: &mut Cursor,
        k: usize,
        mut read: impl FnMut(&mut Cursor) -> Result<u64, IoError>,
    ) -> Result<(), IoError> {
        let Some(index) = &self.nodes else {
            return Err(c.error("$Elements comes before $Nodes"));
        };
        self.node_buf.clear();
        for _ in 0..k {
            let tag = read(c)?;
            match index.get(tag) {
                Some(i) => self.node_buf.push(i),
                None => {
                    return Err(c.error(format!(
                        "element refers to node {tag}, which is not defined in $Nodes"
                    )))
                }
            }
        }
        Ok(())
    }

    /// Adds the element whose nodes are in `node_buf`.
    fn add(
        &mut self,
        role: Role,
        etype: i64,
        tag: i64,
        c: &Cursor,
        line: Option<usize>,
    ) -> Result<(), IoError> {
        let n = &self.node_buf;
        if matches!(etype, 8 | 9 | 11) {
            self.quadratic = true;
        }
        let tag32 = i32::try_from(tag)
            .map_err(|_| c.error(format!("tag {tag} does not fit a 32-bit integer")))?;
        match role {
            Role::Tet => {
                self.data.tets.push([n[0], n[1], n[2], n[3]]);
                self.data.tet_regions.push(tag32);
                if let Some(l) = line {
                    self.data.tet_lines.push(l as u32);
                }
            }
            Role::Triangle => self.data.triangles.push(([n[0], n[1], n[2]], tag32)),
            Role::Edge => self.data.edges.push(([n[0], n[1]], tag32)),
            Role::Corner => self.data.corners.push(n[0]),
            Role::Skip => {}
        }
        Ok(())
    }

    fn set_nodes(
        &mut self,
        c: &Cursor,
        tags: &[u64],
        coords: Vec<[f64; 3]>,
    ) -> Result<(), IoError> {
        if self.nodes.is_some() {
            return Err(c.error("a second $Nodes section"));
        }
        self.nodes = Some(NodeIndex::build(c, tags)?);
        self.data.points = coords;
        Ok(())
    }

    fn finish(mut self, path: &Path) -> Result<MeshData, IoError> {
        if self.nodes.is_none() {
            return Err(IoError::file(path, "no $Nodes section"));
        }
        if self.data.tets.is_empty() {
            return Err(IoError::file(
                path,
                "no tetrahedra (element type 4 or 11): not a volume mesh",
            ));
        }
        if self.data.tet_lines.len() != self.data.tets.len() {
            self.data.tet_lines.clear();
        }
        if self.quadratic {
            drop_unused_points(&mut self.data);
        }
        Ok(self.data)
    }
}

/// Reads a Gmsh `.msh` file (MSH 2.2 or 4.1, ASCII or binary).
pub fn read(path: &Path) -> Result<MeshData, IoError> {
    let bytes = read_bytes(path)?;
    if bytes.iter().all(|c| c.is_ascii_whitespace()) {
        return Err(IoError::file(path, "empty file"));
    }
    let mut c = Cursor::new(path, &bytes);
    let first = c.token("$MeshFormat")?;
    if first != "$MeshFormat" {
        return Err(c.error(format!(
            "expected $MeshFormat, found '{}': not a Gmsh .msh file",
            shorten(first)
        )));
    }
    let version = c.token("the format version")?;
    let v2 = match version {
        "2" | "2.0" | "2.1" | "2.2" => true,
        "4.1" => false,
        other => {
            return Err(c.error(format!(
                "MSH version {} is not supported (use 2.2 or 4.1)",
                shorten(other)
            )))
        }
    };
    let file_type: i64 = c.parse("the file type (0 ASCII, 1 binary)")?;
    let data_size: i64 = c.parse("the data size")?;
    match (file_type, data_size) {
        (0, _) => {}
        (1, 8) => c.size_t = 8,
        (1, 4) if !v2 => c.size_t = 4,
        (1, d) => return Err(c.error(format!("unsupported data size {d} in a binary file"))),
        (t, _) => return Err(c.error(format!("file type {t} is neither 0 (ASCII) nor 1 (binary)"))),
    }
    if file_type == 1 {
        c.line_end()?;
        let one = c.bytes::<4>("the endianness marker")?;
        if i32::from_le_bytes(one) == 1 {
            c.swap = false;
        } else if i32::from_be_bytes(one) == 1 {
            c.swap = true;
        } else {
            return Err(c.error("bad endianness marker (expected the integer 1)"));
        }
    }
    c.expect("$EndMeshFormat")?;
    c.binary = file_type == 1;
    let mut col = Collector::new();
    let mut physical: HashMap<(i64, i64), i64> = HashMap::new();
    while let Some(section) = c.maybe_token()? {
        match section {
            "$Nodes" if v2 => read_nodes_v2(&mut c, &mut col)?,
            "$Elements" if v2 => read_elements_v2(&mut c, &mut col)?,
            "$Entities" if !v2 => read_entities_v41(&mut c, &mut physical)?,
            "$Nodes" => read_nodes_v41(&mut c, &mut col)?,
            "$Elements" => read_elements_v41(&mut c, &mut col, &physical)?,
            s if s.starts_with('$') && !s.starts_with("$End") && s.len() > 1 => {
                c.skip_section(s)?
            }
            other => {
                return Err(c.error(format!(
                    "expected a section such as $Nodes, found '{}'",
                    shorten(other)
                )))
            }
        }
    }
    col.finish(path)
}

fn end_section(c: &mut Cursor, kw: &str) -> Result<(), IoError> {
    let t = c.token(kw)?;
    if t == kw {
        Ok(())
    } else {
        Err(c.error(format!(
            "expected {kw}, found '{}' (wrong count in the section header?)",
            shorten(t)
        )))
    }
}

fn read_nodes_v2(c: &mut Cursor, col: &mut Collector) -> Result<(), IoError> {
    let binary = c.binary;
    c.binary = false;
    let n = c.count("the node count", if binary { 28 } else { 8 })?;
    c.binary = binary;
    if binary {
        c.line_end()?;
    }
    let mut tags = Vec::with_capacity(n);
    let mut coords = Vec::with_capacity(n);
    for _ in 0..n {
        let tag = c.int("a node tag")?;
        if tag < 0 {
            return Err(c.error(format!("node tag {tag} is negative")));
        }
        let x = c.coord("an x coordinate")?;
        let y = c.coord("a y coordinate")?;
        let z = c.coord("a z coordinate")?;
        tags.push(tag as u64);
        coords.push([x, y, z]);
    }
    end_section(c, "$EndNodes")?;
    col.set_nodes(c, &tags, coords)
}

/// MSH 2.2 tags: physical first (0 for none), then elementary.
fn region_v2(tags: &[i64]) -> i64 {
    match tags {
        [p, ..] if *p != 0 => *p,
        [_, e, ..] => *e,
        _ => 0,
    }
}

fn read_elements_v2(c: &mut Cursor, col: &mut Collector) -> Result<(), IoError> {
    let binary = c.binary;
    c.binary = false;
    let n = c.count("the element count", if binary { 12 } else { 8 })?;
    c.binary = binary;
    let mut tags: Vec<i64> = Vec::new();
    if binary {
        c.line_end()?;
        let mut done = 0usize;
        while done < n {
            let etype = c.int("an element type")?;
            let count = c.int("an element count")?;
            let ntags = c.int("a tag count")?;
            if count <= 0 || count as usize > n - done {
                return Err(c.error(format!(
                    "element block of {count} elements does not fit the {n} announced"
                )));
            }
            if !(0..=64).contains(&ntags) {
                return Err(c.error(format!("{ntags} tags per element is not valid")));
            }
            let k = nodes_of_type(etype)
                .ok_or_else(|| c.error(format!("unknown element type {etype}")))?;
            let role = role_of_type(etype);
            for _ in 0..count {
                let _num = c.int("an element number")?;
                tags.clear();
                for _ in 0..ntags {
                    tags.push(c.int("an element tag")?);
                }
                col.read_nodes(c, k, |c| {
                    let t = c.int("a node tag")?;
                    Ok(if t < 0 { u64::MAX } else { t as u64 })
                })?;
                let r = region_v2(&tags);
                col.add(role, etype, r, c, None)?;
            }
            done += count as usize;
        }
    } else {
        for _ in 0..n {
            let _num: i64 = c.parse("an element number")?;
            let line = c.last_line;
            let etype: i64 = c.parse("an element type")?;
            let ntags = c.count("a tag count", 2)?;
            tags.clear();
            for _ in 0..ntags {
                tags.push(c.parse("an element tag")?);
            }
            let role = role_of_type(etype);
            if role == Role::Skip {
                c.skip_line();
                continue;
            }
            let k = nodes_of_type(etype).unwrap_or(0);
            col.read_nodes(c, k, |c| c.parse("a node tag"))?;
            if c.last_line != line {
                return Err(c.error(format!(
                    "element of type {etype} has fewer than {k} nodes on its line"
                )));
            }
            if !c.rest_of_line_blank() {
                return Err(c.error(format!(
                    "element of type {etype} has more than {k} nodes on its line"
                )));
            }
            let r = region_v2(&tags);
            col.add(role, etype, r, c, Some(line))?;
        }
    }
    end_section(c, "$EndElements")
}

fn read_entities_v41(
    c: &mut Cursor,
    physical: &mut HashMap<(i64, i64), i64>,
) -> Result<(), IoError> {
    if c.binary {
        c.line_end()?;
    }
    let mut counts = [0usize; 4];
    for (dim, n) in counts.iter_mut().enumerate() {
        *n = c.count(
            [
                "the point entity count",
                "the curve entity count",
                "the surface entity count",
                "the volume entity count",
            ][dim],
            8,
        )?;
    }
    for (dim, &n) in counts.iter().enumerate() {
        for _ in 0..n {
            let tag = c.int("an entity tag")?;
            let nbox = if dim == 0 { 3 } else { 6 };
            for _ in 0..nbox {
                c.double("a bounding-box coordinate")?;
            }
            let nphys = c.count("a physical tag count", 4)?;
            for i in 0..nphys {
                let p = c.int("a physical tag")?;
                if i == 0 {
                    physical.insert((dim as i64, tag), p);
                }
            }
            if dim > 0 {
                let nb = c.count("a bounding entity count", 4)?;
                for _ in 0..nb {
                    c.int("a bounding entity tag")?;
                }
            }
        }
    }
    end_section(c, "$EndEntities")
}

fn read_nodes_v41(c: &mut Cursor, col: &mut Collector) -> Result<(), IoError> {
    if c.binary {
        c.line_end()?;
    }
    let nblocks = c.count("the node block count", 8)?;
    let n = c.count("the node count", 8)?;
    let _min = c.size("the smallest node tag")?;
    let _max = c.size("the largest node tag")?;
    let (header_line, header_pos) = (c.last_line, c.last_pos);
    let mut tags: Vec<u64> = Vec::with_capacity(n);
    let mut coords: Vec<[f64; 3]> = Vec::with_capacity(n);
    for _ in 0..nblocks {
        let dim = c.int("an entity dimension")?;
        let _tag = c.int("an entity tag")?;
        let parametric = c.int("the parametric flag")?;
        let k = c.count("the node count of a block", 8)?;
        if !(0..=3).contains(&dim) {
            return Err(c.error(format!("entity dimension {dim} is not 0..3")));
        }
        let extra = if parametric != 0 { dim as usize } else { 0 };
        if tags.len() + k > n {
            return Err(c.error(format!(
                "node blocks hold more than the {n} nodes announced"
            )));
        }
        for _ in 0..k {
            tags.push(c.size("a node tag")?);
        }
        for _ in 0..k {
            let x = c.coord("an x coordinate")?;
            let y = c.coord("a y coordinate")?;
            let z = c.coord("a z coordinate")?;
            for _ in 0..extra {
                c.double("a parametric coordinate")?;
            }
            coords.push([x, y, z]);
        }
    }
    if tags.len() != n {
        return Err(c.error_at(
            header_line,
            header_pos,
            format!(
                "node blocks hold {} nodes but the header announced {n}",
                tags.len()
            ),
        ));
    }
    end_section(c, "$EndNodes")?;
    col.set_nodes(c, &tags, coords)
}

fn read_elements_v41(
    c: &mut Cursor,
    col: &mut Collector,
    physical: &HashMap<(i64, i64), i64>,
) -> Result<(), IoError> {
    if c.binary {
        c.line_end()?;
    }
    let nblocks = c.count("the element block count", 8)?;
    let n = c.count("the element count", 4)?;
    let _min = c.size("the smallest element tag")?;
    let _max = c.size("the largest element tag")?;
    let (header_line, header_pos) = (c.last_line, c.last_pos);
    let mut total = 0usize;
    for _ in 0..nblocks {
        let dim = c.int("an entity dimension")?;
        let tag = c.int("an entity tag")?;
        let etype = c.int("an element type")?;
        let k = c.count("the element count of a block", 4)?;
        total += k;
        if total > n {
            return Err(c.error(format!(
                "element blocks hold more than the {n} elements announced"
            )));
        }
        let role = role_of_type(etype);
        let tag_value = physical.get(&(dim, tag)).copied().unwrap_or(tag);
        let Some(nodes) = nodes_of_type(etype) else {
            if c.binary {
                return Err(c.error(format!("unknown element type {etype}")));
            }
            c.skip_line();
            for _ in 0..k {
                c.skip_line();
            }
            continue;
        };
        for _ in 0..k {
            let _etag = c.size("an element tag")?;
            let line = c.last_line;
            if role == Role::Skip {
                for _ in 0..nodes {
                    c.size("a node tag")?;
                }
                continue;
            }
            col.read_nodes(c, nodes, |c| c.size("a node tag"))?;
            if !c.binary && c.last_line != line {
                return Err(c.error(format!(
                    "element of type {etype} has fewer than {nodes} nodes on its line"
                )));
            }
            if !c.binary && !c.rest_of_line_blank() {
                return Err(c.error(format!(
                    "element of type {etype} has more than {nodes} nodes on its line"
                )));
            }
            let l = (!c.binary).then_some(line);
            col.add(role, etype, tag_value, c, l)?;
        }
    }
    if total != n {
        return Err(c.error_at(
            header_line,
            header_pos,
            format!("element blocks hold {total} elements but the header announced {n}"),
        ));
    }
    end_section(c, "$EndElements")
}

/// Writes `mesh` as Gmsh MSH 4.1 ASCII (through a temporary file).
pub fn write(path: &Path, mesh: &TetMesh) -> Result<(), IoError> {
    write_data(path, &mesh.to_data())
}

/// Physical tag of the point entities that carry corners: corners have no
/// marker of their own, but meshio needs every entity to have a physical tag
/// once any has one.
const CORNER_PHYSICAL: i32 = 1;

/// One entity of the written file: its physical tag and the elements in it.
struct Entity<E> {
    physical: i32,
    elements: Vec<E>,
}

fn group<E: Copy>(items: impl Iterator<Item = (E, i32)>) -> Vec<Entity<E>> {
    let mut by_tag: BTreeMap<i32, Vec<E>> = BTreeMap::new();
    for (e, t) in items {
        by_tag.entry(t).or_default().push(e);
    }
    by_tag
        .into_iter()
        .map(|(physical, elements)| Entity { physical, elements })
        .collect()
}

fn bounding_box(points: &[[f64; 3]], nodes: impl Iterator<Item = u32>) -> [f64; 6] {
    let mut b = [
        f64::INFINITY,
        f64::INFINITY,
        f64::INFINITY,
        f64::NEG_INFINITY,
        f64::NEG_INFINITY,
        f64::NEG_INFINITY,
    ];
    for v in nodes {
        let p = points[v as usize];
        for i in 0..3 {
            b[i] = b[i].min(p[i]);
            b[i + 3] = b[i + 3].max(p[i]);
        }
    }
    if !b[0].is_finite() {
        b = [0.0; 6];
    }
    b
}

/// Writes plain mesh data as Gmsh MSH 4.1 ASCII.
pub fn write_data(path: &Path, d: &MeshData) -> Result<(), IoError> {
    let volumes = group(d.tets.iter().enumerate().map(|(t, v)| (*v, d.region(t))));
    let surfaces = group(d.triangles.iter().copied());
    let curves = group(d.edges.iter().copied());
    let mut corners = d.corners.clone();
    corners.sort_unstable();
    corners.dedup();
    let n_elements = d.tets.len() + d.triangles.len() + d.edges.len() + corners.len();
    let n_blocks = volumes.len() + surfaces.len() + curves.len() + corners.len();
    let np = d.points.len();
    write_atomic(path, |w| {
        writeln!(w, "$MeshFormat\n4.1 0 8\n$EndMeshFormat")?;
        writeln!(w, "$Entities")?;
        writeln!(
            w,
            "{} {} {} {}",
            corners.len(),
            curves.len(),
            surfaces.len(),
            volumes.len()
        )?;
        for (i, &v) in corners.iter().enumerate() {
            let p = d.points[v as usize];
            writeln!(
                w,
                "{} {:?} {:?} {:?} 1 {CORNER_PHYSICAL}",
                i + 1,
                p[0],
                p[1],
                p[2]
            )?;
        }
        let write_box = |w: &mut dyn Write, tag: usize, b: [f64; 6], physical: i32| {
            writeln!(
                w,
                "{tag} {:?} {:?} {:?} {:?} {:?} {:?} 1 {physical} 0",
                b[0], b[1], b[2], b[3], b[4], b[5]
            )
        };
        for (i, e) in curves.iter().enumerate() {
            let b = bounding_box(&d.points, e.elements.iter().flatten().copied());
            write_box(w, i + 1, b, e.physical)?;
        }
        for (i, e) in surfaces.iter().enumerate() {
            let b = bounding_box(&d.points, e.elements.iter().flatten().copied());
            write_box(w, i + 1, b, e.physical)?;
        }
        for (i, e) in volumes.iter().enumerate() {
            let b = bounding_box(&d.points, e.elements.iter().flatten().copied());
            write_box(w, i + 1, b, e.physical)?;
        }
        writeln!(w, "$EndEntities")?;
        // All nodes in one block on the first volume entity; Gmsh and meshio
        // look nodes up by tag, whatever entity they are classified on.
        writeln!(w, "$Nodes\n1 {np} 1 {np}\n3 1 0 {np}")?;
        for i in 1..=np {
            writeln!(w, "{i}")?;
        }
        for p in &d.points {
            writeln!(w, "{:?} {:?} {:?}", p[0], p[1], p[2])?;
        }
        writeln!(w, "$EndNodes")?;
        writeln!(w, "$Elements\n{n_blocks} {n_elements} 1 {n_elements}")?;
        let mut tag = 0usize;
        for (i, &v) in corners.iter().enumerate() {
            tag += 1;
            writeln!(w, "0 {} 15 1\n{tag} {}", i + 1, v + 1)?;
        }
        for (i, e) in curves.iter().enumerate() {
            writeln!(w, "1 {} 1 {}", i + 1, e.elements.len())?;
            for v in &e.elements {
                tag += 1;
                writeln!(w, "{tag} {} {}", v[0] + 1, v[1] + 1)?;
            }
        }
        for (i, e) in surfaces.iter().enumerate() {
            writeln!(w, "2 {} 2 {}", i + 1, e.elements.len())?;
            for v in &e.elements {
                tag += 1;
                writeln!(w, "{tag} {} {} {}", v[0] + 1, v[1] + 1, v[2] + 1)?;
            }
        }
        for (i, e) in volumes.iter().enumerate() {
            writeln!(w, "3 {} 4 {}", i + 1, e.elements.len())?;
            for v in &e.elements {
                tag += 1;
                writeln!(
                    w,
                    "{tag} {} {} {} {}",
                    v[0] + 1,
                    v[1] + 1,
                    v[2] + 1,
                    v[3] + 1
                )?;
            }
        }
        writeln!(w, "$EndElements")
    })
}
