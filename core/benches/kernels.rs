//! The projection kernels alone: one constraint evaluated and its correction computed, in f32 (the
//! fast solver) and f64 (the reference), for each family. `cargo bench -p tetlab-core`.

use criterion::{Criterion, criterion_group, criterion_main};
use glam::{DVec3, Vec3A};
use std::hint::black_box;
use tetlab_core::constraints::{distance, plane, volume};
use tetlab_core::solver::project_kernel;

fn kernels(c: &mut Criterion) {
    let tet = [
        DVec3::new(0.0, 0.0, 0.0),
        DVec3::new(1.0, 0.1, 0.0),
        DVec3::new(0.2, 1.0, 0.1),
        DVec3::new(0.1, 0.2, 0.9),
    ];
    let tet32 = tet.map(|p| p.as_vec3a());
    let w = [1.0, 0.5, 0.8, 1.2];
    let w32 = w.map(|x| x as f32);
    let mut group = c.benchmark_group("projection");
    group.bench_function("distance f32", |b| {
        b.iter(|| {
            project_kernel(
                distance::evaluate::<Vec3A>,
                black_box(&[tet32[0], tet32[1]]),
                0.9,
                [w32[0], w32[1]],
            )
        })
    });
    group.bench_function("distance f64", |b| {
        b.iter(|| {
            project_kernel(
                distance::evaluate::<DVec3>,
                black_box(&[tet[0], tet[1]]),
                0.9,
                [w[0], w[1]],
            )
        })
    });
    group.bench_function("plane f32", |b| {
        b.iter(|| project_kernel(plane::evaluate::<Vec3A>, black_box(&tet32), 0.7, w32))
    });
    group.bench_function("plane f64", |b| {
        b.iter(|| project_kernel(plane::evaluate::<DVec3>, black_box(&tet), 0.7, w))
    });
    group.bench_function("volume f32", |b| {
        b.iter(|| project_kernel(volume::evaluate::<Vec3A>, black_box(&tet32), 0.2, w32))
    });
    group.bench_function("volume f64", |b| {
        b.iter(|| project_kernel(volume::evaluate::<DVec3>, black_box(&tet), 0.2, w))
    });
    group.finish();
}

criterion_group!(benches, kernels);
criterion_main!(benches);
