//! The constraint files of assets/constraints: each loads, and its gradient is checked against
//! automatic differentiation as `tetlab check-gradients --constraint-file` checks it.

use std::path::{Path, PathBuf};
use tetlab_core::constraint_file::ConstraintFile;
use tetlab_core::constraint_file::check::{Reflection, check};

fn asset(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../assets/constraints")
        .join(name)
}

fn load(name: &str) -> ConstraintFile {
    ConstraintFile::load(&asset(name)).unwrap_or_else(|e| panic!("{e}"))
}

#[test]
fn the_source_notes_height_agrees_with_automatic_differentiation() {
    let report = check(&load("height.toml"), 2000, 1);
    assert_eq!(report.compared, 2000);
    assert!(report.agrees(), "{report:?}");
    assert!(
        report.translation_invariant() && report.rotation_invariant(),
        "{report:?}"
    );
    assert_eq!(report.reflection, Reflection::Negated);
    assert!(report.automatic_vs_finite_difference < 1e-5, "{report:?}");
}

#[test]
fn the_signed_volume_agrees_and_is_negated_by_a_reflection() {
    let report = check(&load("volume.toml"), 2000, 2);
    assert!(report.agrees(), "{report:?}");
    assert!(report.translation_invariant() && report.rotation_invariant());
    assert_eq!(report.reflection, Reflection::Negated);
}

#[test]
fn the_volume_gradient_without_its_sixth_is_reported() {
    let report = check(&load("volume-without-sixth.toml"), 500, 3);
    assert!(!report.agrees());
    // Six times too large: the error is 5 × the gradient's largest component, at most 5 |∇C|.
    let worst = report.worst.expect("a worst configuration");
    assert!(
        worst.relative_error > 4.0 && worst.relative_error < 5.0 + 1e-9,
        "{worst:?}"
    );
    for error in report.max_relative_error.iter().flatten() {
        assert!(*error > 1.0);
    }
}

#[test]
fn the_edge_agrees_and_a_reflection_leaves_it_unchanged() {
    let report = check(&load("edge.toml"), 2000, 4);
    assert!(report.agrees(), "{report:?}");
    assert_eq!(report.max_relative_error.len(), 2);
    assert_eq!(report.reflection, Reflection::Unchanged);
    assert!(report.translation_invariant() && report.rotation_invariant());
}

#[test]
fn the_triangle_area_agrees() {
    let report = check(&load("triangle-area.toml"), 2000, 5);
    assert!(report.agrees(), "{report:?}");
    assert_eq!(report.reflection, Reflection::Unchanged);
}

#[test]
fn a_flipped_sign_is_found_at_the_particle_it_is_in() {
    let report = check(&load("height-wrong-sign.toml"), 500, 6);
    assert!(!report.agrees());
    let errors = &report.max_relative_error;
    assert!(
        errors[1].unwrap() < 1e-9 && errors[2].unwrap() < 1e-9,
        "{errors:?}"
    );
    assert!(
        errors[3].unwrap() > 0.1 && errors[0].unwrap() > 0.1,
        "{errors:?}"
    );
    let worst = report.worst.unwrap();
    assert!(worst.particle == 3 || worst.particle == 0);
    // The configuration shown really shows it.
    let file = load("height-wrong-sign.toml");
    let at = file.evaluate(&worst.points, worst.rest, &[]);
    let automatic = at.automatic.unwrap();
    let yours = at.yours[worst.particle].unwrap();
    assert!((yours - automatic[worst.particle]).length() > 0.1 * automatic[1].length());
}

#[test]
fn near_degenerate_configurations_are_flagged_never_nan() {
    for name in [
        "height.toml",
        "volume.toml",
        "edge.toml",
        "triangle-area.toml",
    ] {
        let file = load(name);
        let report = check(&file, 10, 7);
        assert_eq!(report.near_degenerate, 200);
        // Coincident points: C or ∇C undefined for the normalised ones, flagged.
        if name != "volume.toml" {
            assert!(report.undefined > 0, "{name}");
        }
        let flat = [glam::DVec3::ZERO; 4];
        let e = file.evaluate(&flat[..file.arity()], 0.0, &[]);
        if let Some(g) = &e.automatic {
            assert!(g.iter().all(|v| v.is_finite()), "{name}");
        }
    }
}

/// The error for `text`, as one line.
fn error(text: &str) -> String {
    ConstraintFile::parse(Path::new("mine.toml"), text)
        .unwrap_err()
        .to_string()
}

#[test]
fn every_mistake_names_file_line_and_column() {
    let header = "name = \"c\"\napplies_to = \"edges\"\n";
    let cases = [
        (
            "value = \"length(p0 - q) - rest\"",
            "mine.toml:3:22: ",
            "unknown name `q`",
        ),
        (
            "value = \"lenght(p0 - p1)\"",
            "mine.toml:3:10: ",
            "unknown function `lenght`",
        ),
        (
            "value = \"dot(p0)\"",
            "mine.toml:3:10: ",
            "`dot` takes 2 arguments, and is given 1",
        ),
        (
            "value = \"p0 - p1\"",
            "mine.toml:3:10: ",
            "value must be a scalar, and this is a vector",
        ),
        (
            "value = \"p0 * p1\"",
            "mine.toml:3:10: ",
            "type error: a vector * a vector",
        ),
        (
            "value = \"length(p3 - p0)\"",
            "mine.toml:3:17: ",
            "p0…p1 only",
        ),
        (
            "value = \"length(p0 - p1\"",
            "mine.toml:3:24: ",
            "expected an operator or a comparison or `)`",
        ),
        (
            "value = \"sqrt(p0)\"",
            "mine.toml:3:15: ",
            "argument 1 of `sqrt` must be a scalar",
        ),
        (
            "value = \"1\"\n[gradient]\np3 = \"p0\"",
            "mine.toml:5:1: ",
            "p0…p1 only",
        ),
    ];
    for (body, at, what) in cases {
        let message = error(&format!("{header}{body}\n"));
        assert!(message.starts_with(at), "{body}: {message}");
        assert!(message.contains(what), "{body}: {message}");
    }
    // A bracketed operand is quoted with its brackets, at its opening one.
    let tets = "name = \"c\"\napplies_to = \"tets\"\n";
    for (value, at, quoted) in [
        (
            "dot((p1 - p0) * F, p2)",
            "mine.toml:3:14: ",
            "(`(p1 - p0) * F`)",
        ),
        (
            "dot(F + (p1 - p0), p2)",
            "mine.toml:3:14: ",
            "(`F + (p1 - p0)`)",
        ),
    ] {
        let message = error(&format!("{tets}value = \"{value}\"\n"));
        assert!(message.starts_with(at), "{value}: {message}");
        assert!(message.ends_with(quoted), "{value}: {message}");
    }
    // A tet's volume on a triangle, a tet's matrices on an edge: the binding's particles
    // counted right, and what has them said.
    let message = error("name = \"c\"\napplies_to = \"triangles\"\nvalue = \"V0\"\n");
    assert!(
        message.contains(
            "`V0` is a tet's (a triangle has A0): this binding has three particles, p0…p2"
        ),
        "{message}"
    );
    let message = error("name = \"c\"\napplies_to = \"edges\"\nvalue = \"det(Dm)\"\n");
    assert!(
        message.contains("`Dm` is a tet's or a triangle's: this binding has two particles, p0…p1"),
        "{message}"
    );
    let message = error(header);
    assert!(message.contains("no `value`"), "{message}");
    let message = error("name = \"c\"\napplies_to = \"faces\"\nvalue = \"1\"\n");
    assert!(message.starts_with("mine.toml:2:14: "), "{message}");
    // Inside a multi-line define, the line of the definition.
    let message = error(&format!(
        "{header}define = \"\"\"\nu = p0 - p1\nw = u * u\n\"\"\"\nvalue = \"1\"\n"
    ));
    assert!(message.starts_with("mine.toml:5:5: "), "{message}");
}

/// Random well-conditioned configurations of `n` points.
fn configurations(n: usize, count: usize, seed: u64) -> Vec<Vec<glam::DVec3>> {
    let mut rng = tetlab_core::numbers::random::SplitMix64::new(seed);
    let mut out = Vec::new();
    while out.len() < count {
        let points: Vec<glam::DVec3> = (0..n).map(|_| rng.in_cube(1.0)).collect();
        if tetlab_core::constraint_file::check::well_conditioned(&points) {
            out.push(points);
        }
    }
    out
}

/// The evaluation a simulation uses, in f64, f32 and eight f32 lanes, against the AD of the check.
#[test]
fn the_same_program_evaluates_in_f64_f32_and_lanes() {
    use glam::{DVec3, Vec3A};
    use tetlab_core::numbers::lanes::{F32x8, Vec3x8};
    use tetlab_core::numbers::vector::{Real, Vector3};
    let file = load("height.toml");
    let configs = configurations(4, 8, 11);
    let mut lanes = [[[0.0f32; 8]; 3]; 4];
    for (lane, points) in configs.iter().enumerate() {
        let rest = 0.1;
        let checked = file.evaluate(points, rest, &[]);
        let automatic = checked.automatic.unwrap();
        let p: [DVec3; 4] = std::array::from_fn(|k| points[k]);
        let f64s = file.evaluate_vectors(&p, rest, &[]);
        assert!((f64s.value - checked.value).abs() < 1e-14);
        assert!(!f64s.degenerate);
        let scale = automatic.iter().map(|g| g.length()).fold(0.0, f64::max);
        for (g, a) in f64s.gradients.iter().zip(&automatic) {
            assert!((*g - *a).length() < 1e-13 * scale);
        }
        let q: [Vec3A; 4] = std::array::from_fn(|k| points[k].as_vec3a());
        let f32s = file.evaluate_vectors(&q, rest as f32, &[]);
        for (k, (g, a)) in f32s.gradients.iter().zip(&automatic).enumerate() {
            let g = g.as_dvec3();
            assert!((g - *a).length() < 1e-4 * scale, "{g} {a}");
            for (axis, component) in lanes[k].iter_mut().enumerate() {
                component[lane] = q[k][axis];
            }
        }
    }
    let p: [Vec3x8; 4] = std::array::from_fn(|k| Vec3x8::from_array(lanes[k].map(F32x8::new)));
    let wide = file.evaluate_vectors(&p, F32x8::from_f64(0.1), &[]);
    for (lane, points) in configs.iter().enumerate() {
        let q: [Vec3A; 4] = std::array::from_fn(|k| points[k].as_vec3a());
        let one = file.evaluate_vectors(&q, 0.1f32, &[]);
        assert_eq!(wide.value.to_array()[lane], one.value);
        for (w, g) in wide.gradients.iter().zip(&one.gradients) {
            assert_eq!(w.lane(lane), *g);
        }
    }
}

#[test]
fn a_simulation_gets_a_zero_gradient_where_it_is_undefined_and_yours_when_asked() {
    use glam::DVec3;
    let edge = load("edge.toml");
    let e = edge.evaluate_vectors(&[DVec3::ONE, DVec3::ONE], 0.5, &[]);
    assert!(e.degenerate);
    assert_eq!(e.gradients, [DVec3::ZERO; 2]);
    assert_eq!(e.value, -0.5);
    // The wrong height is simulated with its own gradient (use_gradient = true); without the
    // key, with AD's.
    let wrong = load("height-wrong-sign.toml");
    assert!(wrong.use_gradient);
    let text = std::fs::read_to_string(asset("height-wrong-sign.toml")).unwrap();
    let by_ad = text.replace("use_gradient = true", "");
    assert!(
        !ConstraintFile::parse(Path::new("ad.toml"), &by_ad)
            .unwrap()
            .use_gradient
    );
    let points = &configurations(4, 1, 12)[0];
    let p: [DVec3; 4] = std::array::from_fn(|k| points[k]);
    let used = wrong.evaluate_vectors(&p, 0.0, &[]);
    let checked = wrong.evaluate(points, 0.0, &[]);
    for k in 0..4 {
        assert_eq!(
            used.gradients[k],
            checked.yours[k].unwrap(),
            "the file's own, wrong as it is"
        );
    }
}

/// The gradient a simulation uses (reverse mode over the compiled tape, one pass back) is the
/// one `check-gradients` compares yours with (forward mode, one pass per coordinate): on every
/// example, on random configurations, they agree to rounding.
#[test]
fn reverse_and_forward_mode_agree_on_every_example() {
    use glam::DVec3;
    use tetlab_core::constraint_file::EXAMPLES;
    let material = tetlab_core::constraints::material::Material::default();
    for example in EXAMPLES {
        for file in ConstraintFile::parse_all(Path::new(example.path), example.text).unwrap() {
            let mut worst: f64 = 0.0;
            for (k, points) in configurations(file.arity(), 300, 21).iter().enumerate() {
                let rest = 0.1 * (k + 1) as f64 / 300.0; // never 0: C = V / rest − 1 needs one
                // A rest shape for a file that reads one: a sheared copy of the points.
                let shape: Vec<DVec3> = points.iter().map(|p| *p + DVec3::X * p.y * 0.3).collect();
                let stored = file.store(&shape, &material);
                let forward = file
                    .evaluate(points, rest, &stored)
                    .automatic
                    .expect("well conditioned");
                let reverse = file.gradients_of(points, rest, &stored, false);
                let scale = forward.iter().map(|g| g.length()).fold(0.0, f64::max);
                for (f, r) in forward.iter().zip(&reverse) {
                    worst = worst.max((*f - *r).length() / scale);
                }
            }
            assert!(worst < 1e-12, "{}: {worst:e}", example.file);
        }
    }
}

/// A file may give every Hessian block its binding has, and they cost an element no storage:
/// only the check runs them, from the rest shape. `green-strain.toml` gives all ten of a tet's,
/// constant blocks bᵢ bⱼ I (90 numbers), and stores only what C and its gradient read (22
/// numbers); each block
/// agrees with AD. (Before, the blocks were stored with what else depends on the rest shape, and
/// the file was refused at its value's line: "108 numbers per element; at most 48 are
/// stored".)
#[test]
fn hessian_blocks_cost_an_element_no_storage() {
    let file = load("green-strain.toml");
    // What C and the gradient read of the rest shape: inverse(Dm) and the four bᵢ, 22 numbers.
    assert!(file.stored_len() <= 24, "stores {}", file.stored_len());
    let mut families = tetlab_core::constraints::Families::builtin();
    let family = families.register(file.clone()).unwrap();
    let report = tetlab_core::energy::check::check(&families, family, Some(&file), 200, 1);
    assert_eq!(report.compared, 200);
    assert_eq!(report.yours.len(), 10, "{report:?}");
    for ((i, j), error) in &report.yours {
        assert!(*error < 1e-12, "p{i}p{j}: {error}");
    }
    let gradients = check(&file, 2000, 1);
    assert!(gradients.agrees(), "{gradients:?}");
}

#[test]
fn a_file_on_contacts_is_refused_what_a_contact_has_not() {
    // A contact is found where surfaces meet: it has no rest shape, no rest value of its own,
    // no stored numbers and no motion of its own (friction is the contact's).
    let header = "name = \"c\"\napplies_to = \"contacts\"\n";
    for (body, what) in [
        ("value = \"length(p0 - q0) - rest\"", "no rest shape"),
        ("value = \"dot(p0 - p1, q2 - q1) - rest\"", "no rest shape"),
        ("value = \"det(Dm) - rest\"", "no rest shape"),
        ("value = \"V0 - rest\"", "no rest shape"),
        (
            "value = \"length(p0 - p1) - rest\"\n[gradient]\np0 = \"q0 - p1\"",
            "no rest shape",
        ),
        (
            "value = \"length(p0 - p1)\"\nrest = \"0.1\"",
            "no rest shape",
        ),
        (
            "value = \"length(p0 - start0) - rest\"",
            "not where they were",
        ),
        (
            "value = \"length(p0 - p1) * h - rest\"",
            "not where they were",
        ),
    ] {
        let message = error(&format!("{header}{body}\n"));
        assert!(message.starts_with("mine.toml:2:14: "), "{body}: {message}");
        assert!(message.contains(what), "{body}: {message}");
    }
    // What it may read: where its four particles are and the thickness.
    let file = ConstraintFile::parse(
        Path::new("mine.toml"),
        &format!("{header}value = \"dot(p0 - p1, normalize(cross(p2 - p1, p3 - p1))) - rest\"\n"),
    );
    assert!(file.is_ok(), "{:?}", file.err().map(|e| e.to_string()));
}
