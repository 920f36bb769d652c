//! [`PlcError`]: why a PLC cannot be meshed.

/// `" (line N)"`, or nothing without a line.
fn on_line(line: Option<usize>) -> String {
    line.map_or_else(String::new, |l| format!(" (line {l})"))
}

impl PlcError {
    /// The error with the lines of its seeds filled in from `lines` (the
    /// lines the seeds were read from; see [`crate::io::SeedLines`]).
    pub(crate) fn with_seed_lines(self, lines: &super::SeedLines) -> PlcError {
        let at = |v: &[usize], i: usize| i.checked_sub(1).and_then(|i| v.get(i)).copied();
        match self {
            PlcError::SeedOnFacet {
                what,
                index,
                facet,
                line,
            } => PlcError::SeedOnFacet {
                what,
                index,
                facet,
                line: line.or_else(|| {
                    at(
                        if what == "hole" {
                            &lines.holes
                        } else {
                            &lines.regions
                        },
                        index,
                    )
                }),
            },
            PlcError::SeedOutside {
                index,
                coords,
                line,
            } => PlcError::SeedOutside {
                index,
                coords,
                line: line.or_else(|| at(&lines.regions, index)),
            },
            PlcError::SeedInHole {
                index,
                hole,
                line,
                hole_line,
            } => PlcError::SeedInHole {
                index,
                hole,
                line: line.or_else(|| at(&lines.regions, index)),
                hole_line: hole_line.or_else(|| at(&lines.holes, hole)),
            },
            e => e,
        }
    }
}

/// Why a PLC cannot be meshed. Point, facet, polygon, hole and region numbers
/// are 1-based, in the order of the [`crate::io::Plc`]'s lists.
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
    #[error("{what} {index}{} lies on facet {facet}: seeds must lie strictly inside a region", on_line(*.line))]
    SeedOnFacet {
        /// "hole" or "region".
        what: &'static str,
        /// 1-based seed number.
        index: usize,
        /// 1-based facet number.
        facet: usize,
        /// 1-based line of the seed in the file it was read from, if known
        /// ([`crate::io::SeedLines`]).
        line: Option<usize>,
    },
    /// A region seed lies in no bounded cell: outside the surface.
    #[error("region {index}{} has its seed at {coords:?}, outside the surface: a region seed must lie inside the volume (TetGen crashes on it)", on_line(*.line))]
    SeedOutside {
        /// 1-based region number.
        index: usize,
        /// The seed.
        coords: [f64; 3],
        /// 1-based line of the seed in the file it was read from, if known.
        line: Option<usize>,
    },
    /// A region seed lies in a cell that a hole seed empties.
    #[error(
        "region {index}{} has its seed in the cell that hole {hole}{} empties: the region would vanish",
        on_line(*.line),
        on_line(*.hole_line)
    )]
    SeedInHole {
        /// 1-based region number.
        index: usize,
        /// 1-based number of the hole seed of the same cell.
        hole: usize,
        /// 1-based line of the region seed in its file, if known.
        line: Option<usize>,
        /// 1-based line of the hole seed in its file, if known.
        hole_line: Option<usize>,
    },
    /// The facets do not split space into cells consistently.
    #[error("the facets do not enclose volumes consistently ({0}); do they intersect?")]
    Inconsistent(String),
    /// After the holes are removed nothing is left to mesh.
    #[error("the surface encloses no volume once the holes are removed")]
    NothingEnclosed,
}
