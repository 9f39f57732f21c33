//! `tetlab gradient` and `tetlab check-gradients`, run as a user would, checked against values
//! computed by hand.

mod support;

use serde_json::Value;
use support::{assert_usage_error, stderr, stdout, tetlab};

fn json(args: &[&str]) -> Value {
    let output = tetlab(args);
    assert!(output.status.success(), "{args:?}: {}", stderr(&output));
    serde_json::from_str(&stdout(&output)).expect("one JSON object")
}

fn vectors(value: &Value) -> Vec<[f64; 3]> {
    value
        .as_array()
        .unwrap()
        .iter()
        .map(|v| {
            let a: Vec<f64> = v
                .as_array()
                .unwrap()
                .iter()
                .map(|x| x.as_f64().unwrap())
                .collect();
            [a[0], a[1], a[2]]
        })
        .collect()
}

fn assert_close(actual: &[[f64; 3]], expected: &[[f64; 3]], tolerance: f64) {
    assert_eq!(actual.len(), expected.len());
    for (a, e) in actual.iter().zip(expected) {
        for k in 0..3 {
            assert!(
                (a[k] - e[k]).abs() <= tolerance,
                "{actual:?} != {expected:?}"
            );
        }
    }
}

/// A 3-4-5 triangle: |p0 − p1| = 5, so C = 5 − 4 = 1 and ∇ₚ₀C = (p0 − p1)/5.
#[test]
fn distance_by_hand() {
    let v = json(&[
        "gradient",
        "--constraint",
        "distance",
        "--points",
        "-1,0,0.5",
        "2,4,0.5",
        "--rest",
        "4",
        "--json",
    ]);
    // `distance` is an alias: the answer names the family.
    assert_eq!(v["constraint"], "edges");
    assert_eq!(v["value"], 1.0);
    assert_eq!(v["rest"], 4.0);
    assert_eq!(v["degenerate"], false);
    assert_close(
        &vectors(&v["gradients"]),
        &[[-0.6, -0.8, 0.0], [0.6, 0.8, 0.0]],
        1e-15,
    );
    assert_close(
        &vectors(&v["finite_difference"]),
        &[[-0.6, -0.8, 0.0], [0.6, 0.8, 0.0]],
        1e-9,
    );
    assert!(v["max_abs_error"].as_f64().unwrap() < 1e-9);
}

/// Face p0 = 0, p2 = x̂, p3 = ŷ (normal ẑ), p1 = (−0.2, 0.3, 2): height 2.
/// Raising p2 by δ tilts the plane to z = δx, which at p1 (x = −0.2) lowers the plane by 0.2δ:
/// ∂C/∂p2z = +0.2. Likewise ∂C/∂p3z = −0.3 and ∂C/∂p0z = −(1 + 0.2 − 0.3) = −0.9.
#[test]
fn height_by_hand() {
    let v = json(&[
        "gradient",
        "--constraint",
        "height",
        "--points",
        "0,0,0",
        "-0.2,0.3,2",
        "1,0,0",
        "0,1,0",
        "--rest",
        "-1.5",
        "--json",
    ]);
    assert_eq!(v["value"], 3.5);
    assert_close(
        &vectors(&v["gradients"]),
        &[
            [0.0, 0.0, -0.9],
            [0.0, 0.0, 1.0],
            [0.0, 0.0, 0.2],
            [0.0, 0.0, -0.3],
        ],
        1e-15,
    );
    assert!(v["max_abs_error"].as_f64().unwrap() < 1e-8);
}

/// The unit right-angle tet has volume 1/6; ∇ₚᵢC is a sixth of the face normal opposite pᵢ.
#[test]
fn volume_by_hand() {
    let v = json(&[
        "gradient",
        "--constraint",
        "volume",
        "--points",
        "0,0,0",
        "1,0,0",
        "0,1,0",
        "0,0,1",
        "--rest",
        "0.1",
        "--json",
    ]);
    assert!((v["value"].as_f64().unwrap() - (1.0 / 6.0 - 0.1)).abs() < 1e-15);
    let s = 1.0 / 6.0;
    assert_close(
        &vectors(&v["gradients"]),
        &[[-s, -s, -s], [s, 0.0, 0.0], [0.0, s, 0.0], [0.0, 0.0, s]],
        1e-15,
    );
}

#[test]
fn degenerate_input_is_flagged_and_finite() {
    let v = json(&[
        "gradient",
        "--constraint",
        "plane",
        "--points",
        "0,0,0",
        "0,0,1",
        "1,0,0",
        "2,0,0",
        "--rest",
        "0.5",
        "--json",
    ]);
    assert_eq!(v["degenerate"], true);
    assert_eq!(v["value"], -0.5);
    assert_close(&vectors(&v["gradients"]), &[[0.0; 3]; 4], 0.0);

    let v = json(&[
        "gradient",
        "--constraint",
        "distance",
        "--points",
        "1,1,1",
        "1,1,1",
        "--json",
    ]);
    assert_eq!(v["degenerate"], true);
    assert_eq!(v["value"], 0.0);
}

#[test]
fn the_table_shows_every_particle_and_the_error() {
    let output = tetlab(&[
        "gradient",
        "--constraint",
        "volume",
        "--points",
        "0,0,0",
        "1,0,0",
        "0,1,0",
        "0,0,1",
    ]);
    assert!(output.status.success());
    let text = stdout(&output);
    for needle in [
        "constraint  volume",
        "p0",
        "p1",
        "p2",
        "p3",
        "max |analytic - central",
    ] {
        assert!(text.contains(needle), "missing {needle:?} in\n{text}");
    }
}

#[test]
fn bad_input_is_one_line_naming_the_argument_with_status_2() {
    let cases: &[(&[&str], &str)] = &[
        (
            &["--constraint", "bend", "--points", "0,0,0", "1,0,0"],
            "--constraint",
        ),
        (
            &[
                "--constraint",
                "distance",
                "--points",
                "0,0,0",
                "1,0,0",
                "2,0,0",
            ],
            "--points",
        ),
        (
            &["--constraint", "plane", "--points", "0,0,0", "1,0,0"],
            "takes 4 points, got 2",
        ),
        (
            &["--constraint", "distance", "--points", "0,0,0", "1,x,0"],
            "'x' is not a number",
        ),
        (
            &["--constraint", "distance", "--points", "0,0,0", "1,nan,0"],
            "not a finite number",
        ),
        (
            &["--constraint", "distance", "--points", "0,0,0", "inf,0,0"],
            "not a finite number",
        ),
        (
            &["--constraint", "distance", "--points", "0,0,0", "1,0"],
            "--points",
        ),
        (
            &[
                "--constraint",
                "distance",
                "--points",
                "0,0,0",
                "1,0,0",
                "--rest",
                "x",
            ],
            "--rest",
        ),
        (
            &[
                "--constraint",
                "distance",
                "--points",
                "0,0,0",
                "1,0,0",
                "--rest",
                "nan",
            ],
            "--rest",
        ),
        (&["--constraint", "distance"], "--points"),
        (&["--points", "0,0,0", "1,0,0"], "--constraint"),
        (&["--constraint", "distance", "--points"], "--points"),
        (
            &[
                "--constraint",
                "volume",
                "--points",
                "0,0,0",
                "1e300,0,0",
                "0,1e300,0",
                "0,0,1e300",
            ],
            "too large",
        ),
    ];
    for (args, names) in cases {
        let mut full = vec!["gradient"];
        full.extend_from_slice(args);
        assert_usage_error(&tetlab(&full), names);
    }
}

#[test]
fn check_gradients_reports_every_family_within_bound() {
    let output = tetlab(&[
        "check-gradients",
        "--samples",
        "2000",
        "--seed",
        "7",
        "--json",
    ]);
    assert!(output.status.success());
    let rows: Vec<Value> = stdout(&output)
        .lines()
        .map(|l| serde_json::from_str(l).unwrap())
        .collect();
    let names: Vec<&str> = rows
        .iter()
        .map(|r| r["constraint"].as_str().unwrap())
        .collect();
    assert_eq!(
        names,
        [
            "edges",
            "height",
            "volume",
            "neohookean-deviatoric",
            "neohookean-hydrostatic"
        ]
    );
    for row in &rows {
        assert_eq!(row["compared"], 2000);
        assert!(row["max_relative_error"].as_f64().unwrap() <= 1e-6, "{row}");
    }
}

/// A neo-Hookean constraint reads its rest shape: the unit tet mirrored through the face
/// (p0, p2, p3) has det F = −1, so C_H = √V₀ (−1) − rest.
#[test]
fn the_hydrostatic_constraint_of_a_mirrored_tet() {
    let v = json(&[
        "gradient",
        "--constraint",
        "neohookean-hydrostatic",
        "--points",
        "0,0,0",
        "-1,0,0",
        "0,1,0",
        "0,0,1",
        "--rest-shape",
        "0,0,0",
        "1,0,0",
        "0,1,0",
        "0,0,1",
        "--json",
    ]);
    let s = (1.0f64 / 6.0).sqrt();
    assert!((v["value"].as_f64().unwrap() + s).abs() < 1e-15, "{v}");
    assert!(v["max_abs_error"].as_f64().unwrap() < 1e-9);
    let at_p1 = &vectors(&v["gradients"])[1];
    assert!(
        at_p1[0] > 0.0,
        "cof F points p1 back through the face: {at_p1:?}"
    );
    let output = tetlab(&[
        "gradient",
        "--constraint",
        "volume",
        "--points",
        "0,0,0",
        "1,0,0",
        "0,1,0",
        "0,0,1",
        "--rest-shape",
        "0,0,0",
        "1,0,0",
        "0,1,0",
        "0,0,1",
    ]);
    assert_usage_error(&output, "does not read a rest shape");
}

/// A constraint file from assets/constraints.
fn asset(name: &str) -> String {
    format!(
        "{}/../assets/constraints/{name}",
        env!("CARGO_MANIFEST_DIR")
    )
}

#[test]
fn a_right_constraint_file_agrees_and_exits_zero() {
    let file = asset("height.toml");
    let output = tetlab(&[
        "check-gradients",
        "--constraint-file",
        &file,
        "--configs",
        "500",
        "--json",
    ]);
    assert_eq!(output.status.code(), Some(0), "{}", stderr(&output));
    let v: Value = serde_json::from_str(&stdout(&output)).unwrap();
    assert_eq!(v["agrees"], true);
    assert_eq!(v["compared"], 500);
    for p in ["p0", "p1", "p2", "p3"] {
        assert!(v["max_relative_error"][p].as_f64().unwrap() < 1e-12, "{v}");
    }
    assert_eq!(v["translation_invariant"], true);
    assert_eq!(v["rotation_invariant"], true);
    assert_eq!(v["reflection"], "negated");
    assert!(v["worst"].is_null());
}

#[test]
fn a_flipped_sign_exits_one_and_names_the_particle_and_a_command_that_shows_it() {
    let file = asset("height-wrong-sign.toml");
    let output = tetlab(&[
        "check-gradients",
        "--constraint-file",
        &file,
        "--configs",
        "300",
    ]);
    assert_eq!(output.status.code(), Some(1), "{}", stderr(&output));
    let text = stdout(&output);
    assert!(text.contains("p3  2.00e0  WRONG"), "{text}");
    assert!(text.contains("p1  ") && text.contains("agrees"), "{text}");
    let json_output = tetlab(&[
        "check-gradients",
        "--constraint-file",
        &file,
        "--configs",
        "300",
        "--json",
    ]);
    assert_eq!(json_output.status.code(), Some(1));
    let v: Value = serde_json::from_str(&stdout(&json_output)).unwrap();
    assert_eq!(v["agrees"], false);
    let worst = &v["worst"];
    let particle = worst["particle"].as_str().unwrap();
    assert!(particle == "p3" || particle == "p0", "{worst}");
    // The command printed is ready to paste: run it, and it shows the difference.
    let command = worst["command"].as_str().unwrap();
    let words: Vec<&str> = command.split(' ').skip(1).collect();
    let mut args = words.clone();
    args.push("--json");
    let shown = json(&args);
    let k: usize = particle[1..].parse().unwrap();
    let automatic = vectors(&shown["automatic"])[k];
    let yours = vectors(&shown["yours"])[k];
    let difference: f64 = (0..3)
        .map(|i| (automatic[i] - yours[i]).abs())
        .fold(0.0, f64::max);
    assert!(
        difference > 0.1 * automatic.iter().map(|x| x.abs()).fold(0.0, f64::max),
        "{shown}"
    );
}

#[test]
fn a_mistake_in_a_constraint_file_exits_two_at_its_line_and_column() {
    let dir = std::env::temp_dir().join(format!("tetlab-constraint-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("mine.toml");
    std::fs::write(
        &path,
        "name = \"c\"\napplies_to = \"edges\"\nvalue = \"length(p0 - p3)\"\n",
    )
    .unwrap();
    let path = path.to_str().unwrap();
    for command in ["check-gradients", "gradient"] {
        let mut args = vec![command, "--constraint-file", path];
        if command == "gradient" {
            args.extend(["--points", "0,0,0", "1,0,0"]);
        }
        let err = assert_usage_error(&tetlab(&args), "`p3`");
        assert!(err.starts_with(&format!("error: {path}:3:22: ")), "{err}");
    }
    std::fs::remove_dir_all(&dir).unwrap();
}

/// The unit right-angle tet: V = 1/6, and ∇V at p1 is e2 × e3 / 6 = (1/6, 0, 0).
#[test]
fn gradient_of_a_constraint_file_shows_automatic_yours_and_finite_differences() {
    let v = json(&[
        "gradient",
        "--constraint-file",
        &asset("volume.toml"),
        "--points",
        "0,0,0",
        "1,0,0",
        "0,1,0",
        "0,0,1",
        "--json",
    ]);
    assert!((v["value"].as_f64().unwrap() - 1.0 / 6.0).abs() < 1e-15);
    let automatic = vectors(&v["automatic"]);
    let yours = vectors(&v["yours"]);
    let numeric = vectors(&v["finite_difference"]);
    assert_eq!(automatic[1], [1.0 / 6.0, 0.0, 0.0]);
    for k in 0..4 {
        for i in 0..3 {
            assert!((automatic[k][i] - yours[k][i]).abs() < 1e-15);
            assert!((automatic[k][i] - numeric[k][i]).abs() < 1e-8);
        }
    }
    assert_eq!(v["degenerate"], false);
}
