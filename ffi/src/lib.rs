//! Minimal bindings to TetGen 1.5 (Hang Si, WIAS Berlin; <https://tetgen.org>)
//! as packaged by Debian (`libtet1.5-dev`), through a small C++ shim.
//!
//! TetGen is AGPL-3: code that links this crate is bound by that licence.
//!
//! Two layers:
//!
//! * [`raw`]: the shim's `extern "C"` functions and `#[repr(C)]` structs,
//!   one-to-one. Calling them is `unsafe` (pointers and lengths must agree,
//!   indices must be in range) and not thread-safe.
//! * [`tetrahedralize`]: a thin safe layer over plain arrays. It checks every
//!   length, index and number before TetGen sees them (so that TetGen never
//!   reads out of bounds), serialises all calls behind one global mutex
//!   (TetGen keeps global state for its exact predicates), turns TetGen's
//!   error codes into [`Error`], and copies the output into owned vectors.
//!
//! What the safe layer does *not* guarantee: TetGen still contains `assert`s
//! that abort the process on some degenerate geometry. The layer rejects the
//! one known case (all points coplanar, found with exact predicates); callers
//! should validate the geometry of their input as well (the `tetrefine` crate
//! checks closedness, facet planarity and duplicates before calling).
//! An input that TetGen cannot mesh may also come back as `Ok` with zero
//! tetrahedra: check the result.

#![warn(missing_docs)]

use std::ffi::CString;
use std::fmt;
use std::sync::{Mutex, MutexGuard};

/// The shim's C interface (see `src/shim.cpp`).
pub mod raw {
    use std::os::raw::{c_char, c_int, c_void};

    /// Input arrays for [`tg_tetrahedralize`]; null pointers and zero counts
    /// for what is absent. Indices are 0-based.
    #[repr(C)]
    #[derive(Debug)]
    pub struct RawInput {
        /// Number of points.
        pub npoints: c_int,
        /// `3 * npoints` coordinates.
        pub points: *const f64,
        /// Number of facets (PLC input).
        pub nfacets: c_int,
        /// Polygons per facet (`nfacets` entries).
        pub facet_polygon_counts: *const c_int,
        /// Vertices per polygon, over all facets in order.
        pub polygon_vertex_counts: *const c_int,
        /// Vertex indices of all polygons, concatenated.
        pub polygon_vertices: *const c_int,
        /// One marker per facet, or null.
        pub facet_markers: *const c_int,
        /// Hole points per facet (`nfacets` entries), or null.
        pub facet_hole_counts: *const c_int,
        /// `3 *` total facet holes coordinates.
        pub facet_holes: *const f64,
        /// Number of volume hole seeds.
        pub nholes: c_int,
        /// `3 * nholes` coordinates.
        pub holes: *const f64,
        /// Number of region seeds.
        pub nregions: c_int,
        /// `5 * nregions` values: x, y, z, attribute, maximum volume.
        pub regions: *const f64,
        /// Number of input tetrahedra (mesh input, `-r`).
        pub ntets: c_int,
        /// `4 * ntets` vertex indices.
        pub tets: *const c_int,
        /// One attribute per tet, or null.
        pub tet_attributes: *const f64,
        /// One target edge length per point (`pointmtrlist`, used by `-m`), or null.
        pub point_sizes: *const f64,
        /// Number of input boundary triangles (mesh input).
        pub ntrifaces: c_int,
        /// `3 * ntrifaces` vertex indices.
        pub trifaces: *const c_int,
        /// One marker per triangle.
        pub trifacemarkers: *const c_int,
    }

    /// Output arrays, owned by the C++ side until [`tg_output_free`].
    #[repr(C)]
    #[derive(Debug)]
    pub struct RawOutput {
        /// The owning `tetgenio`.
        pub io: *mut c_void,
        /// Index of the first point in the output lists (0 or 1).
        pub firstnumber: c_int,
        /// Number of points.
        pub npoints: c_int,
        /// `3 * npoints` coordinates.
        pub points: *const f64,
        /// Number of tetrahedra.
        pub ntets: c_int,
        /// Nodes per tetrahedron (4, or 10 with `-o2`).
        pub ncorners: c_int,
        /// `ncorners * ntets` point indices.
        pub tets: *const c_int,
        /// Attributes per tetrahedron.
        pub nattributes: c_int,
        /// `nattributes * ntets` values.
        pub tet_attributes: *const f64,
        /// Number of output triangles (boundary and facet faces).
        pub ntrifaces: c_int,
        /// `3 * ntrifaces` point indices.
        pub trifaces: *const c_int,
        /// One marker per triangle (may be null).
        pub trifacemarkers: *const c_int,
    }

    extern "C" {
        /// Runs `tetrahedralize(switches, in, out)`. Returns 0 and fills `out`
        /// (free it with [`tg_output_free`]), or TetGen's error code: 1 out of
        /// memory, 2 internal error, 3 self-intersection, 4 very small feature,
        /// 5 very close facets, 10 input error; -1 for any other C++ exception.
        ///
        /// # Safety
        /// Every pointer must be valid for the counts given and indices in
        /// range; `switches` must be NUL-terminated. Not thread-safe.
        pub fn tg_tetrahedralize(
            switches: *const c_char,
            input: *const RawInput,
            out: *mut RawOutput,
        ) -> c_int;

        /// Frees the output of a successful [`tg_tetrahedralize`].
        ///
        /// # Safety
        /// `out` must come from a successful call and not be freed twice
        /// (it is zeroed, so freeing a zeroed struct again is harmless).
        pub fn tg_output_free(out: *mut RawOutput);
    }
}

/// Why a call failed.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum Error {
    /// The arrays are inconsistent or hold values TetGen must not see.
    InvalidInput(String),
    /// TetGen stopped with this error code (see [`Error::message`]).
    Tetgen(i32),
}

impl Error {
    /// A sentence for the user.
    pub fn message(&self) -> String {
        match self {
            Error::InvalidInput(m) => m.clone(),
            Error::Tetgen(code) => tetgen_message(*code).to_string(),
        }
    }
}

/// The meaning of TetGen's `terminatetetgen` codes (TetGen 1.5 source).
pub fn tetgen_message(code: i32) -> &'static str {
    match code {
        1 => "TetGen ran out of memory (error 1)",
        2 => "TetGen stopped on an internal error (error 2): the input may be degenerate",
        3 => "TetGen found a self-intersection (error 3): two input facets cross or overlap",
        4 => "TetGen found a very small input feature (error 4): points or edges closer than its tolerance (-T)",
        5 => "TetGen found two very close input facets (error 5)",
        10 => "TetGen rejected the input (error 10)",
        -1 => "TetGen threw an unexpected C++ exception",
        _ => "TetGen stopped with an unknown error code",
    }
}

impl fmt::Display for Error {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(&self.message())
    }
}

impl std::error::Error for Error {}

/// Input as flat arrays with 0-based indices; leave absent parts empty/`None`.
///
/// A PLC uses `points`, the facet arrays, `holes` and `regions`; a mesh to
/// refine (`-r`) uses `points`, `tets`, `tet_attributes`, `point_sizes` and
/// `trifaces`/`trifacemarkers`.
#[derive(Clone, Copy, Debug, Default)]
pub struct Input<'a> {
    /// Coordinates, 3 per point.
    pub points: &'a [f64],
    /// Polygons per facet.
    pub facet_polygon_counts: &'a [i32],
    /// Vertices per polygon (all facets' polygons in order).
    pub polygon_vertex_counts: &'a [i32],
    /// Vertex indices of all polygons, concatenated.
    pub polygon_vertices: &'a [i32],
    /// One marker per facet.
    pub facet_markers: Option<&'a [i32]>,
    /// Hole points per facet (one entry per facet), with their coordinates in `facet_holes`.
    pub facet_hole_counts: Option<&'a [i32]>,
    /// Facet hole coordinates, 3 per hole.
    pub facet_holes: &'a [f64],
    /// Volume hole seeds, 3 per hole.
    pub holes: &'a [f64],
    /// Region seeds, 5 per region: x, y, z, attribute, maximum volume.
    pub regions: &'a [f64],
    /// Tetrahedra, 4 indices each.
    pub tets: &'a [i32],
    /// One attribute per tetrahedron.
    pub tet_attributes: Option<&'a [f64]>,
    /// One target edge length per point (positive), for `-m`.
    pub point_sizes: Option<&'a [f64]>,
    /// Boundary triangles of a mesh input, 3 indices each.
    pub trifaces: &'a [i32],
    /// One marker per boundary triangle.
    pub trifacemarkers: &'a [i32],
}

/// TetGen's output, copied into owned vectors, indices made 0-based.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Output {
    /// Coordinates, 3 per point.
    pub points: Vec<f64>,
    /// Tetrahedra, 4 point indices each (the corner nodes).
    pub tets: Vec<i32>,
    /// The first attribute of each tetrahedron (the region attribute with
    /// `-A`); empty when TetGen produced none.
    pub tet_attributes: Vec<f64>,
    /// Triangles on the boundary and on input facets, 3 point indices each.
    pub trifaces: Vec<i32>,
    /// One marker per triangle (empty when TetGen produced none).
    pub trifacemarkers: Vec<i32>,
}

impl Output {
    /// Number of points.
    pub fn n_points(&self) -> usize {
        self.points.len() / 3
    }

    /// Number of tetrahedra.
    pub fn n_tets(&self) -> usize {
        self.tets.len() / 4
    }
}

/// Serialises every call into TetGen (its predicates keep global state).
static TETGEN: Mutex<()> = Mutex::new(());

/// The right to call TetGen: the global lock that serialises every call,
/// held until this value is dropped (see [`lock`] and [`tetrahedralize_locked`]).
///
/// A caller that forks a process to run TetGen in takes it around `fork`, so
/// that no other thread is inside TetGen (or holds the lock) at that moment:
/// the child then inherits TetGen's global state at rest and a lock it owns.
#[derive(Debug)]
pub struct Lock(#[allow(dead_code)] MutexGuard<'static, ()>);

/// Waits for and takes the global TetGen lock.
pub fn lock() -> Lock {
    // A panic elsewhere while holding the lock leaves TetGen's state as good
    // as any other call would: recover the guard from a poisoned mutex.
    Lock(TETGEN.lock().unwrap_or_else(|e| e.into_inner()))
}

fn invalid(m: impl Into<String>) -> Error {
    Error::InvalidInput(m.into())
}

fn count_i32(n: usize, what: &str) -> Result<i32, Error> {
    i32::try_from(n).map_err(|_| invalid(format!("too many {what} for TetGen ({n})")))
}

fn check_finite(values: &[f64], what: &str) -> Result<(), Error> {
    match values.iter().position(|x| !x.is_finite()) {
        Some(i) => Err(invalid(format!(
            "{what} value {} is {}, not a finite number",
            i + 1,
            values[i]
        ))),
        None => Ok(()),
    }
}

fn check_indices(indices: &[i32], n_points: usize, what: &str) -> Result<(), Error> {
    match indices
        .iter()
        .position(|&i| i < 0 || i as usize >= n_points)
    {
        Some(k) => Err(invalid(format!(
            "{what} refers to point {} but there are {n_points} points (0-based)",
            indices[k]
        ))),
        None => Ok(()),
    }
}

fn coord(p: &[f64]) -> robust::Coord3D<f64> {
    robust::Coord3D {
        x: p[0],
        y: p[1],
        z: p[2],
    }
}

/// Whether some four points span a volume (exact predicates). TetGen asserts
/// (and aborts the process) on inputs whose points are all coplanar.
fn spans_volume(points: &[f64]) -> bool {
    let p: Vec<&[f64]> = points.chunks_exact(3).collect();
    let Some(&a) = p.first() else { return false };
    let Some(b) = p.iter().copied().find(|q| *q != a) else {
        return false;
    };
    let collinear = |c: &[f64]| {
        let xy = |q: &[f64]| robust::Coord { x: q[0], y: q[1] };
        let yz = |q: &[f64]| robust::Coord { x: q[1], y: q[2] };
        let zx = |q: &[f64]| robust::Coord { x: q[2], y: q[0] };
        robust::orient2d(xy(a), xy(b), xy(c)) == 0.0
            && robust::orient2d(yz(a), yz(b), yz(c)) == 0.0
            && robust::orient2d(zx(a), zx(b), zx(c)) == 0.0
    };
    let Some(c) = p.iter().copied().find(|q| !collinear(q)) else {
        return false;
    };
    p.iter()
        .any(|d| robust::orient3d(coord(a), coord(b), coord(c), coord(d)) != 0.0)
}

/// Checks the arrays so that TetGen never reads out of bounds.
fn validate(input: &Input) -> Result<(), Error> {
    if input.points.len() % 3 != 0 {
        return Err(invalid("point coordinates are not a multiple of 3"));
    }
    let np = input.points.len() / 3;
    count_i32(np, "points")?;
    check_finite(input.points, "point coordinate")?;
    if !spans_volume(input.points) {
        return Err(invalid(
            "all points are coplanar (or fewer than four): there is no volume to mesh",
        ));
    }
    let nf = input.facet_polygon_counts.len();
    count_i32(nf, "facets")?;
    if input.facet_polygon_counts.iter().any(|&c| c < 1) {
        return Err(invalid("a facet has no polygon"));
    }
    let npoly: usize = input.facet_polygon_counts.iter().map(|&c| c as usize).sum();
    if npoly != input.polygon_vertex_counts.len() {
        return Err(invalid(format!(
            "facets name {npoly} polygons but {} polygon sizes are given",
            input.polygon_vertex_counts.len()
        )));
    }
    if input.polygon_vertex_counts.iter().any(|&c| c < 1) {
        return Err(invalid("a polygon has no vertex"));
    }
    let nv: usize = input
        .polygon_vertex_counts
        .iter()
        .map(|&c| c as usize)
        .sum();
    if nv != input.polygon_vertices.len() {
        return Err(invalid(format!(
            "polygons name {nv} vertices but {} are given",
            input.polygon_vertices.len()
        )));
    }
    check_indices(input.polygon_vertices, np, "a polygon")?;
    if let Some(m) = input.facet_markers {
        if m.len() != nf {
            return Err(invalid(format!(
                "{} facet markers for {nf} facets",
                m.len()
            )));
        }
    }
    match input.facet_hole_counts {
        Some(h) => {
            if h.len() != nf {
                return Err(invalid(format!(
                    "{} facet hole counts for {nf} facets",
                    h.len()
                )));
            }
            if h.iter().any(|&c| c < 0) {
                return Err(invalid("a facet hole count is negative"));
            }
            let total: usize = h.iter().map(|&c| c as usize).sum();
            if 3 * total != input.facet_holes.len() {
                return Err(invalid(
                    "facet hole coordinates do not match the hole counts",
                ));
            }
        }
        None => {
            if !input.facet_holes.is_empty() {
                return Err(invalid("facet hole coordinates without facet hole counts"));
            }
        }
    }
    check_finite(input.facet_holes, "facet hole coordinate")?;
    if input.holes.len() % 3 != 0 {
        return Err(invalid("hole coordinates are not a multiple of 3"));
    }
    count_i32(input.holes.len() / 3, "holes")?;
    check_finite(input.holes, "hole coordinate")?;
    if input.regions.len() % 5 != 0 {
        return Err(invalid("region values are not a multiple of 5"));
    }
    count_i32(input.regions.len() / 5, "regions")?;
    check_finite(input.regions, "region value")?;
    if input.tets.len() % 4 != 0 {
        return Err(invalid("tetrahedron indices are not a multiple of 4"));
    }
    let nt = input.tets.len() / 4;
    count_i32(nt, "tetrahedra")?;
    check_indices(input.tets, np, "a tetrahedron")?;
    if let Some(a) = input.tet_attributes {
        if a.len() != nt {
            return Err(invalid(format!(
                "{} tet attributes for {nt} tetrahedra",
                a.len()
            )));
        }
        check_finite(a, "tet attribute")?;
    }
    if let Some(s) = input.point_sizes {
        if s.len() != np {
            return Err(invalid(format!("{} point sizes for {np} points", s.len())));
        }
        if let Some(i) = s.iter().position(|x| !(x.is_finite() && *x > 0.0)) {
            return Err(invalid(format!(
                "point size {} is {}: sizes must be finite and positive",
                i + 1,
                s[i]
            )));
        }
    }
    if input.trifaces.len() % 3 != 0 {
        return Err(invalid("triangle indices are not a multiple of 3"));
    }
    let ntri = input.trifaces.len() / 3;
    count_i32(ntri, "triangles")?;
    check_indices(input.trifaces, np, "a triangle")?;
    if input.trifacemarkers.len() != ntri {
        return Err(invalid(format!(
            "{} triangle markers for {ntri} triangles",
            input.trifacemarkers.len()
        )));
    }
    Ok(())
}

fn ptr_or_null<T>(s: &[T]) -> *const T {
    if s.is_empty() {
        std::ptr::null()
    } else {
        s.as_ptr()
    }
}

/// Copies `n` items from a C array (empty when null or `n <= 0`).
///
/// # Safety
/// `p` must be valid for `n` reads when not null.
unsafe fn copy_out<T: Copy>(p: *const T, n: i64) -> Vec<T> {
    if p.is_null() || n <= 0 {
        Vec::new()
    } else {
        std::slice::from_raw_parts(p, n as usize).to_vec()
    }
}

/// Runs TetGen's `tetrahedralize(switches, in, out)` on checked arrays.
///
/// `switches` are TetGen's command-line switches without the dash
/// (e.g. `"pq1.414a0.1AQ"`). Calls are serialised by a global mutex.
pub fn tetrahedralize(switches: &str, input: &Input) -> Result<Output, Error> {
    let lock = lock();
    tetrahedralize_locked(&lock, switches, input)
}

/// [`tetrahedralize`] for a caller that holds the global lock already
/// (taken with [`lock`], e.g. in a child process forked while holding it).
pub fn tetrahedralize_locked(_lock: &Lock, switches: &str, input: &Input) -> Result<Output, Error> {
    validate(input)?;
    let sw = CString::new(switches).map_err(|_| invalid("switches contain a NUL byte"))?;
    let raw_in = raw::RawInput {
        npoints: (input.points.len() / 3) as i32,
        points: ptr_or_null(input.points),
        nfacets: input.facet_polygon_counts.len() as i32,
        facet_polygon_counts: ptr_or_null(input.facet_polygon_counts),
        polygon_vertex_counts: ptr_or_null(input.polygon_vertex_counts),
        polygon_vertices: ptr_or_null(input.polygon_vertices),
        facet_markers: input.facet_markers.map_or(std::ptr::null(), ptr_or_null),
        facet_hole_counts: input
            .facet_hole_counts
            .map_or(std::ptr::null(), ptr_or_null),
        facet_holes: ptr_or_null(input.facet_holes),
        nholes: (input.holes.len() / 3) as i32,
        holes: ptr_or_null(input.holes),
        nregions: (input.regions.len() / 5) as i32,
        regions: ptr_or_null(input.regions),
        ntets: (input.tets.len() / 4) as i32,
        tets: ptr_or_null(input.tets),
        tet_attributes: input.tet_attributes.map_or(std::ptr::null(), ptr_or_null),
        point_sizes: input.point_sizes.map_or(std::ptr::null(), ptr_or_null),
        ntrifaces: (input.trifaces.len() / 3) as i32,
        trifaces: ptr_or_null(input.trifaces),
        trifacemarkers: ptr_or_null(input.trifacemarkers),
    };
    let mut out = raw::RawOutput {
        io: std::ptr::null_mut(),
        firstnumber: 0,
        npoints: 0,
        points: std::ptr::null(),
        ntets: 0,
        ncorners: 0,
        tets: std::ptr::null(),
        nattributes: 0,
        tet_attributes: std::ptr::null(),
        ntrifaces: 0,
        trifaces: std::ptr::null(),
        trifacemarkers: std::ptr::null(),
    };
    // SAFETY: `validate` checked every count, length and index; the pointers
    // borrow `input`, which outlives the call; the shim copies what it keeps;
    // `_lock` proves that no other call runs at the same time.
    let code = unsafe { raw::tg_tetrahedralize(sw.as_ptr(), &raw_in, &mut out) };
    if code != 0 {
        return Err(Error::Tetgen(code));
    }
    // SAFETY: on success `out` describes arrays owned by the C++ side with the
    // given counts; they are copied before `tg_output_free` releases them.
    let result = unsafe {
        let np = out.npoints as i64;
        let nt = out.ntets as i64;
        let nc = out.ncorners as i64;
        let na = out.nattributes as i64;
        let nf = out.ntrifaces as i64;
        let points = copy_out(out.points, 3 * np);
        let all_tets = copy_out(out.tets, nc * nt);
        let all_attrs = copy_out(out.tet_attributes, na * nt);
        let trifaces = copy_out(out.trifaces, 3 * nf);
        let trifacemarkers = copy_out(out.trifacemarkers, nf);
        let first = out.firstnumber;
        raw::tg_output_free(&mut out);
        (
            points,
            all_tets,
            nc,
            all_attrs,
            na,
            trifaces,
            trifacemarkers,
            first,
        )
    };
    let (points, all_tets, nc, all_attrs, na, mut trifaces, trifacemarkers, first) = result;
    if nc != 0 && nc < 4 {
        return Err(invalid(format!(
            "TetGen returned {nc} nodes per tetrahedron"
        )));
    }
    let mut tets = Vec::with_capacity(all_tets.len() / 10 * 4 + 4);
    if nc >= 4 {
        for t in all_tets.chunks_exact(nc as usize) {
            tets.extend(t[..4].iter().map(|&i| i - first));
        }
    }
    for i in trifaces.iter_mut() {
        *i -= first;
    }
    let np = points.len() / 3;
    check_indices(&tets, np, "TetGen's output tetrahedron")?;
    check_indices(&trifaces, np, "TetGen's output triangle")?;
    let tet_attributes = if na > 0 {
        all_attrs.chunks_exact(na as usize).map(|a| a[0]).collect()
    } else {
        Vec::new()
    };
    Ok(Output {
        points,
        tets,
        tet_attributes,
        trifaces,
        trifacemarkers,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Points, polygons per facet, vertices per polygon, vertices, markers.
    type Arrays = (Vec<f64>, Vec<i32>, Vec<i32>, Vec<i32>, Vec<i32>);

    /// The unit cube as six quadrilateral facets with markers 1..=6.
    fn cube() -> Arrays {
        let mut p = Vec::new();
        for i in 0..8 {
            p.extend([(i & 1) as f64, ((i >> 1) & 1) as f64, ((i >> 2) & 1) as f64]);
        }
        let quads = [
            [0, 2, 3, 1],
            [4, 5, 7, 6],
            [0, 1, 5, 4],
            [2, 6, 7, 3],
            [0, 4, 6, 2],
            [1, 3, 7, 5],
        ];
        let verts: Vec<i32> = quads.iter().flatten().copied().collect();
        (p, vec![1; 6], vec![4; 6], verts, (1..=6).collect())
    }

    fn tet_volume(p: &[f64], t: &[i32]) -> f64 {
        let q = |i: i32| &p[3 * i as usize..3 * i as usize + 3];
        let (a, b, c, d) = (q(t[0]), q(t[1]), q(t[2]), q(t[3]));
        let u = [b[0] - a[0], b[1] - a[1], b[2] - a[2]];
        let v = [c[0] - a[0], c[1] - a[1], c[2] - a[2]];
        let w = [d[0] - a[0], d[1] - a[1], d[2] - a[2]];
        (u[0] * (v[1] * w[2] - v[2] * w[1]) - u[1] * (v[0] * w[2] - v[2] * w[0])
            + u[2] * (v[0] * w[1] - v[1] * w[0]))
            / 6.0
    }

    #[test]
    fn meshes_the_unit_cube_with_markers() {
        let (p, fp, pv, v, m) = cube();
        let input = Input {
            points: &p,
            facet_polygon_counts: &fp,
            polygon_vertex_counts: &pv,
            polygon_vertices: &v,
            facet_markers: Some(&m),
            ..Default::default()
        };
        let out = tetrahedralize("pQ", &input).unwrap();
        assert!(out.n_tets() > 0);
        let vol: f64 = out
            .tets
            .chunks_exact(4)
            .map(|t| tet_volume(&out.points, t).abs())
            .sum();
        assert!((vol - 1.0).abs() < 1e-12, "volume {vol}");
        // 12 boundary triangles (two per face), each with its face's marker.
        assert_eq!(out.trifaces.len(), 36);
        let mut seen: Vec<i32> = out.trifacemarkers.clone();
        seen.sort_unstable();
        assert_eq!(seen, vec![1, 1, 2, 2, 3, 3, 4, 4, 5, 5, 6, 6]);
    }

    #[test]
    fn a_caller_holding_the_lock_meshes_with_tetrahedralize_locked() {
        let (p, fp, pv, v, m) = cube();
        let input = Input {
            points: &p,
            facet_polygon_counts: &fp,
            polygon_vertex_counts: &pv,
            polygon_vertices: &v,
            facet_markers: Some(&m),
            ..Default::default()
        };
        let lock = lock();
        let out = tetrahedralize_locked(&lock, "pQ", &input).unwrap();
        drop(lock);
        let vol: f64 = out
            .tets
            .chunks_exact(4)
            .map(|t| tet_volume(&out.points, t).abs())
            .sum();
        assert!((vol - 1.0).abs() < 1e-12, "volume {vol}");
        // The lock is free again: the locking entry point works.
        assert_eq!(tetrahedralize("pQ", &input).unwrap(), out);
    }

    #[test]
    fn bad_arrays_are_rejected_before_tetgen() {
        let (p, fp, pv, mut v, m) = cube();
        v[3] = 8;
        let input = Input {
            points: &p,
            facet_polygon_counts: &fp,
            polygon_vertex_counts: &pv,
            polygon_vertices: &v,
            facet_markers: Some(&m),
            ..Default::default()
        };
        let e = tetrahedralize("pQ", &input).unwrap_err();
        assert!(e.to_string().contains("refers to point 8"), "{e}");
        let flat = [0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 1.0, 1.0, 0.0];
        let e = tetrahedralize(
            "Q",
            &Input {
                points: &flat,
                ..Default::default()
            },
        )
        .unwrap_err();
        assert!(e.to_string().contains("coplanar"), "{e}");
    }

    #[test]
    fn tetgen_errors_come_back_and_the_process_survives() {
        // Two cubes that interpenetrate: TetGen finds the self-intersection.
        let (mut p, mut fp, mut pv, mut v, mut m) = cube();
        let (p2, fp2, pv2, v2, m2) = cube();
        p.extend(p2.iter().map(|x| x + 0.5));
        fp.extend(fp2);
        pv.extend(pv2);
        v.extend(v2.iter().map(|i| i + 8));
        m.extend(m2);
        let input = Input {
            points: &p,
            facet_polygon_counts: &fp,
            polygon_vertex_counts: &pv,
            polygon_vertices: &v,
            facet_markers: Some(&m),
            ..Default::default()
        };
        let e = tetrahedralize("pQ", &input).unwrap_err();
        assert_eq!(e, Error::Tetgen(3), "{e}");
        // A good call afterwards still works.
        let (p, fp, pv, v, m) = cube();
        let good = Input {
            points: &p,
            facet_polygon_counts: &fp,
            polygon_vertex_counts: &pv,
            polygon_vertices: &v,
            facet_markers: Some(&m),
            ..Default::default()
        };
        assert!(tetrahedralize("pQ", &good).unwrap().n_tets() > 0);
    }
}
