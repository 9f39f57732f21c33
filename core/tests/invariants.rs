//! Geometric invariants of the three constraints, on seeded random configurations.

use glam::{DVec3, Vec3, Vec3A};
use tetlab_core::constraints::verify::well_conditioned;
use tetlab_core::constraints::{Families, Family, distance, height, volume};
use tetlab_core::numbers::random::SplitMix64;

/// The built-in families.
fn builtin() -> Families {
    Families::builtin()
}

const TRIALS: usize = 2_000;

fn random_points(rng: &mut SplitMix64, n: usize) -> Vec<DVec3> {
    (0..n).map(|_| rng.in_cube(1.0)).collect()
}

fn well_conditioned_points(rng: &mut SplitMix64, family: Family) -> Vec<DVec3> {
    loop {
        let p = random_points(rng, builtin().arity(family));
        if well_conditioned(&p) {
            return p;
        }
    }
}

fn max_gradient(g: &[DVec3]) -> f64 {
    g.iter().map(|g| g.length()).fold(0.0, f64::max)
}

#[test]
fn gradients_sum_to_zero() {
    let mut rng = SplitMix64::new(10);
    for family in Family::builtins() {
        for _ in 0..TRIALS {
            let p = well_conditioned_points(&mut rng, family);
            let e = builtin().constraint(family).evaluate(&p, 0.3, &p);
            let sum: DVec3 = e.gradients.iter().sum();
            assert!(
                sum.length() <= 1e-12 * max_gradient(&e.gradients),
                "{family:?}: Σ∇C = {sum} at {p:?}"
            );
        }
    }
}

#[test]
fn value_is_invariant_under_rigid_motion_and_gradients_rotate_with_the_body() {
    let mut rng = SplitMix64::new(11);
    for family in Family::builtins() {
        for _ in 0..TRIALS {
            let p = well_conditioned_points(&mut rng, family);
            let rotation = rng.rotation();
            let shift = rng.in_cube(5.0);
            let moved: Vec<DVec3> = p.iter().map(|&x| rotation * x + shift).collect();
            // A family that reads the rest shape (the neo-Hookean pair) keeps its own: a body
            // moved rigidly away from rest is as deformed as before.
            let (before, after) = if builtin().row(family).reads_rest_shape {
                let rest = well_conditioned_points(&mut rng, family);
                (
                    builtin().constraint(family).evaluate(&p, 0.2, &rest),
                    builtin().constraint(family).evaluate(&moved, 0.2, &rest),
                )
            } else {
                (
                    builtin().constraint(family).evaluate(&p, 0.2, &p),
                    builtin().constraint(family).evaluate(&moved, 0.2, &moved),
                )
            };
            assert!(
                (before.value - after.value).abs() <= 1e-11,
                "{family:?}: C changed from {} to {}",
                before.value,
                after.value
            );
            let scale = max_gradient(&before.gradients);
            for (g, g_moved) in before.gradients.iter().zip(&after.gradients) {
                assert!(
                    (rotation * *g - *g_moved).length() <= 1e-10 * scale.max(1.0),
                    "{family:?}: ∇C did not rotate with the body"
                );
            }
        }
    }
}

#[test]
fn swapping_two_vertices_flips_volume_and_height() {
    let mut rng = SplitMix64::new(12);
    for _ in 0..TRIALS {
        let p: [DVec3; 4] = random_points(&mut rng, 4).try_into().unwrap();
        let v = volume::signed_volume(&p);
        for (i, j) in [(0, 1), (0, 2), (0, 3), (1, 2), (1, 3), (2, 3)] {
            let mut q = p;
            q.swap(i, j);
            let flipped = volume::signed_volume(&q);
            assert!(
                (flipped + v).abs() <= 1e-14,
                "swap {i}<->{j}: {v} became {flipped}"
            );
        }
        let mut q = p;
        q.swap(2, 3);
        let (h, h_swapped) = (height::rest_value(&p), height::rest_value(&q));
        assert!((h + h_swapped).abs() <= 1e-12 * h.abs().max(1.0));
    }
}

#[test]
fn height_equals_three_volumes_over_the_opposite_face_area() {
    let mut rng = SplitMix64::new(13);
    for _ in 0..TRIALS {
        let p: [DVec3; 4] = well_conditioned_points(&mut rng, Family::HEIGHT)
            .try_into()
            .unwrap();
        let area = 0.5 * (p[2] - p[0]).cross(p[3] - p[0]).length();
        let height = height::rest_value(&p);
        let expected = 3.0 * volume::signed_volume(&p) / area;
        assert!((height - expected).abs() <= 1e-10 * expected.abs().max(1.0));
    }
}

#[test]
fn the_four_heights_of_a_positive_tet_are_positive_and_match_each_vertex() {
    let mut rng = SplitMix64::new(14);
    for _ in 0..TRIALS {
        let mut t: [DVec3; 4] = random_points(&mut rng, 4).try_into().unwrap();
        if volume::signed_volume(&t) < 0.0 {
            t.swap(0, 1);
        }
        for (vertex, order) in height::tet_vertex_order().into_iter().enumerate() {
            assert_eq!(order[1], vertex, "entry k keeps vertex k off its face");
            let p = order.map(|i| t[i]);
            assert!(
                height::rest_value(&p) > 0.0,
                "vertex {vertex}: height not positive"
            );
        }
    }
}

#[test]
fn mirrored_tet_keeps_its_edges_but_not_its_volume_or_heights() {
    let t = [DVec3::ZERO, DVec3::X, DVec3::Y, DVec3::Z];
    let mirrored = t.map(|p| DVec3::new(-p.x, p.y, p.z));
    for (i, j) in [(0, 1), (0, 2), (0, 3), (1, 2), (1, 3), (2, 3)] {
        let d = distance::rest_value(&[t[i], t[j]]);
        assert_eq!(
            distance::evaluate(&[mirrored[i], mirrored[j]], d).value,
            0.0
        );
    }
    let v = volume::rest_value(&t);
    assert_eq!(volume::evaluate(&mirrored, v).value, -2.0 * v);
    let h = height::rest_value(&t);
    assert!(height::evaluate(&mirrored, h).value < -h * 1.99);
}

#[test]
fn coincident_points_and_zero_area_faces_are_flagged_with_finite_values() {
    let p = DVec3::new(0.3, -0.2, 0.7);
    let d = distance::evaluate(&[p, p], 1.0);
    assert!(d.degenerate && d.value == -1.0 && d.gradients == [DVec3::ZERO; 2]);

    // Zero-area face (p0, p2, p3): p3 on the line through p0 and p2.
    let flat = [DVec3::ZERO, DVec3::Y, DVec3::X, 2.0 * DVec3::X];
    let h = height::evaluate(&flat, 0.5);
    assert!(h.degenerate && h.value == -0.5 && h.gradients == [DVec3::ZERO; 4]);

    // All four points on one line: no volume gradient.
    let line = [DVec3::ZERO, DVec3::X, 2.0 * DVec3::X, 3.0 * DVec3::X];
    let v = volume::evaluate(&line, 0.25);
    assert!(v.degenerate && v.value == -0.25 && v.gradients == [DVec3::ZERO; 4]);

    // All four coincident.
    for family in Family::builtins() {
        let e = builtin().constraint(family).evaluate(
            &vec![p; builtin().arity(family)],
            0.1,
            &vec![p; builtin().arity(family)],
        );
        assert!(e.degenerate && e.value.is_finite(), "{family:?}");
    }

    // A flat tet with a proper face is *not* degenerate: the volume gradient is the face normal.
    let flat_tet = [DVec3::ZERO, DVec3::X + DVec3::Y, DVec3::X, DVec3::Y];
    let v = volume::evaluate(&flat_tet, 0.0);
    assert!(!v.degenerate && v.gradients[0].length() > 0.0);
}

#[test]
fn near_degenerate_configurations_stay_finite() {
    let mut rng = SplitMix64::new(15);
    for _ in 0..TRIALS {
        let p = random_points(&mut rng, 4);
        // Each vertex in turn moved to 1e-6 from the line through two others.
        for v in 0..4 {
            let (a, b) = ((v + 1) % 4, (v + 2) % 4);
            let mut q = p.clone();
            let along = q[a].lerp(q[b], rng.range(-1.0, 2.0));
            let offset = (q[b] - q[a]).normalize().any_orthonormal_vector() * 1e-6;
            q[v] = along + offset;
            for family in [Family::HEIGHT, Family::VOLUME] {
                let e = builtin().constraint(family).evaluate(&q, 0.1, &q);
                assert!(e.value.is_finite(), "{family:?} value at {q:?}");
                assert!(
                    e.gradients.iter().all(|g| g.is_finite()),
                    "{family:?} ∇C at {q:?}"
                );
            }
            let pair = [q[v], q[v] + offset];
            let d = builtin()
                .constraint(Family::EDGES)
                .evaluate(&pair, 0.1, &pair);
            assert!(d.value.is_finite() && d.gradients.iter().all(|g| g.is_finite()));
        }
    }
}

#[test]
fn f32_and_f64_share_one_implementation_and_agree() {
    let mut rng = SplitMix64::new(16);
    for _ in 0..TRIALS {
        let p: [DVec3; 4] = well_conditioned_points(&mut rng, Family::HEIGHT)
            .try_into()
            .unwrap();
        let p32 = p.map(|x| x.as_vec3());
        let p32a = p.map(|x| Vec3A::from(x.as_vec3()));
        let rest = 0.1;
        let e64 = height::evaluate(&p, rest);
        let e32 = height::evaluate::<Vec3>(&p32, rest as f32);
        let e32a = height::evaluate::<Vec3A>(&p32a, rest as f32);
        assert!((e64.value - e32.value as f64).abs() < 1e-4);
        assert_eq!(e32.value, e32a.value);
        let scale = max_gradient(&e64.gradients);
        for (g64, g32) in e64.gradients.iter().zip(&e32.gradients) {
            assert!((*g64 - g32.as_dvec3()).length() < 1e-3 * scale.max(1.0));
        }
        let v64 = volume::evaluate(&p, 0.0);
        let v32 = volume::evaluate::<Vec3>(&p32, 0.0);
        assert!((v64.value - v32.value as f64).abs() < 1e-5);
    }
}

/// An independent derivation of the height gradients: moving p0, p2 or p3 tilts the face about
/// the other two, and the plane at p1's foot f moves by that vertex's barycentric weight of f.
/// So every gradient is parallel to n, and ∇ₚₖC = −βₖ n for the face vertices k = 0, 2, 3.
#[test]
fn height_gradients_are_minus_barycentric_weights_of_the_foot_times_n() {
    let mut rng = SplitMix64::new(17);
    for _ in 0..TRIALS {
        let p: [DVec3; 4] = well_conditioned_points(&mut rng, Family::HEIGHT)
            .try_into()
            .unwrap();
        let e = height::evaluate(&p, 0.0);
        let n = e.gradients[1];
        let foot = p[1] - n * e.value;
        // Barycentric weights of the foot in the face (p0, p2, p3) from sub-triangle areas.
        let area = |a: DVec3, b: DVec3, c: DVec3| (b - a).cross(c - a).dot(n);
        let whole = area(p[0], p[2], p[3]);
        let beta0 = area(foot, p[2], p[3]) / whole;
        let beta2 = area(p[0], foot, p[3]) / whole;
        let beta3 = area(p[0], p[2], foot) / whole;
        let scale = max_gradient(&e.gradients).max(1.0);
        for (k, beta) in [(0, beta0), (2, beta2), (3, beta3)] {
            assert!(
                (e.gradients[k] + n * beta).length() <= 1e-10 * scale,
                "∇p{k} = {} but −β n = {}",
                e.gradients[k],
                -n * beta
            );
        }
    }
}
