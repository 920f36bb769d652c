//! `tetrefine surface SCHEME IN -o OUT --steps N [options]`.

use std::path::PathBuf;
use tetrefine::surface::catmull_clark::catmull_clark;
use tetrefine::surface::catmull_clark_weighted::{catmull_clark_weighted, WeightedConfig};
use tetrefine::surface::doo_sabin::doo_sabin;
use tetrefine::surface::loop_scheme::loop_subdivide;
use tetrefine::surface::sqrt3::{sqrt3, FaceSelection, Sqrt3Options, Sqrt3Rule};
use tetrefine::surface::{load_surface, write_surface, Features, PolyMesh, SurfaceFormat};

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
    // Sierpinski, Truncate and Ifs are wired here by the lead after merging
    // the other surface branch (see the match in `run`).
}

/// Arguments of `surface`.
#[derive(clap::Args)]
pub struct Args {
    /// Subdivision scheme.
    #[arg(value_enum)]
    pub scheme: Scheme,
    /// Input surface (.obj, .off, .ply).
    pub input: PathBuf,
    /// Output surface (.obj, .off, .ply, .vtp, .vtk).
    #[arg(short, long)]
    pub output: PathBuf,
    /// Number of subdivision steps.
    #[arg(long, default_value_t = 1)]
    pub steps: usize,
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
}

/// Faces above which a run is refused rather than exhausting memory.
const MAX_FACES: f64 = 2.0e8;

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

/// Runs `surface`.
pub fn run(a: Args) -> super::CliResult {
    SurfaceFormat::of(&a.output).map_err(|e| e.to_string())?;
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
    if a.weights.is_some() && a.scheme != Scheme::CatmullClarkWeighted {
        return Err("--weights is for catmull-clark-weighted".into());
    }
    let features = Features {
        creases: a
            .crease
            .iter()
            .map(|s| parse_crease(s))
            .collect::<Result<_, _>>()?,
        corners: a.corner.clone(),
        crease_angle: a.crease_angle,
    };
    if a.scheme == Scheme::DooSabin && features != Features::default() {
        return Err("doo-sabin does not support creases or corners".into());
    }
    let weights = match &a.weights {
        Some(p) => Some(WeightedConfig::from_json_file(p).map_err(|e| e.to_string())?),
        None => None,
    };
    let mesh = load_surface(&a.input).map_err(|e| e.to_string())?;
    let growth: f64 = if is_sqrt3 { 3.0 } else { 4.0 };
    let sides: usize = mesh.faces.iter().map(|f| f.len()).sum();
    let predicted = sides as f64 * growth.powi(a.steps.saturating_sub(1).min(64) as i32);
    if predicted > MAX_FACES {
        return Err(format!(
            "{} steps would make about {predicted:.2e} faces; use fewer steps",
            a.steps
        ));
    }
    let ctx = |e: tetrefine::surface::SubdivisionError| format!("{}: {e}", a.input.display());
    // One arm per scheme; Sierpinski, Truncate and Ifs get their arms here
    // when the other surface branch is merged.
    let out: PolyMesh = match a.scheme {
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
            sqrt3(&mesh, rule, a.steps, &opts).map_err(ctx)?
        }
        Scheme::Loop => loop_subdivide(&mesh, a.steps, &features).map_err(ctx)?,
        Scheme::CatmullClark => catmull_clark(&mesh, a.steps, &features).map_err(ctx)?,
        Scheme::DooSabin => doo_sabin(&mesh, a.steps).map_err(ctx)?,
        Scheme::CatmullClarkWeighted => {
            let cfg = weights.unwrap_or_default();
            catmull_clark_weighted(&mesh, a.steps, &cfg, &features).map_err(ctx)?
        }
    };
    write_surface(&a.output, &out).map_err(|e| e.to_string())?;
    eprintln!(
        "wrote {}: {} vertices, {} edges, {} faces, Euler characteristic {}",
        a.output.display(),
        out.used_vertices(),
        out.edge_list().len(),
        out.faces.len(),
        out.euler_characteristic()
    );
    Ok(())
}
