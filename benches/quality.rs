//! Throughput of [`MeshStats::compute`] on a generated cube grid of over a
//! million tets (Freudenthal/Kuhn, n = 56: 6·56³ = 1,053,696 tets).
//! Criterion reports tets/s. Target (issue 2): ≥ 30M tets/s on 2 cores.

use criterion::{criterion_group, criterion_main, Criterion, Throughput};
use std::hint::black_box;
use std::time::Duration;
use tetrefine::cube_grid;
use tetrefine::{MeshStats, TetMesh};

fn quality_stats(c: &mut Criterion) {
    let n = 56;
    let (mesh, _) = TetMesh::from_data(&cube_grid(n)).expect("cube grid builds");
    let tets = mesh.n_tets() as u64;
    assert_eq!(tets, 6 * (n as u64).pow(3));

    let mut g = c.benchmark_group("quality");
    g.sample_size(10)
        .warm_up_time(Duration::from_secs(1))
        .measurement_time(Duration::from_secs(4))
        .throughput(Throughput::Elements(tets));
    g.bench_function("MeshStats::compute, cube grid 1.05M tets", |b| {
        b.iter(|| black_box(MeshStats::compute(black_box(&mesh))))
    });
    g.finish();
}

criterion_group!(benches, quality_stats);
criterion_main!(benches);
