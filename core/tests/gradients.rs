//! Every built-in family through the one gradient check: against central finite differences and
//! automatic differentiation on 10⁴ random configurations each, and every check a constraint
//! file gets (invariances, reflection, near-degenerate configurations).

use glam::DVec3;
use tetlab_core::constraints::verify::{analytic_and_numeric, random_check, relative_error};
use tetlab_core::constraints::{Families, Family};

const SAMPLES: usize = 10_000;
const BOUND: f64 = 1e-6;

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
    let (mut analytic, numeric) =
        analytic_and_numeric(&Families::builtin(), Family::HEIGHT, &p, 0.0, &p);
    assert!(relative_error(&analytic, &numeric) <= BOUND);
    let (e1, e2, e3) = (p[1] - p[0], p[2] - p[0], p[3] - p[0]);
    let c = e2.cross(e3);
    analytic[2] = e3.cross(e1) / c.length();
    analytic[0] = -(analytic[1] + analytic[2] + analytic[3]);
    assert!(relative_error(&analytic, &numeric) > 1e-3);
}

/// Every check of the one harness, on every built-in family (the neo-Hookean pair included), as
/// on a constraint file: the analytic gradient against AD per particle, AD against central
/// differences, translation and rotation invariance, what a reflection does, and that
/// near-degenerate configurations are flagged, never NaN.
#[test]
fn every_built_in_family_passes_every_check_of_the_harness() {
    use tetlab_core::constraints::verify::{Reflection, TableFamily, check};
    let families = Families::builtin();
    // With rest value 0 (as the harness reflects): |p0 − p1| and √V₀ ‖F‖ keep their value, the
    // signed height (a tet's, or a contact's above its triangle), the signed volume and
    // √V₀ det F change sign.
    let expected = [
        (Family::EDGES, Reflection::Unchanged),
        (Family::HEIGHT, Reflection::Negated),
        (Family::VOLUME, Reflection::Negated),
        (Family::NEOHOOKEAN_DEVIATORIC, Reflection::Unchanged),
        (Family::NEOHOOKEAN_HYDROSTATIC, Reflection::Negated),
        (Family::CONTACT, Reflection::Negated),
    ];
    for family in Family::builtins() {
        let reflection = (expected.iter().find(|(f, _)| *f == family))
            .unwrap_or_else(|| panic!("{family}: say above what a reflection does to it"))
            .1;
        let source = TableFamily {
            families: &families,
            family,
        };
        let report = check(&source, 2000, 7);
        assert_eq!(report.compared, 2000, "{family}");
        assert!(report.agrees(), "{family}: {:?}", report.max_relative_error);
        assert!(
            report
                .max_relative_error
                .iter()
                .all(|e| e.is_some_and(|e| e <= 1e-12)),
            "{family}: the analytic gradient is AD's to rounding: {:?}",
            report.max_relative_error
        );
        assert!(
            report.automatic_vs_finite_difference <= 1e-6,
            "{family}: {report:?}"
        );
        assert!(
            report.translation_invariant(),
            "{family}: {}",
            report.translation
        );
        assert!(report.rotation_invariant(), "{family}: {}", report.rotation);
        assert_eq!(report.reflection, reflection, "{family}");
        assert_eq!(report.near_degenerate, 200, "{family}");
        assert!(report.undefined <= report.near_degenerate, "{family}");
    }
}

/// The figures `tetlab check-gradients` prints for the built-in families, asserted: against
/// central differences (the neo-Hookean pair's too) and against AD, on 10⁴ configurations.
#[test]
fn the_printed_figures_hold_for_every_built_in_family() {
    for family in Family::builtins() {
        let report = random_check(&Families::builtin(), family, SAMPLES, 1);
        assert_eq!(report.compared, SAMPLES, "{family}");
        assert!(report.max_relative_error <= BOUND, "{family}: {report:?}");
        assert!(
            report.mean_relative_error <= report.max_relative_error,
            "{family}"
        );
        assert!(report.max_automatic_error <= 1e-12, "{family}: {report:?}");
    }
}
