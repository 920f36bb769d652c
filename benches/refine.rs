//! Per-phase and full-step throughput of one uniform √3 step on generated
//! cube meshes (`cube_grid(n)`, 6n³ Kuhn tets) of about 100k, 1M and 5M tets,
//! reported as output tets per second (the tets the phase leaves behind).
//!
//! Each phase is timed by the step's own clock (`StepReport::phases`), so
//! the earlier phases of the same step, which have to run first, are not
//! counted in it; cloning the input is not counted either.
//!
//! The 5M size takes several minutes per phase group (criterion needs at
//! least ten samples, each one a step up to the phase). Choose sizes with
//! `TETREFINE_BENCH_SIZES`, e.g. `TETREFINE_BENCH_SIZES=100k,1M cargo bench
//! --bench refine`; the default is all three.

use criterion::{criterion_group, criterion_main, BenchmarkGroup, Criterion, Throughput};
use std::time::Duration;
use tetrefine::cube_grid;
use tetrefine::TetMesh;
use tetrefine::{refine_step, Phase, RefineOptions};

/// Benchmark sizes: label and grid resolution `n` (6n³ tets).
const SIZES: [(&str, usize); 3] = [
    ("100k", 26), // 105,456 tets
    ("1M", 55),   // 998,250 tets
    ("5M", 94),   // 4,983,504 tets
];

/// Sizes selected by `TETREFINE_BENCH_SIZES` (all when unset).
fn selected_sizes() -> Vec<(&'static str, usize)> {
    match std::env::var("TETREFINE_BENCH_SIZES") {
        Ok(list) => SIZES
            .iter()
            .copied()
            .filter(|(label, _)| {
                list.split(',')
                    .any(|s| s.trim().eq_ignore_ascii_case(label))
            })
            .collect(),
        Err(_) => SIZES.to_vec(),
    }
}

/// Times `iters` runs of one step with `opts` on clones of `mesh`; `pick`
/// chooses the measured seconds from the step's report.
fn time_steps(
    mesh: &TetMesh,
    opts: &RefineOptions,
    iters: u64,
    pick: impl Fn(&tetrefine::StepReport) -> f64,
) -> Duration {
    let mut total = Duration::ZERO;
    for _ in 0..iters {
        let mut m = mesh.clone();
        let r = refine_step(&mut m, 1, opts);
        total += Duration::from_secs_f64(pick(&r));
    }
    total
}

fn configure(group: &mut BenchmarkGroup<'_, criterion::measurement::WallTime>, n: usize) {
    group.sample_size(10);
    // Large meshes: let criterion take the few iterations it can get.
    group.measurement_time(Duration::from_secs(if n > 60 { 60 } else { 15 }));
    group.warm_up_time(Duration::from_secs(1));
}

fn bench_phases(c: &mut Criterion) {
    for (label, n) in selected_sizes() {
        let (mesh, _) = TetMesh::from_data(&cube_grid(n)).expect("cube grid builds");

        // One probe step gives every phase's output tet count.
        let mut probe = mesh.clone();
        let full = refine_step(&mut probe, 1, &RefineOptions::default());
        drop(probe);

        let mut group = c.benchmark_group(format!("refine_phase/{label}"));
        configure(&mut group, n);
        for (i, phase) in Phase::ALL.into_iter().enumerate() {
            let opts = RefineOptions {
                stop_after: Some(phase),
                ..Default::default()
            };
            group.throughput(Throughput::Elements(full.phases[i].tets as u64));
            group.bench_function(phase.name(), |b| {
                b.iter_custom(|iters| {
                    time_steps(&mesh, &opts, iters, |r| {
                        r.phases.last().expect("the phase ran").seconds
                    })
                })
            });
        }
        group.finish();

        let mut group = c.benchmark_group(format!("refine_step/{label}"));
        configure(&mut group, n);
        let out = full.phases.last().expect("six phases").tets as u64;
        group.throughput(Throughput::Elements(out));
        group.bench_function("full_step", |b| {
            b.iter_custom(|iters| {
                time_steps(&mesh, &RefineOptions::default(), iters, |r| r.seconds)
            })
        });
        group.finish();
    }
}

criterion_group!(benches, bench_phases);
criterion_main!(benches);
