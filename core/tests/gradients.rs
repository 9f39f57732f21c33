//! Analytic gradients against central finite differences, 10⁴ random configurations per family.

use glam::DVec3;
use tetlab_core::constraints::Family;
use tetlab_core::teaching::verify::{analytic_and_numeric, random_check, relative_error};

const SAMPLES: usize = 10_000;
const BOUND: f64 = 1e-6;

fn check(family: Family, seed: u64) {
    let report = random_check(family, SAMPLES, seed);
    assert_eq!(report.compared, SAMPLES);
    assert!(
        report.max_relative_error <= BOUND,
        "{family:?}: max relative error {:e} over {} configurations exceeds {BOUND:e}",
        report.max_relative_error,
        report.compared
    );
}

#[test]
fn distance_gradient_matches_finite_differences() {
    check(Family::EDGES, 1);
}

#[test]
fn height_gradient_matches_finite_differences() {
    check(Family::HEIGHT, 2);
}

#[test]
fn volume_gradient_matches_finite_differences() {
    check(Family::VOLUME, 3);
}

/// The check itself must be able to fail: a gradient with one term of the source note's formula
/// dropped (the (n×e₃)(n·e₁) term of ∇ₚ₂C) is caught.
#[test]
fn the_check_catches_a_wrong_gradient() {
    let p = [
        DVec3::new(0.1, -0.2, 0.05),
        DVec3::new(0.3, 0.9, 0.4),
        DVec3::new(1.0, 0.1, -0.2),
        DVec3::new(-0.1, 0.2, 1.1),
    ];
    let (mut analytic, numeric) = analytic_and_numeric(Family::HEIGHT, &p, 0.0, &p);
    assert!(relative_error(&analytic, &numeric) <= BOUND);
    let (e1, e2, e3) = (p[1] - p[0], p[2] - p[0], p[3] - p[0]);
    let c = e2.cross(e3);
    analytic[2] = e3.cross(e1) / c.length();
    analytic[0] = -(analytic[1] + analytic[2] + analytic[3]);
    assert!(relative_error(&analytic, &numeric) > 1e-3);
}
