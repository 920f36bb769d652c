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

mod error;
mod geometry;
mod locate;
mod validate;
mod volume;

pub use error::PlcError;

use crate::io::IoError;
use std::collections::HashMap;
use std::path::Path;
use validate::Analysis;

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
    /// The lines of the text file the seeds were read from, so that the
    /// seed errors of [`Plc::analyze`] name them; empty for a PLC built in
    /// code or read from a format without seeds.
    pub seed_lines: SeedLines,
}

/// The 1-based lines of a `.poly`/`.smesh` file that hold the seeds of a
/// [`Plc`]: `holes[i]` is the line of `plc.holes[i]`, `regions[i]` that of
/// `plc.regions[i]`. A list shorter than its seeds (e.g. empty) leaves the
/// seeds past its end without a line.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct SeedLines {
    /// Line of each volume hole seed.
    pub holes: Vec<usize>,
    /// Line of each region seed.
    pub regions: Vec<usize>,
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
    /// volume is the sum over its shells. Hole and region seeds are then
    /// located exactly (crossing parity with exact orientation signs, see
    /// `locate.rs`); the cells of hole seeds are left out.
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
            seed_lines: SeedLines::default(),
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
            "poly" => crate::io::poly::read_poly(path),
            "smesh" => crate::io::poly::read_smesh(path),
            "off" => crate::io::off::read(path),
            "stl" => crate::io::stl::read(path),
            "mesh" => crate::io::medit::read_surface(path),
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

#[cfg(test)]
mod tests;
