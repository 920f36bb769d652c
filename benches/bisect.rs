//! One uniform 1:8 red refinement step (`refine::bisect`) on generated cube
//! meshes of ~100k and ~1M tets; throughput in output tets per second.

use criterion::{criterion_group, criterion_main, BenchmarkId, Criterion, Throughput};
use std::time::Duration;
use tetrefine::bisect;

fn bench_bisect(c: &mut Criterion) {
    let mut group = c.benchmark_group("bisect");
    group.sample_size(10);
    group.warm_up_time(Duration::from_secs(1));
    group.measurement_time(Duration::from_secs(5));
    // 6 n³ tets: 26 → 105,456; 55 → 998,250.
    for n in [26usize, 55] {
        let mesh = tetrefine::TetMesh::from_data(&tetrefine::cube_grid(n))
            .expect("the cube grid is a valid mesh")
            .0;
        let input = mesh.n_tets();
        group.throughput(Throughput::Elements(8 * input as u64));
        group.bench_with_input(BenchmarkId::new("cube", input), &mesh, |b, m| {
            b.iter(|| bisect(m).expect("the cube bisects"))
        });
    }
    group.finish();
}

criterion_group!(benches, bench_bisect);
criterion_main!(benches);
