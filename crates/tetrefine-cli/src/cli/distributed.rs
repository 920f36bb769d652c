//! `tetrefine refine` under `mpirun -n P` (feature `mpi`): rank 0 reads and
//! partitions, every rank refines its part, the cut moves once for a last
//! improvement, and the result is written as one `.vtu` piece per rank plus
//! a `.pvtu` (an `-o *.pvtu`), or gathered into one file of any format,
//! which rank 0 writes as the serial command does (point locations in the
//! input it kept, `--parent-map`, `--fields`/`--transfer`, `marked`). With
//! pieces, `--parent-map` and the fields come from rank 0 too, one piece at
//! a time ([`super::piece_fields`]); each rank writes its own.
//! A `.pvtu` input with a `.pvtu` output is read per rank instead
//! ([`super::pvtu_input`]).
//! Rank 0 prints the step table of the whole mesh; every file appears only
//! when every rank succeeded.

use super::piece_fields::{locate_pieces, Input, Located};
use super::progress::BarProgress;
use super::pvtu_merge::{RUN_CELL_ARRAYS, RUN_POINT_ARRAYS};
use super::refine::{mark_strategy, selection_of, Args, SmoothScope};
use super::steps::{peak_rss_bytes, StepStats};
use std::path::{Path, PathBuf};
use std::time::Instant;
use tetrefine::distributed::{self as dist, Comm, DistributedOptions, LocalMesh};
use tetrefine::io::{CellArray, PointArray, VtuSummary};
use tetrefine::report::{step_row, step_table_header};
use tetrefine::{MeshStats, RefineOptions};

/// Whether this `refine` runs distributed: a `.pvtu` output, or a launch by
/// `mpirun` with more than one rank (Open MPI's, MPICH's or PMIx's
/// environment says so).
pub fn wanted(a: &Args) -> bool {
    if is_pvtu(&a.output) {
        return true;
    }
    ["OMPI_COMM_WORLD_SIZE", "PMI_SIZE", "PMIX_SIZE"]
        .iter()
        .filter_map(|k| std::env::var(k).ok())
        .any(|v| v.trim().parse::<u32>().is_ok_and(|n| n > 1))
}

pub use super::pvtu_merge::is_pvtu;

/// The `--stats` file of a distributed run.
#[derive(serde::Serialize)]
struct StatsFile<'a> {
    ranks: u32,
    steps: &'a [StepStats],
    /// After the cut moved and the band it froze was improved.
    #[serde(skip_serializing_if = "Option::is_none")]
    after_cut_move: Option<&'a MeshStats>,
    /// Peak resident memory of each rank.
    rank_peak_rss_bytes: Vec<u64>,
    seconds: f64,
}

/// The checks of `a` made before any work (alike on every rank): the size
/// plan and the marking strategy they yield.
fn check_arguments(
    a: &Args,
    pieces: bool,
    pvtu_in: bool,
) -> Result<(super::size::Plan, Option<tetrefine::MarkStrategy>), String> {
    if !pieces {
        tetrefine::io::Format::for_writing(&a.output).map_err(|e| e.to_string())?;
    }
    super::outputs::refuse_shared_paths(&a.named_outputs())?;
    if let Some(f) = &a.features_out {
        tetrefine::PolylineFormat::of(f).map_err(|e| e.to_string())?;
    }
    let plan = super::size::plan(a)?;
    if pvtu_in && a.size.is_some() {
        return Err(format!(
            "{} is read per rank (a .pvtu input with a .pvtu output), and --size numbers the points of one whole mesh: write a .vtu output (rank 0 reads the whole input), or give --size-array NAME (a point array of the pieces), --hsiz or --hmax",
            a.input.display()
        ));
    }
    if let Some(h) = &a.histogram {
        super::check_histogram_path(h)?;
    }
    super::refine::check_numbers(a)?;
    Ok((plan, mark_strategy(a)?))
}

/// Runs `refine` distributed.
pub fn run(a: Args) -> super::CliResult {
    let pieces = is_pvtu(&a.output);
    let pvtu_in = super::pvtu_input::per_rank(&a);
    let (_universe, comm) = dist::init()?;
    // The arguments' checks fail alike on every rank: said once.
    let (plan, strategy) = comm.agree_alike(check_arguments(&a, pieces, pvtu_in))?;
    let n_steps = plan.n_steps;
    let t0 = Instant::now();
    let root = comm.rank == 0;
    let mut steps = Vec::new();
    let (mut input, meta, selection, transfer, mut local, first_selection) = if pvtu_in {
        // Every rank reads its own pieces; nobody holds the whole input.
        // With its size map (--size-array, --hsiz, --hmax; --size was
        // refused above).
        let local = super::pvtu_input::load_pieces(&comm, &a)?;
        let c = dist::census(&comm, &local.mesh)?;
        let first = dist::global_stats(&comm, &local.mesh, &c)?;
        if root {
            crate::say!("{}", step_table_header());
            crate::say!("{}", step_row("input", &first, 0.0));
            steps.push(StepStats::input(first));
        }
        (None, Default::default(), None, false, local, None)
    } else {
        // Rank 0 reads; its failure (a bad file) ends every rank.
        let loaded = if root {
            load_on_root(&a, strategy.as_ref())
        } else {
            Ok(None)
        };
        let loaded = comm.agree(loaded)?;
        let (input, meta, selection, transfer, size) = match loaded {
            Some((m, meta, s, t, size)) => (Some(m), meta, s, t, size),
            None => (None, Default::default(), None, false, None),
        };
        if let Some(m) = &input {
            let first = MeshStats::compute(m);
            crate::say!("{}", step_table_header());
            crate::say!("{}", step_row("input", &first, 0.0));
            steps.push(StepStats::input(first));
            eprintln!(
                "distributing {} tets over {} ranks (METIS)",
                m.n_tets(),
                comm.size
            );
        }
        // Size passes split where the map says, not uniformly: every tet
        // weighs alike (as one step's growth).
        let growth_steps = if plan.size_given { 1 } else { n_steps };
        let (local, first_selection) = dist::distribute(
            &comm,
            input.as_ref(),
            selection.as_deref(),
            size.as_ref(),
            growth_steps,
        )?;
        (input, meta, selection, transfer, local, first_selection)
    };
    // Pieces are located in the input (on rank 0) only for the parent map
    // and the fields; a gathered output always is, as the serial one.
    let locate = a.parent_map.is_some() || comm.sum(&[u64::from(transfer)])[0] > 0;
    if pieces && !locate {
        input = None;
    }
    // The steps the input has had (see `refine::step_offset`): from the
    // pieces each rank read, or from the file rank 0 read; said once.
    let step_offset = match a.step_offset {
        Some(k) => k,
        None => {
            let own = if pvtu_in {
                let all = tetrefine::io::read_pvtu_pieces(&a.input).unwrap_or_default();
                super::pvtu_input::own_pieces(&comm, &all)
                    .into_iter()
                    .map(|(_, p)| super::refine::steps_done(p))
                    .max()
                    .unwrap_or(0)
            } else if comm.rank == 0 && super::refine::is_vtu_or_pvtu(&a.input) {
                super::refine::steps_done(&a.input)
            } else {
                0
            };
            let steps = comm.all_gather(own as u64).into_iter().max().unwrap_or(0) as usize;
            if comm.rank == 0 {
                super::refine::note_steps_done(&a.input, steps);
            }
            steps
        }
    };
    let opts = DistributedOptions {
        refine: RefineOptions {
            boundary: a.boundary,
            opt_passes: a.opt_passes,
            threshold: a.threshold,
            stop_after: a.stop_after,
            selection: None,
            smooth_refined_only: first_selection.is_some() && a.smooth == SmoothScope::Refined,
            step_offset,
            check_each_phase: false,
            effort: a.effort,
            hausd: a.hausd,
            interfaces: a.interfaces,
        },
        steps: n_steps,
        // A step stopped early has not optimised: the cut stays.
        improve_across_cut: a.stop_after.is_none(),
    };
    let (census, last, moved) = if plan.size_given {
        let (census, last) = size_loop(&comm, &mut local, &a, &plan, &mut steps)?;
        (census, last, false)
    } else {
        // Rank 0's phases drive the bar (the parts are balanced by METIS).
        let bar = root.then(|| BarProgress::new(n_steps, tetrefine::Phase::ALL.len()));
        let progress: &dyn tetrefine::Progress = match &bar {
            Some(b) => b,
            None => &tetrefine::NoProgress,
        };
        let (census, last) = dist::refine_distributed(
            &comm,
            &mut local,
            first_selection,
            &opts,
            progress,
            |s, stats, report| {
                if let Some(b) = &bar {
                    b.suspend(|| {
                        crate::say!("{}", step_row(&format!("step {s}"), stats, report.seconds))
                    });
                    steps.push(StepStats::step(stats.clone(), report));
                }
            },
        )?;
        if let Some(b) = &bar {
            b.finish();
        }
        let moved = comm.size > 1 && n_steps > 0;
        if root && moved {
            crate::say!("{}", step_row("cut", &last, 0.0));
        }
        (census, last, moved)
    };
    if root && comm.size > 1 {
        eprintln!(
            "cut: {} partition faces ({:.2} % of the {} interior faces)",
            census.partition_faces / 2,
            100.0 * census.partition_faces as f64 / 2.0 / last.interior_faces.max(1) as f64,
            last.interior_faces
        );
    }
    let rss = comm.all_gather(peak_rss_bytes().unwrap_or(0));
    if root {
        eprintln!(
            "peak memory per rank: {}",
            rss.iter()
                .map(|b| format!("{:.1} MB", *b as f64 / 1e6))
                .collect::<Vec<_>>()
                .join(", ")
        );
    }
    local.mesh.compact();
    // The union on rank 0: the output itself, or the feature lines' source.
    let mut union = if !pieces || a.features_out.is_some() {
        dist::gather(&comm, &local)?
    } else {
        None
    };
    let written = if pieces {
        let located = if locate {
            let at = input.as_ref().map(|mesh| Input {
                mesh,
                meta: &meta,
                transfer,
            });
            Some(locate_pieces(&comm, at.as_ref(), &mut local.mesh)?)
        } else {
            None
        };
        // Rank 0's selection, per input tet, for each piece's `marked`
        // (empty: uniform, every tet marked).
        let selected = comm.broadcast(
            selection
                .as_deref()
                .map_or_else(Vec::new, |s| s.iter().map(|&x| u8::from(x)).collect()),
        );
        write_pieces(
            &comm,
            &a.output,
            a.parent_map.as_deref(),
            &mut local,
            located,
            &selected,
            &last,
        )
    } else {
        match (union.as_mut(), &input) {
            (Some(mesh), Some(input)) => {
                super::refine::write_output(&a, input, mesh, meta, transfer, selection.as_deref())
            }
            _ => Ok(()),
        }
    };
    comm.agree(written)?;
    let lines = match (&a.features_out, &union) {
        (Some(f), Some(m)) => super::write_feature_lines(f, m),
        _ => Ok(()),
    };
    comm.agree(lines)?;
    let extras = if root {
        write_root_extras(&a, &steps, moved.then_some(&last), rss, t0)
    } else {
        Ok(())
    };
    comm.agree(extras)?;
    if root {
        eprintln!(
            "wrote {} ({} tets on {} ranks) in {:.2}s",
            a.output.display(),
            last.tets,
            comm.size,
            t0.elapsed().as_secs_f64()
        );
    }
    Ok(())
}

/// The size passes of a run with a size map ([`dist::size_distributed`]):
/// a row per pass from rank 0, and the serial command's notes.
fn size_loop(
    comm: &Comm,
    local: &mut LocalMesh,
    a: &Args,
    plan: &super::size::Plan,
    steps: &mut Vec<StepStats>,
) -> Result<(dist::Census, MeshStats), String> {
    let root = comm.rank == 0;
    let opts = dist::DistributedSizeOptions {
        passes: plan.n_steps,
        until_met: plan.auto,
        improve: super::size::improve_options_of(a),
    };
    let mut said_moves = 0;
    let (census, last, r) = dist::size_distributed(comm, local, &opts, |s, stats, r, secs| {
        if !root {
            return;
        }
        if r.cut_moves > said_moves {
            eprintln!(
                "the cut moved ({}): the band it froze is improved, the passes go on",
                r.cut_moves
            );
            said_moves = r.cut_moves;
        }
        crate::say!("{}", step_row(&format!("size {s}"), stats, secs));
        eprintln!(
            "size pass {s}: {} long edges, {} split, {} refused (would invert a tet or fall below the worst quality so far, measured in the metric), {} still long, {} on the cut still long",
            r.long_edges, r.split, r.refused, r.long_after, r.long_on_cut
        );
        let report = tetrefine::StepReport {
            seconds: secs,
            ..tetrefine::StepReport::default()
        };
        steps.push(StepStats::step(stats.clone(), &report));
    })?;
    if root {
        super::size::note_still_long(r.long_after, r.split == 0, plan);
        if r.long_on_cut > 0 {
            eprintln!(
                "note: {} long edges lie on the cut between ranks where it ended; they stay whole (refining the output again splits them)",
                r.long_on_cut
            );
        }
    }
    Ok((census, last))
}

/// Rank 0's input, its metadata (with `--fields`), the selection and
/// whether the fields are carried over.
type Loaded = (
    tetrefine::TetMesh,
    tetrefine::io::MeshMeta,
    Option<Vec<bool>>,
    bool,
    Option<tetrefine::SizeMap>,
);

/// Rank 0: the input with its features, the selection and the size map.
fn load_on_root(
    a: &Args,
    strategy: Option<&tetrefine::MarkStrategy>,
) -> Result<Option<Loaded>, String> {
    let (mut input, mut meta) = super::load_with_meta(&a.input)?;
    let transfer = super::refine::load_fields(a, &input, &mut meta)?;
    let selection = selection_of(a, strategy, &input)?;
    super::apply_feature_option(&mut input, &a.features, a.feature_angle, a.interfaces)?;
    let size = super::size::size_map_of(a, &input, &meta)?;
    Ok(Some((input, meta, selection, transfer, size)))
}

/// `OUT_r.vtu` beside `OUT.pvtu` for rank `r`.
fn piece_path(pvtu: &Path, rank: u32) -> PathBuf {
    let stem = pvtu
        .file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_default();
    pvtu.with_file_name(format!("{stem}_{rank}.vtu"))
}

/// `MAP_r.EXT` beside `MAP.EXT` (`MAP_r` without an extension): rank `r`'s
/// `--parent-map` with a `.pvtu` output.
pub fn piece_map_path(map: &Path, rank: u32) -> PathBuf {
    let stem = map
        .file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_default();
    match map.extension() {
        Some(e) => map.with_file_name(format!("{stem}_{rank}.{}", e.to_string_lossy())),
        None => map.with_file_name(format!("{stem}_{rank}")),
    }
}

/// A field named like one of the pieces' own arrays (`GlobalPointIds`,
/// `rank`) gets `_input` appended, as the serial arrays' names do.
fn rename_clashes(fields: &mut [tetrefine::io::Field], taken: &[&str]) {
    for f in fields.iter_mut() {
        f.name = super::transfer::vtu_name(&f.name, taken);
    }
}

/// One `.vtu` per rank (with `GlobalPointIds`, `rank`, `level`, `parent`,
/// `marked` (from `selected`, rank 0's selection per input tet) and the
/// quality arrays; with `located`, the vertex parent map's arrays
/// and the input's fields, and `parent` is the input tet holding each
/// centroid), `MAP_r` for `--parent-map MAP`, and on rank 0 the `.pvtu`
/// listing the pieces with the same arrays.
fn write_pieces(
    comm: &Comm,
    pvtu: &Path,
    parent_map: Option<&Path>,
    local: &mut LocalMesh,
    located: Option<Located>,
    selected: &[u8],
    global: &MeshStats,
) -> Result<(), String> {
    let ids = dist::global_point_ids(comm, &local.mesh)?;
    dist::strip_partition_markers(local);
    let mesh = &local.mesh;
    let gids = ids
        .iter()
        .map(|&g| i32::try_from(g).map_err(|_| format!("global point id {g} exceeds Int32")))
        .collect::<Result<Vec<i32>, String>>()?;
    let n = mesh.n_tets();
    let rank = comm.rank as i32;
    let level = |i: usize| i32::from(mesh.level(i as u32));
    let parent = |i: usize| mesh.parent(i as u32) as i32;
    let rank_of = |_: usize| rank;
    // As the serial output's: whether the tet's `parent` was selected
    // (every tet of a uniform run).
    let marked = |i: usize| {
        let p = mesh.parent(i as u32) as usize;
        i32::from(selected.is_empty() || selected.get(p).is_some_and(|&x| x == 1))
    };
    let mut cells = vec![
        CellArray::Int32With("level".into(), n, &level),
        CellArray::Int32With("parent".into(), n, &parent),
        CellArray::Int32With("marked".into(), n, &marked),
        CellArray::Int32With("rank".into(), n, &rank_of),
    ];
    let mut points = vec![PointArray::Int32("GlobalPointIds".into(), 1, gids)];
    if let Some(mut l) = located {
        if let Some(map) = parent_map {
            let vertices = |i: usize| l.vertices[i];
            super::transfer::write_parent_map(
                &piece_map_path(map, comm.rank),
                &vertices,
                mesh,
                &l.locations,
            )?;
        }
        rename_clashes(&mut l.point_fields, &RUN_POINT_ARRAYS);
        rename_clashes(&mut l.cell_fields, &RUN_CELL_ARRAYS);
        let (p, c) = super::transfer::vtu_arrays(
            &|i| l.vertices[i],
            Some(&l.locations),
            &l.point_fields,
            &l.cell_fields,
        );
        points.extend(p);
        cells.extend(c);
    }
    let valence = MeshStats::vertex_valence(mesh);
    let summary = VtuSummary {
        valence: &valence,
        histogram_counts: &global.histogram.counts,
        histogram_edges_deg: &global.histogram.edges_deg,
    };
    let piece = piece_path(pvtu, comm.rank);
    tetrefine::io::write_vtu_with(&piece, mesh, Some(&summary), &cells, &points)
        .map_err(|e| e.to_string())?;
    if comm.rank == 0 {
        let names: Vec<String> = (0..comm.size)
            .map(|r| {
                piece_path(pvtu, r)
                    .file_name()
                    .map(|s| s.to_string_lossy().into_owned())
                    .unwrap_or_default()
            })
            .collect();
        tetrefine::io::write_pvtu(pvtu, &names, true, &cells, &points)
            .map_err(|e| e.to_string())?;
    }
    Ok(())
}

/// Rank 0: `--stats` and `--histogram` of the whole mesh.
fn write_root_extras(
    a: &Args,
    steps: &[StepStats],
    after: Option<&MeshStats>,
    rss: Vec<u64>,
    t0: Instant,
) -> super::CliResult {
    if let Some(path) = &a.stats {
        let file = StatsFile {
            ranks: rss.len() as u32,
            steps,
            after_cut_move: after,
            rank_peak_rss_bytes: rss,
            seconds: t0.elapsed().as_secs_f64(),
        };
        let text = serde_json::to_string_pretty(&file).map_err(|e| e.to_string())?;
        tetrefine::io::write_atomic(path, |w| std::io::Write::write_all(w, text.as_bytes()))
            .map_err(|e| e.to_string())?;
    }
    if let Some(h) = &a.histogram {
        let last = after.unwrap_or(&steps.last().expect("input entry").stats);
        super::write_histogram(h, last)?;
    }
    Ok(())
}
