//! Gmsh `.msh`: MSH 2.2 (ASCII and binary) and MSH 4.1 (ASCII and binary)
//! read; MSH 2.2 ASCII, 4.1 ASCII and 4.1 binary written ([`MshFormat`]).
//! The layouts follow the "MSH file format" chapter of the Gmsh reference
//! manual (C. Geuzaine, J.-F. Remacle, gmsh.info).
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
//! Nothing of the tagging is lost ([`read_with_meta`], [`MeshMeta`]):
//! `$PhysicalNames` are kept (a name for a `(dim, tag)` no entity or element
//! has is an error at its line); an entity in several physical groups keeps
//! all of them: the mesh stores the first tag, and the full list is recorded
//! for it (an entity whose first tag another entity's list starts with gets a
//! fresh integer above all tags, with its list recorded). MSH 2.2, which
//! lists an element once per physical group, has the copies merged by their
//! nodes. Point elements' tags are kept by the coordinates of their node.
//! `$NodeData` views become point fields (the last time step of each name;
//! every node needs a finite value). `$ElementData` views become cell fields
//! the same way: every tetrahedron needs a finite value (an MSH 2.2 copy of
//! a tet, one per physical group, the same values), an element tag the file
//! does not define is an error at its line, and values at the other
//! elements (boundary triangles, lines, points) are skipped, since they are
//! no cells of the mesh — tetrefine's own writer and meshio's give every
//! element a value. An `$ElementData` before `$Elements` is an error.
//!
//! The writer puts every stored value in its own entity with the physical
//! tags behind it, every corner in a point entity (physical tag 1 when the
//! input gave it none), writes the names of the groups that have entities,
//! and point and cell fields of matching length (1 to 9 components) as
//! `$NodeData` and `$ElementData`, so that Gmsh and meshio read everything
//! back. `$ElementData` gives a value to every element of the file, with
//! element tags 1, 2, … in file order (MSH 2.2: every copy of a tet too):
//! the tets their field values, the boundary triangles, feature lines and
//! corner points NaN ("no value"). meshio needs this: it reads the values
//! in file order, splits them over all element blocks and checks that the
//! binary tags are 1, 2, …, so values for the tets alone would land on the
//! triangles. NaN, not a neighbouring tet's value, because a marked face
//! between two regions has two neighbours with different values, and
//! because a statistic over all cells (ParaView's range, `numpy.nanmean`)
//! then sees the tets' values only; it is what `Mesh.to_meshio` of the
//! Python package puts on triangles too.

use super::meta::{assign_values, Field, MeshMeta};
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

/// The physical tags an element gets: an interned list of physical tags
/// (`List`), or, without any, its entity's tag (`Plain`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum ElemTag {
    List(u32),
    Plain(i32),
}

/// A `$NodeData` view as read: node tags and values, with the line of its
/// header for messages.
struct NodeView {
    name: String,
    components: usize,
    tags: Vec<u64>,
    values: Vec<f64>,
    line: usize,
}

/// An `$ElementData` view as read: its values at the tetrahedra (NaN where
/// the view gave none), which tets it covered, and the line of its header.
struct ElementView {
    name: String,
    components: usize,
    values: Vec<f64>,
    have: Vec<bool>,
    line: usize,
}

/// What an element tag of `$Elements` stands for, for `$ElementData`.
#[derive(Clone, Copy)]
enum ElemSlot {
    /// The tetrahedron of this index (an MSH 2.2 copy of it, one per
    /// physical group, too).
    Tet(u32),
    /// An element that is not a tetrahedron (a triangle, line, point or
    /// skipped element): its values are not a cell field of the mesh.
    Other,
}

/// Collects the elements of a file into [`MeshData`] and [`MeshMeta`].
struct Collector {
    data: MeshData,
    nodes: Option<NodeIndex>,
    quadratic: bool,
    node_buf: Vec<u32>,
    /// Interned physical tag lists.
    lists: Vec<Vec<i32>>,
    list_ids: HashMap<Vec<i32>, u32>,
    tet_tags: Vec<ElemTag>,
    tri_tags: Vec<ElemTag>,
    edge_tags: Vec<ElemTag>,
    corner_tags: Vec<ElemTag>,
    /// MSH 2.2 writes an element once per physical group it is in: the
    /// copies are merged by their nodes.
    merge: bool,
    seen_tets: HashMap<[u32; 4], u32>,
    seen_tris: HashMap<[u32; 3], u32>,
    seen_edges: HashMap<[u32; 2], u32>,
    seen_corners: HashMap<u32, u32>,
    /// Every `(dim, physical tag)` the file uses, for checking `$PhysicalNames`.
    physicals: std::collections::BTreeSet<(i32, i32)>,
    /// `$PhysicalNames` entries with their lines.
    names: Vec<(i32, i32, String, usize)>,
    views: Vec<NodeView>,
    /// The element tag of each tet (its first copy in MSH 2.2).
    tet_elems: Vec<u64>,
    /// MSH 2.2 copies of a tet: (element tag, tet index).
    copy_elems: Vec<(u64, u32)>,
    /// The element tags of the elements that are not tets.
    other_elems: Vec<u64>,
    /// Whether an `$Elements` section was read.
    have_elements: bool,
    /// Element tag → slot, built at the first `$ElementData`.
    elem_index: Option<HashMap<u64, ElemSlot>>,
    element_views: Vec<ElementView>,
}

/// The index of an earlier element with the vertex set `key` (sorted), or
/// `None` after noting this one, the `next` element, under that key.
fn seen_before<K: std::hash::Hash + Eq>(
    seen: &mut HashMap<K, u32>,
    key: K,
    next: usize,
) -> Option<usize> {
    match seen.entry(key) {
        std::collections::hash_map::Entry::Occupied(e) => Some(*e.get() as usize),
        std::collections::hash_map::Entry::Vacant(e) => {
            e.insert(next as u32);
            None
        }
    }
}

impl Collector {
    fn new(merge: bool) -> Collector {
        Collector {
            data: MeshData::default(),
            nodes: None,
            quadratic: false,
            node_buf: Vec::with_capacity(16),
            lists: Vec::new(),
            list_ids: HashMap::new(),
            tet_tags: Vec::new(),
            tri_tags: Vec::new(),
            edge_tags: Vec::new(),
            corner_tags: Vec::new(),
            merge,
            seen_tets: HashMap::new(),
            seen_tris: HashMap::new(),
            seen_edges: HashMap::new(),
            seen_corners: HashMap::new(),
            physicals: Default::default(),
            names: Vec::new(),
            views: Vec::new(),
            tet_elems: Vec::new(),
            copy_elems: Vec::new(),
            other_elems: Vec::new(),
            have_elements: false,
            elem_index: None,
            element_views: Vec::new(),
        }
    }

    /// The slot of every element tag of `$Elements` (built once).
    fn element_index(&mut self) -> &HashMap<u64, ElemSlot> {
        self.elem_index.get_or_insert_with(|| {
            let mut m = HashMap::with_capacity(
                self.tet_elems.len() + self.copy_elems.len() + self.other_elems.len(),
            );
            for &t in &self.other_elems {
                m.insert(t, ElemSlot::Other);
            }
            for (i, &t) in self.tet_elems.iter().enumerate() {
                m.insert(t, ElemSlot::Tet(i as u32));
            }
            for &(t, i) in &self.copy_elems {
                m.insert(t, ElemSlot::Tet(i));
            }
            m
        })
    }

    /// The tag of an element with these physical tags (none: `entity`).
    fn tag_of(&mut self, physical: &[i32], entity: i32) -> ElemTag {
        if physical.is_empty() {
            return ElemTag::Plain(entity);
        }
        if let Some(&id) = self.list_ids.get(physical) {
            return ElemTag::List(id);
        }
        let id = self.lists.len() as u32;
        self.lists.push(physical.to_vec());
        self.list_ids.insert(physical.to_vec(), id);
        ElemTag::List(id)
    }

    /// The tag of an element listed again with another physical tag (MSH
    /// 2.2), or `None` when the copy brings no new tag (a true duplicate,
    /// kept so that building the mesh reports it).
    fn merged(&mut self, old: ElemTag, new: ElemTag) -> Option<ElemTag> {
        let (ElemTag::List(a), ElemTag::List(b)) = (old, new) else {
            return None;
        };
        let mut l = self.lists[a as usize].clone();
        let before = l.len();
        for &p in &self.lists[b as usize] {
            if !l.contains(&p) {
                l.push(p);
            }
        }
        (l.len() > before).then(|| self.tag_of(&l, 0))
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

    /// Adds the element whose nodes are in `node_buf`; `elem` is its
    /// element tag (for `$ElementData`).
    fn add(&mut self, role: Role, etype: i64, tag: ElemTag, line: Option<usize>, elem: u64) {
        if role != Role::Tet {
            self.other_elems.push(elem);
        }
        let n = self.node_buf.clone();
        if matches!(etype, 8 | 9 | 11) {
            self.quadratic = true;
        }
        fn sorted<const N: usize>(mut a: [u32; N]) -> [u32; N] {
            a.sort_unstable();
            a
        }
        match role {
            Role::Tet => {
                let v = [n[0], n[1], n[2], n[3]];
                let seen = self
                    .merge
                    .then(|| seen_before(&mut self.seen_tets, sorted(v), self.data.tets.len()))
                    .flatten();
                if self.absorb(role, seen, tag) {
                    let j = seen.expect("absorbed into an earlier tet");
                    self.copy_elems.push((elem, j as u32));
                    return;
                }
                self.data.tets.push(v);
                self.tet_tags.push(tag);
                self.tet_elems.push(elem);
                if let Some(l) = line {
                    self.data.tet_lines.push(l as u32);
                }
            }
            Role::Triangle => {
                let v = [n[0], n[1], n[2]];
                let seen = self
                    .merge
                    .then(|| seen_before(&mut self.seen_tris, sorted(v), self.data.triangles.len()))
                    .flatten();
                if self.absorb(role, seen, tag) {
                    return;
                }
                self.data.triangles.push((v, 0));
                self.tri_tags.push(tag);
            }
            Role::Edge => {
                let v = [n[0], n[1]];
                let seen = self
                    .merge
                    .then(|| seen_before(&mut self.seen_edges, sorted(v), self.data.edges.len()))
                    .flatten();
                if self.absorb(role, seen, tag) {
                    return;
                }
                self.data.edges.push((v, 0));
                self.edge_tags.push(tag);
            }
            Role::Corner => {
                let seen = self
                    .merge
                    .then(|| seen_before(&mut self.seen_corners, n[0], self.data.corners.len()))
                    .flatten();
                if self.absorb(role, seen, tag) {
                    return;
                }
                self.data.corners.push(n[0]);
                self.corner_tags.push(tag);
            }
            Role::Skip => {}
        }
    }

    /// MSH 2.2's merge of an element listed again: element `seen` (of
    /// `role`, found by [`seen_before`]) takes the copy's physical tags.
    /// `false` when there is no earlier element, or when the copy brings no
    /// new tag — a true duplicate, which is then added so that building the
    /// mesh reports it.
    fn absorb(&mut self, role: Role, seen: Option<usize>, tag: ElemTag) -> bool {
        let Some(j) = seen else {
            return false;
        };
        let old = self.tags_mut(role)[j];
        match self.merged(old, tag) {
            Some(m) => {
                self.tags_mut(role)[j] = m;
                true
            }
            None => false,
        }
    }

    /// The tag list of the elements of `role`.
    fn tags_mut(&mut self, role: Role) -> &mut Vec<ElemTag> {
        match role {
            Role::Tet => &mut self.tet_tags,
            Role::Triangle => &mut self.tri_tags,
            Role::Edge => &mut self.edge_tags,
            Role::Corner => &mut self.corner_tags,
            Role::Skip => unreachable!("skipped elements are never stored"),
        }
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

    /// The stored values of one dimension's elements, with the tag sets
    /// behind them recorded in `meta`.
    fn values(&self, dim: i32, tags: &[ElemTag], meta: &mut MeshMeta) -> Vec<i32> {
        let mut order: Vec<u32> = Vec::new();
        let mut pos: HashMap<u32, usize> = HashMap::new();
        let mut reserved = std::collections::BTreeSet::new();
        for t in tags {
            match *t {
                ElemTag::List(id) => {
                    pos.entry(id).or_insert_with(|| {
                        order.push(id);
                        order.len() - 1
                    });
                }
                ElemTag::Plain(v) => {
                    reserved.insert(v);
                }
            }
        }
        let lists: Vec<Vec<i32>> = order
            .iter()
            .map(|&id| self.lists[id as usize].clone())
            .collect();
        let values = assign_values(&lists, &reserved);
        for (l, &v) in lists.iter().zip(&values) {
            if l.as_slice() != [v] {
                meta.tag_sets.insert((dim, v), l.clone());
            }
        }
        tags.iter()
            .map(|t| match *t {
                ElemTag::List(id) => values[pos[&id]],
                ElemTag::Plain(v) => v,
            })
            .collect()
    }

    fn finish(mut self, path: &Path) -> Result<(MeshData, MeshMeta), IoError> {
        if self.nodes.is_none() {
            return Err(IoError::file(path, "no $Nodes section"));
        }
        if self.data.tets.is_empty() {
            return Err(IoError::file(
                path,
                "no tetrahedra (element type 4 or 11): not a volume mesh",
            ));
        }
        for (dim, tag, name, line) in &self.names {
            if !self.physicals.contains(&(*dim, *tag)) {
                return Err(IoError::at(
                    path,
                    *line,
                    format!(
                        "$PhysicalNames names physical tag {tag} of dimension {dim} (\"{name}\"), which no entity or element of the file has"
                    ),
                ));
            }
        }
        let mut meta = MeshMeta::default();
        for (dim, tag, name, _) in &self.names {
            meta.physical_names.insert((*dim, *tag), name.clone());
        }
        self.data.tet_regions = self.values(3, &self.tet_tags, &mut meta);
        let tri = self.values(2, &self.tri_tags, &mut meta);
        for (t, v) in self.data.triangles.iter_mut().zip(tri) {
            t.1 = v;
        }
        let edge = self.values(1, &self.edge_tags, &mut meta);
        for (e, v) in self.data.edges.iter_mut().zip(edge) {
            e.1 = v;
        }
        for (&v, t) in self.data.corners.iter().zip(&self.corner_tags) {
            if let ElemTag::List(id) = *t {
                meta.point_tags.push((
                    self.data.points[v as usize],
                    self.lists[id as usize].clone(),
                ));
            }
        }
        if self.data.tet_lines.len() != self.data.tets.len() {
            self.data.tet_lines.clear();
        }
        let index = self.nodes.take().expect("checked above");
        let np = self.data.points.len();
        // Views: the last one of each name (the last time step) covers every node.
        let mut by_name: BTreeMap<String, usize> = BTreeMap::new();
        for (i, v) in self.views.iter().enumerate() {
            by_name.insert(v.name.clone(), i);
        }
        let mut keep: Vec<usize> = by_name.into_values().collect();
        keep.sort_unstable();
        for i in keep {
            let v = &self.views[i];
            let mut values = vec![f64::NAN; np * v.components];
            let mut have = vec![false; np];
            for (k, &tag) in v.tags.iter().enumerate() {
                let Some(n) = index.get(tag) else {
                    return Err(IoError::at(
                        path,
                        v.line,
                        format!(
                            "$NodeData \"{}\" refers to node {tag}, which is not defined in $Nodes",
                            v.name
                        ),
                    ));
                };
                have[n as usize] = true;
                values[n as usize * v.components..(n as usize + 1) * v.components]
                    .copy_from_slice(&v.values[k * v.components..(k + 1) * v.components]);
            }
            let missing = have.iter().filter(|&&h| !h).count();
            if missing > 0 {
                return Err(IoError::at(
                    path,
                    v.line,
                    format!(
                        "$NodeData \"{}\" has values for {} of the {np} nodes ({missing} missing): a field must cover every node",
                        v.name,
                        np - missing
                    ),
                ));
            }
            meta.point_fields.push(Field {
                name: v.name.clone(),
                components: v.components,
                values,
            });
        }
        // Element views likewise: the last one of each name covers every tet.
        let mut by_name: BTreeMap<String, usize> = BTreeMap::new();
        for (i, v) in self.element_views.iter().enumerate() {
            by_name.insert(v.name.clone(), i);
        }
        let mut keep: Vec<usize> = by_name.into_values().collect();
        keep.sort_unstable();
        let nt = self.data.tets.len();
        for i in keep {
            let v = &mut self.element_views[i];
            let missing = v.have.iter().filter(|&&h| !h).count();
            if missing > 0 || v.have.len() != nt {
                let first = v.have.iter().position(|&h| !h).unwrap_or(v.have.len());
                let tag = self.tet_elems.get(first).copied().unwrap_or(0);
                return Err(IoError::at(
                    path,
                    v.line,
                    format!(
                        "$ElementData \"{}\" has values for {} of the {nt} tetrahedra ({} missing, the first element {tag}): a cell field must cover every tetrahedron",
                        v.name,
                        v.have.len() - missing,
                        missing + nt.saturating_sub(v.have.len()),
                    ),
                ));
            }
            meta.cell_fields.push(Field {
                name: std::mem::take(&mut v.name),
                components: v.components,
                values: std::mem::take(&mut v.values),
            });
        }
        if self.quadratic {
            let before = self.data.points.clone();
            drop_unused_points(&mut self.data);
            if self.data.points.len() != before.len() && !meta.point_fields.is_empty() {
                // Kept points stay in order: match them up in one pass.
                let mut kept = Vec::with_capacity(self.data.points.len());
                let mut j = 0;
                for (i, p) in before.iter().enumerate() {
                    if j < self.data.points.len() && self.data.points[j] == *p {
                        kept.push(i);
                        j += 1;
                    }
                }
                for f in &mut meta.point_fields {
                    let c = f.components;
                    f.values = kept
                        .iter()
                        .flat_map(|&i| f.values[i * c..(i + 1) * c].to_vec())
                        .collect();
                }
            }
        }
        Ok((self.data, meta))
    }
}

/// Reads a Gmsh `.msh` file (MSH 2.2 or 4.1, ASCII or binary).
pub fn read(path: &Path) -> Result<MeshData, IoError> {
    read_with_meta(path).map(|(d, _)| d)
}

/// Reads a Gmsh `.msh` file with its physical names, full tag lists and
/// `$NodeData` views (see [`MeshMeta`]).
pub fn read_with_meta(path: &Path) -> Result<(MeshData, MeshMeta), IoError> {
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
    let mut col = Collector::new(v2);
    let mut physical: HashMap<(i64, i64), ElemTag> = HashMap::new();
    while let Some(section) = c.maybe_token()? {
        match section {
            "$PhysicalNames" => read_physical_names(&mut c, &mut col)?,
            "$NodeData" => read_node_data(&mut c, &mut col)?,
            "$ElementData" => read_element_data(&mut c, &mut col)?,
            "$Nodes" if v2 => read_nodes_v2(&mut c, &mut col)?,
            "$Elements" if v2 => read_elements_v2(&mut c, &mut col)?,
            "$Entities" if !v2 => read_entities_v41(&mut c, &mut col, &mut physical)?,
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

/// The rest of a `"quoted"` token that started with `first` (names may hold
/// blanks): the text between the quotes.
fn quoted(c: &mut Cursor, first: &str, what: &str) -> Result<String, IoError> {
    let Some(rest) = first.strip_prefix('"') else {
        return Err(c.error(format!(
            "expected {what} in double quotes, found '{}'",
            shorten(first)
        )));
    };
    let mut s = rest.to_string();
    let line = c.last_line;
    loop {
        if let Some(body) = s.strip_suffix('"') {
            return Ok(body.to_string());
        }
        let t = c.token(what)?;
        if c.last_line != line {
            return Err(c.error_at(
                line,
                c.last_pos,
                format!("{what} has no closing double quote on its line"),
            ));
        }
        s.push(' ');
        s.push_str(t);
    }
}

/// `$PhysicalNames` (ASCII in every variant): `dim tag "name"` per line.
fn read_physical_names(c: &mut Cursor, col: &mut Collector) -> Result<(), IoError> {
    let binary = c.binary;
    c.binary = false;
    let n = c.count("the physical name count", 6)?;
    for _ in 0..n {
        let dim: i32 = c.parse("a physical dimension")?;
        let line = c.last_line;
        if !(0..=3).contains(&dim) {
            return Err(c.error(format!("physical dimension {dim} is not 0..3")));
        }
        let tag: i32 = c.parse("a physical tag")?;
        let t = c.token("a physical name")?;
        let name = quoted(c, t, "a physical name")?;
        if col.names.iter().any(|(d, g, _, _)| (*d, *g) == (dim, tag)) {
            return Err(c.error(format!(
                "physical tag {tag} of dimension {dim} is named twice"
            )));
        }
        col.names.push((dim, tag, name, line));
    }
    end_section(c, "$EndPhysicalNames")?;
    c.binary = binary;
    Ok(())
}

/// The header of a `$NodeData` / `$ElementData` view (`section` without
/// the `$`), in ASCII in every variant: the string tags (the first is the
/// name), the real tags (the time), the integer tags (time step,
/// components, entries). Returns the name, the components, the entry count
/// and the line of the entry count; the cursor is then before the entries
/// (past the line end in binary files).
fn data_header(
    c: &mut Cursor,
    section: &str,
    per: &str,
) -> Result<(String, usize, usize, usize), IoError> {
    let binary = c.binary;
    c.binary = false;
    let ns = c.count("the string tag count", 2)?;
    let mut name = String::from("field");
    for i in 0..ns {
        let t = c.token("a string tag")?;
        let s = quoted(c, t, "a string tag")?;
        if i == 0 {
            name = s;
        }
    }
    let nr = c.count("the real tag count", 2)?;
    for _ in 0..nr {
        c.double("a real tag")?;
    }
    let ni = c.count("the integer tag count", 2)?;
    let mut ints = Vec::with_capacity(ni);
    let mut line = c.last_line;
    for i in 0..ni {
        ints.push(c.parse::<i64>("an integer tag")?);
        if i <= 2 {
            // The line of the entry count, for messages about the entries.
            line = c.last_line;
        }
    }
    let (components, n) = match ints.as_slice() {
        [_, comp, n, ..] => (*comp, *n),
        _ => {
            return Err(c.error(format!(
                "${section} needs three integer tags (time step, components, entries)"
            )))
        }
    };
    if !(1..=9).contains(&components) {
        return Err(c.error(format!(
            "${section} \"{name}\": {components} components per {per} is not valid (1 to 9)"
        )));
    }
    let components = components as usize;
    let left = (c.b.len() - c.pos) as i64;
    if n < 0 || n > left / (2 * components as i64 + 2) + 1 {
        let message = format!(
            "${section} \"{name}\": {n} entries is more than the rest of the file can hold (truncated?)"
        );
        // The header is ASCII: name the line of the entry count.
        return Err(IoError::at(c.path, line, message));
    }
    c.binary = binary;
    if binary {
        c.line_end()?;
    }
    Ok((name, components, n as usize, line))
}

/// The node or element tag of one entry of a view: an `int` in binary
/// files (MSH 2.2 and 4.1 alike, as Gmsh 4.15 writes them), a number in
/// ASCII.
fn entry_tag(c: &mut Cursor, what: &str) -> Result<u64, IoError> {
    if c.binary {
        let t = c.int(what)?;
        Ok(u64::try_from(t).unwrap_or(u64::MAX))
    } else {
        c.parse::<u64>(what)
    }
}

/// `$NodeData`: a view's header ([`data_header`]), then one node tag and
/// `components` doubles per entry.
fn read_node_data(c: &mut Cursor, col: &mut Collector) -> Result<(), IoError> {
    let (name, components, n, line) = data_header(c, "NodeData", "node")?;
    let mut tags = Vec::with_capacity(n);
    let mut values = Vec::with_capacity(n * components);
    for _ in 0..n {
        let tag = entry_tag(c, "a node tag")?;
        tags.push(tag);
        for _ in 0..components {
            let x = c.double("a field value")?;
            if !x.is_finite() {
                return Err(c.error(format!(
                    "$NodeData \"{name}\": value {x} at node {tag} is not a finite number"
                )));
            }
            values.push(x);
        }
    }
    end_section(c, "$EndNodeData")?;
    col.views.push(NodeView {
        name,
        components,
        tags,
        values,
        line,
    });
    Ok(())
}

/// `$ElementData`: a view's header ([`data_header`]), then one element tag
/// and `components` doubles per entry. Values at tetrahedra become a cell
/// field (they must be finite; an MSH 2.2 copy of a tet, one per physical
/// group, must repeat its values); values at other elements (boundary
/// triangles, lines, points: not cells of the mesh, whatever they hold —
/// tetrefine's and meshio's writers give every element a value) are
/// skipped. An element tag `$Elements` does not define is an error at its
/// line.
fn read_element_data(c: &mut Cursor, col: &mut Collector) -> Result<(), IoError> {
    if !col.have_elements {
        return Err(c.error(
            "$ElementData comes before $Elements (its element tags name elements of the file)",
        ));
    }
    let (name, components, n, line) = data_header(c, "ElementData", "element")?;
    let nt = col.data.tets.len();
    let mut values = vec![f64::NAN; nt * components];
    let mut have = vec![false; nt];
    let mut entry = vec![0.0; components];
    for _ in 0..n {
        let tag = entry_tag(c, "an element tag")?;
        let slot = col.element_index().get(&tag).copied();
        let Some(slot) = slot else {
            return Err(c.error(format!(
                "$ElementData \"{name}\" refers to element {tag}, which is not defined in $Elements"
            )));
        };
        for x in entry.iter_mut() {
            *x = c.double("a field value")?;
        }
        let ElemSlot::Tet(t) = slot else {
            continue;
        };
        if let Some(x) = entry.iter().find(|x| !x.is_finite()) {
            return Err(c.error(format!(
                "$ElementData \"{name}\": value {x} at element {tag} (a tetrahedron) is not a finite number"
            )));
        }
        let t = t as usize;
        let slot = &mut values[t * components..(t + 1) * components];
        if have[t] && slot != entry.as_slice() {
            return Err(c.error(format!(
                "$ElementData \"{name}\": element {tag} is given {entry:?}, but the same tetrahedron (another copy of it, or the same tag) was given {slot:?}"
            )));
        }
        slot.copy_from_slice(&entry);
        have[t] = true;
    }
    end_section(c, "$EndElementData")?;
    col.element_views.push(ElementView {
        name,
        components,
        values,
        have,
        line,
    });
    Ok(())
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

/// An MSH 2.2 element number as a tag (a negative one, which no
/// `$ElementData` can name, becomes `u64::MAX`).
fn elem_tag(num: i64) -> u64 {
    u64::try_from(num).unwrap_or(u64::MAX)
}

/// An `i64` tag as the `i32` the mesh stores.
fn tag32(c: &Cursor, tag: i64) -> Result<i32, IoError> {
    i32::try_from(tag).map_err(|_| c.error(format!("tag {tag} does not fit a 32-bit integer")))
}

/// The dimension of the elements of a role.
fn dim_of(role: Role) -> Option<i32> {
    match role {
        Role::Tet => Some(3),
        Role::Triangle => Some(2),
        Role::Edge => Some(1),
        Role::Corner => Some(0),
        Role::Skip => None,
    }
}

/// Dimension of an element type, for element types we skip.
fn dim_of_type(t: i64) -> Option<i32> {
    Some(match t {
        15 => 0,
        1 | 8 | 26 | 27 | 28 => 1,
        2 | 3 | 9 | 10 | 16 | 20..=25 => 2,
        4..=7 | 11..=14 | 17..=19 | 29..=31 | 92 | 93 => 3,
        _ => return None,
    })
}

/// MSH 2.2 tags: physical first (0 for none), then elementary.
fn tag_v2(c: &Cursor, col: &mut Collector, etype: i64, tags: &[i64]) -> Result<ElemTag, IoError> {
    let (p, e) = match tags {
        [p, e, ..] => (*p, *e),
        [p] => (*p, 0),
        [] => (0, 0),
    };
    let (p, e) = (tag32(c, p)?, tag32(c, e)?);
    if p != 0 {
        if let Some(d) = dim_of_type(etype) {
            col.physicals.insert((d, p));
        }
        Ok(col.tag_of(&[p], e))
    } else {
        Ok(ElemTag::Plain(e))
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
                let num = c.int("an element number")?;
                tags.clear();
                for _ in 0..ntags {
                    tags.push(c.int("an element tag")?);
                }
                col.read_nodes(c, k, |c| {
                    let t = c.int("a node tag")?;
                    Ok(if t < 0 { u64::MAX } else { t as u64 })
                })?;
                let tag = tag_v2(c, col, etype, &tags)?;
                col.add(role, etype, tag, None, elem_tag(num));
            }
            done += count as usize;
        }
    } else {
        for _ in 0..n {
            let num: i64 = c.parse("an element number")?;
            let line = c.last_line;
            let etype: i64 = c.parse("an element type")?;
            let ntags = c.count("a tag count", 2)?;
            tags.clear();
            for _ in 0..ntags {
                tags.push(c.parse("an element tag")?);
            }
            let role = role_of_type(etype);
            if role == Role::Skip {
                tag_v2(c, col, etype, &tags)?;
                col.other_elems.push(elem_tag(num));
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
            let tag = tag_v2(c, col, etype, &tags)?;
            col.add(role, etype, tag, Some(line), elem_tag(num));
        }
    }
    col.have_elements = true;
    end_section(c, "$EndElements")
}

fn read_entities_v41(
    c: &mut Cursor,
    col: &mut Collector,
    physical: &mut HashMap<(i64, i64), ElemTag>,
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
    let mut tags = Vec::new();
    for (dim, &n) in counts.iter().enumerate() {
        for _ in 0..n {
            let tag = c.int("an entity tag")?;
            let nbox = if dim == 0 { 3 } else { 6 };
            for _ in 0..nbox {
                c.double("a bounding-box coordinate")?;
            }
            let nphys = c.count("a physical tag count", 4)?;
            tags.clear();
            for _ in 0..nphys {
                let p = c.int("a physical tag")?;
                let p = tag32(c, p)?;
                col.physicals.insert((dim as i32, p));
                if !tags.contains(&p) {
                    tags.push(p);
                }
            }
            let t = col.tag_of(&tags, tag32(c, tag)?);
            if physical.insert((dim as i64, tag), t).is_some() {
                return Err(c.error(format!(
                    "entity {tag} of dimension {dim} is defined twice in $Entities"
                )));
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
    physical: &HashMap<(i64, i64), ElemTag>,
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
        if let Some(d) = dim_of(role) {
            if i64::from(d) != dim {
                return Err(c.error(format!(
                    "element type {etype} is of dimension {d}, but its block is on an entity of dimension {dim}"
                )));
            }
        }
        let tag_value = match physical.get(&(dim, tag)) {
            Some(&t) => t,
            None if physical.is_empty() => ElemTag::Plain(tag32(c, tag)?),
            None => {
                return Err(c.error(format!(
                "element block on entity {tag} of dimension {dim}, which $Entities does not define"
            )))
            }
        };
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
            let etag = c.size("an element tag")?;
            let line = c.last_line;
            if role == Role::Skip {
                col.other_elems.push(etag);
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
            col.add(role, etype, tag_value, l, etag);
        }
    }
    if total != n {
        return Err(c.error_at(
            header_line,
            header_pos,
            format!("element blocks hold {total} elements but the header announced {n}"),
        ));
    }
    col.have_elements = true;
    end_section(c, "$EndElements")
}

/// The MSH variant a Gmsh writer writes ([`crate::io::WriteOptions`]).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum MshFormat {
    /// MSH 2.2 ASCII: an element in several physical groups is written once
    /// per group, as Gmsh itself does.
    V22,
    /// MSH 4.1 ASCII (the default).
    #[default]
    V41,
    /// MSH 4.1 binary (little-endian, 8-byte `size_t`).
    V41Binary,
}

impl std::str::FromStr for MshFormat {
    type Err = String;

    fn from_str(s: &str) -> Result<MshFormat, String> {
        match s {
            "2.2" => Ok(MshFormat::V22),
            "4.1" => Ok(MshFormat::V41),
            "4.1-binary" => Ok(MshFormat::V41Binary),
            other => Err(format!(
                "unknown MSH format '{other}' (use 2.2, 4.1 or 4.1-binary)"
            )),
        }
    }
}

impl std::fmt::Display for MshFormat {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(match self {
            MshFormat::V22 => "2.2",
            MshFormat::V41 => "4.1",
            MshFormat::V41Binary => "4.1-binary",
        })
    }
}

/// Writes `mesh` as Gmsh MSH 4.1 ASCII (through a temporary file).
pub fn write(path: &Path, mesh: &TetMesh) -> Result<(), IoError> {
    write_data(path, &mesh.to_data())
}

/// Writes `mesh` with its side table (physical names, tag lists, fields) in
/// the chosen MSH variant.
pub fn write_with(
    path: &Path,
    mesh: &TetMesh,
    meta: &MeshMeta,
    format: MshFormat,
) -> Result<(), IoError> {
    write_data_with(path, &mesh.to_data(), meta, format)
}

/// Physical tag of the point entities that carry corners the input gave no
/// tag: corners have no marker of their own, but meshio needs every entity
/// to have a physical tag once any has one.
const CORNER_PHYSICAL: i32 = 1;

/// An element of the written file that is not a tet (see `elem_tet` in
/// [`write_data_with`]).
const NO_TET: u32 = u32::MAX;

/// One entity of the written file: its physical tags and the elements in it.
struct Entity<E> {
    physical: Vec<i32>,
    elements: Vec<E>,
}

fn group<E: Copy>(
    dim: i32,
    meta: &MeshMeta,
    items: impl Iterator<Item = (E, i32)>,
) -> Vec<Entity<E>> {
    let mut by_tag: BTreeMap<i32, Vec<E>> = BTreeMap::new();
    for (e, t) in items {
        by_tag.entry(t).or_default().push(e);
    }
    by_tag
        .into_iter()
        .map(|(value, elements)| Entity {
            physical: meta.physical_tags(dim, value),
            elements,
        })
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
    write_data_with(path, d, &MeshMeta::default(), MshFormat::V41)
}

/// Values of one line of a 4.1 file, written as ASCII tokens or as binary
/// `int` / `size_t` / `double`.
struct Emit<'w, W: Write> {
    w: &'w mut W,
    binary: bool,
    first: bool,
}

impl<W: Write> Emit<'_, W> {
    fn sep(&mut self) -> std::io::Result<()> {
        if !self.first {
            self.w.write_all(b" ")?;
        }
        self.first = false;
        Ok(())
    }
    fn int(&mut self, v: i64) -> std::io::Result<()> {
        if self.binary {
            self.w.write_all(&(v as i32).to_le_bytes())
        } else {
            self.sep()?;
            write!(self.w, "{v}")
        }
    }
    fn size(&mut self, v: u64) -> std::io::Result<()> {
        if self.binary {
            self.w.write_all(&v.to_le_bytes())
        } else {
            self.sep()?;
            write!(self.w, "{v}")
        }
    }
    fn dbl(&mut self, v: f64) -> std::io::Result<()> {
        if self.binary {
            self.w.write_all(&v.to_le_bytes())
        } else {
            self.sep()?;
            write!(self.w, "{v:?}")
        }
    }
    /// Ends a line (ASCII only).
    fn nl(&mut self) -> std::io::Result<()> {
        self.first = true;
        if self.binary {
            Ok(())
        } else {
            self.w.write_all(b"\n")
        }
    }
    /// Ends the binary block of a section: a line end before `$End…`.
    fn end(&mut self) -> std::io::Result<()> {
        self.first = true;
        if self.binary {
            self.w.write_all(b"\n")
        } else {
            Ok(())
        }
    }
}

/// Writes plain mesh data and its side table in the chosen MSH variant.
pub fn write_data_with(
    path: &Path,
    d: &MeshData,
    meta: &MeshMeta,
    format: MshFormat,
) -> Result<(), IoError> {
    let volumes = group(
        3,
        meta,
        d.tets.iter().enumerate().map(|(t, v)| (*v, d.region(t))),
    );
    // The tets of each volume entity, in the order `group` lists them.
    let mut volume_tets: BTreeMap<i32, Vec<u32>> = BTreeMap::new();
    for t in 0..d.tets.len() {
        volume_tets.entry(d.region(t)).or_default().push(t as u32);
    }
    let volume_tets: Vec<Vec<u32>> = volume_tets.into_values().collect();
    let surfaces = group(2, meta, d.triangles.iter().copied());
    let curves = group(1, meta, d.edges.iter().copied());
    let mut corner_ids = d.corners.clone();
    corner_ids.sort_unstable();
    corner_ids.dedup();
    let corners: Vec<Entity<u32>> = corner_ids
        .iter()
        .map(|&v| Entity {
            physical: meta
                .point_physical_tags(d.points[v as usize])
                .map(<[i32]>::to_vec)
                .unwrap_or_else(|| vec![CORNER_PHYSICAL]),
            elements: vec![v],
        })
        .collect();
    // Names of the physical groups that have entities in the file.
    let mut used: std::collections::BTreeSet<(i32, i32)> = Default::default();
    for (dim, list) in corners
        .iter()
        .map(|e| (0, &e.physical))
        .chain(curves.iter().map(|e| (1, &e.physical)))
        .chain(surfaces.iter().map(|e| (2, &e.physical)))
        .chain(volumes.iter().map(|e| (3, &e.physical)))
    {
        for &p in list {
            used.insert((dim, p));
        }
    }
    let names: Vec<(&(i32, i32), &String)> = meta
        .physical_names
        .iter()
        .filter(|(k, _)| used.contains(k))
        .collect();
    let np = d.points.len();
    let nt = d.tets.len();
    let point_fields: Vec<&Field> = meta
        .point_fields
        .iter()
        .filter(|f| f.len() == np && f.values.len() == np * f.components)
        .filter(|f| (1..=9).contains(&f.components))
        .collect();
    let cell_fields: Vec<&Field> = meta
        .cell_fields
        .iter()
        .filter(|f| f.len() == nt && f.values.len() == nt * f.components)
        .filter(|f| (1..=9).contains(&f.components))
        .collect();
    write_atomic(path, |w| {
        match format {
            MshFormat::V22 => writeln!(w, "$MeshFormat\n2.2 0 8\n$EndMeshFormat")?,
            MshFormat::V41 => writeln!(w, "$MeshFormat\n4.1 0 8\n$EndMeshFormat")?,
            MshFormat::V41Binary => {
                writeln!(w, "$MeshFormat\n4.1 1 8")?;
                w.write_all(&1i32.to_le_bytes())?;
                writeln!(w, "\n$EndMeshFormat")?;
            }
        }
        if !names.is_empty() {
            writeln!(w, "$PhysicalNames\n{}", names.len())?;
            for ((dim, tag), name) in &names {
                writeln!(w, "{dim} {tag} \"{name}\"")?;
            }
            writeln!(w, "$EndPhysicalNames")?;
        }
        // Per element of the file, in element-tag order (tags 1, 2, …): the
        // tet it is, or NO_TET (for $ElementData).
        let mut elem_tet: Vec<u32> = Vec::new();
        if format == MshFormat::V22 {
            writeln!(w, "$Nodes\n{np}")?;
            for (i, p) in d.points.iter().enumerate() {
                writeln!(w, "{} {:?} {:?} {:?}", i + 1, p[0], p[1], p[2])?;
            }
            writeln!(w, "$EndNodes")?;
            fn count<E>(es: &[Entity<E>]) -> usize {
                es.iter().map(|e| e.physical.len() * e.elements.len()).sum()
            }
            let n = count(&corners) + count(&curves) + count(&surfaces) + count(&volumes);
            writeln!(w, "$Elements\n{n}")?;
            let mut num = 0usize;
            let mut line = |w: &mut dyn Write, etype: u8, phys: i32, ent: usize, nodes: &[u32]| {
                num += 1;
                write!(w, "{num} {etype} 2 {phys} {ent}")?;
                for v in nodes {
                    write!(w, " {}", v + 1)?;
                }
                writeln!(w)
            };
            for (i, e) in corners.iter().enumerate() {
                for &p in &e.physical {
                    line(w, 15, p, i + 1, &e.elements)?;
                }
            }
            for (i, e) in curves.iter().enumerate() {
                for &p in &e.physical {
                    for v in &e.elements {
                        line(w, 1, p, i + 1, v)?;
                    }
                }
            }
            for (i, e) in surfaces.iter().enumerate() {
                for &p in &e.physical {
                    for v in &e.elements {
                        line(w, 2, p, i + 1, v)?;
                    }
                }
            }
            for (i, e) in volumes.iter().enumerate() {
                for &p in &e.physical {
                    for v in &e.elements {
                        line(w, 4, p, i + 1, v)?;
                    }
                }
            }
            writeln!(w, "$EndElements")?;
            if !cell_fields.is_empty() {
                // Every copy of a tet (one per physical group) has its values.
                elem_tet = vec![NO_TET; n - count(&volumes)];
                for (e, ts) in volumes.iter().zip(&volume_tets) {
                    for _ in &e.physical {
                        elem_tet.extend_from_slice(ts);
                    }
                }
            }
        } else {
            let binary = format == MshFormat::V41Binary;
            let mut e = Emit {
                w: &mut *w,
                binary,
                first: true,
            };
            writeln!(e.w, "$Entities")?;
            for n in [corners.len(), curves.len(), surfaces.len(), volumes.len()] {
                e.size(n as u64)?;
            }
            e.nl()?;
            for (i, c) in corners.iter().enumerate() {
                let p = d.points[c.elements[0] as usize];
                e.int(i as i64 + 1)?;
                for x in p {
                    e.dbl(x)?;
                }
                e.size(c.physical.len() as u64)?;
                for &t in &c.physical {
                    e.int(t.into())?;
                }
                e.nl()?;
            }
            fn boxed<W: Write, E: Copy + IntoIterator<Item = u32>>(
                e: &mut Emit<W>,
                points: &[[f64; 3]],
                es: &[Entity<E>],
            ) -> std::io::Result<()> {
                for (i, ent) in es.iter().enumerate() {
                    let b = bounding_box(points, ent.elements.iter().flat_map(|x| *x));
                    e.int(i as i64 + 1)?;
                    for x in b {
                        e.dbl(x)?;
                    }
                    e.size(ent.physical.len() as u64)?;
                    for &t in &ent.physical {
                        e.int(t.into())?;
                    }
                    e.size(0)?;
                    e.nl()?;
                }
                Ok(())
            }
            boxed(&mut e, &d.points, &curves)?;
            boxed(&mut e, &d.points, &surfaces)?;
            boxed(&mut e, &d.points, &volumes)?;
            e.end()?;
            writeln!(e.w, "$EndEntities")?;
            // All nodes in one block on the first volume entity; Gmsh and
            // meshio look nodes up by tag, whatever entity they are on.
            writeln!(e.w, "$Nodes")?;
            for n in [1, np as u64, 1, np as u64] {
                e.size(n)?;
            }
            e.nl()?;
            e.int(3)?;
            e.int(1)?;
            e.int(0)?;
            e.size(np as u64)?;
            e.nl()?;
            for i in 1..=np {
                e.size(i as u64)?;
                e.nl()?;
            }
            for p in &d.points {
                for x in p {
                    e.dbl(*x)?;
                }
                e.nl()?;
            }
            e.end()?;
            writeln!(e.w, "$EndNodes")?;
            let n_elements = nt + d.triangles.len() + d.edges.len() + corners.len();
            let n_blocks = volumes.len() + surfaces.len() + curves.len() + corners.len();
            writeln!(e.w, "$Elements")?;
            for n in [n_blocks as u64, n_elements as u64, 1, n_elements as u64] {
                e.size(n)?;
            }
            e.nl()?;
            let mut tag = 0u64;
            let mut block = |e: &mut Emit<_>,
                             dim: i64,
                             ent: usize,
                             etype: i64,
                             elements: &mut dyn Iterator<Item = &[u32]>,
                             count: usize|
             -> std::io::Result<()> {
                e.int(dim)?;
                e.int(ent as i64)?;
                e.int(etype)?;
                e.size(count as u64)?;
                e.nl()?;
                for nodes in elements {
                    tag += 1;
                    e.size(tag)?;
                    for &v in nodes {
                        e.size(u64::from(v) + 1)?;
                    }
                    e.nl()?;
                }
                Ok(())
            };
            for (i, c) in corners.iter().enumerate() {
                block(
                    &mut e,
                    0,
                    i + 1,
                    15,
                    &mut std::iter::once(&c.elements[..]),
                    1,
                )?;
            }
            for (i, c) in curves.iter().enumerate() {
                let n = c.elements.len();
                block(
                    &mut e,
                    1,
                    i + 1,
                    1,
                    &mut c.elements.iter().map(|x| &x[..]),
                    n,
                )?;
            }
            for (i, c) in surfaces.iter().enumerate() {
                let n = c.elements.len();
                block(
                    &mut e,
                    2,
                    i + 1,
                    2,
                    &mut c.elements.iter().map(|x| &x[..]),
                    n,
                )?;
            }
            for (i, c) in volumes.iter().enumerate() {
                let n = c.elements.len();
                block(
                    &mut e,
                    3,
                    i + 1,
                    4,
                    &mut c.elements.iter().map(|x| &x[..]),
                    n,
                )?;
            }
            e.end()?;
            writeln!(e.w, "$EndElements")?;
            if !cell_fields.is_empty() {
                // Element tags run 1, 2, … in block order, the volumes last.
                elem_tet = vec![NO_TET; n_elements - nt];
                for ts in &volume_tets {
                    elem_tet.extend_from_slice(ts);
                }
            }
        }
        let binary = format == MshFormat::V41Binary;
        let nan = [f64::NAN; 9];
        let data_block = |w: &mut dyn Write,
                          section: &str,
                          f: &Field,
                          n: usize,
                          entry: &dyn Fn(usize) -> Option<usize>|
         -> std::io::Result<()> {
            writeln!(
                w,
                "${section}\n1\n\"{}\"\n1\n0.0\n3\n0\n{}\n{n}",
                f.name.replace('"', "'"),
                f.components
            )?;
            for i in 0..n {
                let values = match entry(i) {
                    Some(k) => f.entry(k),
                    None => &nan[..f.components],
                };
                // Tags 1..=n in order: meshio reads the values in file order
                // and checks that the binary tags are 1, 2, ….
                if binary {
                    w.write_all(&(i as i32 + 1).to_le_bytes())?;
                    for x in values {
                        w.write_all(&x.to_le_bytes())?;
                    }
                } else {
                    write!(w, "{}", i + 1)?;
                    for x in values {
                        write!(w, " {x:?}")?;
                    }
                    writeln!(w)?;
                }
            }
            if binary {
                writeln!(w)?;
            }
            writeln!(w, "$End{section}")
        };
        for f in &point_fields {
            data_block(w, "NodeData", f, np, &|i| Some(i))?;
        }
        for f in &cell_fields {
            data_block(w, "ElementData", f, elem_tet.len(), &|i| {
                (elem_tet[i] != NO_TET).then(|| elem_tet[i] as usize)
            })?;
        }
        Ok(())
    })
}
