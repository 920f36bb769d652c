//! `tetrefine surface SCHEME IN -o OUT --steps N [options]`.

use std::ops::ControlFlow;
use std::path::{Path, PathBuf};
use tetrefine_surface::catmull_clark::catmull_clark_tracked;
use tetrefine_surface::catmull_clark_weighted::{catmull_clark_weighted_tracked, WeightedConfig};
use tetrefine_surface::doo_sabin::doo_sabin_tracked;
use tetrefine_surface::ifs::{
    gasket_control, ifs_shape, koch_control, regular_net, write_points_csv, write_points_vtp,
    write_polylines, IfsOptions, IfsShape, IfsStart, PolylineFormat,
};
use tetrefine_surface::loop_scheme::loop_subdivide_tracked;
use tetrefine_surface::sierpinski::{sierpinski_tracked, SierpinskiOptions};
use tetrefine_surface::sqrt3::{sqrt3_tracked, FaceSelection, Sqrt3Options, Sqrt3Rule};
use tetrefine_surface::truncate::{check_cut, truncate_tracked};
use tetrefine_surface::{
    load_surface, read_surface, write_surface_with, Encoding, FaceAttributes, Features, IfsKind,
    PolyMesh, StepObserver, Subdivided, SurfaceFormat, WriteOptions,
};

/// The surface schemes.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum Scheme {
    /// Kobbelt's approximating √3 (triangles).
    Sqrt3,
    /// Labsik–Greiner's interpolating √3 (triangles).
    Sqrt3Interp,
    /// √3 topology only: old points fixed, new points at centroids (triangles).
    Sqrt3Linear,
    /// Loop (triangles).
    Loop,
    /// Catmull–Clark (any polygons).
    CatmullClark,
    /// Doo–Sabin (any polygons; no creases).
    DooSabin,
    /// Hansmeyer's weighted and extruded Catmull–Clark; weights from --weights FILE.json.
    CatmullClarkWeighted,
    /// Sierpinski polyhedra (closed surfaces; joints as tiny tubes, see --neck).
    Sierpinski,
    /// Chaikin vertex truncation, every edge cut at --cut and 1 − cut (closed surfaces).
    Truncate,
    /// Attractor of the IFS of a subdivision scheme (--kind); curves as polylines
    /// (.vtp, .csv), surfaces (bicubic, loop, sqrt3) as triangle meshes.
    Ifs,
}

/// The subdivision schemes whose IFS `ifs` iterates.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum IfsKindArg {
    /// Uniform cubic B-spline curve (at least 4 control points).
    CubicBspline,
    /// Interpolating four-point curve (at least 6 control points).
    FourPoint,
    /// Bicubic B-spline patch (a --grid NU,NV of control points, row-major).
    Bicubic,
    /// Koch curve (5 control points; the standard ones without input).
    Koch,
    /// Sierpinski gasket (6 control points; the standard ones without input).
    Gasket,
    /// End-interpolating cubic B-spline (knots of multiplicity 4 at the ends;
    /// at least 4 control points).
    ClampedBspline,
    /// Bézier curve of degree n − 1 (at least 2 control points).
    Bezier,
    /// Regular Loop patch over one triangle (12 control points of a triangular
    /// net; the regular planar net without input).
    Loop,
    /// Regular √3 patch over one triangle (27 control points of a triangular
    /// net; the regular planar net without input).
    Sqrt3,
}

/// Arguments of `surface`.
#[derive(clap::Args)]
pub struct Args {
    /// Subdivision scheme.
    #[arg(value_enum)]
    pub scheme: Scheme,
    /// Input surface (.obj, .off, .ply, .stl; PLY and STL ASCII or binary);
    /// for ifs, its points are the control points (optional for --kind koch,
    /// gasket, loop and sqrt3).
    pub input: Option<PathBuf>,
    /// Output surface (.obj, .off, .ply, .stl, .vtp, .vtk); for ifs, curves,
    /// segments and points as .vtp or .csv, surfaces and triangles as a mesh. .ply and .stl are binary unless --ascii; .stl
    /// holds triangles only (other faces are split into fans). .ply, .vtp and
    /// .vtk carry per-face generation, origin (input face) and group.
    #[arg(short, long)]
    pub output: PathBuf,
    /// Write .ply and .stl outputs as text instead of binary.
    #[arg(long)]
    pub ascii: bool,
    /// Write every generation, the input as generation 0, to its own file:
    /// OUTPUT with _K before the extension (-o out.vtp writes out_0.vtp,
    /// out_1.vtp, …, out_N.vtp for --steps N); OUTPUT itself is not written.
    #[arg(long)]
    pub every_step: bool,
    /// Number of subdivision steps (for ifs: rounds of the maps).
    #[arg(long, visible_alias = "iterations", default_value_t = 1)]
    pub steps: usize,
    /// Largest memory the subdivision may take (bytes, or with K, M, G, T);
    /// default: what /proc/meminfo says is available. The output's size is
    /// projected from the input and the steps, and a run that would not fit
    /// is refused before any work.
    #[arg(long, value_name = "SIZE")]
    pub max_memory: Option<String>,
    /// Tag every edge whose faces meet at more than DEG degrees (normal
    /// deviation) as a crease.
    #[arg(long, value_name = "DEG")]
    pub crease_angle: Option<f64>,
    /// Tag crease edges, as 0-based vertex pairs "a-b" (comma separated or repeated).
    #[arg(long, value_delimiter = ',', value_name = "A-B")]
    pub crease: Vec<String>,
    /// Tag corner vertices (0-based ids, comma separated or repeated).
    #[arg(long, value_delimiter = ',', value_name = "V")]
    pub corner: Vec<u32>,
    /// √3 only: refine adaptively the triangles whose centroid is in the box
    /// "xmin,ymin,zmin,xmax,ymax,zmax".
    #[arg(
        long,
        value_delimiter = ',',
        allow_negative_numbers = true,
        value_name = "X0,Y0,Z0,X1,Y1,Z1"
    )]
    pub select_box: Option<Vec<f64>>,
    /// √3 only: refine adaptively the triangles whose centroid is in the ball
    /// "x,y,z,radius".
    #[arg(
        long,
        value_delimiter = ',',
        allow_negative_numbers = true,
        value_name = "X,Y,Z,R"
    )]
    pub select_sphere: Option<Vec<f64>>,
    /// catmull-clark-weighted only: the weights as a JSON file (see the README).
    #[arg(long, value_name = "FILE.json")]
    pub weights: Option<PathBuf>,
    /// sierpinski only: where the tube at a joint leaves each piece, as a
    /// fraction of the piece edges (0 < F < 0.5) [default: 0.05].
    #[arg(long, value_name = "F")]
    pub neck: Option<f64>,
    /// truncate only: cut every edge at F and 1 − F of its length (0 < F < 0.5)
    /// [default: 0.25, Chaikin].
    #[arg(long, value_name = "F")]
    pub cut: Option<f64>,
    /// ifs only: the subdivision scheme.
    #[arg(long, value_enum)]
    pub kind: Option<IfsKindArg>,
    /// ifs --kind bicubic only: the control grid size, "NU,NV".
    #[arg(long, value_delimiter = ',', value_name = "NU,NV")]
    pub grid: Option<Vec<usize>>,
    /// ifs only: keep only these maps (0-based, comma separated), a fractal
    /// on the curve or surface; q kept maps make q^N pieces after N steps.
    #[arg(long, value_delimiter = ',', value_name = "I,J,…")]
    pub maps: Option<Vec<usize>>,
    /// ifs only: the set the maps are applied to: point (the first control
    /// point), segment (first to last control point), triangle (first,
    /// middle, last control point), or a mesh FILE (.obj, .off, .ply, .stl);
    /// default: points on the attractor.
    #[arg(long, value_name = "point|segment|triangle|FILE")]
    pub start: Option<String>,
}

/// Faces above which a run is refused rather than exhausting memory.
const MAX_FACES: f64 = 2.0e8;
/// Peak bytes per projected face (the projection below counts face sides
/// of the input times the growth per step): `VmHWM` 627 MB for Loop ×10
/// on a tetrahedron (3.1 M projected, 199 bytes each) and 148 MB for
/// Catmull–Clark ×9 (786 k projected, 189 bytes each), rounded up. The
/// per-face attributes (generation, origin, group) add about 7%: Loop ×9 on
/// a tetrahedron, 786 k projected, 170 MB without them and 181 MB with
/// them (231 bytes each).
const BYTES_PER_PROJECTED_FACE: f64 = 300.0;

fn parse_crease(s: &str) -> Result<[u32; 2], String> {
    let (a, b) = s
        .split_once('-')
        .ok_or_else(|| format!("--crease '{s}': expected two vertex ids as A-B"))?;
    let parse = |t: &str| {
        t.trim()
            .parse::<u32>()
            .map_err(|_| format!("--crease '{s}': '{t}' is not a vertex id"))
    };
    Ok([parse(a)?, parse(b)?])
}

/// Checks that every option given belongs to the scheme, before any work.
fn check_options(a: &Args, features: &Features) -> Result<(), String> {
    let only = |given: bool, option: &str, scheme: Scheme, name: &str| {
        if given && a.scheme != scheme {
            Err(format!("{option} is for {name}"))
        } else {
            Ok(())
        }
    };
    only(
        a.weights.is_some(),
        "--weights",
        Scheme::CatmullClarkWeighted,
        "catmull-clark-weighted",
    )?;
    only(a.neck.is_some(), "--neck", Scheme::Sierpinski, "sierpinski")?;
    only(a.cut.is_some(), "--cut", Scheme::Truncate, "truncate")?;
    only(a.kind.is_some(), "--kind", Scheme::Ifs, "ifs")?;
    only(a.maps.is_some(), "--maps", Scheme::Ifs, "ifs")?;
    only(a.start.is_some(), "--start", Scheme::Ifs, "ifs")?;
    if a.grid.is_some() && a.kind != Some(IfsKindArg::Bicubic) {
        return Err("--grid is for ifs --kind bicubic".into());
    }
    if matches!(
        a.scheme,
        Scheme::Sierpinski | Scheme::Truncate | Scheme::Ifs
    ) && *features != Features::default()
    {
        return Err("sierpinski, truncate and ifs do not support creases or corners".into());
    }
    if a.scheme == Scheme::DooSabin && *features != Features::default() {
        return Err("doo-sabin does not support creases or corners".into());
    }
    if let Some(neck) = a.neck {
        SierpinskiOptions { neck }
            .check()
            .map_err(|e| format!("--neck: {e}"))?;
    }
    if let Some(cut) = a.cut {
        check_cut(cut).map_err(|e| format!("--cut: {e}"))?;
    }
    if a.scheme == Scheme::Ifs && a.every_step {
        return Err("--every-step is for the subdivision schemes, not ifs".into());
    }
    if a.scheme == Scheme::Ifs {
        if a.kind.is_none() {
            return Err(
                "ifs needs --kind cubic-bspline, four-point, bicubic, koch, gasket, clamped-bspline, bezier, loop or sqrt3".into(),
            );
        }
        if a.kind == Some(IfsKindArg::Bicubic) && a.grid.as_ref().is_none_or(|g| g.len() != 2) {
            return Err("ifs --kind bicubic needs --grid NU,NV (the control grid size)".into());
        }
        if a.input.is_none()
            && !matches!(
                a.kind,
                Some(IfsKindArg::Koch | IfsKindArg::Gasket | IfsKindArg::Loop | IfsKindArg::Sqrt3)
            )
        {
            return Err("ifs needs an input file with the control points (optional only for --kind koch, gasket, loop and sqrt3)".into());
        }
    } else if a.input.is_none() {
        return Err("give the input surface (.obj, .off, .ply or .stl)".into());
    }
    Ok(())
}

/// What `surface ifs` writes.
#[derive(Clone, Copy, PartialEq, Eq)]
enum IfsOutput {
    Points,
    Polylines,
    Surface,
}

/// `surface ifs`: the attractor as points, polylines or a triangle mesh.
fn run_ifs(a: &Args) -> super::CliResult {
    let kind = match a.kind {
        Some(IfsKindArg::CubicBspline) => IfsKind::CubicBSpline,
        Some(IfsKindArg::FourPoint) => IfsKind::FourPoint,
        Some(IfsKindArg::Bicubic) => {
            let g = a.grid.as_deref().unwrap_or(&[]);
            IfsKind::Bicubic {
                nu: g.first().copied().unwrap_or(0),
                nv: g.get(1).copied().unwrap_or(0),
            }
        }
        Some(IfsKindArg::Koch) => IfsKind::Koch,
        Some(IfsKindArg::ClampedBspline) => IfsKind::ClampedCubicBSpline,
        Some(IfsKindArg::Bezier) => IfsKind::Bezier,
        Some(IfsKindArg::Loop) => IfsKind::Loop,
        Some(IfsKindArg::Sqrt3) => IfsKind::Sqrt3,
        Some(IfsKindArg::Gasket) | None => IfsKind::Gasket,
    };
    let start = match a.start.as_deref() {
        None => IfsStart::Attractor,
        Some("point") => IfsStart::Point,
        Some("segment") => IfsStart::Segment,
        Some("triangle") => IfsStart::Triangle,
        Some(file) => {
            let path = Path::new(file);
            let f = read_surface(path).map_err(|e| format!("--start: {e}"))?;
            IfsStart::Mesh(f.mesh)
        }
    };
    // The output's kind, known before any work, so a wrong extension is
    // refused first.
    let output = match &start {
        IfsStart::Attractor if kind.is_surface() => IfsOutput::Surface,
        IfsStart::Attractor | IfsStart::Segment => IfsOutput::Polylines,
        IfsStart::Point => IfsOutput::Points,
        IfsStart::Triangle => IfsOutput::Surface,
        IfsStart::Mesh(m) if m.faces.is_empty() => IfsOutput::Points,
        IfsStart::Mesh(_) => IfsOutput::Surface,
    };
    match output {
        IfsOutput::Surface => {
            let format = SurfaceFormat::of(&a.output)
                .map_err(|e| format!("{e} (ifs writes a triangle mesh here)"))?;
            if a.ascii && !matches!(format, SurfaceFormat::Ply | SurfaceFormat::Stl) {
                return Err(format!(
                    "--ascii is for .ply and .stl outputs; {} is text already",
                    a.output.display()
                ));
            }
        }
        IfsOutput::Polylines | IfsOutput::Points => {
            PolylineFormat::of(&a.output).map_err(|e| e.to_string())?;
            if a.ascii {
                return Err(format!(
                    "--ascii is for .ply and .stl surface outputs; {} is text already",
                    a.output.display()
                ));
            }
        }
    }
    let (control, source) = match &a.input {
        Some(path) => {
            let file = read_surface(path).map_err(|e| e.to_string())?;
            (file.mesh.points, path.display().to_string())
        }
        None => {
            let name = format!("--kind {:?}", kind).to_lowercase();
            let builtin = match kind {
                IfsKind::Koch => koch_control().to_vec(),
                IfsKind::Gasket => gasket_control().to_vec(),
                _ => regular_net(kind).unwrap_or_default(),
            };
            (builtin, name)
        }
    };
    let ifs = tetrefine_surface::Ifs::new(kind, &control).map_err(|e| format!("{source}: {e}"))?;
    if let Some(keep) = &a.maps {
        ifs.subset(keep).map_err(|e| format!("--maps: {e}"))?;
    }
    let options = IfsOptions {
        maps: a.maps.clone(),
        start,
    };
    let shape =
        ifs_shape(kind, &control, a.steps, &options).map_err(|e| format!("{source}: {e}"))?;
    match shape {
        IfsShape::Surface(mesh) => {
            let options = WriteOptions {
                encoding: if a.ascii {
                    Encoding::Ascii
                } else {
                    Encoding::Binary
                },
                attributes: None,
            };
            write_surface_with(&a.output, &mesh, &options).map_err(|e| e.to_string())?;
            eprintln!(
                "wrote {}: {} vertices, {} triangles",
                a.output.display(),
                mesh.points.len(),
                mesh.faces.len()
            );
        }
        IfsShape::Polylines(lines) => {
            write_polylines(&a.output, &lines).map_err(|e| e.to_string())?;
            eprintln!(
                "wrote {}: {} polylines, {} points",
                a.output.display(),
                lines.len(),
                lines.iter().map(Vec::len).sum::<usize>()
            );
        }
        IfsShape::Points(points) => {
            match PolylineFormat::of(&a.output).map_err(|e| e.to_string())? {
                PolylineFormat::Csv => write_points_csv(&a.output, &points),
                PolylineFormat::Vtp => write_points_vtp(&a.output, &points),
            }
            .map_err(|e| e.to_string())?;
            eprintln!("wrote {}: {} points", a.output.display(), points.len());
        }
    }
    Ok(())
}

/// Runs `surface`.
pub fn run(a: Args) -> super::CliResult {
    let features = Features {
        creases: a
            .crease
            .iter()
            .map(|s| parse_crease(s))
            .collect::<Result<_, _>>()?,
        corners: a.corner.clone(),
        crease_angle: a.crease_angle,
    };
    check_options(&a, &features)?;
    if a.scheme == Scheme::Ifs {
        return run_ifs(&a);
    }
    let format = SurfaceFormat::of(&a.output).map_err(|e| e.to_string())?;
    if a.ascii && !matches!(format, SurfaceFormat::Ply | SurfaceFormat::Stl) {
        return Err(format!(
            "--ascii is for .ply and .stl outputs; {} is text already",
            a.output.display()
        ));
    }
    let is_sqrt3 = matches!(
        a.scheme,
        Scheme::Sqrt3 | Scheme::Sqrt3Interp | Scheme::Sqrt3Linear
    );
    if !is_sqrt3 && (a.select_box.is_some() || a.select_sphere.is_some()) {
        return Err("--select-box and --select-sphere are for the sqrt3 schemes".into());
    }
    if a.select_box.is_some() && a.select_sphere.is_some() {
        return Err("give either --select-box or --select-sphere, not both".into());
    }
    if a.select_box.as_ref().is_some_and(|b| b.len() != 6) {
        return Err("--select-box needs six numbers: xmin,ymin,zmin,xmax,ymax,zmax".into());
    }
    if a.select_sphere.as_ref().is_some_and(|b| b.len() != 4) {
        return Err("--select-sphere needs four numbers: x,y,z,radius".into());
    }
    let weights = match &a.weights {
        Some(p) => Some(WeightedConfig::from_json_file(p).map_err(|e| e.to_string())?),
        None => None,
    };
    let input = a.input.clone().unwrap_or_default();
    let mesh = load_surface(&input).map_err(|e| e.to_string())?;
    let growth: f64 = if is_sqrt3 || a.scheme == Scheme::Truncate {
        3.0
    } else {
        4.0
    };
    let sides: usize = mesh.faces.iter().map(|f| f.len()).sum();
    let predicted = sides as f64 * growth.powi(a.steps.saturating_sub(1).min(64) as i32);
    if predicted > MAX_FACES {
        return Err(format!(
            "{} steps would make about {predicted:.2e} faces; use fewer steps",
            a.steps
        ));
    }
    super::guard::MemoryBudget::new(a.max_memory.as_deref())?.check(
        &format!("surface {} with {} steps", input.display(), a.steps),
        predicted * BYTES_PER_PROJECTED_FACE,
        &format!("about {predicted:.2e} faces at {BYTES_PER_PROJECTED_FACE} bytes each (measured)"),
    )?;
    let ctx = |e: tetrefine_surface::SubdivisionError| format!("{}: {e}", input.display());
    let ctx2 = |e: tetrefine_surface::SurfaceError| format!("{}: {e}", input.display());
    let what = format!(
        "{}{}",
        a.input
            .as_ref()
            .map_or_else(String::new, |p| format!("{}: ", p.display())),
        format!("{:?}", a.scheme).to_lowercase()
    );
    let encoding = if a.ascii {
        Encoding::Ascii
    } else {
        Encoding::Binary
    };
    // With --every-step, each generation is checked and written as it comes;
    // the first failure stops the subdivision.
    let mut failure: Option<String> = None;
    let mut write_step = |k: usize, m: &PolyMesh, at: &FaceAttributes| {
        let path = step_path(&a.output, k);
        let done = if k == 0 {
            Ok(())
        } else {
            super::guard::check_surface_output(m, &format!("{what}, step {k}"))
        }
        .and_then(|()| write_with_attributes(&path, m, at, encoding));
        match done {
            Ok(()) => ControlFlow::Continue(()),
            Err(e) => {
                failure = Some(e);
                ControlFlow::Break(())
            }
        }
    };
    let observer: Option<&mut StepObserver> = if a.every_step {
        Some(&mut write_step)
    } else {
        None
    };
    let out: Subdivided = match a.scheme {
        Scheme::Sqrt3 | Scheme::Sqrt3Interp | Scheme::Sqrt3Linear => {
            let rule = match a.scheme {
                Scheme::Sqrt3 => Sqrt3Rule::Approximating,
                Scheme::Sqrt3Interp => Sqrt3Rule::Interpolating,
                _ => Sqrt3Rule::Linear,
            };
            let selection = if let Some(b) = &a.select_box {
                FaceSelection::Box {
                    min: glam::DVec3::new(b[0], b[1], b[2]),
                    max: glam::DVec3::new(b[3], b[4], b[5]),
                }
            } else if let Some(s) = &a.select_sphere {
                FaceSelection::Sphere {
                    center: glam::DVec3::new(s[0], s[1], s[2]),
                    radius: s[3],
                }
            } else {
                FaceSelection::All
            };
            let opts = Sqrt3Options {
                features,
                selection,
            };
            sqrt3_tracked(&mesh, rule, a.steps, &opts, observer).map_err(ctx)?
        }
        Scheme::Loop => loop_subdivide_tracked(&mesh, a.steps, &features, observer).map_err(ctx)?,
        Scheme::CatmullClark => {
            catmull_clark_tracked(&mesh, a.steps, &features, observer).map_err(ctx)?
        }
        Scheme::DooSabin => doo_sabin_tracked(&mesh, a.steps, observer).map_err(ctx)?,
        Scheme::CatmullClarkWeighted => {
            let cfg = weights.unwrap_or_default();
            catmull_clark_weighted_tracked(&mesh, a.steps, &cfg, &features, observer)
                .map_err(ctx)?
        }
        Scheme::Sierpinski => {
            let mut opts = SierpinskiOptions::default();
            if let Some(neck) = a.neck {
                opts.neck = neck;
            }
            sierpinski_tracked(&mesh, a.steps, &opts, observer).map_err(ctx2)?
        }
        Scheme::Truncate => {
            truncate_tracked(&mesh, a.steps, a.cut.unwrap_or(0.25), observer).map_err(ctx2)?
        }
        Scheme::Ifs => return run_ifs(&a),
    };
    if let Some(e) = failure {
        return Err(e);
    }
    let out_path = if a.every_step {
        step_path(&a.output, out.steps)
    } else {
        super::guard::check_surface_output(&out.mesh, &what)?;
        write_with_attributes(&a.output, &out.mesh, &out.attributes, encoding)?;
        a.output.clone()
    };
    let m = &out.mesh;
    if a.every_step {
        eprintln!(
            "wrote {} files, {} to {}",
            out.steps + 1,
            step_path(&a.output, 0).display(),
            out_path.display()
        );
    }
    eprintln!(
        "wrote {}: {} vertices, {} edges, {} faces, Euler characteristic {}",
        out_path.display(),
        m.used_vertices(),
        m.edge_list().len(),
        m.faces.len(),
        m.euler_characteristic()
    );
    Ok(())
}

/// The file of generation `k` for --every-step: `OUT` with `_k` before the
/// extension (`out.vtp` → `out_3.vtp`).
pub fn step_path(output: &Path, k: usize) -> PathBuf {
    let stem = output
        .file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_default();
    let name = match output.extension() {
        Some(ext) => format!("{stem}_{k}.{}", ext.to_string_lossy()),
        None => format!("{stem}_{k}"),
    };
    output.with_file_name(name)
}

/// Writes a surface with its face attributes (where the format has room).
fn write_with_attributes(
    path: &Path,
    mesh: &PolyMesh,
    attributes: &FaceAttributes,
    encoding: Encoding,
) -> Result<(), String> {
    let options = WriteOptions {
        encoding,
        attributes: Some(attributes),
    };
    write_surface_with(path, mesh, &options).map_err(|e| e.to_string())
}
