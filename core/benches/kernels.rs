//! The projection kernels alone: one constraint evaluated and its correction computed, in f32 (the
//! fast solver), f64 (the reference) and four at once in f32 SIMD lanes (the fast solver's main
//! loop), for each family. `cargo bench -p tetlab-core`.

use criterion::{Criterion, criterion_group, criterion_main};
use glam::{DVec3, Vec3A};
use std::hint::black_box;
use tetlab_core::constraints::{distance, plane, volume};
use tetlab_core::lanes::{F32x4, Vec3x4};
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
    // Four constraints at once in SIMD lanes (time per four).
    let lanes = tet32.map(|p| Vec3x4::gather([p; 4]));
    let w4 = w32.map(|x| F32x4::new([x; 4]));
    let rest4 = |r: f32| F32x4::new([r; 4]);
    group.bench_function("distance f32 x4 lanes", |b| {
        b.iter(|| {
            project_kernel(
                distance::evaluate::<Vec3x4>,
                black_box(&[lanes[0], lanes[1]]),
                rest4(0.9),
                [w4[0], w4[1]],
            )
        })
    });
    group.bench_function("plane f32 x4 lanes", |b| {
        b.iter(|| project_kernel(plane::evaluate::<Vec3x4>, black_box(&lanes), rest4(0.7), w4))
    });
    group.bench_function("volume f32 x4 lanes", |b| {
        b.iter(|| {
            project_kernel(
                volume::evaluate::<Vec3x4>,
                black_box(&lanes),
                rest4(0.2),
                w4,
            )
        })
    });
    group.finish();
}

criterion_group!(benches, kernels);
criterion_main!(benches);
