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
            "neohookean-hydrostatic",
            "contact"
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

/// A file `name` with `text` in a fresh folder (whose name has a space, as paths do), and the
/// folder to remove.
/// For a file that reads the rest shape (F), the printed command gives the failing rest shape
/// too, so that it shows the configuration that failed, not F = I.
#[test]
fn the_printed_command_of_a_file_that_reads_the_rest_shape_reproduces_the_failure() {
    let dir = std::env::temp_dir().join(format!("tetlab-rest-shape-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("detf.toml");
    let text = "name = \"detf\"\napplies_to = \"tets\"\nvalue = \"det(F) - 1\"\n\n[gradient]\n\
                p0 = \"p0 * 0\"\np1 = \"p1 * 0\"\np2 = \"p2 * 0\"\np3 = \"p3 * 0\"\n";
    std::fs::write(&path, text).unwrap();
    let file = path.to_str().unwrap();
    let output = tetlab(&["check-gradients", "--constraint-file", file, "--json"]);
    assert_eq!(output.status.code(), Some(1), "{}", stderr(&output));
    let v: Value = serde_json::from_str(&stdout(&output)).unwrap();
    let command = v["worst"]["command"].as_str().unwrap();
    assert!(command.contains(" --rest-shape "), "{command}");
    let mut args: Vec<&str> = command.split(' ').skip(1).collect();
    args.push("--json");
    let shown = json(&args);
    // Not the rest shape's F = I (where det F − 1 = 0 and AD's gradient is the cofactor of I):
    // the failing configuration's C, and the gradients that differ there.
    let value = shown["value"].as_f64().unwrap();
    assert!(value.abs() > 1e-6, "{shown}");
    let automatic = vectors(&shown["automatic"]);
    let yours = vectors(&shown["yours"]);
    let largest = |g: &[[f64; 3]]| g.iter().flatten().map(|x| x.abs()).fold(0.0, f64::max);
    assert!(
        largest(&automatic) > 0.0 && largest(&yours) == 0.0,
        "{shown}"
    );
    let _ = std::fs::remove_dir_all(dir);
}

fn written(name: &str, text: &str) -> (std::path::PathBuf, String) {
    let dir = std::env::temp_dir().join(format!("tetlab constraint {} {name}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join(name);
    std::fs::write(&path, text).unwrap();
    let shown = path.to_str().unwrap().to_owned();
    (dir, shown)
}

/// Each of `check-gradients`, `run` and `gradient` on the edge file `path`, as a user runs them.
fn every_command(path: &str) -> Vec<std::process::Output> {
    vec![
        tetlab(&[
            "check-gradients",
            "--constraint-file",
            path,
            "--configs",
            "50",
        ]),
        tetlab(&[
            "run",
            "--scene",
            "tet",
            "--frames",
            "1",
            "--constraint-file",
            path,
        ]),
        tetlab(&[
            "gradient",
            "--constraint-file",
            path,
            "--points",
            "0,0,0",
            "1,0,0",
        ]),
    ]
}

#[test]
fn inputs_that_crashed_the_parser_exit_two_at_their_place_in_every_command() {
    let header = "name = \"c\"\napplies_to = \"edges\"\n";
    let deep =
        |n: usize, open: &str, inner: &str| format!("{}{inner}{}", open.repeat(n), ")".repeat(n));
    let sum = vec!["length(p0 - p1)"; 70_000].join(" + ");
    let cases = [
        (
            "parentheses",
            format!("{header}value = \"{}\"\n", deep(10_000, "(", "1")),
        ),
        (
            "define",
            format!(
                "{header}define = \"k = {}\"\nvalue = \"k\"\n",
                deep(10_000, "(", "1")
            ),
        ),
        (
            "gradient",
            format!(
                "{header}value = \"length(p0 - p1)\"\n[gradient]\np0 = \"{}\"\n",
                deep(10_000, "(", "p0")
            ),
        ),
        (
            "abs",
            format!("{header}value = \"{}\"\n", deep(10_000, "abs(", "1")),
        ),
        (
            "minus",
            format!("{header}value = \"{}1\"\n", "-".repeat(20_000)),
        ),
        ("megabyte", format!("{header}value = \"{sum}\"\n")),
    ];
    for (what, text) in cases {
        assert!(what != "megabyte" || text.len() > 1_000_000);
        let (dir, path) = written(&format!("{what}.toml"), &text);
        for output in every_command(&path) {
            let err = assert_usage_error(&output, "nests too deeply");
            // `run` says which option it was: "--constraint-file PATH:LINE:COLUMN: …".
            let at = err
                .find(&format!("{path}:"))
                .unwrap_or_else(|| panic!("{what}: {err}"));
            let place: Vec<&str> = err[at + path.len() + 1..].splitn(3, ':').collect();
            assert!(
                place[0].parse::<usize>().is_ok() && place[1].parse::<usize>().is_ok(),
                "{what}: no line and column in {err}"
            );
        }
        std::fs::remove_dir_all(&dir).unwrap();
    }
}

#[test]
fn an_undefined_constant_exits_two_at_its_place_in_every_command() {
    for (value, what) in [
        ("length(p0 - p1) / (1 - 1)", "division by zero"),
        ("length(p0 - p1) + 1e308 * 10", "too large"),
        ("length(p0 - p1) + log(0)", "log of 0"),
    ] {
        let text = format!("name = \"c\"\napplies_to = \"edges\"\nvalue = \"{value}\"\n");
        let (dir, path) = written("undefined.toml", &text);
        for output in every_command(&path) {
            let err = assert_usage_error(&output, what);
            assert!(err.contains(&format!("{path}:3:")), "{err}");
        }
        std::fs::remove_dir_all(&dir).unwrap();
    }
}

/// `check-gradients` on an edge file whose value is `value` and gradient `gradient`.
fn checked(value: &str, gradient: &str, json: bool) -> (std::process::Output, String) {
    let text = format!(
        "name = \"c\"\napplies_to = \"edges\"\nvalue = \"{value}\"\n[gradient]\n{gradient}\n"
    );
    let (dir, path) = written("check.toml", &text);
    let mut args = vec![
        "check-gradients",
        "--constraint-file",
        &path,
        "--configs",
        "200",
    ];
    if json {
        args.push("--json");
    }
    let output = tetlab(&args);
    std::fs::remove_dir_all(&dir).unwrap();
    (output, path)
}

#[test]
fn the_checks_messages_say_what_is_true() {
    // An error of 10⁻⁴ at one particle, in two significant digits.
    let (output, _) = checked(
        "length(p0 - p1)",
        "p0 = \"normalize(p0 - p1) * 1.0001\"\np1 = \"normalize(p1 - p0)\"",
        false,
    );
    assert_eq!(output.status.code(), Some(1));
    let text = stdout(&output);
    assert!(
        text.contains("p0 is off by 1.0e-4 of the gradient's size"),
        "{text}"
    );
    // Translation invariance is reported for your gradient too.
    assert!(
        text.contains("AD's yes") && text.contains("and yours no"),
        "{text}"
    );
    // A gradient that is never finite is "non_finite" in JSON, not null ("not given").
    let (output, _) = checked(
        "length(p0 - p1)",
        "p0 = \"normalize(p0 - p1) * log(length(p0 - p1) - length(p0 - p1))\"",
        true,
    );
    let v: Value = serde_json::from_str(&stdout(&output)).unwrap();
    assert_eq!(v["max_relative_error"]["p0"], "non_finite", "{v}");
    assert!(v["max_relative_error"]["p1"].is_null(), "{v}");
    // Where AD's gradient is zero the error is absolute, and said to be.
    let (output, _) = checked("0 * length(p0 - p1)", "p0 = \"vec3(0.5, 0, 0)\"", false);
    let text = stdout(&output);
    assert!(
        text.contains("off by 0.50 (absolute: AD's gradient is zero there)"),
        "{text}"
    );
}

#[test]
fn the_suggested_command_runs_from_a_path_with_a_space() {
    let text = "name = \"c\"\napplies_to = \"edges\"\nvalue = \"length(p0 - p1)\"\n[gradient]\np0 = \"normalize(p1 - p0)\"\n";
    let (dir, path) = written("wrong.toml", text);
    let output = tetlab(&[
        "check-gradients",
        "--constraint-file",
        &path,
        "--configs",
        "50",
        "--json",
    ]);
    let v: Value = serde_json::from_str(&stdout(&output)).unwrap();
    let command = v["worst"]["command"].as_str().unwrap();
    let mut words = shlex::split(command).expect("a command a shell reads");
    assert_eq!(words.remove(0), "tetlab");
    assert!(words.contains(&path), "{command}");
    words.push("--json".into());
    let args: Vec<&str> = words.iter().map(String::as_str).collect();
    let shown = json(&args);
    assert_eq!(shown["name"], "c");
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn kinks_are_reported_where_they_are() {
    let text =
        "name = \"k\"\napplies_to = \"edges\"\nvalue = \"abs(p0.x - p1.x) + max(p0.y, 0)\"\n";
    let (dir, path) = written("kinks.toml", text);
    let output = tetlab(&[
        "check-gradients",
        "--constraint-file",
        &path,
        "--configs",
        "100",
    ]);
    assert!(output.status.success(), "{}", stderr(&output));
    let out = stdout(&output);
    assert!(out.contains("C has kinks"), "{out}");
    assert!(out.contains(&format!("abs at {path}:3:10")), "{out}");
    assert!(out.contains(&format!("max at {path}:3:29")), "{out}");
    // On the kink of abs, `gradient` says so.
    let output = tetlab(&[
        "gradient",
        "--constraint-file",
        &path,
        "--points",
        "0.5,-1,0",
        "0.5,0,0",
    ]);
    let out = stdout(&output);
    assert!(
        out.contains("kink        yes") && out.contains("abs at"),
        "{out}"
    );
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn a_file_of_several_constraints_is_checked_constraint_by_constraint() {
    let output = tetlab(&[
        "check-gradients",
        "--constraint-file",
        &asset("neohookean.toml"),
        "--configs",
        "300",
        "--json",
    ]);
    assert!(output.status.success(), "{}", stderr(&output));
    let text = stdout(&output);
    let rows: Vec<Value> = text
        .lines()
        .map(|l| serde_json::from_str(l).unwrap())
        .collect();
    assert_eq!(rows.len(), 2);
    assert_eq!(rows[0]["name"], "my-neohookean-deviatoric");
    assert_eq!(rows[1]["name"], "my-neohookean-hydrostatic");
    for row in &rows {
        assert!(
            row["automatic_vs_finite_difference"].as_f64().unwrap() < 1e-6,
            "{row}"
        );
        assert_eq!(row["translation_invariant"], true);
    }
    // The bending example's hand gradient agrees with AD.
    let output = tetlab(&[
        "check-gradients",
        "--constraint-file",
        &asset("bending.toml"),
        "--configs",
        "300",
    ]);
    assert_eq!(output.status.code(), Some(0), "{}", stdout(&output));
}

/// check-gradients gives every built-in family a Hessian column: ∇²C by forward mode over the
/// analytic ∇C, against second-order dual numbers of C (to rounding) and against central
/// differences of ∇C.
#[test]
fn check_gradients_checks_every_familys_hessian() {
    let output = tetlab(&["check-gradients", "--samples", "300", "--json"]);
    assert!(output.status.success(), "{}", stderr(&output));
    for line in stdout(&output).lines() {
        let row: Value = serde_json::from_str(line).unwrap();
        let hessian = &row["hessian"];
        assert_eq!(hessian["compared"], 300, "{row}");
        assert!(
            hessian["against_second_order"].as_f64().unwrap() < 1e-12,
            "{row}"
        );
        assert!(
            hessian["against_finite_differences"].as_f64().unwrap() < 1e-5,
            "{row}"
        );
    }
    let table = stdout(&tetlab(&["check-gradients", "--samples", "300"]));
    assert!(table.contains("Hessian vs AD²"), "{table}");
}

/// A file's own Hessian blocks are checked like its gradient: the edge example's agree (exit 0),
/// a wrong block is named with its error (exit 1), and a block of a particle the constraint does
/// not have is a mistake at its line and column (exit 2).
#[test]
fn a_files_own_hessian_is_checked_block_by_block() {
    let right = tetlab(&[
        "check-gradients",
        "--constraint-file",
        &asset("edge.toml"),
        "--json",
    ]);
    assert!(right.status.success(), "{}", stderr(&right));
    let row: Value = serde_json::from_str(stdout(&right).lines().next().unwrap()).unwrap();
    assert_eq!(row["hessian_agrees"], true, "{row}");
    for block in ["p0p0", "p0p1", "p1p1"] {
        assert!(
            row["hessian"]["yours"][block].as_f64().unwrap() < 1e-12,
            "{row}"
        );
    }

    let (dir, wrong) = written(
        "wrong-hessian.toml",
        "name = \"e\"\napplies_to = \"edges\"\nvalue = \"length(p0 - p1) - rest\"\n\
         [hessian]\np0p0 = \"I / length(p0 - p1)\"\n",
    );
    let output = tetlab(&["check-gradients", "--constraint-file", &wrong]);
    assert_eq!(output.status.code(), Some(1), "{}", stdout(&output));
    let text = stdout(&output);
    assert!(text.contains("your p0p0  1.00e0  WRONG"), "{text}");
    assert!(
        text.contains("DISAGREES: your Hessian block p0p0"),
        "{text}"
    );

    let (_, bad) = written(
        "bad-hessian.toml",
        "name = \"e\"\napplies_to = \"edges\"\nvalue = \"length(p0 - p1) - rest\"\n\
         [hessian]\np0p2 = \"I\"\n",
    );
    let output = tetlab(&["check-gradients", "--constraint-file", &bad]);
    assert_eq!(output.status.code(), Some(2));
    assert!(
        stderr(&output).contains("bad-hessian.toml:5:1: hessian entry `p0p2`"),
        "{}",
        stderr(&output)
    );
    std::fs::remove_dir_all(dir).ok();
}

/// `tetlab modes` on the unit tet: at rest the volume's energy has 11 zero eigenvalues and one
/// positive, |∇V|² (with α = 1), flattened it has negative
/// ones, which the projection clamps; the Hessian passes its checks; the neo-Hookean pair gets
/// its F-space system; bad points are a usage error.
#[test]
fn modes_prints_the_classified_eigenmodes_and_their_checks() {
    let rest = json(&["modes", "--constraints", "volume", "--json"]);
    assert_eq!(rest["zero_count"], 11, "{rest}");
    assert_eq!(rest["negative_count"], 0, "{rest}");
    let modes = rest["modes"].as_array().unwrap();
    assert_eq!(modes.len(), 12);
    // |∇V|² at the unit tet: ∇V = (−1,−1,−1)/6, (1,0,0)/6, (0,1,0)/6, (0,0,1)/6, so 6/36.
    let top = modes[11]["eigenvalue"].as_f64().unwrap();
    assert!((top - 6.0 / 36.0).abs() < 1e-12, "{top}");
    assert!(rest["asymmetry"].as_f64().unwrap() <= 1e-12);
    assert!(rest["against_second_order"].as_f64().unwrap() <= 1e-12);

    let flat = json(&[
        "modes",
        "--constraints",
        "volume",
        "--points",
        "0,0,0",
        "1,0,0",
        "0,1,0",
        "0.25,0.25,0",
        "--json",
    ]);
    assert_eq!(flat["negative_count"], 3, "{flat}");
    for mode in flat["modes"].as_array().unwrap() {
        let (value, projected) = (
            mode["eigenvalue"].as_f64().unwrap(),
            mode["projected"].as_f64().unwrap(),
        );
        assert_eq!(projected, value.max(0.0));
    }
    let slope = flat["convergence_slope"].as_f64().unwrap();
    assert!(
        (slope - 2.0).abs() < 0.1 && flat["convergence_decades"].as_f64().unwrap() >= 3.0,
        "{flat}"
    );

    let neo = json(&[
        "modes",
        "--constraints",
        "neohookean",
        "--points",
        "0,0,0",
        "1,0,0",
        "0,1,0",
        "0,0,0.5",
        "--json",
    ]);
    assert!(neo["f_space"].is_object(), "{neo}");
    let table = stdout(&tetlab(&["modes", "--constraints", "neohookean"]));
    assert!(table.contains("6 zero"), "{table}");
    assert!(
        table.contains("translation") && table.contains("rotation"),
        "{table}"
    );

    // Coincident corners: the edges are degenerate (their gradient taken as 0), the
    // second-order check has no value there, and it says so instead of printing NaN.
    let coincident = ["modes", "--points", "0,0,0", "0,0,0", "0,0,0", "0,0,0"];
    let table = tetlab(&coincident);
    assert!(table.status.success(), "{}", stderr(&table));
    let text = stdout(&table);
    assert!(!text.contains("NaN") && !text.contains("inf"), "{text}");
    assert!(
        text.contains("against second-order dual numbers undefined"),
        "{text}"
    );
    let degenerate = json(&[&coincident[..], &["--json"]].concat());
    assert!(degenerate["against_second_order"].is_null(), "{degenerate}");
    for (args, names) in [
        (
            &["modes", "--points", "0,0,0", "1,0,0", "0,1,0"][..],
            "--points",
        ),
        (
            &[
                "modes",
                "--rest-shape",
                "0,0,0",
                "1e200,0,0",
                "0,1e200,0",
                "0,0,1e200",
            ][..],
            "--rest-shape: the rest tet's volume is not finite",
        ),
        (
            &["modes", "--rest-shape", "0,0,0", "1,0,0", "2,0,0", "3,0,0"][..],
            "--rest-shape",
        ),
        (
            &["modes", "--constraints", "none"][..],
            "no family is active",
        ),
    ] {
        assert_usage_error(&tetlab(args), names);
    }
}

/// A file that reads where the particles were at the start of the substep (`start0`…) and h:
/// `--start` and `--h` give them, C and ∇C follow by hand, and they are refused (status 2, named)
/// where nothing reads them or where they do not fit.
#[test]
fn the_start_of_the_substep_and_h_are_given_to_a_file_that_reads_them() {
    let damper = asset("edge-damper.toml");
    // The edge was along x, 0.9 long; now 1 long: it grew by 0.1 in h = 0.01 s, C = 10 m/s, and
    // ∇p1 C = n / h = (100, 0, 0).
    let out = json(&[
        "gradient",
        "--constraint-file",
        &damper,
        "--points",
        "0,0,0",
        "1,0,0",
        "--start",
        "0,0,0",
        "0.9,0,0",
        "--h",
        "0.01",
        "--json",
    ]);
    assert!(
        (out["value"].as_f64().unwrap() - 10.0).abs() < 1e-12,
        "{out}"
    );
    assert_close(
        &vectors(&out["automatic"]),
        &[[-100.0, 0.0, 0.0], [100.0, 0.0, 0.0]],
        1e-9,
    );
    for (args, says) in [
        (
            vec![
                "gradient",
                "--constraint",
                "edges",
                "--points",
                "0,0,0",
                "1,0,0",
                "--h",
                "0.01",
            ],
            "--start, --h",
        ),
        (
            vec![
                "gradient",
                "--constraint-file",
                &damper,
                "--points",
                "0,0,0",
                "1,0,0",
                "--start",
                "0,0,0",
            ],
            "--start: 1 points, as many as --points (2)",
        ),
        (
            vec![
                "gradient",
                "--constraint-file",
                &damper,
                "--points",
                "0,0,0",
                "1,0,0",
                "--h",
                "0",
            ],
            "--h",
        ),
    ] {
        assert_usage_error(&tetlab(&args), says);
    }
}
