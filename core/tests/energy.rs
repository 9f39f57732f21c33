//! The Hessian of every family's energy and of every example constraint file's, checked the way
//! HOBAK's tests check theirs, and further: against central differences over several decades
//! (the error falls as ε²), against a second, independent AD, for symmetry, and by the number of
//! its zero eigenvalues where that number is known; and the neo-Hookean energy's analytic
//! eigensystem against a numeric one at HOBAK's configurations and inverted ones.

#[path = "support/example_files.rs"]
mod example_files;
use example_files::example_files;
use glam::{DMat3, DQuat, DVec3};
use tetlab_core::constraint_file::ConstraintFile;
use tetlab_core::constraints::material::Material;
use tetlab_core::constraints::{Binding, Families, PerFamily};
use tetlab_core::energy::element::ElementEnergy;
use tetlab_core::energy::hessian::{
    Matrix12, asymmetry, convergence, coordinates, hessian, second_order,
};
use tetlab_core::energy::modes::{Class, Modes};
use tetlab_core::energy::neohookean::{
    Matrix9, Parameters, analytic, d_f_d_x, f_space_shares, hessian_by_ad,
};
use tetlab_core::energy::svd::signed_svd;
use tetlab_core::numbers::random::SplitMix64;
use tetlab_core::simulation::Settings;

/// A tet of good shape.
const REST: [DVec3; 4] = [
    DVec3::new(0.0, 0.0, 0.0),
    DVec3::new(1.0, 0.1, 0.0),
    DVec3::new(0.2, 0.9, 0.1),
    DVec3::new(0.1, 0.2, 1.1),
];

/// Every built-in group and every example file, as (name, table, active families).
fn every_energy() -> Vec<(String, Families, PerFamily<bool>)> {
    let builtin = Families::builtin();
    let mut out: Vec<_> = ["edges", "height", "volume", "neohookean"]
        .iter()
        .map(|name| {
            let active = builtin.parse_list(name).unwrap();
            (name.to_string(), builtin.clone(), active)
        })
        .collect();
    for path in example_files() {
        let mut families = Families::builtin();
        let files = ConstraintFile::load_all(&path).unwrap_or_else(|e| panic!("{e}"));
        // A damper (it reads where the particles were) has no energy of the positions, and a
        // family on single particles (a pin) or on contacts none on a tet alone.
        let on_particles =
            |f: &ConstraintFile| matches!(f.binding, Binding::Particles | Binding::Contacts);
        if files.iter().any(|f| f.reads_motion() || on_particles(f)) {
            continue;
        }
        let added = families.register_all(files).unwrap();
        let mut active = PerFamily::default();
        for family in added {
            active[family] = true;
        }
        out.push((path.display().to_string(), families, active));
    }
    out
}

/// The rest tet moved by a random deformation near the identity, rotated and shifted.
fn deformed(random: &mut SplitMix64, by: f64) -> [DVec3; 4] {
    let mut f = DMat3::IDENTITY;
    for c in 0..3 {
        for r in 0..3 {
            f.col_mut(c)[r] += by * (random.next_f64() - 0.5);
        }
    }
    let rotation = DQuat::from_euler(
        glam::EulerRot::XYZ,
        random.next_f64() * 3.0,
        random.next_f64() * 3.0,
        random.next_f64() * 3.0,
    );
    let shift = DVec3::new(random.next_f64(), random.next_f64(), random.next_f64());
    REST.map(|q| rotation * (f * (q - REST[0])) + shift)
}

fn relative(a: &Matrix12, b: &Matrix12) -> f64 {
    (a - b).amax() / a.amax().max(b.amax()).max(f64::MIN_POSITIVE)
}

/// Every family and file: H by forward mode over ∇C equals H by second-order duals (which never
/// uses a gradient formula), is symmetric to 10⁻¹², converges to central differences of ∇E as ε²
/// over at least three decades, and has the three translations among its zero modes.
#[test]
fn every_hessian_is_checked_against_central_differences_and_a_second_ad() {
    let mut random = SplitMix64::new(7);
    for (name, families, active) in every_energy() {
        let energy = ElementEnergy::new(&families, &active, &Settings::default(), REST)
            .unwrap_or_else(|e| panic!("{name}: {e}"));
        for _ in 0..3 {
            let x = deformed(&mut random, 0.6);
            let at = coordinates(&x);
            let h = hessian(&energy, &at);
            let independent = second_order(&energy, &at);
            assert!(
                relative(&h, &independent) < 1e-9,
                "{name}: forward over ∇C against second-order AD: {}",
                relative(&h, &independent)
            );
            assert!(asymmetry(&h) < 1e-12, "{name}: asymmetry {}", asymmetry(&h));
            let c = convergence(&energy, &at, &h);
            assert!(
                (c.slope - 2.0).abs() < 0.25 && c.decades >= 3.0,
                "{name}: slope {} over {} decades ({:?})",
                c.slope,
                c.decades,
                c.steps
            );
            let modes = Modes::of_matrix(h, &x, &REST, energy.corner_mass());
            assert!(modes.zero_count() >= 3, "{name}: {:?}", modes.values());
            let translations = modes
                .modes()
                .iter()
                .filter(|m| m.class == Class::Translation)
                .count();
            assert!(translations >= 3, "{name}: {translations} translations");
        }
    }
}

/// Where every C = 0, ½ Σ C²/α has the rank of its constraints: a tet's volume leaves 11 zero
/// eigenvalues, its four heights 8, its six edges 6; the neo-Hookean pair at its rest shape (a
/// stationary point, not a zero of C) 6, the translations and the rotations.
#[test]
fn at_rest_the_zero_modes_are_as_many_as_the_constraints_leave() {
    let families = Families::builtin();
    let mut random = SplitMix64::new(3);
    for (name, zeros) in [
        ("volume", 11),
        ("height", 8),
        ("edges", 6),
        ("neohookean", 6),
    ] {
        let active = families.parse_list(name).unwrap();
        let energy = ElementEnergy::new(&families, &active, &Settings::default(), REST).unwrap();
        // At rest, and at the rest shape rotated and moved (still every C = 0).
        let moved = deformed(&mut random, 0.0);
        for x in [REST, moved] {
            let modes = Modes::of(&energy, &x);
            assert_eq!(modes.zero_count(), zeros, "{name}: {:?}", modes.values());
            assert_eq!(modes.negative_count(), 0, "{name}: {:?}", modes.values());
        }
        if name == "neohookean" {
            let modes = Modes::of(&energy, &REST);
            let classes: Vec<Class> = modes.modes()[..6].iter().map(|m| m.class).collect();
            let count = |c: Class| classes.iter().filter(|&&k| k == c).count();
            assert_eq!((count(Class::Translation), count(Class::Rotation)), (3, 3));
        }
    }
}

/// Away from rest the rotations are no longer null: they carry the stress. A stretched tet
/// under the neo-Hookean pair has only the three translations at zero.
#[test]
fn away_from_rest_the_rotational_modes_carry_the_stress() {
    let families = Families::builtin();
    let active = families.parse_list("neohookean").unwrap();
    let energy = ElementEnergy::new(&families, &active, &Settings::default(), REST).unwrap();
    let stretched = REST.map(|q| DVec3::new(1.5 * q.x, q.y, q.z));
    let modes = Modes::of(&energy, &stretched);
    assert_eq!(modes.zero_count(), 3, "{:?}", modes.values());
    let rotations: Vec<f64> = modes
        .modes()
        .iter()
        .filter(|m| m.class == Class::Rotation)
        .map(|m| m.value)
        .collect();
    assert!(!rotations.is_empty() && rotations.iter().all(|&l| l.abs() > 1e-6 * modes.largest()));
}

/// F = U diag(σ) Vᵀ with random rotations U and V.
fn with_singular_values(random: &mut SplitMix64, sigma: [f64; 3]) -> DMat3 {
    let mut rotation = || {
        DMat3::from_quat(DQuat::from_euler(
            glam::EulerRot::ZYX,
            random.next_f64() * 6.0,
            random.next_f64() * 6.0,
            random.next_f64() * 6.0,
        ))
    };
    let (u, v) = (rotation(), rotation());
    u * DMat3::from_diagonal(DVec3::from_array(sigma)) * v.transpose()
}

/// HOBAK's configurations, σ = (2, 3, 5), with one and with three reflections, and random
/// compressions.
fn hobak_configurations() -> Vec<DMat3> {
    let mut random = SplitMix64::new(11);
    let mut out = Vec::new();
    for sigma in [[2.0, 3.0, 5.0], [2.0, 3.0, -5.0], [-2.0, -3.0, -5.0]] {
        for _ in 0..4 {
            out.push(with_singular_values(&mut random, sigma));
        }
    }
    for _ in 0..8 {
        let sigma = [0, 1, 2].map(|_| 0.1 + 0.9 * random.next_f64());
        out.push(with_singular_values(&mut random, sigma));
    }
    out
}

fn sorted(mut values: Vec<f64>) -> Vec<f64> {
    values.sort_by(f64::total_cmp);
    values
}

/// The nine analytic eigenvalues of ∂²Ψ/∂F² against a numeric decomposition of that matrix by AD,
/// each to 10⁻⁸ relative, and each analytic eigenvector an eigenvector of it; at every HOBAK
/// configuration, for a soft and a nearly incompressible material.
#[test]
fn the_analytic_f_space_eigensystem_is_the_numeric_one() {
    for material in [
        Material::default(),
        Material::parse("E=1e6,nu=0.49").unwrap(),
    ] {
        let p = Parameters::of(&material);
        for f in hobak_configurations() {
            let h: Matrix9 = hessian_by_ad(&f, &p);
            let numeric = sorted(
                nalgebra::SymmetricEigen::new(h)
                    .eigenvalues
                    .iter()
                    .copied()
                    .collect(),
            );
            let modes = analytic(&f, &p);
            let exact = sorted(modes.iter().map(|m| m.value).collect());
            let scale = numeric.iter().fold(0.0f64, |m, x| m.max(x.abs()));
            for (a, b) in numeric.iter().zip(&exact) {
                assert!(
                    (a - b).abs() <= 1e-8 * scale,
                    "{f}: {numeric:?} against {exact:?}"
                );
            }
            for mode in &modes {
                let q =
                    nalgebra::SVector::<f64, 9>::from_column_slice(&mode.matrix.to_cols_array());
                assert!((q.norm() - 1.0).abs() < 1e-12);
                let residual = (h * q - q * mode.value).norm();
                assert!(
                    residual <= 1e-8 * scale,
                    "{f}: {:?} residual {residual}",
                    mode.class
                );
                // And it is of its class.
                let shares = f_space_shares(&f, &mode.matrix);
                let k = match mode.class {
                    Class::Twist => 0,
                    Class::Flip => 1,
                    _ => 2,
                };
                assert!(shares[k] > 1.0 - 1e-9, "{:?}: {shares:?}", mode.class);
            }
            // The signed SVD: rotations, and a negative σ exactly when F is inverted.
            let (u, s, v) = signed_svd(&f);
            assert!((u.determinant() - 1.0).abs() < 1e-9 && (v.determinant() - 1.0).abs() < 1e-9);
            assert_eq!(s[0] * s[1] * s[2] < 0.0, f.determinant() < 0.0);
        }
    }
}

/// |V₀| Bᵀ (∂²Ψ/∂F²) B, B = ∂vec F/∂x, against the AD Hessian of the pair's energy on a tet
/// deformed by F, to 10⁻⁸ relative, at every HOBAK configuration.
#[test]
fn the_f_space_hessian_carried_to_the_tet_is_the_ad_one() {
    let families = Families::builtin();
    let active = families.parse_list("neohookean").unwrap();
    let settings = Settings::default();
    let p = Parameters::of(&settings.material);
    let energy = ElementEnergy::new(&families, &active, &settings, REST).unwrap();
    let b = d_f_d_x(&REST);
    let v0 = tetlab_core::constraints::volume::signed_volume(&REST).abs();
    for f in hobak_configurations() {
        let x = REST.map(|q| f * (q - REST[0]));
        let ad = hessian(&energy, &coordinates(&x));
        let carried: Matrix12 = b.transpose() * hessian_by_ad(&f, &p) * b * v0;
        assert!(
            relative(&ad, &carried) < 1e-8,
            "{f}: {}",
            relative(&ad, &carried)
        );
    }
}

/// A tet flattened and then inverted: the volume's energy has a negative mode on the way (E is
/// not convex there), and the projected Hessian has none.
#[test]
fn a_flattened_tet_has_a_negative_mode_that_projection_removes() {
    let families = Families::builtin();
    let active = families.parse_list("volume").unwrap();
    let energy = ElementEnergy::new(&families, &active, &Settings::default(), REST).unwrap();
    let mut flat = REST;
    flat[3].z = 0.0;
    let modes = Modes::of(&energy, &flat);
    assert!(modes.negative_count() >= 1, "{:?}", modes.values());
    assert!(modes.projected_values().iter().all(|&l| l >= 0.0));
    let projected = Modes::of_matrix(modes.projected(), &flat, &REST, 1.0);
    assert_eq!(projected.negative_count(), 0);
}
