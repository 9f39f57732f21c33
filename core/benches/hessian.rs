//! What a Newton-type engine would pay per element: the 12 × 12 Hessian of one tet's energy
//! (½ C²/α of a family's constraints on it), by AD (forward mode over ∇C, what `tetlab modes`
//! and the workbench use) for each built-in family and two example files, by second-order dual
//! numbers (the independent check), and for the neo-Hookean pair by its analytic eigensystem in
//! F-space (|V₀| Bᵀ H_F B); then its eigen-decomposition. `cargo bench -p tetlab-core --bench
//! hessian`.

use criterion::{Criterion, criterion_group, criterion_main};
use glam::DVec3;
use std::hint::black_box;
use tetlab_core::constraint_file::ConstraintFile;
use tetlab_core::constraints::Families;
use tetlab_core::energy::element::ElementEnergy;
use tetlab_core::energy::hessian::{coordinates, hessian, second_order};
use tetlab_core::energy::modes::Modes;
use tetlab_core::energy::neohookean::{Parameters, projected_in_f_space};
use tetlab_core::simulation::Settings;

fn hessians(c: &mut Criterion) {
    let rest = [DVec3::ZERO, DVec3::X, DVec3::Y, DVec3::Z];
    // A deformed tet, away from every symmetry.
    let x = [
        DVec3::new(0.0, 0.0, 0.0),
        DVec3::new(1.1, 0.1, 0.0),
        DVec3::new(0.2, 0.9, 0.1),
        DVec3::new(0.1, 0.2, 0.7),
    ];
    let mut families = Families::builtin();
    for name in ["volume.toml", "neohookean.toml"] {
        let example = tetlab_core::constraint_file::EXAMPLES
            .iter()
            .find(|e| e.file == name)
            .unwrap();
        let files = ConstraintFile::parse_all(&example.shown(), example.text).unwrap();
        families.register_all(files).unwrap();
    }
    let settings = Settings::default();
    let energy = |list: &str| {
        let active = families.parse_list(list).unwrap();
        ElementEnergy::new(&families, &active, &settings, rest).unwrap()
    };
    let coordinates = coordinates(&x);
    let mut group = c.benchmark_group("hessian per element");
    for (label, list) in [
        ("edges", "edges"),
        ("height", "height"),
        ("volume", "volume"),
        ("neohookean", "neohookean"),
        ("volume.toml", "my-volume"),
        // A file of several constraints is named by the file's name, for all of them.
        ("neohookean.toml", "my-neohookean"),
    ] {
        let e = energy(list);
        group.bench_function(format!("{label}, AD"), |b| {
            b.iter(|| hessian(black_box(&e), black_box(&coordinates)))
        });
        group.bench_function(format!("{label}, second-order duals"), |b| {
            b.iter(|| second_order(black_box(&e), black_box(&coordinates)))
        });
    }
    let p = Parameters::of(&settings.material);
    let edges = |q: &[DVec3; 4]| glam::DMat3::from_cols(q[1] - q[0], q[2] - q[0], q[3] - q[0]);
    group.bench_function("neohookean, analytic in F-space", |b| {
        b.iter(|| {
            let f = edges(black_box(&x)) * edges(&rest).inverse();
            projected_in_f_space(&rest, &f, &p, false)
        })
    });
    let e = energy("volume");
    group.bench_function("eigen-decomposition and classes (Modes::of_matrix)", |b| {
        let h = hessian(&e, &coordinates);
        b.iter(|| Modes::of_matrix(black_box(h), &x, &rest, 1.0))
    });
    group.finish();
}

criterion_group!(benches, hessians);
criterion_main!(benches);
