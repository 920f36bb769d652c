//! `tetrefine._core`: the Python extension over the tetrefine core.
//!
//! The Python side only: arguments, numpy arrays, exceptions, the GIL and
//! Ctrl-C. Every call into the core goes through [`core_api`] (the one file
//! that names `tetrefine::…` paths); numpy conversions are in [`arrays`].
//!
//! Every call into the core runs with the GIL released and inside
//! `catch_unwind`, so a panic becomes a `RuntimeError`, never an abort.
//! Long refinements check for signals (Ctrl-C) at the start of every phase
//! and stop there, raising `KeyboardInterrupt`.

mod arrays;
mod core_api;

use std::panic::{catch_unwind, AssertUnwindSafe};
use std::path::PathBuf;
use std::sync::{Arc, Mutex, OnceLock};

use numpy::ndarray::ArrayView2;
use numpy::{IntoPyArray, PyArray1, PyArray2, PyArrayMethods};
use pyo3::exceptions::{PyFileNotFoundError, PyOSError, PyRuntimeError, PyValueError};
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList};

use core_api::{BuildNotes, FieldIn, TetMesh, VertexParents};

/// The unwinding payload of a cancelled run (Ctrl-C, or an exception raised
/// by a progress callback). It is thrown with `resume_unwind`, which does not
/// run the panic hook, and caught by [`run_core`].
struct Cancelled;

/// The text of a panic payload.
fn panic_text(p: &(dyn std::any::Any + Send)) -> String {
    if let Some(s) = p.downcast_ref::<&str>() {
        (*s).to_string()
    } else if let Some(s) = p.downcast_ref::<String>() {
        s.clone()
    } else {
        "unknown panic".to_string()
    }
}

/// Runs `f` (a call into the core) with the GIL released and panics caught.
/// `cancelled` holds the exception that stopped a cancelled run.
fn run_core<T: Send>(
    py: Python<'_>,
    cancelled: Option<&Mutex<Option<PyErr>>>,
    f: impl FnOnce() -> T + Send,
) -> PyResult<T> {
    match py.detach(|| catch_unwind(AssertUnwindSafe(f))) {
        Ok(v) => Ok(v),
        Err(p) if p.is::<Cancelled>() => {
            let err = cancelled.and_then(|c| c.lock().ok().and_then(|mut e| e.take()));
            Err(err.unwrap_or_else(|| PyRuntimeError::new_err("tetrefine: the run was cancelled")))
        }
        Err(p) => Err(PyRuntimeError::new_err(format!(
            "tetrefine: internal error (a bug; please report it): {}",
            panic_text(p.as_ref())
        ))),
    }
}

/// Marks a numpy array read-only.
fn readonly<T>(a: Bound<'_, T>) -> PyResult<Bound<'_, T>> {
    a.as_any().getattr("flags")?.setattr("writeable", false)?;
    Ok(a)
}

/// A JSON text as a Python object (dict, list, …).
fn json_value<'py>(py: Python<'py>, text: &str) -> PyResult<Bound<'py, PyAny>> {
    py.import("json")?.getattr("loads")?.call1((text,))
}

/// Tells the user (as a `UserWarning`) what building changed, as the CLI's
/// notes on stderr do.
fn warn_notes(py: Python<'_>, what: &str, n: &BuildNotes) -> PyResult<()> {
    let warn = py.import("warnings")?.getattr("warn")?;
    if n.reoriented > 0 {
        warn.call1((format!(
            "{what}: {} tetrahedra were negatively oriented and have been turned around",
            n.reoriented
        ),))?;
    }
    if n.dropped_triangles > 0 || n.dropped_edges > 0 {
        warn.call1((format!(
            "{what}: dropped {} marked triangles and {} tagged edges that are not faces/edges of any tetrahedron",
            n.dropped_triangles, n.dropped_edges
        ),))?;
    }
    Ok(())
}

/// A tetrahedral mesh: points, positively oriented tets, a region per tet,
/// marked boundary/interface faces and feature edges.
///
/// Mesh(points, tets, regions=None, boundary_faces=None, boundary_markers=None,
///      feature_edges=None, corners=None)
///
/// points: (n, 3) float64 or float32.  tets: (m, 4) point ids, any integer
/// dtype, 0-based, any orientation (negative tets are turned around, with a
/// warning).  regions: (m,) integers (default all 0).  boundary_faces: (k, 3)
/// point ids of marked triangles (boundary or interface faces), with
/// boundary_markers: (k,) integers (default 0).  feature_edges: (e, 2) point
/// ids of sharp edges to keep.  corners: point ids that never move.
///
/// The arrays are validated by the library's own mesh building, the checks
/// the file readers run: ids in range, no repeated vertex, no flat or
/// duplicate tet, at most two tets per face, no two tets overlapping across a
/// face, finite coordinates. A bad array raises ValueError with the
/// library's message (its tet and point numbers are 1-based, as in mesh
/// files; the message also names the 0-based row).
///
/// A Mesh is immutable: refine(), improve() and bisect() return new meshes.
/// Its arrays (points, tets, regions, level, parent, marked, boundary_faces,
/// ...) are read-only numpy arrays; points and tets are views of the mesh's
/// own memory, no copies.
#[pyclass(frozen, module = "tetrefine", name = "Mesh")]
pub struct Mesh {
    inner: TetMesh,
    /// For a mesh made by refine(), until its parents are located: the input
    /// mesh and the selection (per input tet).
    lineage: Mutex<Option<Lineage>>,
    /// Located parents and the marked flags (refine() meshes, on first use).
    located: OnceLock<(Vec<u32>, Vec<bool>)>,
    /// JSON reports of the operation that made the mesh (one per step).
    reports: Vec<String>,
    /// JSON wall times of refine()'s parts (empty for other meshes).
    timings: String,
    notes: BuildNotes,
    /// Point fields (refine(): the input's, carried over).
    point_fields: Vec<FieldIn>,
    /// Cell fields, per tet.
    cell_fields: Vec<FieldIn>,
    /// The vertex parent map (refine() with fields or vertex_parents=True).
    vertex_parents: Option<VertexParents>,
}

/// Where a refined mesh came from: what locating its parents needs.
struct Lineage {
    input: Py<Mesh>,
    selection: Option<Arc<Vec<bool>>>,
}

impl Mesh {
    fn new_plain(inner: TetMesh, notes: BuildNotes) -> Mesh {
        Mesh::made(inner, Vec::new(), String::new(), notes, None)
    }

    fn made(
        inner: TetMesh,
        reports: Vec<String>,
        timings: String,
        notes: BuildNotes,
        lineage: Option<Lineage>,
    ) -> Mesh {
        Mesh {
            inner,
            lineage: Mutex::new(lineage),
            located: OnceLock::new(),
            reports,
            timings,
            notes,
            point_fields: Vec::new(),
            cell_fields: Vec::new(),
            vertex_parents: None,
        }
    }

    /// The located parents and marked flags of a mesh made by refine()
    /// (located on first use, with the GIL released); `None` for others.
    fn located(&self, py: Python<'_>) -> PyResult<Option<&(Vec<u32>, Vec<bool>)>> {
        if let Some(v) = self.located.get() {
            return Ok(Some(v));
        }
        // The lock is held only while the GIL is, never across `detach`.
        let (input, selection) = {
            let g = self.lineage.lock().map_err(|_| {
                PyRuntimeError::new_err("tetrefine: a parent location failed earlier")
            })?;
            match &*g {
                Some(l) => (l.input.clone_ref(py), l.selection.clone()),
                None => return Ok(self.located.get()),
            }
        };
        let input_mesh = &input.get().inner;
        let mesh = &self.inner;
        let sel = selection.as_deref().map(Vec::as_slice);
        let v = run_core(py, None, || core_api::locate(input_mesh, mesh, sel))?;
        let _ = self.located.set(v);
        if let Ok(mut g) = self.lineage.lock() {
            *g = None; // the input may go now
        }
        Ok(self.located.get())
    }
}

/// Fields as a dict `{name: read-only array}`: `(n,)` for one component,
/// `(n, k)` for more.
fn fields_dict<'py>(py: Python<'py>, fields: &[FieldIn]) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    for f in fields {
        let a = f.values.clone().into_pyarray(py);
        let a = if f.components == 1 {
            a.into_any()
        } else {
            a.reshape([f.values.len() / f.components, f.components])?
                .into_any()
        };
        d.set_item(&f.name, readonly(a)?)?;
    }
    Ok(d)
}

/// Reads a `point_fields=` / `cell_fields=` argument.
fn fields_arg(obj: &Bound<'_, PyAny>, arg: &str) -> PyResult<Vec<FieldIn>> {
    Ok(arrays::fields(obj, arg)?
        .into_iter()
        .map(|(name, components, values)| FieldIn {
            name,
            components,
            values,
        })
        .collect())
}

/// Reads the `mark` argument: a spec string or a list of them.
fn mark_specs(mark: Option<&Bound<'_, PyAny>>) -> PyResult<Option<Vec<String>>> {
    let Some(m) = mark else { return Ok(None) };
    if let Ok(s) = m.extract::<String>() {
        return Ok(Some(vec![s]));
    }
    m.extract::<Vec<String>>().map(Some).map_err(|_| {
        PyValueError::new_err("mark must be a string such as 'doerfler:0.5', or a list of them")
    })
}

/// `region=` as the spec `region:ID,…`.
fn region_spec(region: &Bound<'_, PyAny>) -> PyResult<String> {
    let ids: Vec<i64> = if let Ok(i) = region.extract::<i64>() {
        vec![i]
    } else {
        region.extract::<Vec<i64>>().map_err(|_| {
            PyValueError::new_err("region must be a region id or a list of region ids")
        })?
    };
    Ok(format!(
        "region:{}",
        ids.iter().map(i64::to_string).collect::<Vec<_>>().join(",")
    ))
}

fn number_list(name: &str, spec: &str, v: &Bound<'_, PyAny>) -> PyResult<String> {
    let xs: Vec<f64> = v.extract().map_err(|_| {
        PyValueError::new_err(format!("{name} must be a sequence of numbers ({spec})"))
    })?;
    Ok(format!(
        "{name}:{}",
        xs.iter().map(f64::to_string).collect::<Vec<_>>().join(",")
    ))
}

#[pymethods]
impl Mesh {
    #[new]
    #[pyo3(signature = (points, tets, regions=None, boundary_faces=None, boundary_markers=None, feature_edges=None, corners=None))]
    #[allow(clippy::too_many_arguments)]
    fn py_new(
        py: Python<'_>,
        points: &Bound<'_, PyAny>,
        tets: &Bound<'_, PyAny>,
        regions: Option<&Bound<'_, PyAny>>,
        boundary_faces: Option<&Bound<'_, PyAny>>,
        boundary_markers: Option<&Bound<'_, PyAny>>,
        feature_edges: Option<&Bound<'_, PyAny>>,
        corners: Option<&Bound<'_, PyAny>>,
    ) -> PyResult<Mesh> {
        let mut input = core_api::Input {
            points: arrays::points(points)?,
            tets: arrays::ids::<4>(tets, "tets")?,
            ..Default::default()
        };
        if let Some(r) = regions {
            input.regions = arrays::labels(r, "regions")?;
            if input.regions.len() != input.tets.len() {
                return Err(PyValueError::new_err(format!(
                    "regions has {} values for {} tets",
                    input.regions.len(),
                    input.tets.len()
                )));
            }
        }
        if let Some(f) = boundary_faces {
            let faces = arrays::ids::<3>(f, "boundary_faces")?;
            let markers = match boundary_markers {
                Some(m) => arrays::labels(m, "boundary_markers")?,
                None => vec![0; faces.len()],
            };
            if markers.len() != faces.len() {
                return Err(PyValueError::new_err(format!(
                    "boundary_markers has {} values for {} boundary_faces",
                    markers.len(),
                    faces.len()
                )));
            }
            input.faces = faces.into_iter().zip(markers).collect();
        } else if boundary_markers.is_some() {
            return Err(PyValueError::new_err(
                "boundary_markers needs boundary_faces (the triangles they mark)",
            ));
        }
        if let Some(e) = feature_edges {
            input.edges = arrays::ids::<2>(e, "feature_edges")?
                .into_iter()
                .map(|e| (e, 0))
                .collect();
        }
        if let Some(c) = corners {
            input.corners = arrays::ids::<1>(c, "corners")?
                .into_iter()
                .map(|[v]| v)
                .collect();
        }
        let built = run_core(py, None, move || core_api::build(input))?;
        match built {
            Ok((mesh, notes)) => {
                warn_notes(py, "Mesh", &notes)?;
                Ok(Mesh::new_plain(mesh, notes))
            }
            Err(f) => {
                let row = f
                    .tet
                    .map(|t| format!("tets[{}]: ", t - 1))
                    .unwrap_or_default();
                Err(PyValueError::new_err(format!(
                    "{row}{} (numbers in this message are 1-based, as in mesh files)",
                    f.message
                )))
            }
        }
    }

    /// Number of points (including points no tet uses).
    #[getter]
    fn n_points(&self) -> usize {
        core_api::n_points(&self.inner)
    }

    /// Number of tets.
    #[getter]
    fn n_tets(&self) -> usize {
        core_api::n_tets(&self.inner)
    }

    /// (n_points, 3) float64, read-only view of the mesh's points (no copy).
    #[getter]
    fn points<'py>(slf: &Bound<'py, Self>) -> PyResult<Bound<'py, PyArray2<f64>>> {
        let p = core_api::points(&slf.get().inner);
        // SAFETY: `[f64; 3]` rows are contiguous f64s; the slice lives in the
        // frozen (never mutated) Mesh, which the array keeps alive as its base.
        let view = unsafe { ArrayView2::from_shape_ptr((p.len(), 3), p.as_ptr().cast::<f64>()) };
        let a = unsafe { PyArray2::borrow_from_array(&view, slf.clone().into_any()) };
        readonly(a)
    }

    /// (n_tets, 4) uint32, read-only view of the tets (no copy): point ids,
    /// positively oriented (orient3d > 0), face i opposite vertex i.
    #[getter]
    fn tets<'py>(slf: &Bound<'py, Self>) -> PyResult<Bound<'py, PyArray2<u32>>> {
        let t = core_api::tets(&slf.get().inner);
        // SAFETY: as for `points`.
        let view = unsafe { ArrayView2::from_shape_ptr((t.len(), 4), t.as_ptr().cast::<u32>()) };
        let a = unsafe { PyArray2::borrow_from_array(&view, slf.clone().into_any()) };
        readonly(a)
    }

    /// (n_tets,) int32: region (material) per tet.
    #[getter]
    fn regions<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray1<i32>>> {
        readonly(core_api::regions(&self.inner).into_pyarray(py))
    }

    /// (n_tets,) uint8: how often each tet's ancestors were refined (0 for an
    /// unrefined mesh).
    #[getter]
    fn level<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray1<u8>>> {
        readonly(core_api::levels(&self.inner).into_pyarray(py))
    }

    /// (n_tets,) uint32: after refine(), the input tet that holds each tet's
    /// centroid (to carry solver fields over), located on first use as the
    /// CLI locates it after the steps (until then the refined mesh keeps
    /// its input alive); for other meshes, the tet's own index or the tet it
    /// was made from.
    #[getter]
    fn parent<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray1<u32>>> {
        let v = match self.located(py)? {
            Some((p, _)) => p.clone(),
            None => core_api::parents(&self.inner),
        };
        readonly(v.into_pyarray(py))
    }

    /// (n_tets,) bool: after refine(), whether the tet descends from a
    /// selected input tet (all True after uniform refinement); all False for a
    /// mesh that refine() did not make.
    #[getter]
    fn marked<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray1<bool>>> {
        let v = match self.located(py)? {
            Some((_, m)) => m.clone(),
            None => vec![false; core_api::n_tets(&self.inner)],
        };
        readonly(v.into_pyarray(py))
    }

    /// (k, 3) uint32: the marked triangles (boundary or interface faces with a
    /// marker), sorted vertex ids, in sorted order.
    #[getter]
    fn boundary_faces<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray2<u32>>> {
        let f = core_api::marked_faces(&self.inner);
        let flat: Vec<u32> = f.iter().flat_map(|(v, _)| *v).collect();
        readonly(flat.into_pyarray(py).reshape([f.len(), 3])?)
    }

    /// (k,) int32: the marker of each of boundary_faces.
    #[getter]
    fn boundary_markers<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray1<i32>>> {
        let f = core_api::marked_faces(&self.inner);
        readonly(
            f.iter()
                .map(|(_, m)| *m)
                .collect::<Vec<_>>()
                .into_pyarray(py),
        )
    }

    /// (e, 2) uint32: the feature (crease) edges, sorted pairs in sorted
    /// order. refine() adds the detected ones (features="auto").
    #[getter]
    fn feature_edges<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray2<u32>>> {
        let e = core_api::feature_edges(&self.inner);
        let flat: Vec<u32> = e.iter().flat_map(|(v, _)| *v).collect();
        readonly(flat.into_pyarray(py).reshape([e.len(), 2])?)
    }

    /// (c,) uint32: corner vertices (never moved by refinement).
    #[getter]
    fn corners<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray1<u32>>> {
        readonly(core_api::corners(&self.inner).into_pyarray(py))
    }

    /// dict name -> read-only array (n_points,) or (n_points, k): the point
    /// fields refine() carried over (interpolated linearly in the input tet
    /// holding each point; a point outside the input domain gets the value
    /// at the nearest input boundary point). Empty for other meshes. A
    /// further refine() carries them over again by default.
    #[getter]
    fn point_fields<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        fields_dict(py, &self.point_fields)
    }

    /// dict name -> read-only array (n_tets,) or (n_tets, k): the cell
    /// fields refine() carried over (each tet has its parent's values).
    /// Empty for other meshes.
    #[getter]
    fn cell_fields<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        fields_dict(py, &self.cell_fields)
    }

    /// The vertex parent map of a mesh refine() made with fields to carry
    /// over or vertex_parents=True (else None): a dict of read-only arrays
    /// per point, "tet" (n_points,) uint32, the input tet holding the point;
    /// "vertices" (n_points, 4) uint32, that tet's vertices; "bary"
    /// (n_points, 4) float64, the point's barycentric coordinates for them;
    /// "outside" (n_points,) bool, the point lies outside the input (then
    /// "bary" give the nearest input boundary point). The CLI's .vtu arrays
    /// parent_tet, parent_vertices, parent_bary, parent_outside.
    #[getter]
    fn vertex_parents<'py>(&self, py: Python<'py>) -> PyResult<Option<Bound<'py, PyDict>>> {
        let Some(v) = &self.vertex_parents else {
            return Ok(None);
        };
        let n = v.tet.len();
        let d = PyDict::new(py);
        d.set_item("tet", readonly(v.tet.clone().into_pyarray(py))?)?;
        let verts: Vec<u32> = v.vertices.iter().flatten().copied().collect();
        d.set_item(
            "vertices",
            readonly(verts.into_pyarray(py).reshape([n, 4])?)?,
        )?;
        let bary: Vec<f64> = v.bary.iter().flatten().copied().collect();
        d.set_item("bary", readonly(bary.into_pyarray(py).reshape([n, 4])?)?)?;
        d.set_item("outside", readonly(v.outside.clone().into_pyarray(py))?)?;
        Ok(Some(d))
    }

    /// The reports of the operation that made this mesh: for refine(), one
    /// dict per step (phases with tets and seconds, operation counts, the
    /// optimize report; with stats=True also "quality", the quality() dict
    /// after the step); for bisect(), one per step; for improve(), one.
    /// Empty for a mesh read or built from arrays.
    #[getter]
    fn reports<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyList>> {
        let items = self
            .reports
            .iter()
            .map(|s| json_value(py, s))
            .collect::<PyResult<Vec<_>>>()?;
        PyList::new(py, items)
    }

    /// For a mesh made by refine(): wall seconds of its parts — "copy" (of
    /// the input), "features" (detection), "steps" (the √3 steps, as the
    /// library's step clocks count them), "compact", and with fields to
    /// carry over or vertex_parents=True "transfer" (parent and point
    /// location, interpolation). (Otherwise parents are located later, on
    /// first use.) None for other meshes.
    #[getter]
    fn timings<'py>(&self, py: Python<'py>) -> PyResult<Option<Bound<'py, PyAny>>> {
        if self.timings.is_empty() {
            return Ok(None);
        }
        json_value(py, &self.timings).map(Some)
    }

    /// What building changed: reoriented tets, unreferenced points, dropped
    /// triangles and edges (the CLI's notes).
    #[getter]
    fn build_notes<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let d = PyDict::new(py);
        d.set_item("reoriented", self.notes.reoriented)?;
        d.set_item("unreferenced_points", self.notes.unreferenced_points)?;
        d.set_item("dropped_triangles", self.notes.dropped_triangles)?;
        d.set_item("dropped_edges", self.notes.dropped_edges)?;
        Ok(d)
    }

    fn __repr__(&self) -> String {
        format!(
            "<tetrefine.Mesh: {} points, {} tets>",
            core_api::n_points(&self.inner),
            core_api::n_tets(&self.inner)
        )
    }

    /// The statistics of `tetrefine quality --json`, as a dict with the same
    /// keys: nodes, edges, tets, boundary_faces, interior_faces,
    /// min_dihedral_deg {worst, avg, best}, max_dihedral_deg {worst, avg},
    /// valence {avg, max}, inverted, volume, regions {"<id>": tets},
    /// histogram {edges_deg, counts}, feature_edges, corners.
    ///
    /// bins: number of equal histogram bins of the per-tet minimum dihedral
    /// angle over 0-71 degrees (71: bins of 1 degree; at most 10000).
    #[pyo3(signature = (bins=core_api::DEFAULT_BINS), text_signature = "(self, bins=71)")]
    fn quality<'py>(&self, py: Python<'py>, bins: usize) -> PyResult<Bound<'py, PyAny>> {
        if bins == 0 || bins > 10_000 {
            return Err(PyValueError::new_err(format!(
                "bins must be between 1 and 10000 (got {bins})"
            )));
        }
        let mesh = &self.inner;
        let text = run_core(py, None, || core_api::quality_json(mesh, bins))?;
        json_value(py, &text)
    }

    /// Per tet, the cell arrays tetrefine writes into .vtu files:
    /// "min_dihedral" and "max_dihedral" (degrees), "quality" (the paper's
    /// measure: minimum sine of the signed dihedral angles, 0.9428 for the
    /// regular tet, negative when inverted) and "volume".
    fn tet_quality<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let mesh = &self.inner;
        let [min, max, q, vol] = run_core(py, None, || core_api::tet_quality(mesh))?;
        let d = PyDict::new(py);
        d.set_item("min_dihedral", readonly(min.into_pyarray(py))?)?;
        d.set_item("max_dihedral", readonly(max.into_pyarray(py))?)?;
        d.set_item("quality", readonly(q.into_pyarray(py))?)?;
        d.set_item("volume", readonly(vol.into_pyarray(py))?)?;
        Ok(d)
    }

    /// Writes the mesh; the format follows the extension, as for the CLI:
    /// .mesh (Medit), .msh (Gmsh 4.1), .vtu (VTK XML, with the quality cell
    /// arrays and level, parent, marked for ParaView), .node/.ele (TetGen).
    /// Raises OSError with the library's message; a failed write leaves no
    /// file behind.
    fn write(&self, py: Python<'_>, path: PathBuf) -> PyResult<()> {
        core_api::check_output_path(&path).map_err(PyOSError::new_err)?;
        let is_vtu = path
            .extension()
            .is_some_and(|e| e.eq_ignore_ascii_case("vtu"));
        let located = if is_vtu { self.located(py)? } else { None };
        let parents = located.map(|(p, _)| p.as_slice());
        let marked = located.map(|(_, m)| m.as_slice());
        let mesh = &self.inner;
        run_core(py, None, || core_api::write(&path, mesh, parents, marked))?
            .map_err(PyOSError::new_err)
    }

    /// Refine with the √3 tetrahedral subdivision (uniform, or adaptive with
    /// a selection) — `tetrefine refine`. Returns a new Mesh; this one is
    /// left as it is. The new mesh's `reports` hold one dict per step.
    ///
    /// Each step runs the phases of the seed paper in order: split (1-4 split
    /// of every selected tet), flip (2-3 flip of old interior faces),
    /// boundary-split, boundary-flip (the √3 flip of old boundary edges;
    /// feature edges kept in odd steps, trisected in even ones),
    /// boundary-smooth and optimize (edge removal and smoothing).
    ///
    /// Options (the CLI flag in brackets):
    ///   steps         Number of √3 steps [--steps] (default 1); with a size
    ///                 map, of size passes, or 'auto' (the default there):
    ///                 passes until no edge is longer than its target, at
    ///                 most 20.
    ///   boundary      Boundary rule: 'interpolating' (Labsik–Greiner),
    ///                 'approximating' (Kobbelt) or 'linear' [--boundary].
    ///   opt_passes    Passes of the optimize phase (edge removal +
    ///                 smoothing); 0 skips it [--opt-passes] (default 3).
    ///   threshold     Minimum-sine quality below which vertices get
    ///                 optimization-based smoothing [--threshold] (0.35).
    ///   stop_after    Stop each step after this phase: 'split', 'flip',
    ///                 'boundary-split', 'boundary-flip', 'boundary-smooth',
    ///                 'optimize' [--stop-after].
    ///   features      Sharp features: 'auto' (input tags plus detected
    ///                 creases, patch borders and interface junctions),
    ///                 'none', or an edge-list file ('v0 v1' per line,
    ///                 0-based) added to the input tags [--features].
    ///   feature_angle Normal deviation (degrees) above which a boundary edge
    ///                 is a crease, with features='auto' [--feature-angle]
    ///                 (45, MMG's ridge angle).
    ///   indicator     Per-tet error indicator: array of n_tets finite values
    ///                 >= 0, in tet order [--indicator].
    ///   mark          Marking strategy for the indicator, a string or a list
    ///                 of strings (a union) [--mark]: 'fraction:F',
    ///                 'doerfler:θ', 'max:γ', 'threshold:X' (these need
    ///                 indicator), 'region:ID[,ID…]',
    ///                 'box:x0,y0,z0,x1,y1,z1', 'sphere:x,y,z,r'. Default
    ///                 'doerfler:0.5' when an indicator is given; without one,
    ///                 refinement is uniform unless region/box/sphere select.
    ///   region        Select the tets of these regions: an id or a list
    ///                 [--region].
    ///   box           Select the tets whose centroid is in the box
    ///                 (x0, y0, z0, x1, y1, z1) [--box].
    ///   sphere        Select the tets whose centroid is in the sphere
    ///                 (x, y, z, r) [--sphere].
    ///   smooth        With a selection: 'refined' (default) lets smoothing
    ///                 and edge removal touch only the refined zone, so tets
    ///                 sharing no vertex with it come out bit-identical;
    ///                 'all' optimises everywhere [--smooth].
    ///   step_offset   Refinement rounds already done on this mesh (in an
    ///                 adaptive loop, the round number): feature edges are
    ///                 kept in odd and trisected in even global steps
    ///                 [--step-offset].
    ///   progress      True: one line per phase on sys.stderr; or a callable
    ///                 progress(step, phase, tets) called at the start of
    ///                 every phase (an exception it raises stops the run); a
    ///                 step that runs again to keep its input's worst (its
    ///                 report's "held") repeats its phases, same step.
    ///   stats         Also compute quality() after every step, into the
    ///                 step's report as "quality" [--stats].
    ///   allow_empty   A selection that selects no tet returns the mesh
    ///                 unrefined instead of raising ValueError [--allow-empty].
    ///   allow_steps_zero  steps=0 returns the mesh unrefined instead of
    ///                 raising ValueError [--allow-steps-zero].
    ///   point_fields  Fields to carry over, a dict name -> array
    ///                 (n_points,) or (n_points, k) [--fields]: each is
    ///                 interpolated linearly in the input tet holding every
    ///                 output point (a field linear in x, y, z comes back to
    ///                 round-off; a point the boundary rule moved outside the
    ///                 input gets the value at the nearest input boundary
    ///                 point). Default: this mesh's own point_fields.
    ///   cell_fields   Per-tet fields, a dict name -> array (n_tets,) or
    ///                 (n_tets, k), copied from each new tet's parent
    ///                 [--fields]. Default: this mesh's own cell_fields.
    ///   transfer      Carry the fields over: None (default) when there are
    ///                 any, True (an error without fields) [--transfer], or
    ///                 False to drop them [--no-transfer]. The new mesh's
    ///                 point_fields, cell_fields and vertex_parents hold the
    ///                 result.
    ///   vertex_parents  Compute the vertex parent map (the new mesh's
    ///                 vertex_parents) even without fields [--parent-map].
    ///   size          MMG size map, per point [--size] [--size-array]: an
    ///                 array (n_points,) of target edge lengths, or
    ///                 (n_points, 6) of metrics m11 m12 m22 m13 m23 m33
    ///                 (MMG's order). Long edges are split, longest first,
    ///                 pass after pass, until every edge is at most √2 × its
    ///                 target (the √3 step is not used).
    ///   hsiz          One target edge length everywhere [--hsiz].
    ///   hmax          The largest target edge length: caps size or hsiz,
    ///                 or alone is the size map [--hmax].
    ///   effort        'fast' (boundary fixed, no long-edge splits),
    ///                 'default' (boundary vertices move inside their patch
    ///                 and along feature lines, sliver caps removed, two
    ///                 rounds of long-edge splits and, from the second step
    ///                 on, a third for the edges that still stand out) or
    ///                 'best' [--effort].
    ///   hausd         Hausdorff bound of boundary moves (MMG's -hausd);
    ///                 None: 5 % of the local edge length (15 % of a
    ///                 sliver cap's mean edge for its removal) [--hausd].
    ///   interfaces    'linear' (material interfaces split flat, exact
    ///                 region volumes) or 'sqrt3' (smoothed on both sides by
    ///                 the boundary rule) [--interfaces].
    ///
    /// The GIL is released while the mesh is refined. Ctrl-C (SIGINT) stops
    /// the run at the start of the next phase and raises KeyboardInterrupt.
    /// Bad options raise ValueError with the CLI's message; an unreadable
    /// features file raises OSError.
    #[pyo3(
        signature = (steps=None, *, boundary="interpolating", opt_passes=3, threshold=0.35,
                     stop_after=None, features=PathOrName("auto".into()), feature_angle=45.0, indicator=None,
                     mark=None, region=None, r#box=None, sphere=None, smooth="refined",
                     step_offset=0, progress=None, stats=false, allow_empty=false,
                     allow_steps_zero=false, point_fields=None, cell_fields=None,
                     transfer=None, vertex_parents=false, size=None, hsiz=None, hmax=None,
                     effort="default", hausd=None, interfaces="linear"),
        text_signature = "(self, steps=None, *, boundary='interpolating', opt_passes=3, threshold=0.35, stop_after=None, features='auto', feature_angle=45.0, indicator=None, mark='doerfler:0.5', region=None, box=None, sphere=None, smooth='refined', step_offset=0, progress=False, stats=False, allow_empty=False, allow_steps_zero=False, point_fields=None, cell_fields=None, transfer=None, vertex_parents=False, size=None, hsiz=None, hmax=None, effort='default', hausd=None, interfaces='linear')"
    )]
    #[allow(clippy::too_many_arguments)]
    fn refine(
        slf: &Bound<'_, Self>,
        py: Python<'_>,
        steps: Option<&Bound<'_, PyAny>>,
        boundary: &str,
        opt_passes: usize,
        threshold: f64,
        stop_after: Option<String>,
        features: PathOrName,
        feature_angle: f64,
        indicator: Option<&Bound<'_, PyAny>>,
        mark: Option<&Bound<'_, PyAny>>,
        region: Option<&Bound<'_, PyAny>>,
        r#box: Option<&Bound<'_, PyAny>>,
        sphere: Option<&Bound<'_, PyAny>>,
        smooth: &str,
        step_offset: usize,
        progress: Option<&Bound<'_, PyAny>>,
        stats: bool,
        allow_empty: bool,
        allow_steps_zero: bool,
        point_fields: Option<&Bound<'_, PyAny>>,
        cell_fields: Option<&Bound<'_, PyAny>>,
        transfer: Option<bool>,
        vertex_parents: bool,
        size: Option<&Bound<'_, PyAny>>,
        hsiz: Option<f64>,
        hmax: Option<f64>,
        effort: &str,
        hausd: Option<f64>,
        interfaces: &str,
    ) -> PyResult<Mesh> {
        let this = slf.get();
        let size = match size {
            Some(x) => Some(arrays::table(x, "size")?),
            None => None,
        };
        let size_given = size.is_some() || hsiz.is_some() || hmax.is_some();
        // steps: None (1, or 'auto' with a size map), an int, or 'auto'.
        let (steps, steps_auto) = match steps {
            None if size_given => (core_api::AUTO_SIZE_PASSES, true),
            None => (1, false),
            Some(s) if s.extract::<String>().is_ok_and(|t| t == "auto") => {
                (core_api::AUTO_SIZE_PASSES, true)
            }
            Some(s) => (
                s.extract::<usize>().map_err(|_| {
                    PyValueError::new_err("steps must be a number of steps (>= 0) or 'auto'")
                })?,
                false,
            ),
        };
        let point_fields = match point_fields {
            Some(f) => fields_arg(f, "point_fields")?,
            None => this.point_fields.clone(),
        };
        let cell_fields = match cell_fields {
            Some(f) => fields_arg(f, "cell_fields")?,
            None => this.cell_fields.clone(),
        };
        let has_fields = !point_fields.is_empty() || !cell_fields.is_empty();
        let smooth_refined = match smooth {
            "refined" => true,
            "all" => false,
            other => {
                return Err(PyValueError::new_err(format!(
                    "smooth={other:?}: use 'refined' or 'all'"
                )))
            }
        };
        let values = match indicator {
            Some(x) => Some(arrays::reals(x, "indicator")?),
            None => None,
        };
        let mut marks = match (mark_specs(mark)?, values.is_some()) {
            (Some(m), _) => m,
            (None, true) => vec!["doerfler:0.5".to_string()],
            (None, false) => Vec::new(),
        };
        if let Some(r) = region {
            marks.push(region_spec(r)?);
        }
        if let Some(b) = r#box {
            marks.push(number_list("box", "x0, y0, z0, x1, y1, z1", b)?);
        }
        if let Some(s) = sphere {
            marks.push(number_list("sphere", "x, y, z, r", s)?);
        }
        let args = core_api::RefineArgs {
            steps,
            boundary: boundary.to_string(),
            opt_passes,
            threshold,
            stop_after,
            features: features.0,
            feature_angle,
            marks,
            smooth_refined,
            step_offset,
            stats,
            allow_empty,
            allow_steps_zero,
            steps_auto,
            size,
            hsiz,
            hmax,
            point_fields,
            cell_fields,
            transfer: transfer.unwrap_or(has_fields),
            vertex_parents,
            effort: effort.to_string(),
            hausd,
            interfaces: interfaces.to_string(),
        };
        // progress: None/False, True (lines on stderr) or a callable.
        let (print, callback): (bool, Option<Py<PyAny>>) = match progress {
            None => (false, None),
            Some(p) if p.is_callable() => (false, Some(p.clone().unbind())),
            Some(p) => (p.is_truthy()?, None),
        };
        let cancelled: Mutex<Option<PyErr>> = Mutex::new(None);
        let hook = |step: usize, phase: &str, tets: u64| {
            let r = Python::attach(|py| -> PyResult<()> {
                py.check_signals()?;
                if print {
                    let line = format!("step {step}/{steps}: {phase} ({tets} tets)\n");
                    py.import("sys")?
                        .getattr("stderr")?
                        .call_method1("write", (line,))?;
                }
                if let Some(cb) = &callback {
                    cb.call1(py, (step, phase, tets))?;
                }
                Ok(())
            });
            if let Err(e) = r {
                if let Ok(mut c) = cancelled.lock() {
                    *c = Some(e);
                }
                std::panic::resume_unwind(Box::new(Cancelled));
            }
        };
        let mesh = &this.inner;
        let ind = values.as_deref();
        let result = run_core(py, Some(&cancelled), || {
            core_api::refine(mesh, &args, ind, &hook)
        })?;
        match result {
            Ok(r) => {
                let lineage = match r.located {
                    Some(_) => None,
                    None => Some(Lineage {
                        input: slf.clone().unbind(),
                        selection: r.selection.map(Arc::new),
                    }),
                };
                let mut m = Mesh::made(r.mesh, r.steps, r.timings, BuildNotes::default(), lineage);
                if let Some(l) = r.located {
                    let _ = m.located.set(l);
                }
                m.point_fields = r.point_fields;
                m.cell_fields = r.cell_fields;
                m.vertex_parents = r.vertex_parents;
                Ok(m)
            }
            Err(core_api::RefineError::Value(m)) => Err(PyValueError::new_err(m)),
            Err(core_api::RefineError::File(m)) => Err(PyOSError::new_err(m)),
        }
    }

    /// Improve the mesh (edge and multi-face removal, edge contraction,
    /// vertex insertion, smoothing, boundary moves inside their patches and
    /// sliver-cap removal; features detected at feature_angle as `--features auto` does) —
    /// `tetrefine improve`. Returns a new Mesh whose `reports` hold one dict
    /// (passes, edges_removed, laplacian_moves, optimized_moves,
    /// surface_moves, line_moves, caps_removed, long_edges_split,
    /// long_edge_boundary_faces, boundary_flips, edges_contracted, faces_removed, vertices_inserted;
    /// improve alone never splits long edges, but it inserts a vertex where
    /// a sliver needs one and contracts short edges, so the point count may
    /// change).
    ///
    ///   opt_passes     Maximum passes of edge removal + smoothing
    ///                  [--opt-passes] (default 5).
    ///   threshold      Minimum-sine quality below which vertices get
    ///                  optimization-based smoothing (0.35).
    ///   effort         'fast' (boundary fixed), 'default' or 'best'
    ///                  [--effort].
    ///   hausd          Hausdorff bound of boundary moves; None: 5 % of the
    ///                  local edge length (15 % of a sliver cap's mean edge
    ///                  for its removal) [--hausd].
    ///   features       'auto' or 'none' [--features].
    ///   feature_angle  Crease angle for 'auto', degrees [--feature-angle].
    #[pyo3(signature = (opt_passes=5, *, threshold=0.35, effort="default", hausd=None,
                        features="auto", feature_angle=45.0))]
    #[allow(clippy::too_many_arguments)]
    fn improve(
        &self,
        py: Python<'_>,
        opt_passes: usize,
        threshold: f64,
        effort: &str,
        hausd: Option<f64>,
        features: &str,
        feature_angle: f64,
    ) -> PyResult<Mesh> {
        let mesh = &self.inner;
        let args = core_api::ImproveArgs {
            passes: opt_passes,
            threshold,
            effort: effort.to_string(),
            hausd,
            features: features.to_string(),
            feature_angle,
        };
        let (m, report) = run_core(py, None, || core_api::improve(mesh, &args))?
            .map_err(PyValueError::new_err)?;
        Ok(Mesh::made(
            m,
            vec![report],
            String::new(),
            BuildNotes::default(),
            None,
        ))
    }

    /// Uniform 1:8 red refinement by edge bisection (the speed-of-light
    /// reference) — `tetrefine bisect`. Returns a new Mesh whose `reports`
    /// hold one dict per step (tets, points, seconds).
    ///
    ///   steps   Number of 1:8 steps [--steps] (default 1).
    #[pyo3(signature = (steps=1))]
    fn bisect(&self, py: Python<'_>, steps: usize) -> PyResult<Mesh> {
        let mesh = &self.inner;
        let (m, reports) =
            run_core(py, None, || core_api::bisect(mesh, steps))?.map_err(PyValueError::new_err)?;
        Ok(Mesh::made(
            m,
            reports,
            String::new(),
            BuildNotes::default(),
            None,
        ))
    }

    /// The mesh as a meshio.Mesh (needs meshio): a "tetra" block with cell
    /// data region, level, parent, marked, min_dihedral, max_dihedral,
    /// quality, volume (and medit:ref, gmsh:physical, gmsh:geometrical =
    /// region, so meshio's Medit and Gmsh writers keep the regions); with
    /// faces=True also a "triangle" block of the marked faces, whose
    /// region/medit:ref/gmsh:* hold the markers, and a "line" block of the
    /// feature edges (the other arrays are -1 or NaN there). Corners have
    /// no meshio cell type and are not carried.
    #[pyo3(signature = (faces=true))]
    fn to_meshio<'py>(slf: &Bound<'py, Self>, faces: bool) -> PyResult<Bound<'py, PyAny>> {
        let py = slf.py();
        py.import("tetrefine._convert")?
            .getattr("to_meshio")?
            .call1((slf, faces))
    }

    /// The tets as a PyVista grid (needs pyvista) with cell data region,
    /// level, parent, marked, min_dihedral, max_dihedral, quality, volume.
    fn to_pyvista<'py>(slf: &Bound<'py, Self>) -> PyResult<Bound<'py, PyAny>> {
        let py = slf.py();
        py.import("tetrefine._convert")?
            .getattr("to_pyvista")?
            .call1((slf,))
    }
}

/// `features=`: 'auto', 'none' or a path (str or os.PathLike).
struct PathOrName(String);

impl<'a, 'py> FromPyObject<'a, 'py> for PathOrName {
    type Error = PyErr;
    fn extract(ob: Borrowed<'a, 'py, PyAny>) -> PyResult<Self> {
        if let Ok(s) = ob.extract::<String>() {
            return Ok(PathOrName(s));
        }
        let p: PathBuf = ob.extract().map_err(|_| {
            PyValueError::new_err("features must be 'auto', 'none' or a path to an edge list")
        })?;
        Ok(PathOrName(p.to_string_lossy().into_owned()))
    }
}

/// Reads a mesh file; the format follows the extension, as for the CLI:
/// .mesh (Medit/MMG), .msh (Gmsh 2.2/4.1 ASCII or binary, or GiD — told
/// apart by the first keyword), .vtu (VTK XML), .node/.ele/.face (TetGen).
/// Regions, boundary markers and feature tags are kept. Raises
/// FileNotFoundError / OSError with the library's message (file and line).
#[pyfunction]
fn read(py: Python<'_>, path: PathBuf) -> PyResult<Mesh> {
    if !path.exists() {
        return Err(PyFileNotFoundError::new_err(format!(
            "{}: no such file",
            path.display()
        )));
    }
    let p = &path;
    let (mesh, notes) = run_core(py, None, || core_api::read(p))?.map_err(PyOSError::new_err)?;
    warn_notes(py, &path.display().to_string(), &notes)?;
    Ok(Mesh::new_plain(mesh, notes))
}

/// Panics inside the guard that wraps every call into the core, so that the
/// tests can check that a panic becomes a RuntimeError (never an abort).
#[pyfunction]
fn _panic_for_tests(py: Python<'_>) -> PyResult<()> {
    run_core(py, None, || -> () {
        panic!("deliberate panic for the tests")
    })
}

/// Mesh the volume a closed surface encloses, with TetGen — `tetrefine
/// mesh`. Only in builds with the `tetgen` feature (TetGen is AGPL-3):
/// `MATURIN_PEP517_ARGS="--features tetgen" pip install ./python`.
///
///   surface       A path (.poly, .smesh, .off, .stl, triangles-only .mesh)
///                 or a tuple (points (n, 3), triangles (k, 3)[, markers]).
///   min_ratio     Largest radius-edge ratio of a tet (TetGen -q; >= 1).
///   min_dihedral  Smallest dihedral angle in degrees (a goal, not a
///                 guarantee; TetGen -q<R>/<DEG>).
///   max_volume    Largest tet volume (TetGen -a).
///   switches      More TetGen switches, appended.
///   time_limit    Seconds TetGen may run (None: no limit) — the CLI's
///                 --time-limit. Past it TetGen is stopped and TimeoutError
///                 is raised. Some switches make TetGen refine for hours.
///
/// TetGen runs in a child process forked for the call (Linux/Unix), so a
/// TetGen that crashes raises RuntimeError naming the surface and the
/// signal (e.g. SIGSEGV) instead of killing the interpreter, and the time
/// limit kills only the child. The mesh is the one TetGen makes in-process.
/// Raises FileNotFoundError / OSError for an unreadable file and ValueError
/// for bad options, a surface TetGen may not be given, or TetGen's errors.
#[cfg(feature = "tetgen")]
#[pyfunction]
#[pyo3(signature = (surface, *, min_ratio=None, min_dihedral=None, max_volume=None, switches=None, time_limit=None))]
fn mesh_surface(
    py: Python<'_>,
    surface: &Bound<'_, PyAny>,
    min_ratio: Option<f64>,
    min_dihedral: Option<f64>,
    max_volume: Option<f64>,
    switches: Option<String>,
    time_limit: Option<f64>,
) -> PyResult<Mesh> {
    let args = core_api::MeshArgs {
        min_ratio,
        min_dihedral,
        max_volume,
        switches,
        time_limit,
    };
    let path: Option<PathBuf> = surface.extract().ok();
    let result = if let Some(p) = &path {
        if !p.exists() {
            return Err(PyFileNotFoundError::new_err(format!(
                "{}: no such file",
                p.display()
            )));
        }
        run_core(py, None, || {
            core_api::mesh_surface(core_api::Surface::File(p), args)
        })?
    } else {
        let t = surface.cast::<pyo3::types::PyTuple>().map_err(|_| {
            PyValueError::new_err(
                "surface must be a path or a tuple (points, triangles[, markers])",
            )
        })?;
        if t.len() < 2 || t.len() > 3 {
            return Err(PyValueError::new_err(
                "surface must be a tuple (points, triangles[, markers])",
            ));
        }
        let points = arrays::points(&t.get_item(0)?)?;
        let tris = arrays::ids::<3>(&t.get_item(1)?, "triangles")?;
        let markers = if t.len() == 3 {
            arrays::labels(&t.get_item(2)?, "markers")?
        } else {
            vec![1; tris.len()]
        };
        if markers.len() != tris.len() {
            return Err(PyValueError::new_err(format!(
                "markers has {} values for {} triangles",
                markers.len(),
                tris.len()
            )));
        }
        let tris: Vec<([u32; 3], i32)> = tris.into_iter().zip(markers).collect();
        run_core(py, None, || {
            core_api::mesh_surface(core_api::Surface::Triangles(points, tris), args)
        })?
    };
    // A Ctrl-C that killed TetGen's child (same process group) is raised
    // as KeyboardInterrupt, not as the child's death.
    py.check_signals()?;
    match result {
        Ok(mesh) => Ok(Mesh::new_plain(mesh, BuildNotes::default())),
        Err(core_api::MeshError::File(m)) => Err(PyOSError::new_err(m)),
        Err(core_api::MeshError::Value(m)) => Err(PyValueError::new_err(m)),
        Err(core_api::MeshError::Timeout(m)) => Err(pyo3::exceptions::PyTimeoutError::new_err(m)),
        Err(core_api::MeshError::Crash(m)) => Err(PyRuntimeError::new_err(m)),
    }
}

/// The extension module `tetrefine._core`.
#[pymodule]
fn _core(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<Mesh>()?;
    m.add_function(wrap_pyfunction!(read, m)?)?;
    m.add_function(wrap_pyfunction!(_panic_for_tests, m)?)?;
    #[cfg(feature = "tetgen")]
    m.add_function(wrap_pyfunction!(mesh_surface, m)?)?;
    m.add("HAS_TETGEN", cfg!(feature = "tetgen"))?;
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    Ok(())
}
