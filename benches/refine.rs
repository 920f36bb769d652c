//! Per-phase timing of one √3 step on a generated ~300k-tet cube mesh
//! (`cube_grid(37)`: 303,918 tets), reported as output tets per second.
//! Each phase is timed by the step's own clock (`StepReport::phases`), so
//! the preceding phases of the same step are not counted in it.

use criterion::{criterion_group, criterion_main, Criterion, Throughput};
use std::time::Duration;
use tetrefine::mesh::generate::cube_grid;
use tetrefine::refine::{refine_step, Phase, RefineOptions};
use tetrefine::TetMesh;

fn bench_phases(c: &mut Criterion) {
    let (mesh, _) = TetMesh::from_data(&cube_grid(37)).unwrap();
    let mut group = c.benchmark_group("refine_phase");
    group.sample_size(10);
    group.measurement_time(Duration::from_secs(20));
    for phase in Phase::ALL {
        let opts = RefineOptions {
            stop_after: Some(phase),
            ..Default::default()
        };
        // Output tets of the phase, for the throughput figure.
        let mut probe = mesh.clone();
        let r = refine_step(&mut probe, 1, &opts);
        let out = r.phases.last().map(|p| p.tets).unwrap_or(0) as u64;
        group.throughput(Throughput::Elements(out));
        group.bench_function(phase.name(), |b| {
            b.iter_custom(|iters| {
                let mut total = Duration::ZERO;
                for _ in 0..iters {
                    let mut m = mesh.clone();
                    let r = refine_step(&mut m, 1, &opts);
                    let p = r.phases.last().expect("the phase ran");
                    total += Duration::from_secs_f64(p.seconds);
                }
                total
            })
        });
    }
    group.finish();

    // The whole step, all phases.
    let mut group = c.benchmark_group("refine_step");
    group.sample_size(10);
    group.measurement_time(Duration::from_secs(30));
    let mut probe = mesh.clone();
    refine_step(&mut probe, 1, &RefineOptions::default());
    group.throughput(Throughput::Elements(probe.n_tets() as u64));
    group.bench_function("full_step", |b| {
        b.iter_custom(|iters| {
            let mut total = Duration::ZERO;
            for _ in 0..iters {
                let mut m = mesh.clone();
                let r = refine_step(&mut m, 1, &RefineOptions::default());
                total += Duration::from_secs_f64(r.seconds);
            }
            total
        })
    });
    group.finish();
}

criterion_group!(benches, bench_phases);
criterion_main!(benches);
