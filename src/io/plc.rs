//! [`Plc`]: a piecewise linear complex — the surface input of a tetrahedral
//! mesher, in TetGen's model (Si, "TetGen, a Delaunay-based quality
//! tetrahedral mesh generator", ACM TOMS 41(2), 2015, §2): points, planar
//! polygonal facets with markers (a facet is one or more polygons, as in a
//! `.poly` file, possibly with hole points that cut parts of it away), volume
//! holes, and region seeds with an attribute and an optional maximum volume.
//!
//! [`Plc::validate`] checks what a mesher needs before it sees the input:
//! finite coordinates, indices in range, non-zero extent along every axis and
//! points that are not all coplanar (exact predicates), facets with three or
//! more distinct points that are planar and not degenerate, no duplicated or
//! overlapping facets, and a closed surface: every edge of a facet is shared
//! with at least one other facet (several at edges where inner walls meet).
//!
//! [`Plc::enclosed_volume`] computes the volume a mesher must fill, with the
//! divergence theorem, independently of how the facets are oriented — see
//! [`Plc::enclosed_volume`] for the cell decomposition that makes this work
//! with inner walls between regions, cavities, and hole seeds.
//!
//! Readers for `.poly`/`.smesh`, `.off`, `.stl` and triangles-only Medit
//! `.mesh` produce a `Plc` ([`Plc::read`] chooses by extension).

use super::IoError;
use glam::DVec3;
use std::collections::HashMap;
use std::path::Path;

/// One facet: a planar region bounded by polygons, with a boundary marker.
///
/// Polygons with three or more points are loops; a loop nested inside another
/// one of the same facet is an inner boundary. Polygons of two points are
/// segments embedded in the facet, of one point isolated vertices. A hole
/// point cuts away the part of the facet enclosed by the innermost loop that
/// contains it (TetGen's facet holes).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Facet {
    /// Polygons as 0-based point indices.
    pub polygons: Vec<Vec<u32>>,
    /// Hole points lying in the facet's plane.
    pub holes: Vec<[f64; 3]>,
    /// Boundary marker; it becomes the marker of the mesh faces on this facet.
    pub marker: i32,
}

/// A region seed: the cell of the surface that contains `point` gets
/// `attribute` as its region id, and optionally a maximum tet volume.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Region {
    /// A point strictly inside the region.
    pub point: [f64; 3],
    /// Region id given to the tets of the region.
    pub attribute: i32,
    /// Largest tet volume allowed in the region.
    pub max_volume: Option<f64>,
}

/// A piecewise linear complex: the surface description of a volume to mesh.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Plc {
    /// Point coordinates.
    pub points: Vec<[f64; 3]>,
    /// Facets.
    pub facets: Vec<Facet>,
    /// Volume hole seeds: the cell containing each is left empty.
    pub holes: Vec<[f64; 3]>,
    /// Region seeds.
    pub regions: Vec<Region>,
}

/// Why a PLC cannot be meshed. Point, facet, polygon, hole and region numbers
/// are 1-based, in the order of the [`Plc`]'s lists.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum PlcError {
    /// No facet at all.
    #[error("the surface has no facets")]
    NoFacets,
    /// A point coordinate is NaN or infinite.
    #[error("point {point} has a non-finite coordinate {coords:?}")]
    NonFinite {
        /// 1-based point number.
        point: usize,
        /// The coordinates.
        coords: [f64; 3],
    },
    /// A hole or region seed (or a facet hole) is not finite.
    #[error("{what} {index} has a non-finite coordinate {coords:?}")]
    NonFiniteSeed {
        /// "hole", "region" or "facet hole".
        what: &'static str,
        /// 1-based number.
        index: usize,
        /// The coordinates.
        coords: [f64; 3],
    },
    /// A region's maximum volume is not a positive finite number.
    #[error("region {region} has maximum volume {value}: it must be positive and finite")]
    BadMaxVolume {
        /// 1-based region number.
        region: usize,
        /// The value given.
        value: f64,
    },
    /// A facet refers to a point that does not exist.
    #[error("facet {facet} refers to point {index} but there are {n_points} points")]
    IndexOutOfRange {
        /// 1-based facet number.
        facet: usize,
        /// 1-based point number found.
        index: u64,
        /// Number of points.
        n_points: usize,
    },
    /// The points of the surface have no extent along one axis.
    #[error("the surface is flat: its points have zero extent along {axis}, so there is no volume to mesh")]
    Flat {
        /// 'x', 'y' or 'z'.
        axis: char,
    },
    /// All points of the surface lie in one (tilted) plane.
    #[error("all points of the surface lie in one plane: there is no volume to mesh")]
    Coplanar,
    /// A facet is degenerate: too few points, repeated points, zero area,
    /// not planar, or a hole outside it.
    #[error("facet {facet}: {reason}")]
    BadFacet {
        /// 1-based facet number.
        facet: usize,
        /// What is wrong with it.
        reason: String,
    },
    /// Two facets cover the same polygon.
    #[error("facet {facet} duplicates facet {other}")]
    DuplicateFacet {
        /// 1-based number of the later facet.
        facet: usize,
        /// 1-based number of the earlier one.
        other: usize,
    },
    /// An edge of a facet is shared with no other facet.
    #[error(
        "the surface is not closed: edge ({a}, {b}) of facet {facet} belongs to no other facet"
    )]
    Open {
        /// 1-based facet number.
        facet: usize,
        /// 1-based point numbers of the edge.
        a: u64,
        /// Second end point.
        b: u64,
    },
    /// An edge or a point of one facet pierces another facet.
    #[error("the surface intersects itself: facets {facet} and {other} intersect ({detail})")]
    Intersect {
        /// 1-based number of the piercing facet.
        facet: usize,
        /// 1-based number of the pierced facet.
        other: usize,
        /// How.
        detail: String,
    },
    /// Two facets leave an edge in the same direction: they overlap.
    #[error("facets {facet} and {other} overlap along edge ({a}, {b})")]
    Overlap {
        /// 1-based facet number.
        facet: usize,
        /// 1-based number of the other facet.
        other: usize,
        /// 1-based point numbers of the edge.
        a: u64,
        /// Second end point.
        b: u64,
    },
    /// A hole or region seed lies on a facet instead of strictly inside a cell.
    #[error("{what} {index} lies on facet {facet}: seeds must lie strictly inside a region")]
    SeedOnFacet {
        /// "hole" or "region".
        what: &'static str,
        /// 1-based seed number.
        index: usize,
        /// 1-based facet number.
        facet: usize,
    },
    /// The facets do not split space into cells consistently.
    #[error("the facets do not enclose volumes consistently ({0}); do they intersect?")]
    Inconsistent(String),
    /// After the holes are removed nothing is left to mesh.
    #[error("the surface encloses no volume once the holes are removed")]
    NothingEnclosed,
}

/// What [`Plc::analyze`] finds out about the volume a PLC encloses.
#[derive(Clone, Debug, PartialEq)]
pub struct PlcVolume {
    /// Volume of the bounded cells that contain no hole seed.
    pub enclosed: f64,
    /// Number of bounded cells (regions separated by facets), holes included.
    pub cells: usize,
    /// Number of bounded cells removed by hole seeds.
    pub hole_cells: usize,
    /// Bound on how much the volume of a mesh of this surface may differ from
    /// `enclosed` because facets are not exactly planar: the sum over facet
    /// pieces of area × largest distance of a vertex from the facet's plane.
    pub planarity_slack: f64,
}

impl Plc {
    /// Checks everything listed in the module documentation.
    pub fn validate(&self) -> Result<(), PlcError> {
        self.analyze().map(|_| ())
    }

    /// Volume enclosed by the surface, minus the cells that hole seeds empty.
    ///
    /// The facets cut space into cells; a mesher fills every bounded cell that
    /// contains no hole seed. The volume of a region bounded by closed
    /// surfaces is, by the divergence theorem, `-1/3 ∮ x·n dA` with `n` the
    /// normal pointing *into* the region, and for a planar piece `x·n` is
    /// constant, so each piece contributes `-1/3 (o·n) A`. The input facets
    /// carry no usable orientation (STL and `.poly` files orient them
    /// arbitrarily, and an inner wall has a region on either side), so the
    /// orientation comes from the geometry instead: each facet piece has two
    /// sides, and sorting the pieces around every edge by angle tells which
    /// sides face the same wedge of space; gluing those sides together gives
    /// closed *shells* whose normals all point into the cell they bound. A
    /// shell with a positive volume integral is the outer boundary of a
    /// bounded cell; a negative one is the boundary of a cavity seen from the
    /// cell around it, which a ray cast from the shell finds. A cell's
    /// volume is the sum over its shells. Hole seeds are located by ray
    /// casting as well, and their cells are left out.
    pub fn enclosed_volume(&self) -> Result<f64, PlcError> {
        Ok(self.analyze()?.enclosed)
    }

    /// Validates the PLC and decomposes space into the cells its facets
    /// bound (see [`Plc::enclosed_volume`]).
    pub fn analyze(&self) -> Result<PlcVolume, PlcError> {
        Analysis::run(self)
    }

    /// For each point, the index of the first point with exactly the same
    /// coordinates (itself when it is the first). `-0.0` equals `0.0`.
    pub fn coincident_point_map(&self) -> Vec<u32> {
        let mut first: HashMap<[u64; 3], u32> = HashMap::with_capacity(self.points.len());
        self.points
            .iter()
            .enumerate()
            .map(|(i, p)| {
                let key = p.map(|c| (c + 0.0).to_bits());
                *first.entry(key).or_insert(i as u32)
            })
            .collect()
    }

    /// Merges points with exactly equal coordinates (keeping the first of
    /// each), renumbers the facets and drops the points no longer used.
    pub fn merge_coincident_points(&mut self) {
        let canon = self.coincident_point_map();
        let mut new_index = vec![u32::MAX; self.points.len()];
        let mut points = Vec::with_capacity(self.points.len());
        for (i, &c) in canon.iter().enumerate() {
            if c as usize == i {
                new_index[i] = points.len() as u32;
                points.push(self.points[i]);
            }
        }
        for f in &mut self.facets {
            for poly in &mut f.polygons {
                for v in poly.iter_mut() {
                    if let Some(&c) = canon.get(*v as usize) {
                        *v = new_index[c as usize];
                    }
                }
            }
        }
        self.points = points;
    }

    /// A PLC whose facets are the given triangles with their markers.
    pub fn from_triangles(points: Vec<[f64; 3]>, triangles: &[([u32; 3], i32)]) -> Plc {
        Plc {
            points,
            facets: triangles
                .iter()
                .map(|&(t, marker)| Facet {
                    polygons: vec![t.to_vec()],
                    holes: Vec::new(),
                    marker,
                })
                .collect(),
            holes: Vec::new(),
            regions: Vec::new(),
        }
    }

    /// Reads a surface: TetGen `.poly` or `.smesh`, `.off`, `.stl` (ASCII or
    /// binary) or a Medit `.mesh` holding triangles only; by extension.
    pub fn read(path: &Path) -> Result<Plc, IoError> {
        let ext = path
            .extension()
            .and_then(|e| e.to_str())
            .unwrap_or("")
            .to_ascii_lowercase();
        match ext.as_str() {
            "poly" => super::poly::read_poly(path),
            "smesh" => super::poly::read_smesh(path),
            "off" => super::off::read(path),
            "stl" => super::stl::read(path),
            "mesh" => super::medit::read_surface(path),
            "" => Err(IoError::file(
                path,
                "has no extension; surfaces are read from .poly, .smesh, .off, .stl or .mesh",
            )),
            other => Err(IoError::file(
                path,
                format!(
                    "unknown surface extension '.{other}'; use .poly, .smesh, .off, .stl or .mesh"
                ),
            )),
        }
    }
}

// ---------------------------------------------------------------------------
// The analysis: validation, facet pieces, shells, cells.
// ---------------------------------------------------------------------------

/// A closed polygon of a facet, in the facet's 2-D projection.
struct Loop {
    /// Canonical point ids.
    verts: Vec<u32>,
    /// 2-D coordinates (the facet's projection) of `verts`.
    uv: Vec<[f64; 2]>,
    /// Area in 3-D.
    area: f64,
    /// Counter-clockwise seen from the facet normal.
    ccw: bool,
}

/// A facet in its plane.
struct FacetGeom {
    /// Unit normal.
    n: DVec3,
    /// A point of the plane (centered coordinates).
    o: DVec3,
    /// The coordinate axis dropped by the 2-D projection (the normal's largest).
    drop: usize,
    /// Largest distance of a vertex from the plane.
    deviation: f64,
    loops: Vec<Loop>,
}

/// The part of a facet between one loop and the loops directly inside it.
struct Piece {
    facet: usize,
    /// Index of the outer loop in the facet's loops.
    outer: usize,
    /// Indices of the inner loops.
    inner: Vec<usize>,
    area: f64,
    lo: DVec3,
    hi: DVec3,
}

/// One piece leaving an edge: `d` is the in-plane direction into the piece.
#[derive(Clone, Copy)]
struct Incidence {
    piece: u32,
    d: DVec3,
    from_segment: bool,
}

/// Each edge (sorted canonical point ids) with the pieces that leave it.
type EdgeIncidences = Vec<([u32; 2], Vec<Incidence>)>;

struct UnionFind(Vec<u32>);

impl UnionFind {
    fn new(n: usize) -> UnionFind {
        UnionFind((0..n as u32).collect())
    }
    fn find(&mut self, mut x: u32) -> u32 {
        while self.0[x as usize] != x {
            let p = self.0[x as usize];
            self.0[x as usize] = self.0[p as usize];
            x = p;
        }
        x
    }
    fn union(&mut self, a: u32, b: u32) {
        let (a, b) = (self.find(a), self.find(b));
        if a != b {
            self.0[a.max(b) as usize] = a.min(b);
        }
    }
}

/// Index of side `s` (+1 or -1) of piece `k`.
#[inline]
fn side(k: usize, s: f64) -> u32 {
    (2 * k + usize::from(s < 0.0)) as u32
}

/// 2-D coordinates of `p` with axis `drop` removed (cyclic order kept).
#[inline]
fn project(p: DVec3, drop: usize) -> [f64; 2] {
    match drop {
        0 => [p.y, p.z],
        1 => [p.z, p.x],
        _ => [p.x, p.y],
    }
}

/// Twice the area vector of a polygon (Newell's method).
fn newell(pts: impl Iterator<Item = DVec3> + Clone) -> DVec3 {
    let first = pts.clone().next();
    let mut n = DVec3::ZERO;
    let mut prev: Option<DVec3> = None;
    for p in pts {
        if let Some(q) = prev {
            n += q.cross(p);
        }
        prev = Some(p);
    }
    if let (Some(q), Some(f)) = (prev, first) {
        n += q.cross(f);
    }
    n
}

/// Even-odd point-in-polygon test.
fn inside_loop(uv: &[[f64; 2]], p: [f64; 2]) -> bool {
    let mut inside = false;
    let n = uv.len();
    for i in 0..n {
        let (a, b) = (uv[i], uv[(i + 1) % n]);
        if (a[1] > p[1]) != (b[1] > p[1]) {
            let x = a[0] + (p[1] - a[1]) * (b[0] - a[0]) / (b[1] - a[1]);
            if x > p[0] {
                inside = !inside;
            }
        }
    }
    inside
}

/// Distance from `p` to the closest edge of a loop.
fn loop_distance(uv: &[[f64; 2]], p: [f64; 2]) -> f64 {
    let n = uv.len();
    let mut best = f64::INFINITY;
    for i in 0..n {
        let (a, b) = (uv[i], uv[(i + 1) % n]);
        let (ex, ey) = (b[0] - a[0], b[1] - a[1]);
        let (px, py) = (p[0] - a[0], p[1] - a[1]);
        let len2 = ex * ex + ey * ey;
        let t = if len2 > 0.0 {
            ((px * ex + py * ey) / len2).clamp(0.0, 1.0)
        } else {
            0.0
        };
        let (dx, dy) = (px - t * ex, py - t * ey);
        best = best.min((dx * dx + dy * dy).sqrt());
    }
    best
}

/// A point strictly inside the region that the even-odd rule over `loops`
/// defines: a horizontal scanline between vertex heights, in the middle of
/// the widest interval it has inside.
fn interior_point(loops: &[&[[f64; 2]]]) -> Option<[f64; 2]> {
    let mut ys: Vec<f64> = loops.iter().flat_map(|l| l.iter().map(|p| p[1])).collect();
    ys.sort_by(f64::total_cmp);
    ys.dedup();
    let mut gaps: Vec<(f64, f64)> = ys
        .windows(2)
        .map(|w| (w[1] - w[0], 0.5 * (w[0] + w[1])))
        .collect();
    gaps.sort_by(|a, b| b.0.total_cmp(&a.0));
    for &(_, y) in gaps.iter().take(16) {
        let mut xs: Vec<f64> = Vec::new();
        for l in loops {
            let n = l.len();
            for i in 0..n {
                let (a, b) = (l[i], l[(i + 1) % n]);
                if (a[1] > y) != (b[1] > y) {
                    xs.push(a[0] + (y - a[1]) * (b[0] - a[0]) / (b[1] - a[1]));
                }
            }
        }
        xs.sort_by(f64::total_cmp);
        let best = xs
            .chunks_exact(2)
            .map(|w| (w[1] - w[0], 0.5 * (w[0] + w[1])))
            .max_by(|a, b| a.0.total_cmp(&b.0));
        if let Some((w, x)) = best {
            if w > 0.0 {
                return Some([x, y]);
            }
        }
    }
    None
}

/// Generic directions for ray casting (a fixed pseudo-random sequence, so
/// that results are reproducible).
fn ray_directions() -> impl Iterator<Item = DVec3> {
    let mut state: u64 = 0x9E37_79B9_7F4A_7C15;
    std::iter::from_fn(move || loop {
        let mut next = || {
            state = state
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            ((state >> 11) as f64 / (1u64 << 53) as f64) * 2.0 - 1.0
        };
        let v = DVec3::new(next(), next(), next());
        let l = v.length();
        if l > 0.2 && l <= 1.0 {
            return Some(v / l);
        }
    })
    .take(64)
}

enum Ray {
    /// Pieces hit, by increasing distance.
    Hits(Vec<(f64, usize)>),
    /// The ray grazes an edge or a plane: try another direction.
    Degenerate,
    /// The origin lies on this piece.
    OnPiece(usize),
}

struct Analysis {
    /// Points, moved so that the bounding box of the surface is centred at
    /// the origin (better conditioned volume sums).
    pts: Vec<DVec3>,
    /// The centre that was subtracted.
    center: DVec3,
    facets: Vec<FacetGeom>,
    pieces: Vec<Piece>,
    /// Distance tolerance for degenerate ray hits.
    tol: f64,
}

impl Analysis {
    fn run(plc: &Plc) -> Result<PlcVolume, PlcError> {
        let (pts, center, canon, diag) = check_points(plc)?;
        let tol = 1e-9 * diag;
        let mut a = Analysis {
            pts,
            center,
            facets: Vec::with_capacity(plc.facets.len()),
            pieces: Vec::new(),
            tol,
        };
        let mut segments: Vec<(usize, [u32; 2])> = Vec::new();
        for (fi, f) in plc.facets.iter().enumerate() {
            let (geom, segs) = a.facet_geometry(fi, f, &canon, diag)?;
            a.facets.push(geom);
            segments.extend(segs.into_iter().map(|s| (fi, s)));
        }
        let hole_loops = a.facet_holes(plc)?;
        a.build_pieces(&hole_loops)?;
        let incidences = a.edge_incidences(&segments, &hole_loops)?;
        a.check_intersections(&incidences)?;
        let mut sides = UnionFind::new(2 * a.pieces.len());
        a.glue_sides(&incidences, &mut sides)?;
        a.cells(plc, &mut sides, diag)
    }

    // ----- points --------------------------------------------------------------

    fn point(&self, v: u32) -> DVec3 {
        self.pts[v as usize]
    }

    // ----- facets --------------------------------------------------------------

    /// Checks one facet and computes its plane, loops and segments.
    fn facet_geometry(
        &self,
        fi: usize,
        f: &Facet,
        canon: &[u32],
        diag: f64,
    ) -> Result<(FacetGeom, Vec<[u32; 2]>), PlcError> {
        let bad = |reason: String| PlcError::BadFacet {
            facet: fi + 1,
            reason,
        };
        if f.polygons.is_empty() {
            return Err(bad("it has no polygon".into()));
        }
        let mut all: Vec<u32> = f
            .polygons
            .iter()
            .flatten()
            .map(|&v| canon[v as usize])
            .collect();
        all.sort_unstable();
        all.dedup();
        if all.len() < 3 {
            return Err(bad(format!(
                "it has {} distinct points; a facet needs at least 3",
                all.len()
            )));
        }
        // Loops and segments, in canonical ids.
        let mut raw_loops: Vec<(usize, Vec<u32>)> = Vec::new();
        let mut segs = Vec::new();
        for (pi, poly) in f.polygons.iter().enumerate() {
            let verts: Vec<u32> = poly.iter().map(|&v| canon[v as usize]).collect();
            let mut sorted = verts.clone();
            sorted.sort_unstable();
            if sorted.windows(2).any(|w| w[0] == w[1]) {
                return Err(bad(format!(
                    "polygon {} repeats a point (or two of its points coincide)",
                    pi + 1
                )));
            }
            match verts.len() {
                0 => return Err(bad(format!("polygon {} is empty", pi + 1))),
                1 => {}
                2 => segs.push([verts[0], verts[1]]),
                _ => raw_loops.push((pi, verts)),
            }
        }
        if raw_loops.is_empty() {
            return Err(bad(
                "it has no polygon of three or more points, so it bounds nothing".into(),
            ));
        }
        // The plane: normal of the largest loop, through the mean vertex.
        let normals: Vec<DVec3> = raw_loops
            .iter()
            .map(|(_, v)| newell(v.iter().map(|&i| self.point(i))))
            .collect();
        let big = (0..normals.len())
            .max_by(|&i, &j| normals[i].length().total_cmp(&normals[j].length()))
            .unwrap_or(0);
        let min_area2 = 1e-24 * diag * diag;
        for (k, nrm) in normals.iter().enumerate() {
            if nrm.length() <= min_area2 {
                return Err(bad(format!(
                    "polygon {} has zero area (its points are collinear)",
                    raw_loops[k].0 + 1
                )));
            }
        }
        let n = normals[big].normalize();
        let o = all.iter().map(|&v| self.point(v)).sum::<DVec3>() / all.len() as f64;
        let deviation = all
            .iter()
            .map(|&v| n.dot(self.point(v) - o).abs())
            .fold(0.0, f64::max);
        if deviation > 1e-6 * diag {
            return Err(bad(format!(
                "it is not planar: a point lies {deviation:.3e} from its plane"
            )));
        }
        let drop = (0..3)
            .max_by(|&i, &j| n[i].abs().total_cmp(&n[j].abs()))
            .unwrap_or(2);
        let loops = raw_loops
            .into_iter()
            .zip(&normals)
            .map(|((_, verts), nrm)| Loop {
                uv: verts
                    .iter()
                    .map(|&v| project(self.point(v), drop))
                    .collect(),
                verts,
                area: 0.5 * nrm.length(),
                ccw: nrm.dot(n) > 0.0,
            })
            .collect();
        Ok((
            FacetGeom {
                n,
                o,
                drop,
                deviation,
                loops,
            },
            segs,
        ))
    }

    /// For each facet, which of its loops hole points empty.
    fn facet_holes(&self, plc: &Plc) -> Result<Vec<Vec<bool>>, PlcError> {
        let center = self.center;
        let mut out = Vec::with_capacity(self.facets.len());
        for (fi, (f, g)) in plc.facets.iter().zip(&self.facets).enumerate() {
            let mut hole = vec![false; g.loops.len()];
            for (hi, h) in f.holes.iter().enumerate() {
                if !h.iter().all(|c| c.is_finite()) {
                    return Err(PlcError::NonFiniteSeed {
                        what: "facet hole",
                        index: hi + 1,
                        coords: *h,
                    });
                }
                let p = project(DVec3::from_array(*h) - center, g.drop);
                match innermost_loop(g, p) {
                    Some(l) => hole[l] = true,
                    None => {
                        return Err(PlcError::BadFacet {
                            facet: fi + 1,
                            reason: format!("hole {} lies outside all its polygons", hi + 1),
                        })
                    }
                }
            }
            out.push(hole);
        }
        Ok(out)
    }
}

/// The smallest loop of facet `g` that contains the 2-D point `p`.
fn innermost_loop(g: &FacetGeom, p: [f64; 2]) -> Option<usize> {
    (0..g.loops.len())
        .filter(|&l| inside_loop(&g.loops[l].uv, p))
        .min_by(|&i, &j| g.loops[i].area.total_cmp(&g.loops[j].area))
}

/// Checks coordinates, seeds, extent and coplanarity. Returns the points
/// centred on the bounding box of the surface, the centre, the map to
/// canonical (first coincident) points and the bounding box diagonal.
fn check_points(plc: &Plc) -> Result<(Vec<DVec3>, DVec3, Vec<u32>, f64), PlcError> {
    if let Some((i, p)) = plc
        .points
        .iter()
        .enumerate()
        .find(|(_, p)| !p.iter().all(|c| c.is_finite()))
    {
        return Err(PlcError::NonFinite {
            point: i + 1,
            coords: *p,
        });
    }
    for (what, list) in [("hole", &plc.holes)] {
        if let Some((i, h)) = list
            .iter()
            .enumerate()
            .find(|(_, h)| !h.iter().all(|c| c.is_finite()))
        {
            return Err(PlcError::NonFiniteSeed {
                what,
                index: i + 1,
                coords: *h,
            });
        }
    }
    for (i, r) in plc.regions.iter().enumerate() {
        if !r.point.iter().all(|c| c.is_finite()) {
            return Err(PlcError::NonFiniteSeed {
                what: "region",
                index: i + 1,
                coords: r.point,
            });
        }
        if let Some(v) = r.max_volume {
            if !(v.is_finite() && v > 0.0) {
                return Err(PlcError::BadMaxVolume {
                    region: i + 1,
                    value: v,
                });
            }
        }
    }
    if plc.facets.is_empty() {
        return Err(PlcError::NoFacets);
    }
    let np = plc.points.len();
    for (fi, f) in plc.facets.iter().enumerate() {
        for poly in &f.polygons {
            if let Some(&v) = poly.iter().find(|&&v| v as usize >= np) {
                return Err(PlcError::IndexOutOfRange {
                    facet: fi + 1,
                    index: v as u64 + 1,
                    n_points: np,
                });
            }
        }
    }
    let canon = plc.coincident_point_map();
    let mut used = vec![false; np];
    for f in &plc.facets {
        for &v in f.polygons.iter().flatten() {
            used[canon[v as usize] as usize] = true;
        }
    }
    let surface: Vec<DVec3> = (0..np)
        .filter(|&i| used[i])
        .map(|i| DVec3::from_array(plc.points[i]))
        .collect();
    let lo = surface.iter().fold(DVec3::INFINITY, |a, &p| a.min(p));
    let hi = surface.iter().fold(DVec3::NEG_INFINITY, |a, &p| a.max(p));
    for (axis, name) in ['x', 'y', 'z'].into_iter().enumerate() {
        if hi[axis] <= lo[axis] {
            return Err(PlcError::Flat { axis: name });
        }
    }
    if !spans_volume(&surface) {
        return Err(PlcError::Coplanar);
    }
    let center = 0.5 * (lo + hi);
    let diag = (hi - lo).length();
    let pts = plc
        .points
        .iter()
        .map(|p| DVec3::from_array(*p) - center)
        .collect();
    Ok((pts, center, canon, diag))
}

/// Whether some four of the points span a volume, with exact predicates.
fn spans_volume(p: &[DVec3]) -> bool {
    use crate::geom::{orient3d_sign, Orientation};
    let Some(&a) = p.first() else { return false };
    let Some(&b) = p.iter().find(|&&q| q != a) else {
        return false;
    };
    let collinear = |c: DVec3| {
        let o2 = |x: [f64; 2], y: [f64; 2], z: [f64; 2]| {
            robust::orient2d(
                robust::Coord { x: x[0], y: x[1] },
                robust::Coord { x: y[0], y: y[1] },
                robust::Coord { x: z[0], y: z[1] },
            ) == 0.0
        };
        (0..3).all(|d| o2(project(a, d), project(b, d), project(c, d)))
    };
    let Some(&c) = p.iter().find(|&&q| !collinear(q)) else {
        return false;
    };
    p.iter()
        .any(|&d| orient3d_sign(a, b, c, d) != Orientation::Zero)
}

impl Analysis {
    /// Splits every facet into pieces: each loop that no hole empties, minus
    /// the loops directly inside it.
    #[allow(clippy::needless_range_loop)] // loops index several parallel arrays
    fn build_pieces(&mut self, hole_loops: &[Vec<bool>]) -> Result<(), PlcError> {
        let mut seen: HashMap<(Vec<u32>, Vec<Vec<u32>>), usize> = HashMap::new();
        for (fi, g) in self.facets.iter().enumerate() {
            let bad = |reason: String| PlcError::BadFacet {
                facet: fi + 1,
                reason,
            };
            let nl = g.loops.len();
            // The parent of a loop is the smallest larger loop around it.
            let mut parent: Vec<Option<usize>> = vec![None; nl];
            if nl > 1 {
                for b in 0..nl {
                    let lb = &g.loops[b];
                    let ip = interior_point(&[&lb.uv]).ok_or_else(|| {
                        bad("a polygon has no interior (self-overlapping?)".into())
                    })?;
                    for a in 0..nl {
                        if a == b {
                            continue;
                        }
                        let la = &g.loops[a];
                        if la.area == lb.area && sorted(&la.verts) == sorted(&lb.verts) {
                            return Err(bad("two of its polygons coincide".into()));
                        }
                        if la.area > lb.area
                            && inside_loop(&la.uv, ip)
                            && parent[b].is_none_or(|p| g.loops[p].area > la.area)
                        {
                            parent[b] = Some(a);
                        }
                    }
                }
            }
            for l in 0..nl {
                if hole_loops[fi][l] {
                    continue;
                }
                let inner: Vec<usize> = (0..nl).filter(|&c| parent[c] == Some(l)).collect();
                let outer = &g.loops[l];
                let area = outer.area - inner.iter().map(|&c| g.loops[c].area).sum::<f64>();
                if area <= 1e-12 * outer.area {
                    return Err(bad(
                        "the polygons inside one of its polygons cover it completely".into(),
                    ));
                }
                let mut inner_keys: Vec<Vec<u32>> =
                    inner.iter().map(|&c| sorted(&g.loops[c].verts)).collect();
                inner_keys.sort();
                let key = (sorted(&outer.verts), inner_keys);
                if let Some(&other) = seen.get(&key) {
                    return Err(if other == fi {
                        bad("two of its polygons coincide".into())
                    } else {
                        PlcError::DuplicateFacet {
                            facet: fi + 1,
                            other: other + 1,
                        }
                    });
                }
                seen.insert(key, fi);
                let lo = outer
                    .verts
                    .iter()
                    .fold(DVec3::INFINITY, |a, &v| a.min(self.pts[v as usize]));
                let hi = outer
                    .verts
                    .iter()
                    .fold(DVec3::NEG_INFINITY, |a, &v| a.max(self.pts[v as usize]));
                self.pieces.push(Piece {
                    facet: fi,
                    outer: l,
                    inner,
                    area,
                    lo,
                    hi,
                });
            }
        }
        Ok(())
    }

    /// The loops of piece `k` (outer first) in 2-D.
    fn piece_loops(&self, k: usize) -> Vec<&[[f64; 2]]> {
        let p = &self.pieces[k];
        let g = &self.facets[p.facet];
        std::iter::once(p.outer)
            .chain(p.inner.iter().copied())
            .map(|l| g.loops[l].uv.as_slice())
            .collect()
    }

    /// For every edge, the pieces that leave it and in which direction.
    /// Checks that the surface is closed.
    fn edge_incidences(
        &self,
        segments: &[(usize, [u32; 2])],
        hole_loops: &[Vec<bool>],
    ) -> Result<EdgeIncidences, PlcError> {
        let mut edges: HashMap<[u32; 2], Vec<Incidence>> = HashMap::new();
        let mut piece_of: HashMap<(usize, usize), usize> = HashMap::new();
        for (k, p) in self.pieces.iter().enumerate() {
            piece_of.insert((p.facet, p.outer), k);
            let g = &self.facets[p.facet];
            for (is_outer, l) in
                std::iter::once((true, p.outer)).chain(p.inner.iter().map(|&l| (false, l)))
            {
                let lp = &g.loops[l];
                // The piece lies left of a counter-clockwise outer loop and
                // right of a counter-clockwise inner loop.
                let sign = if lp.ccw == is_outer { 1.0 } else { -1.0 };
                let m = lp.verts.len();
                for i in 0..m {
                    let (a, b) = (lp.verts[i], lp.verts[(i + 1) % m]);
                    let d = sign * g.n.cross(self.point(b) - self.point(a));
                    edges.entry(edge(a, b)).or_default().push(Incidence {
                        piece: k as u32,
                        d,
                        from_segment: false,
                    });
                }
            }
        }
        // Segments embedded in a piece: the piece leaves them on both sides.
        for &(fi, [a, b]) in segments {
            let g = &self.facets[fi];
            let mid = project(0.5 * (self.point(a) + self.point(b)), g.drop);
            if g.loops
                .iter()
                .any(|l| loop_distance(&l.uv, mid) <= self.tol)
            {
                continue; // an edge of a loop already
            }
            let Some(l) = innermost_loop(g, mid) else {
                continue; // dangling outside the facet: bounds nothing
            };
            if hole_loops[fi][l] {
                continue;
            }
            let k = piece_of[&(fi, l)];
            let d = g.n.cross(self.point(b) - self.point(a));
            for s in [1.0, -1.0] {
                edges.entry(edge(a, b)).or_default().push(Incidence {
                    piece: k as u32,
                    d: s * d,
                    from_segment: true,
                });
            }
        }
        let mut list: Vec<([u32; 2], Vec<Incidence>)> = edges.into_iter().collect();
        list.sort_unstable_by_key(|(e, _)| *e);
        for (e, incs) in list.iter_mut() {
            // A piece whose outer and inner loops (or two inner loops) share
            // an edge does not touch it: the two loop sides cancel.
            let mut count: HashMap<u32, usize> = HashMap::new();
            for i in incs.iter().filter(|i| !i.from_segment) {
                *count.entry(i.piece).or_default() += 1;
            }
            if let Some((&k, _)) = count.iter().find(|(_, &c)| c > 2) {
                return Err(PlcError::BadFacet {
                    facet: self.pieces[k as usize].facet + 1,
                    reason: format!(
                        "edge ({}, {}) appears more than twice among its polygons",
                        e[0] + 1,
                        e[1] + 1
                    ),
                });
            }
            incs.retain(|i| i.from_segment || count[&i.piece] == 1);
            if incs.len() == 1 {
                return Err(PlcError::Open {
                    facet: self.pieces[incs[0].piece as usize].facet + 1,
                    a: e[0] as u64 + 1,
                    b: e[1] as u64 + 1,
                });
            }
        }
        list.retain(|(_, incs)| !incs.is_empty());
        Ok(list)
    }

    /// Whether the 3-D point `q` (in the plane of piece `k`) lies strictly
    /// inside the piece, farther than the tolerance from its boundary.
    fn strictly_inside(&self, k: usize, q: DVec3) -> bool {
        let g = &self.facets[self.pieces[k].facet];
        let q = project(q, g.drop);
        let loops = self.piece_loops(k);
        loops.iter().all(|l| loop_distance(l, q) > self.tol)
            && loops.iter().filter(|l| inside_loop(l, q)).count() % 2 == 1
    }

    /// Finds an edge of one facet that pierces another facet's interior, or
    /// ends inside it (TetGen reports such input as self-intersecting).
    /// Candidate pairs come from a uniform grid over the pieces' boxes.
    /// Facets that overlap within one plane are found by `glue_sides` only
    /// where they share an edge.
    fn check_intersections(&self, edges: &[([u32; 2], Vec<Incidence>)]) -> Result<(), PlcError> {
        let np = self.pieces.len();
        let lo = self.pieces.iter().fold(DVec3::INFINITY, |a, p| a.min(p.lo));
        let hi = self
            .pieces
            .iter()
            .fold(DVec3::NEG_INFINITY, |a, p| a.max(p.hi));
        let ext = (hi - lo).max(DVec3::splat(self.tol));
        let h = (ext.x * ext.y * ext.z / np as f64).cbrt() * 1.5;
        let dims: [usize; 3] = [0, 1, 2].map(|a| ((ext[a] / h).ceil() as usize).clamp(1, 64));
        let cell = |x: DVec3| -> [usize; 3] {
            [0, 1, 2].map(|a| {
                (((x[a] - lo[a]) / ext[a] * dims[a] as f64).floor().max(0.0) as usize)
                    .min(dims[a] - 1)
            })
        };
        let grow = DVec3::splat(self.tol);
        let mut grid: Vec<Vec<u32>> = vec![Vec::new(); dims[0] * dims[1] * dims[2]];
        for (k, p) in self.pieces.iter().enumerate() {
            let (c0, c1) = (cell(p.lo - grow), cell(p.hi + grow));
            for i in c0[0]..=c1[0] {
                for j in c0[1]..=c1[1] {
                    for l in c0[2]..=c1[2] {
                        grid[(i * dims[1] + j) * dims[2] + l].push(k as u32);
                    }
                }
            }
        }
        let piece_verts: Vec<Vec<u32>> = (0..np)
            .map(|k| {
                let p = &self.pieces[k];
                let g = &self.facets[p.facet];
                let mut v: Vec<u32> = std::iter::once(p.outer)
                    .chain(p.inner.iter().copied())
                    .flat_map(|l| g.loops[l].verts.iter().copied())
                    .collect();
                v.sort_unstable();
                v
            })
            .collect();
        let mut stamp = vec![usize::MAX; np];
        for (ei, (e, incs)) in edges.iter().enumerate() {
            let (a, b) = (self.point(e[0]), self.point(e[1]));
            let (elo, ehi) = (a.min(b) - grow, a.max(b) + grow);
            let (c0, c1) = (cell(elo), cell(ehi));
            let own = self.pieces[incs[0].piece as usize].facet;
            for i in c0[0]..=c1[0] {
                for j in c0[1]..=c1[1] {
                    for l in c0[2]..=c1[2] {
                        for &k in &grid[(i * dims[1] + j) * dims[2] + l] {
                            let k = k as usize;
                            if stamp[k] == ei {
                                continue;
                            }
                            stamp[k] = ei;
                            let p = &self.pieces[k];
                            if piece_verts[k].binary_search(&e[0]).is_ok()
                                || piece_verts[k].binary_search(&e[1]).is_ok()
                                || ehi.cmplt(p.lo).any()
                                || elo.cmpgt(p.hi).any()
                            {
                                continue;
                            }
                            let g = &self.facets[p.facet];
                            let tolp = self.tol + g.deviation;
                            let (da, db) = (g.n.dot(a - g.o), g.n.dot(b - g.o));
                            let on_a = da.abs() <= tolp;
                            let on_b = db.abs() <= tolp;
                            let hit = if on_a && on_b {
                                None // in the plane: not tested here
                            } else if on_a || on_b {
                                let (v, q) = if on_a { (e[0], a) } else { (e[1], b) };
                                self.strictly_inside(k, q).then(|| {
                                    format!(
                                        "point {} of facet {} lies inside facet {}",
                                        v + 1,
                                        own + 1,
                                        p.facet + 1
                                    )
                                })
                            } else if (da > 0.0) != (db > 0.0) {
                                let q = a + (b - a) * (da / (da - db));
                                self.strictly_inside(k, q).then(|| {
                                    format!(
                                        "edge ({}, {}) of facet {} crosses facet {}",
                                        e[0] + 1,
                                        e[1] + 1,
                                        own + 1,
                                        p.facet + 1
                                    )
                                })
                            } else {
                                None
                            };
                            if let Some(detail) = hit {
                                return Err(PlcError::Intersect {
                                    facet: own + 1,
                                    other: p.facet + 1,
                                    detail,
                                });
                            }
                        }
                    }
                }
            }
        }
        Ok(())
    }

    /// Sorts the pieces around each edge by angle and glues the sides that
    /// face the same wedge of space.
    fn glue_sides(
        &self,
        edges: &[([u32; 2], Vec<Incidence>)],
        sides: &mut UnionFind,
    ) -> Result<(), PlcError> {
        for (e, incs) in edges {
            let u = (self.point(e[1]) - self.point(e[0])).normalize();
            let axis = (0..3)
                .min_by(|&i, &j| u[i].abs().total_cmp(&u[j].abs()))
                .unwrap_or(0);
            let e1 = u.cross(DVec3::AXES[axis]).normalize();
            let e2 = u.cross(e1);
            let mut around: Vec<(f64, f64, u32)> = incs
                .iter()
                .map(|i| {
                    let n = self.facets[self.pieces[i.piece as usize].facet].n;
                    // +1 when the piece's +n side faces increasing angles.
                    let s = if n.dot(u.cross(i.d)) >= 0.0 {
                        1.0
                    } else {
                        -1.0
                    };
                    (i.d.dot(e2).atan2(i.d.dot(e1)), s, i.piece)
                })
                .collect();
            around.sort_by(|a, b| a.0.total_cmp(&b.0));
            let m = around.len();
            for i in 0..m {
                let j = (i + 1) % m;
                let gap = if j == 0 {
                    around[0].0 + std::f64::consts::TAU - around[i].0
                } else {
                    around[j].0 - around[i].0
                };
                if gap < 1e-10 {
                    let (fa, fb) = (
                        self.pieces[around[i].2 as usize].facet,
                        self.pieces[around[j].2 as usize].facet,
                    );
                    return Err(PlcError::Overlap {
                        facet: fa.min(fb) + 1,
                        other: fa.max(fb) + 1,
                        a: e[0] as u64 + 1,
                        b: e[1] as u64 + 1,
                    });
                }
                let (_, si, ki) = around[i];
                let (_, sj, kj) = around[j];
                sides.union(side(ki as usize, si), side(kj as usize, -sj));
            }
        }
        Ok(())
    }

    /// A point strictly inside piece `k`, in centred 3-D coordinates.
    fn piece_interior(&self, k: usize) -> Option<DVec3> {
        let g = &self.facets[self.pieces[k].facet];
        let [a, b] = interior_point(&self.piece_loops(k))?;
        // Lift (a, b) back onto the plane n·(x - o) = 0.
        let (iu, iv) = match g.drop {
            0 => (1, 2),
            1 => (2, 0),
            _ => (0, 1),
        };
        let mut p = DVec3::ZERO;
        p[iu] = a;
        p[iv] = b;
        p[g.drop] = g.o[g.drop] - (g.n[iu] * (a - g.o[iu]) + g.n[iv] * (b - g.o[iv])) / g.n[g.drop];
        Some(p)
    }

    /// Casts a ray from `x0` along the unit vector `dir`, skipping piece `skip`.
    fn cast(&self, x0: DVec3, dir: DVec3, skip: Option<usize>) -> Ray {
        let mut hits = Vec::new();
        for (k, p) in self.pieces.iter().enumerate() {
            if Some(k) == skip || !ray_meets_box(x0, dir, p.lo, p.hi, self.tol) {
                continue;
            }
            let g = &self.facets[p.facet];
            let denom = g.n.dot(dir);
            let dist = g.n.dot(g.o - x0);
            if denom.abs() < 1e-9 {
                if dist.abs() <= self.tol {
                    return Ray::Degenerate; // the ray runs in the piece's plane
                }
                continue;
            }
            let t = dist / denom;
            if t < -self.tol {
                continue;
            }
            let q = project(x0 + t * dir, g.drop);
            let loops = self.piece_loops(k);
            if loops.iter().any(|l| loop_distance(l, q) <= self.tol) {
                return Ray::Degenerate; // through an edge or a vertex
            }
            let inside = loops.iter().filter(|l| inside_loop(l, q)).count() % 2 == 1;
            if !inside {
                continue;
            }
            if t <= self.tol {
                return Ray::OnPiece(k);
            }
            hits.push((t, k));
        }
        hits.sort_by(|a, b| a.0.total_cmp(&b.0));
        if hits.windows(2).any(|w| w[1].0 - w[0].0 <= self.tol) {
            return Ray::Degenerate;
        }
        Ray::Hits(hits)
    }

    /// Groups shells into cells, locates the seeds and adds up the volumes.
    fn cells(&self, plc: &Plc, sides: &mut UnionFind, diag: f64) -> Result<PlcVolume, PlcError> {
        let np = self.pieces.len();
        // Shells: components of glued sides, numbered densely.
        let mut shell_of_root: HashMap<u32, usize> = HashMap::new();
        let mut shell_of_side = vec![0usize; 2 * np];
        for (s, slot) in shell_of_side.iter_mut().enumerate() {
            let r = sides.find(s as u32);
            let n = shell_of_root.len();
            *slot = *shell_of_root.entry(r).or_insert(n);
        }
        let ns = shell_of_root.len();
        // Volume integral of each shell, normals into the cell it bounds.
        let mut vol = vec![0.0f64; ns];
        for (k, p) in self.pieces.iter().enumerate() {
            let g = &self.facets[p.facet];
            let moment = g.n.dot(g.o) * p.area / 3.0;
            vol[shell_of_side[side(k, 1.0) as usize]] -= moment;
            vol[shell_of_side[side(k, -1.0) as usize]] += moment;
        }
        let eps = 1e-14 * diag * diag * diag;
        if let Some(s) = (0..ns).find(|&s| vol[s].abs() <= eps) {
            let k = (0..np)
                .find(|&k| shell_of_side[2 * k] == s || shell_of_side[2 * k + 1] == s)
                .unwrap_or(0);
            return Err(PlcError::Inconsistent(format!(
                "a closed part of the surface through facet {} encloses no volume",
                self.pieces[k].facet + 1
            )));
        }
        // A side of the largest piece of each shell, to cast rays from.
        let mut start: Vec<Option<(usize, f64)>> = vec![None; ns];
        for (k, p) in self.pieces.iter().enumerate() {
            for s in [1.0, -1.0] {
                let sh = shell_of_side[side(k, s) as usize];
                if start[sh].is_none_or(|(b, _)| self.pieces[b].area < p.area) {
                    start[sh] = Some((k, s));
                }
            }
        }
        // Cells: a positive shell is the outer boundary of a bounded cell; a
        // negative one belongs to the cell around it, found by a ray walk.
        let mut cells = UnionFind::new(ns);
        let mut escapes = vec![false; ns];
        for sh in (0..ns).filter(|&s| vol[s] < 0.0) {
            let (k, s) = start[sh].expect("every shell has a side");
            let g = &self.facets[self.pieces[k].facet];
            let x0 = self.piece_interior(k).ok_or_else(|| {
                PlcError::Inconsistent(format!(
                    "facet {} has no interior point",
                    self.pieces[k].facet + 1
                ))
            })?;
            let mut done = false;
            for gdir in ray_directions() {
                let dir = (s * g.n + 0.6 * gdir).normalize();
                let hits = match self.cast(x0, dir, Some(k)) {
                    Ray::Hits(h) => h,
                    Ray::Degenerate | Ray::OnPiece(_) => continue,
                };
                // Walk along the ray keeping, for every shell crossed, the
                // change of its winding number; while all are zero the ray is
                // still in the cell it started in, and each side it meets
                // there bounds that cell.
                let mut winding: HashMap<usize, i32> = HashMap::new();
                let mut nonzero = 0usize;
                for (_, kh) in hits {
                    let nh = self.facets[self.pieces[kh].facet].n;
                    let facing = if nh.dot(dir) > 0.0 { -1.0 } else { 1.0 };
                    let near = shell_of_side[side(kh, facing) as usize];
                    let far = shell_of_side[side(kh, -facing) as usize];
                    if nonzero == 0 {
                        cells.union(sh as u32, near as u32);
                    }
                    for (x, dw) in [(near, -1), (far, 1)] {
                        let w = winding.entry(x).or_insert(0);
                        let was = *w != 0;
                        *w += dw;
                        match (was, *w != 0) {
                            (false, true) => nonzero += 1,
                            (true, false) => nonzero -= 1,
                            _ => {}
                        }
                    }
                }
                escapes[sh] = nonzero == 0;
                done = true;
                break;
            }
            if !done {
                return Err(PlcError::Inconsistent(
                    "every ray from a cavity grazes an edge".into(),
                ));
            }
        }
        // Each cell: at most one positive shell, and bounded exactly when it
        // has one.
        let mut outer_of_cell: HashMap<u32, usize> = HashMap::new();
        let mut escaping: HashMap<u32, bool> = HashMap::new();
        for sh in 0..ns {
            let c = cells.find(sh as u32);
            if vol[sh] > 0.0 && outer_of_cell.insert(c, sh).is_some() {
                return Err(PlcError::Inconsistent(
                    "a cell has two outer boundaries".into(),
                ));
            }
            *escaping.entry(c).or_default() |= escapes[sh];
        }
        for (c, esc) in &escaping {
            if *esc == outer_of_cell.contains_key(c) {
                return Err(PlcError::Inconsistent(if *esc {
                    "a bounded cell reaches infinity".into()
                } else {
                    "a cavity lies in no cell".into()
                }));
            }
        }
        let mut cell_volume: HashMap<u32, f64> = HashMap::new();
        for (sh, &v) in vol.iter().enumerate() {
            let c = cells.find(sh as u32);
            if outer_of_cell.contains_key(&c) {
                *cell_volume.entry(c).or_default() += v;
            }
        }
        if let Some(v) = cell_volume.values().find(|&&v| v <= eps) {
            return Err(PlcError::Inconsistent(format!(
                "a cell has volume {v:e} after its cavities are removed"
            )));
        }
        // Hole seeds.
        let mut emptied: Vec<u32> = Vec::new();
        for (i, h) in plc.holes.iter().enumerate() {
            let x = DVec3::from_array(*h) - self.center;
            if let Some(c) = self.locate(x, "hole", i, &shell_of_side, &mut cells)? {
                if outer_of_cell.contains_key(&c) {
                    emptied.push(c);
                }
            }
        }
        for (i, r) in plc.regions.iter().enumerate() {
            let x = DVec3::from_array(r.point) - self.center;
            self.locate(x, "region", i, &shell_of_side, &mut cells)?;
        }
        emptied.sort_unstable();
        emptied.dedup();
        let enclosed: f64 = cell_volume
            .iter()
            .filter(|(c, _)| !emptied.contains(c))
            .map(|(_, v)| v)
            .sum();
        if cell_volume.len() == emptied.len() {
            return Err(PlcError::NothingEnclosed);
        }
        let planarity_slack = self
            .pieces
            .iter()
            .map(|p| p.area * self.facets[p.facet].deviation)
            .sum();
        Ok(PlcVolume {
            enclosed,
            cells: cell_volume.len(),
            hole_cells: emptied.len(),
            planarity_slack,
        })
    }

    /// The cell containing `x` (`None`: the unbounded one).
    fn locate(
        &self,
        x: DVec3,
        what: &'static str,
        index: usize,
        shell_of_side: &[usize],
        cells: &mut UnionFind,
    ) -> Result<Option<u32>, PlcError> {
        for dir in ray_directions() {
            match self.cast(x, dir, None) {
                Ray::Degenerate => continue,
                Ray::OnPiece(k) => {
                    return Err(PlcError::SeedOnFacet {
                        what,
                        index: index + 1,
                        facet: self.pieces[k].facet + 1,
                    })
                }
                Ray::Hits(h) => {
                    let Some(&(_, k)) = h.first() else {
                        return Ok(None);
                    };
                    let n = self.facets[self.pieces[k].facet].n;
                    let facing = if n.dot(dir) > 0.0 { -1.0 } else { 1.0 };
                    return Ok(Some(
                        cells.find(shell_of_side[side(k, facing) as usize] as u32),
                    ));
                }
            }
        }
        Err(PlcError::Inconsistent(format!(
            "{what} {} cannot be located: every ray from it grazes an edge",
            index + 1
        )))
    }
}

/// Whether the ray `x0 + t dir`, `t >= 0`, meets the box `[lo, hi]` grown by `tol`.
fn ray_meets_box(x0: DVec3, dir: DVec3, lo: DVec3, hi: DVec3, tol: f64) -> bool {
    let (mut t0, mut t1) = (0.0f64, f64::INFINITY);
    for a in 0..3 {
        let (l, h) = (lo[a] - tol, hi[a] + tol);
        if dir[a] == 0.0 {
            if x0[a] < l || x0[a] > h {
                return false;
            }
        } else {
            let (ta, tb) = ((l - x0[a]) / dir[a], (h - x0[a]) / dir[a]);
            t0 = t0.max(ta.min(tb));
            t1 = t1.min(ta.max(tb));
            if t0 > t1 {
                return false;
            }
        }
    }
    true
}

fn sorted(v: &[u32]) -> Vec<u32> {
    let mut s = v.to_vec();
    s.sort_unstable();
    s
}

#[inline]
fn edge(a: u32, b: u32) -> [u32; 2] {
    if a < b {
        [a, b]
    } else {
        [b, a]
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// An axis-aligned box as six quadrilaterals, marker = face number; the
    /// face orientations are deliberately mixed.
    fn add_box(plc: &mut Plc, lo: [f64; 3], hi: [f64; 3]) {
        let base = plc.points.len() as u32;
        for i in 0..8 {
            plc.points.push([
                if i & 1 == 0 { lo[0] } else { hi[0] },
                if i & 2 == 0 { lo[1] } else { hi[1] },
                if i & 4 == 0 { lo[2] } else { hi[2] },
            ]);
        }
        let quads = [
            [0, 2, 3, 1],
            [4, 5, 7, 6],
            [0, 4, 5, 1], // inward
            [2, 6, 7, 3],
            [0, 2, 6, 4], // inward
            [1, 3, 7, 5],
        ];
        for (m, q) in quads.iter().enumerate() {
            plc.facets.push(Facet {
                polygons: vec![q.iter().map(|&v| base + v).collect()],
                holes: Vec::new(),
                marker: m as i32 + 1,
            });
        }
    }

    fn unit_cube() -> Plc {
        let mut p = Plc::default();
        add_box(&mut p, [0.0; 3], [1.0; 3]);
        p
    }

    #[test]
    fn cube_encloses_one() {
        let v = unit_cube().analyze().unwrap();
        assert!((v.enclosed - 1.0).abs() < 1e-14, "{v:?}");
        assert_eq!(v.cells, 1);
    }

    #[test]
    fn cube_from_triangles_encloses_one() {
        let c = unit_cube();
        let mut tris = Vec::new();
        for f in &c.facets {
            let q = &f.polygons[0];
            tris.push(([q[0], q[1], q[2]], f.marker));
            tris.push(([q[0], q[2], q[3]], f.marker));
        }
        let t = Plc::from_triangles(c.points.clone(), &tris);
        assert!((t.enclosed_volume().unwrap() - 1.0).abs() < 1e-14);
    }

    #[test]
    fn nested_box_is_a_second_cell_unless_a_hole_empties_it() {
        let mut p = unit_cube();
        add_box(&mut p, [0.25; 3], [0.75; 3]);
        let v = p.analyze().unwrap();
        assert_eq!(v.cells, 2);
        assert!((v.enclosed - 1.0).abs() < 1e-14, "{v:?}");
        p.holes.push([0.5; 3]);
        let v = p.analyze().unwrap();
        assert_eq!(v.hole_cells, 1);
        assert!((v.enclosed - (1.0 - 0.125)).abs() < 1e-14, "{v:?}");
        // A hole outside everything changes nothing.
        p.holes[0] = [5.0, 5.0, 5.0];
        assert!((p.enclosed_volume().unwrap() - 1.0).abs() < 1e-14);
        // A hole in the outer cell leaves the inner box.
        p.holes[0] = [0.1, 0.1, 0.1];
        assert!((p.enclosed_volume().unwrap() - 0.125).abs() < 1e-14);
    }

    #[test]
    fn inner_wall_splits_a_box_into_two_cells() {
        // Box [0,2]x[0,1]x[0,1] as two unit cubes sharing the face x = 1.
        let mut p = Plc::default();
        for i in 0..12 {
            p.points
                .push([(i % 3) as f64, ((i / 3) % 2) as f64, (i / 6) as f64]);
        }
        let id = |x: u32, y: u32, z: u32| x + 3 * y + 6 * z;
        let mut quad = |q: [u32; 4], m: i32| {
            p.facets.push(Facet {
                polygons: vec![q.to_vec()],
                holes: vec![],
                marker: m,
            })
        };
        for x in 0..2 {
            quad(
                [id(x, 0, 0), id(x + 1, 0, 0), id(x + 1, 1, 0), id(x, 1, 0)],
                1,
            );
            quad(
                [id(x, 0, 1), id(x + 1, 0, 1), id(x + 1, 1, 1), id(x, 1, 1)],
                2,
            );
            quad(
                [id(x, 0, 0), id(x + 1, 0, 0), id(x + 1, 0, 1), id(x, 0, 1)],
                3,
            );
            quad(
                [id(x, 1, 0), id(x + 1, 1, 0), id(x + 1, 1, 1), id(x, 1, 1)],
                4,
            );
        }
        for x in 0..3 {
            quad([id(x, 0, 0), id(x, 1, 0), id(x, 1, 1), id(x, 0, 1)], 5);
        }
        let v = p.analyze().unwrap();
        assert_eq!(v.cells, 2);
        assert!((v.enclosed - 2.0).abs() < 1e-14, "{v:?}");
        p.holes.push([1.5, 0.5, 0.5]);
        assert!((p.enclosed_volume().unwrap() - 1.0).abs() < 1e-14);
    }

    #[test]
    fn disjoint_boxes_add_up() {
        let mut p = unit_cube();
        add_box(&mut p, [2.0, 0.0, 0.0], [3.0, 2.0, 1.0]);
        assert!((p.enclosed_volume().unwrap() - 3.0).abs() < 1e-14);
    }

    #[test]
    fn open_box_is_rejected() {
        let mut p = unit_cube();
        p.facets.pop();
        assert!(matches!(p.validate(), Err(PlcError::Open { .. })));
    }

    #[test]
    fn duplicated_facet_is_rejected() {
        let mut p = unit_cube();
        let f = p.facets[2].clone();
        p.facets.push(f);
        assert_eq!(
            p.validate(),
            Err(PlcError::DuplicateFacet { facet: 7, other: 3 })
        );
    }

    #[test]
    fn degenerate_inputs_are_rejected() {
        let mut p = unit_cube();
        p.points[3][1] = f64::NAN;
        assert!(matches!(
            p.validate(),
            Err(PlcError::NonFinite { point: 4, .. })
        ));

        let mut p = unit_cube();
        p.facets[1].polygons[0][2] = 99;
        assert!(matches!(
            p.validate(),
            Err(PlcError::IndexOutOfRange {
                facet: 2,
                index: 100,
                ..
            })
        ));

        let mut p = unit_cube();
        for q in &mut p.points {
            q[2] = 0.0;
        }
        assert_eq!(p.validate(), Err(PlcError::Flat { axis: 'z' }));

        // All points on the tilted plane x + y + z = 1.5.
        let mut p = unit_cube();
        for q in &mut p.points {
            q[2] = 1.5 - q[0] - q[1];
        }
        assert_eq!(p.validate(), Err(PlcError::Coplanar));

        let mut p = unit_cube();
        p.facets[0].polygons[0] = vec![0, 2, 2, 1];
        assert!(matches!(
            p.validate(),
            Err(PlcError::BadFacet { facet: 1, .. })
        ));

        let mut p = unit_cube();
        p.points[7] = [1.0, 1.0, 1.3];
        assert!(matches!(p.validate(), Err(PlcError::BadFacet { .. })));
    }

    #[test]
    fn interpenetrating_boxes_are_rejected() {
        let mut p = unit_cube();
        add_box(&mut p, [0.5; 3], [1.5; 3]);
        let e = p.validate().unwrap_err();
        assert!(matches!(e, PlcError::Intersect { .. }), "{e}");
        // A box poking through another's face, sharing no point with it.
        let mut p = unit_cube();
        add_box(&mut p, [0.25, 0.25, 0.5], [0.75, 0.75, 1.5]);
        let e = p.validate().unwrap_err();
        assert!(matches!(e, PlcError::Intersect { .. }), "{e}");
    }

    #[test]
    fn seeds_on_a_facet_are_rejected() {
        let mut p = unit_cube();
        p.holes.push([0.5, 0.5, 1.0]);
        assert!(matches!(p.validate(), Err(PlcError::SeedOnFacet { .. })));
    }

    #[test]
    fn merging_coincident_points_renumbers_facets() {
        let c = unit_cube();
        let mut tris = Vec::new();
        let mut points = Vec::new();
        for f in &c.facets {
            let q = &f.polygons[0];
            for t in [[q[0], q[1], q[2]], [q[0], q[2], q[3]]] {
                let b = points.len() as u32;
                points.extend(t.iter().map(|&v| c.points[v as usize]));
                tris.push(([b, b + 1, b + 2], 0));
            }
        }
        let mut p = Plc::from_triangles(points, &tris);
        assert_eq!(p.points.len(), 36);
        p.merge_coincident_points();
        assert_eq!(p.points.len(), 8);
        assert!((p.enclosed_volume().unwrap() - 1.0).abs() < 1e-14);
    }
}
