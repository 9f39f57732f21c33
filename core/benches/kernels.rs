//! The projection kernels alone: one constraint evaluated and its correction computed, in f32 (the
//! fast solver), f64 (the reference) and eight at once in f32 SIMD lanes (the fast solver's main
//! loop), for each family; a height constraint read from a file (assets/constraints/height.toml)
//! against the built-in one; and one whole frame of the fast solver beside the same frame's
//! arithmetic alone (its kernels on particles already in registers). `cargo bench -p tetlab-core`.

use criterion::{Criterion, criterion_group, criterion_main};
use glam::{DVec3, Vec3A};
use std::hint::black_box;
use tetlab_core::constraint_file::ConstraintFile;
use tetlab_core::constraints::{Family, PerFamily};
use tetlab_core::constraints::{distance, height, volume};
use tetlab_core::numbers::lanes::{F32x8, LANES, Vec3x8};
use tetlab_core::numbers::vector::Real;
use tetlab_core::scene::{Builtin, Scene};
use tetlab_core::simulation::fast::{FastSimulation, Order};
use tetlab_core::simulation::projection::project_kernel;
use tetlab_core::simulation::{Settings, Simulation};

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
                1e3,
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
                1e3,
            )
        })
    });
    group.bench_function("height f32", |b| {
        b.iter(|| project_kernel(height::evaluate::<Vec3A>, black_box(&tet32), 0.7, w32, 1e3))
    });
    group.bench_function("height f64", |b| {
        b.iter(|| project_kernel(height::evaluate::<DVec3>, black_box(&tet), 0.7, w, 1e3))
    });
    group.bench_function("volume f32", |b| {
        b.iter(|| project_kernel(volume::evaluate::<Vec3A>, black_box(&tet32), 0.2, w32, 1e3))
    });
    group.bench_function("volume f64", |b| {
        b.iter(|| project_kernel(volume::evaluate::<DVec3>, black_box(&tet), 0.2, w, 1e3))
    });
    // Eight constraints at once in SIMD lanes (time per eight).
    let lanes = tet32.map(|p| Vec3x8::gather([p; LANES]));
    let w4 = w32.map(|x| F32x8::new([x; LANES]));
    let rest4 = |r: f32| F32x8::new([r; LANES]);
    group.bench_function("distance f32 x8 lanes", |b| {
        b.iter(|| {
            project_kernel(
                distance::evaluate::<Vec3x8>,
                black_box(&[lanes[0], lanes[1]]),
                rest4(0.9),
                [w4[0], w4[1]],
                rest4(1e3),
            )
        })
    });
    group.bench_function("height f32 x8 lanes", |b| {
        b.iter(|| {
            project_kernel(
                height::evaluate::<Vec3x8>,
                black_box(&lanes),
                rest4(0.7),
                w4,
                rest4(1e3),
            )
        })
    });
    group.bench_function("volume f32 x8 lanes", |b| {
        b.iter(|| {
            project_kernel(
                volume::evaluate::<Vec3x8>,
                black_box(&lanes),
                rest4(0.2),
                w4,
                rest4(1e3),
            )
        })
    });
    group.finish();
}

/// C and ∇C of the height: the built-in formula, and the same constraint compiled from
/// assets/constraints/height.toml, with ∇C by reverse-mode AD (what a simulation uses: one pass
/// forward, one back), by forward-mode AD (what `check-gradients` compares with: 12 passes) and
/// with the file's own gradient (`use_gradient`, one pass).
fn constraint_file(c: &mut Criterion) {
    let tet = [
        DVec3::new(0.0, 0.0, 0.0),
        DVec3::new(1.0, 0.1, 0.0),
        DVec3::new(0.2, 1.0, 0.1),
        DVec3::new(0.1, 0.2, 0.9),
    ];
    let path =
        std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../assets/constraints/height.toml");
    let mut file = ConstraintFile::load(&path).expect("the example file");
    let mut group = c.benchmark_group("height evaluation f64");
    group.bench_function("built-in", |b| {
        b.iter(|| height::evaluate::<DVec3>(black_box(&tet), 0.7))
    });
    group.bench_function("file, AD", |b| {
        b.iter(|| file.evaluate_vectors(black_box(&tet), 0.7, &[]))
    });
    group.bench_function("file, forward-mode AD", |b| {
        b.iter(|| file.evaluate(black_box(&tet), 0.7, &[]))
    });
    file.use_gradient = true;
    group.bench_function("file, its own gradient", |b| {
        b.iter(|| file.evaluate_vectors(black_box(&tet), 0.7, &[]))
    });
    group.finish();
}

/// C and ∇C of sixteen constraints in the fast engine's lanes (two batches of eight, as its kernel
/// hands them to a file's family): the built-in volume and neo-Hookean pair against the same
/// constraints from assets/constraints/volume.toml and neohookean.toml. What a file's tape costs
/// beside the formula it replaces, without the projection around it.
fn file_in_lanes(c: &mut Criterion) {
    use tetlab_core::constraints::file::FileConstraint;
    use tetlab_core::constraints::material::Material;
    use tetlab_core::constraints::neohookean::{Deviatoric, Hydrostatic};
    use tetlab_core::constraints::{Constraint, GROUP};
    let tet = [
        DVec3::new(0.0, 0.0, 0.0),
        DVec3::new(1.0, 0.1, 0.0),
        DVec3::new(0.2, 1.0, 0.1),
        DVec3::new(0.1, 0.2, 0.9),
    ];
    let rest_shape = tet.map(|p| p * 1.1);
    // Lane k of batch j a slightly different tet, so that no two lanes are alike.
    let lanes = |points: &[DVec3; 4], j: usize| {
        points.map(|p| {
            Vec3x8::gather(std::array::from_fn(|k| {
                (p + DVec3::splat(0.01 * (k + 8 * j) as f64)).as_vec3a()
            }))
        })
    };
    let p: [[Vec3x8; 4]; GROUP] = std::array::from_fn(|j| lanes(&tet, j));
    let shape: [[Vec3x8; 4]; GROUP] = std::array::from_fn(|j| lanes(&rest_shape, j));
    let rest = [F32x8::new([0.1; LANES]); GROUP];
    let folder = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../assets/constraints");
    let material = Material::default();
    let mut group = c.benchmark_group("sixteen constraints in lanes");
    group.bench_function("volume, built-in", |b| {
        b.iter(|| {
            volume::Volume.evaluate_batches(
                black_box(&p),
                rest,
                &shape,
                [&[]; GROUP],
                (&p, F32x8::ONE),
            )
        })
    });
    let file = ConstraintFile::load(&folder.join("volume.toml")).expect("the example file");
    let file = FileConstraint::<4>(std::sync::Arc::new(file));
    group.bench_function("volume, file", |b| {
        b.iter(|| {
            file.evaluate_batches(black_box(&p), rest, &shape, [&[]; GROUP], (&p, F32x8::ONE))
        })
    });
    group.bench_function("neo-Hookean pair, built-in", |b| {
        b.iter(|| {
            (
                Deviatoric.evaluate_batches(
                    black_box(&p),
                    rest,
                    &shape,
                    [&[]; GROUP],
                    (&p, F32x8::ONE),
                ),
                Hydrostatic.evaluate_batches(
                    black_box(&p),
                    rest,
                    &shape,
                    [&[]; GROUP],
                    (&p, F32x8::ONE),
                ),
            )
        })
    });
    let files = ConstraintFile::load_all(&folder.join("neohookean.toml")).expect("the example");
    let stored: Vec<Vec<F32x8>> = files
        .iter()
        .map(|file| {
            let numbers = file.store(&rest_shape, &material);
            numbers
                .iter()
                .map(|&x| F32x8::new([x as f32; LANES]))
                .collect()
        })
        .collect();
    let files: Vec<FileConstraint<4>> = files
        .into_iter()
        .map(|file| FileConstraint(std::sync::Arc::new(file)))
        .collect();
    group.bench_function("neo-Hookean deviatoric alone, file", |b| {
        b.iter(|| {
            files[0].evaluate_batches(
                black_box(&p),
                rest,
                &shape,
                [&stored[0]; GROUP],
                (&p, F32x8::ONE),
            )
        })
    });
    group.bench_function("neo-Hookean pair, file", |b| {
        b.iter(|| {
            let [a, b] = [&files[0], &files[1]];
            (
                a.evaluate_batches(
                    black_box(&p),
                    rest,
                    &shape,
                    [&stored[0]; GROUP],
                    (&p, F32x8::ONE),
                ),
                b.evaluate_batches(
                    black_box(&p),
                    rest,
                    &shape,
                    [&stored[1]; GROUP],
                    (&p, F32x8::ONE),
                ),
            )
        })
    });
    group.finish();
}

/// One frame of the fast solver (edges + volume, 10 substeps) on the bunny of ../shared/meshes, or
/// on a cube of about the same size when the shared meshes are not there: Gauss–Seidel and
/// Jacobi. The same work as `tetlab bench`, here so that builds for other CPUs are quick to
/// compare (`RUSTFLAGS="-C target-cpu=x86-64" cargo bench -p tetlab-core -- frame`).
fn frame(c: &mut Criterion) {
    let bunny = tetlab_core::input::shared_meshes::folder().join("bunny.node");
    let (name, scene) = match Scene::load(&bunny) {
        Ok(scene) => ("bunny", scene),
        Err(_) => (
            "cube 6",
            Scene::builtin(Builtin::Cube, 6).expect("a built-in cube"),
        ),
    };
    let settings = Settings {
        active: PerFamily::builtin_list("edges,volume").expect("two families"),
        substeps: 10,
        ..Settings::default()
    };
    let simulation = Simulation::new(&scene, settings);
    let mut group = c.benchmark_group("frame");
    for (order, label) in [
        (Order::GaussSeidel, "Gauss-Seidel"),
        (Order::Jacobi { relaxation: 1.0 }, "Jacobi"),
    ] {
        let mut fast = FastSimulation::new(simulation.start());
        fast.set_order(order);
        group.bench_function(format!("{name}, fast, {label}"), |b| b.iter(|| fast.step()));
    }
    // The same frame's arithmetic alone: the same kernels, as many times as the Gauss–Seidel
    // frame runs them (every batch of eight of each family, padding included, every substep),
    // on particles already in registers. The frame's time over this one is what moving the
    // particles (gathering, transposing, writing back) and the rest of the frame cost on top.
    let fast = FastSimulation::new(simulation.start());
    let batches = |family| -> usize {
        let batches = fast.batches(family);
        batches.colours().iter().map(|c| c.batches.len()).sum()
    };
    let (edge_batches, tet_batches) = (batches(Family::EDGES), batches(Family::VOLUME));
    let substeps = settings.substeps;
    let tet = [
        Vec3A::new(0.0, 0.0, 0.0),
        Vec3A::new(1.0, 0.1, 0.0),
        Vec3A::new(0.2, 1.0, 0.1),
        Vec3A::new(0.1, 0.2, 0.9),
    ]
    .map(|p| Vec3x8::gather([p; LANES]));
    let edge = [tet[0], tet[1]];
    let w = F32x8::new([0.7; LANES]);
    group.bench_function(format!("{name}, arithmetic alone"), |b| {
        b.iter(|| {
            for _ in 0..substeps {
                for _ in 0..edge_batches {
                    black_box(project_kernel(
                        distance::evaluate::<Vec3x8>,
                        black_box(&edge),
                        F32x8::new([0.9; LANES]),
                        [w; 2],
                        F32x8::new([1e3; LANES]),
                    ));
                }
                for _ in 0..tet_batches {
                    black_box(project_kernel(
                        volume::evaluate::<Vec3x8>,
                        black_box(&tet),
                        F32x8::new([0.2; LANES]),
                        [w; 4],
                        F32x8::new([1e3; LANES]),
                    ));
                }
            }
        })
    });
    group.finish();
}

criterion_group!(benches, kernels, constraint_file, file_in_lanes, frame);
criterion_main!(benches);
