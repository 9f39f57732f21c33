//! The constraint language beyond + − × ÷: its functions, components, `vec3`, `if`, and
//! expressions over several lines, each derivative checked against central differences in both
//! modes of automatic differentiation and in the fast engine's lanes; the domain errors, named
//! at file:line:column; and the inputs that used to crash the parser (deep nesting, long
//! chains, a megabyte of expression), each an error at its place, on a 1 MB stack as in the
//! browser.

use glam::DVec3;
use std::path::Path;
use tetlab_core::constraint_file::ConstraintFile;
use tetlab_core::constraint_file::expression::MAX_DEPTH;
use tetlab_core::numbers::lanes::{F32x8, Vec3x8};
use tetlab_core::numbers::vector::Real;

/// A file on edges (p0, p1) whose C is `value`, with `define` when given.
fn edge_file(define: &str, value: &str) -> Result<ConstraintFile, String> {
    let text = format!(
        "name = \"c\"\napplies_to = \"edges\"\ndefine = \"\"\"\n{define}\n\"\"\"\nvalue = \"\"\"{value}\"\"\"\n"
    );
    ConstraintFile::parse(Path::new("mine.toml"), &text).map_err(|e| e.to_string())
}

/// A configuration where every function below is defined and smooth.
const POINTS: [DVec3; 2] = [DVec3::new(0.31, 0.17, -0.23), DVec3::new(-0.12, 0.41, 0.29)];

/// ∇C by central differences of C.
fn central_difference(file: &ConstraintFile, points: &[DVec3; 2]) -> [DVec3; 2] {
    let h = 1e-6;
    std::array::from_fn(|i| {
        let mut g = [0.0; 3];
        for (axis, slot) in g.iter_mut().enumerate() {
            let mut plus = *points;
            let mut minus = *points;
            plus[i][axis] += h;
            minus[i][axis] -= h;
            *slot = (file.value(&plus, 0.0, &[]) - file.value(&minus, 0.0, &[])) / (2.0 * h);
        }
        DVec3::from_array(g)
    })
}

#[test]
fn every_function_differentiates_as_central_differences_say_in_both_modes_and_in_lanes() {
    // Each is a scalar of the two points; x, y, z are components, a and b smooth scalars.
    // M is inverted (det M < 0) with distinct singular values, N is not.
    let define = "d = p1 - p0\nx = d.x\ny = d.y\nz = d.z\na = dot(p0, p1) + 0.5\nb = length(d)
        M = mat3(vec3(1.2, 0.1, 0) + p0, vec3(0.2, 0.8, 0.1) + p1, vec3(0, 0.3, -0.5) + d)
        N = mat3(vec3(0.3, 1.1, 0) + p1, vec3(-0.9, 0.2, 0.4) + d, vec3(0.1, 0.3, 1.7) - p0)";
    let cases = [
        "sin(3 * x) + cos(2 * y)",
        "tan(x)",
        "exp(x * y) - log(b)",
        "pow(b, 3) + pow(a, -2) + pow(b, 0.5) + pow(b, 1.7)",
        "cbrt(z) + cbrt(-a)",
        "asin(x) + acos(y / b)",
        "atan2(y, x) + atan2(-z, -x)",
        "clamp(x, -1, 1) + clamp(3 * y, -0.2, 0.2)",
        "sign(x) * x + abs(z)",
        "if(x < y, x * x, y * y * y) + if(z >= 0, z, -2 * z)",
        "length(vec3(x * y, z, 1)) + dot(vec3(1, 2, 3), d)",
        "if(a > 0, length(d), 0) + length(if(y <= x, p0, p1))",
        "atan2(dot(cross(p0, p1), vec3(0, 0, 1)), dot(p0, p1))",
        "norm(M - polar(M)) + norm(N - polar(N))",
        "dot(polar(M).c1, vec3(1, 2, 3)) + polar(N).r2.x + polar(N).xy",
        "dot(singular_values(M), vec3(1, -2, 3)) + singular_values(N).z",
        "det(polar(N)) * singular_values(M).x * singular_values(M).y * singular_values(M).z",
        "dot(svd_u(M).c0, p1) + svd_v(M).yz + dot(svd_u(N) * transpose(svd_v(N)) * p0, p1)",
        "dot(svd_u(N).c2, svd_v(M).c1) + trace(svd_v(N) * svd_u(M))",
        // Vectors and matrices of two.
        "dot(vec2(x, y), vec2(z, a)) + length(vec2(x * y, b)) + normalize(vec2(a, z)).y",
        "det(mat2(vec2(x, y), vec2(z, 1))) + trace(inverse(mat2(vec2(2 + x, y), vec2(z, 3))))",
        "norm(mat2(d, p0) * inverse(mat2(vec2(1, x), vec2(y, 2))))",
        "trace(transpose(mat2(d, p1)) * mat2(d, p1)) + det(transpose(mat2(d, p1)) * mat2(p0, d))",
        "dot(mat2(d, p0) * vec2(x, 1), p1) + (transpose(mat2(d, p0)) * p1).y + mat2(d, p0).zy",
        "outer(vec2(x, y), d).xz + outer(d, vec2(1, y)).zy + transpose(mat3(vec2(x, 1), vec2(y, z), vec2(1, a))).r2.y",
    ];
    for value in cases {
        let file = edge_file(define, value).unwrap_or_else(|e| panic!("{value}: {e}"));
        let numeric = central_difference(&file, &POINTS);
        let forward = file.evaluate(&POINTS, 0.0, &[]).automatic.expect(value);
        let reverse = file.evaluate_vectors(&POINTS, 0.0, &[]);
        assert!(!reverse.degenerate, "{value}");
        for k in 0..2 {
            let scale = numeric[k].length().max(1.0);
            assert!(
                (forward[k] - numeric[k]).length() < 1e-7 * scale,
                "{value}: p{k} forward {} against {}",
                forward[k],
                numeric[k]
            );
            assert!(
                (reverse.gradients[k] - forward[k]).length() < 1e-12 * scale,
                "{value}: p{k} reverse {} against forward {}",
                reverse.gradients[k],
                forward[k]
            );
        }
        // The fast engine's lanes: eight copies in f32 agree with f32 alone (no lane is
        // evaluated on its own: `wide`'s functions run on all eight).
        let p32 = POINTS.map(|p| p.as_vec3a());
        let single = file.evaluate_vectors(&p32, 0.0, &[]);
        let lanes = p32.map(|p| Vec3x8::gather([p; 8]));
        let eight = file.evaluate_vectors(&lanes, F32x8::ZERO, &[]);
        let lane_value = eight.value.to_array()[3];
        assert!(
            (lane_value - single.value).abs() <= 1e-4 * single.value.abs().max(1.0),
            "{value}: lanes {lane_value} against f32 {}",
            single.value
        );
        let g = eight.gradients[1].lane(5);
        assert!(
            (g - single.gradients[1]).length() <= 1e-3 * single.gradients[1].length().max(1.0),
            "{value}: lanes {g} against f32 {}",
            single.gradients[1]
        );
    }
}

/// Shapes that do not fit are type errors that name both shapes, at the expression.
#[test]
fn vectors_and_matrices_of_two_are_typed_by_their_shape() {
    let define = "d = p1 - p0\nx = d.x\ny = d.y";
    for (value, says) in [
        (
            "length(mat2(d, p0) * d)",
            "a 3 × 2 matrix * a vector: the columns of the first (2) must be as many as the rows \
             of the second (3)",
        ),
        (
            "norm(mat2(d, p0) * mat2(d, p0))",
            "the columns of the first (2) must be as many as the rows of the second (3)",
        ),
        (
            "length(vec2(x, y) + d)",
            "type error: a 2-vector + a vector",
        ),
        (
            "length(cross(vec2(x, y), d))",
            "argument 1 of `cross` must be a vector, and this is a 2-vector",
        ),
        (
            "dot(vec2(x, y), d)",
            "argument 2 of `dot` is a vector, and argument 1 a 2-vector",
        ),
        (
            "vec2(x, y).z",
            "a 2-vector has components .x and .y, not .z",
        ),
        (
            "length(mat2(d, p0).c2)",
            "a 3 × 2 matrix has columns .c0 .c1, rows .r0 .r1 .r2 and entries .xx .xy … .zy",
        ),
        (
            "det(mat2(d, p0))",
            "argument 1 of `det` must be a square matrix (2 × 2 or 3 × 3), and this is a 3 × 2 matrix",
        ),
        (
            "norm(polar(mat2(d, p0)))",
            "argument 1 of `polar` must be a matrix, and this is a 3 × 2 matrix",
        ),
    ] {
        let message = edge_file(define, value).unwrap_err();
        assert!(message.contains(says), "{value}: {message}");
        assert!(message.starts_with("mine.toml:"), "{message}");
    }
}

#[test]
fn a_domain_error_is_named_where_it_happens() {
    // At run time: acos of a number just above 1, at the line and column of `acos`.
    let file = edge_file("k = length(p1 - p0)", "acos(k)").unwrap();
    let points = [DVec3::ZERO, DVec3::new(1.000_000_1, 0.0, 0.0)];
    assert!(file.value(&points, 0.0, &[]).is_nan());
    let e = file.undefined_at(&points, 0.0, &[]).expect("undefined");
    let text = e.to_string();
    assert!(text.starts_with("mine.toml:6:12: "), "{text}");
    assert!(text.contains("acos of 1.0000001"), "{text}");
    let e = edge_file("k = length(p1 - p0) - 1", "log(k)")
        .unwrap()
        .undefined_at(&[DVec3::ZERO, DVec3::X], 0.0, &[])
        .expect("log of 0");
    assert!(e.to_string().contains("log of 0"), "{e}");
    assert!(
        edge_file("", "acos(length(p1 - p0) / 2)")
            .unwrap()
            .undefined_at(&[DVec3::ZERO, DVec3::X], 0.0, &[])
            .is_none()
    );
}

#[test]
fn constants_that_are_undefined_are_errors_at_their_place() {
    for (value, column, what) in [
        ("length(p0 - p1) / 0", 30, "division by zero"),
        ("length(p0 - p1) / (1 - 1)", 30, "division by zero"),
        ("length(p0 - p1) + 1e308 * 10", 30, "too large"),
        ("length(p0 - p1) + log(0)", 30, "log of 0"),
        ("acos(1.5) * length(p0 - p1)", 12, "acos of 1.5"),
        ("length(p0 - p1) * sqrt(-1)", 30, "sqrt of -1"),
    ] {
        let e = edge_file("", value).unwrap_err();
        assert!(
            e.starts_with(&format!("mine.toml:6:{column}: ")),
            "{value}: {e}"
        );
        assert!(e.contains(what), "{value}: {e}");
    }
    // In a definition too, at its line (a bracketed divisor at its opening bracket).
    let e = edge_file("a = 1\nb = 2 / (a - 1)", "length(p0 - p1) * b").unwrap_err();
    assert!(e.starts_with("mine.toml:5:9: "), "{e}");
}

#[test]
fn a_file_without_a_value_is_named_at_a_line() {
    let e = ConstraintFile::parse(
        Path::new("mine.toml"),
        "name = \"c\"\napplies_to = \"edges\"\n\n[gradient]\np0 = \"p0\"\n",
    )
    .unwrap_err()
    .to_string();
    assert!(e.starts_with("mine.toml:4:1: no `value`"), "{e}");
}

#[test]
fn a_column_after_an_escape_is_the_column_in_the_file() {
    // `\t` is two characters of the file and one of the string: q is at column 18.
    let text = "name = \"c\"\napplies_to = \"edges\"\nvalue = \"length(\\tq)\"\n";
    let e = ConstraintFile::parse(Path::new("mine.toml"), text)
        .unwrap_err()
        .to_string();
    assert!(e.starts_with("mine.toml:3:19: "), "{e}");
    // A literal string has no escapes.
    let text = "name = \"c\"\napplies_to = \"edges\"\nvalue = 'length(\tq)'\n";
    let e = ConstraintFile::parse(Path::new("mine.toml"), text)
        .unwrap_err()
        .to_string();
    assert!(e.starts_with("mine.toml:3:18: "), "{e}");
}

#[test]
fn expressions_may_span_lines() {
    let file = edge_file(
        "d = p1 -\n    p0\nk = dot(d,\n        d)",
        "sqrt(k)\n  - 1\n  + 0 * (d.x\n         + d.y)",
    )
    .unwrap();
    let points = [DVec3::ZERO, DVec3::new(0.0, 3.0, 4.0)];
    assert_eq!(file.value(&points, 0.0, &[]), 4.0);
    // A mistake on a later line of an expression is named on that line.
    let e = edge_file("", "length(p0 - p1)\n  + q").unwrap_err();
    assert!(e.starts_with("mine.toml:7:5: "), "{e}");
}

#[test]
fn a_constraint_against_a_fixed_plane_and_point_can_be_written() {
    // A wall at y = 0 and an attachment to (1, 2, 3), as written in a file.
    let wall = edge_file("", "min(p0.y, 0)").unwrap();
    let below = [DVec3::new(0.5, -0.25, 0.0), DVec3::ZERO];
    assert_eq!(wall.value(&below, 0.0, &[]), -0.25);
    let g = wall.evaluate_vectors(&below, 0.0, &[]).gradients;
    assert_eq!(g[0], DVec3::Y);
    let pin = edge_file("", "length(p0 - vec3(1, 2, 3))").unwrap();
    let g = pin.evaluate_vectors(&[DVec3::new(1.0, 2.0, 5.0), DVec3::ZERO], 0.0, &[]);
    assert_eq!((g.value, g.gradients[0]), (2.0, DVec3::Z));
}

#[test]
fn the_gradient_tape_on_tangents_gives_second_derivatives() {
    use tetlab_core::numbers::dual::Tangent;
    // C = |p0 − p1|: its Hessian block ∂²C/∂p0² = (I − u uᵀ) / |d|, u = d / |d|.
    let file = edge_file(
        "M = mat3(vec3(1.2, 0.1, 0) + p0, vec3(0.2, 0.8, 0.1) + p1, vec3(0, 0.3, -0.5) + p1 - p0)",
        "length(p0 - p1) + 0.25 * pow(dot(p0, p0), 2) + dot(polar(M).c0, p1) \
         + dot(singular_values(M), p0)",
    )
    .unwrap();
    let p = POINTS;
    for axis in 0..3 {
        // Tangent along p0's `axis` coordinate.
        let points: [[Tangent<f64>; 3]; 2] = std::array::from_fn(|i| {
            std::array::from_fn(|k| {
                Tangent::new(p[i][k], if i == 0 && k == axis { 1.0 } else { 0.0 })
            })
        });
        let (_, gradient) = file.automatic_gradient(&points, Tangent::new(0.0, 0.0), &[]);
        let column = gradient.map(|g| DVec3::new(g[0].slope, g[1].slope, g[2].slope));
        let h = 1e-6;
        let mut plus = p;
        let mut minus = p;
        plus[0][axis] += h;
        minus[0][axis] -= h;
        let g = |q: &[DVec3; 2]| file.evaluate_vectors(q, 0.0, &[]).gradients;
        let (above, below) = (g(&plus), g(&minus));
        for (k, exact) in column.iter().enumerate() {
            let numeric = (above[k] - below[k]) / (2.0 * h);
            assert!(
                (*exact - numeric).length() < 1e-6,
                "axis {axis}, p{k}: {exact} against {numeric}"
            );
        }
    }
}

/// Runs `f` on a thread with a 1 MB stack, the size the browser gives.
fn on_a_small_stack(f: impl FnOnce() + Send + 'static) {
    std::thread::Builder::new()
        .stack_size(1 << 20)
        .spawn(f)
        .expect("a thread")
        .join()
        .expect("no crash");
}

/// A file whose `key` expression (`value`, a definition, or a gradient entry) is `expression`.
fn file_with(key: &str, expression: &str) -> String {
    let header = "name = \"c\"\napplies_to = \"edges\"\n";
    match key {
        "value" => format!("{header}value = \"{expression}\"\n"),
        "define" => format!("{header}define = \"k = {expression}\"\nvalue = \"k\"\n"),
        _ => format!("{header}value = \"length(p0 - p1)\"\n[gradient]\np0 = \"{expression}\"\n"),
    }
}

#[test]
fn inputs_that_crashed_the_parser_are_errors_at_their_place_on_a_1_mb_stack() {
    on_a_small_stack(|| {
        let deep = |n: usize, open: &str, inner: &str| {
            format!("{}{inner}{}", open.repeat(n), ")".repeat(n))
        };
        let sum = vec!["p0"; 55_000].join(" + ");
        let cases = [
            ("value", deep(10_000, "(", "1"), 3, "nests too deeply"),
            ("define", deep(10_000, "(", "1"), 3, "nests too deeply"),
            ("gradient", deep(10_000, "(", "p0"), 5, "nests too deeply"),
            ("value", deep(10_000, "abs(", "1"), 3, "nests too deeply"),
            (
                "value",
                format!("{}1", "-".repeat(20_000)),
                3,
                "nests too deeply",
            ),
            (
                "value",
                format!("{}1", "- ".repeat(20_000)),
                3,
                "nests too deeply",
            ),
            (
                "value",
                vec!["1"; 55_000].join(" + "),
                3,
                "nests too deeply",
            ),
            ("gradient", sum.clone(), 5, "nests too deeply"),
            (
                "value",
                format!("{}1", "-(".repeat(5_000)),
                3,
                "nests too deeply",
            ),
            (
                "value",
                format!("p0{}", ".x".repeat(10_000)),
                3,
                "nests too deeply",
            ),
            ("value", "1 + ".repeat(300_000) + "1", 3, "nests too deeply"),
            ("value", "a".repeat(1 << 20), 3, "bytes long"),
        ];
        for (key, expression, line, what) in cases {
            let text = file_with(key, &expression);
            let e = ConstraintFile::parse(Path::new("deep.toml"), &text)
                .unwrap_err()
                .to_string();
            let head: String = expression.chars().take(20).collect();
            assert!(
                e.starts_with(&format!("deep.toml:{line}:")),
                "{key} {head}: {e}"
            );
            assert!(e.contains(what), "{key} {head}: {e}");
        }
        // As deep as is allowed still parses and compiles, on this stack: the depth counts the
        // parentheses, `length(` and its `-`.
        let at_limit = deep(MAX_DEPTH - 2, "(", "length(p0 - p1)");
        ConstraintFile::parse(Path::new("deep.toml"), &file_with("value", &at_limit))
            .unwrap_or_else(|e| panic!("{e}"));
        let negations = format!("{}length(p0 - p1)", "-".repeat(MAX_DEPTH - 2));
        ConstraintFile::parse(Path::new("deep.toml"), &file_with("value", &negations))
            .unwrap_or_else(|e| panic!("{e}"));
    });
}

#[test]
fn the_material_and_the_rest_shape_are_read_once_per_element_and_follow_a_new_material() {
    use tetlab_core::constraints::material::Material;
    // C = μ (|p0 − p1| − |q0 − q1|) / λ: μ / λ and the rest length are stored, not recomputed.
    let file = edge_file("", "mu / lambda * (length(p0 - p1) - length(q0 - q1))").unwrap();
    assert_eq!(file.stored_len(), 2);
    let rest_shape = [DVec3::ZERO, DVec3::X];
    let stretched = [DVec3::ZERO, 3.0 * DVec3::X];
    for (young, poisson) in [(1e6, 0.3), (5e4, 0.45)] {
        let material = Material { young, poisson };
        let stored = file.store(&rest_shape, &material);
        let expected = material.mu() / material.lambda() * 2.0;
        let value = file.value(&stretched, 0.0, &stored);
        assert!(
            (value - expected).abs() < 1e-15 * expected,
            "{value} against {expected}"
        );
        // The same in the lanes, from the stored numbers in f32.
        let lanes = stretched.map(|p| Vec3x8::gather([p.as_vec3a(); 8]));
        let stored32: Vec<F32x8> = stored.iter().map(|&x| F32x8::from_f64(x)).collect();
        let e = file.evaluate_vectors(&lanes, F32x8::ZERO, &stored32);
        assert!((f64::from(e.value.to_array()[0]) - expected).abs() < 1e-6 * expected);
    }
}

#[test]
fn every_mistake_in_a_file_of_several_constraints_is_named_at_its_place() {
    let header = "name = \"two\"\napplies_to = \"edges\"\n";
    let table = |name: &str, body: &str| format!("[[constraint]]\nname = \"{name}\"\n{body}\n");
    let cases = [
        (
            format!(
                "{header}pair = [\"a\", \"c\"]\n{}{}",
                table("a", "value = \"1 * length(p0 - p1)\""),
                table("b", "value = \"length(p0 - p1)\"")
            ),
            "two.toml:3:14: ",
            "`pair` names \"c\"",
        ),
        (
            format!(
                "{header}pair = [\"a\"]\n{}",
                table("a", "value = \"length(p0 - p1)\"")
            ),
            "two.toml:3:8: ",
            "names two different constraints",
        ),
        (
            format!("{header}pair = [\"a\", \"b\"]\nvalue = \"length(p0 - p1)\"\n"),
            "two.toml:3:8: ",
            "has none",
        ),
        (
            format!(
                "{header}{}{}",
                table("a", "value = \"length(p0 - p1)\""),
                table("a", "value = \"length(p0 - p1)\"")
            ),
            "two.toml:7:8: ",
            "two [[constraint]] tables are named \"a\"",
        ),
        (
            format!("{header}{}", table("a", "rest = \"0\"")),
            "two.toml:4:8: ",
            "has no `value`",
        ),
        (
            format!(
                "{header}value = \"length(p0 - p1)\"\n{}",
                table("a", "value = \"length(p0 - p1)\"")
            ),
            "two.toml:3:9: ",
            "give each its own `value`",
        ),
        (
            format!(
                "{header}{}",
                table("a", "value = \"length(p0 - p1)\"\nstiffness = \"young\"")
            ),
            "two.toml:6:13: ",
            "stiffness is \"young\"",
        ),
        (
            format!(
                "{header}{}",
                table("a", "value = \"length(p0 - p1)\"\nvalu = \"1\"")
            ),
            "two.toml:6:1: ",
            "unknown field `valu`",
        ),
        (
            "name = \"two\"\napplies_to = \"faces\"\nvalue = \"1\"\n".to_owned(),
            "two.toml:2:14: ",
            "\"triangles\"",
        ),
    ];
    for (text, at, what) in cases {
        let e = ConstraintFile::parse_all(Path::new("two.toml"), &text)
            .unwrap_err()
            .to_string();
        assert!(e.starts_with(at) && e.contains(what), "{text}\n{e}");
    }
    // A file of two where one is asked for says so.
    let two = format!(
        "{header}{}{}",
        table("a", "value = \"length(p0 - p1)\""),
        table("b", "value = \"length(p0 - p1)\"")
    );
    let e = ConstraintFile::parse(Path::new("two.toml"), &two)
        .unwrap_err()
        .to_string();
    assert!(e.contains("holds 2 constraints (two-a, two-b)"), "{e}");
}

/// Where F's singular values repeat (F = 2Q, Q a rotation: all three are 2), the polar rotation
/// and what is symmetric in σ have gradients, in both modes and as central differences say; U
/// and V are not unique there, and a C that reads them is flagged as undefined, never NaN.
#[test]
fn at_repeated_singular_values_the_rotation_and_sums_of_sigma_differentiate_and_u_v_are_flagged() {
    use tetlab_core::constraints::material::Material;
    let tet = |value: &str| {
        let text = format!("name = \"c\"\napplies_to = \"tets\"\nvalue = \"{value}\"\n");
        ConstraintFile::parse(Path::new("mine.toml"), &text).unwrap()
    };
    let shape = [DVec3::ZERO, DVec3::X, DVec3::Y, DVec3::Z];
    let turn = glam::DQuat::from_axis_angle(DVec3::new(1.0, 2.0, 2.0) / 3.0, 0.7);
    let points = shape.map(|q| turn * q * 2.0 + DVec3::new(0.1, 0.2, 0.3));
    let material = Material::default();
    for value in [
        "trace(polar(F) * transpose(F)) + dot(polar(F).c0, p1)",
        "dot(singular_values(F), vec3(1, 1, 1)) * singular_values(F).x * singular_values(F).y \
         * singular_values(F).z",
    ] {
        let file = tet(value);
        let stored = file.store(&shape, &material);
        let forward = file
            .evaluate(&points, 0.0, &stored)
            .automatic
            .unwrap_or_else(|| panic!("{value}: defined"));
        let reverse = file.evaluate_vectors(&points, 0.0, &stored);
        assert!(!reverse.degenerate, "{value}");
        let h = 1e-6;
        for i in 0..4 {
            for axis in 0..3 {
                let (mut plus, mut minus) = (points, points);
                plus[i][axis] += h;
                minus[i][axis] -= h;
                let numeric = (file.value(&plus, 0.0, &stored) - file.value(&minus, 0.0, &stored))
                    / (2.0 * h);
                let scale = numeric.abs().max(1.0);
                assert!((forward[i][axis] - numeric).abs() < 1e-6 * scale, "{value}");
                assert!(
                    (reverse.gradients[i][axis] - numeric).abs() < 1e-6 * scale,
                    "{value}"
                );
            }
        }
    }
    for value in ["svd_u(F).c0.x", "dot(svd_v(F).c1, p2)"] {
        let file = tet(value);
        let stored = file.store(&shape, &material);
        let evaluation = file.evaluate(&points, 0.0, &stored);
        assert!(evaluation.value.is_finite(), "{value}");
        assert_eq!(evaluation.automatic, None, "{value}: flagged");
        assert!(
            file.evaluate_vectors(&points, 0.0, &stored).degenerate,
            "{value}"
        );
    }
}
