//! `tetlab run` as a user runs it: defaults, JSON lines, the summary, the shared meshes, and bad
//! options.

mod support;

use serde_json::Value;
use support::{assert_usage_error, asset, stderr, stdout, tetlab};
use tetlab_core::input::shared_meshes;

fn json_lines(args: &[&str]) -> Vec<Value> {
    let output = tetlab(args);
    assert!(output.status.success(), "{args:?}: {}", stderr(&output));
    stdout(&output)
        .lines()
        .map(|line| serde_json::from_str(line).expect("each line is one JSON object"))
        .collect()
}

#[test]
fn json_prints_frame_zero_plus_one_line_per_frame() {
    let lines = json_lines(&["run", "--frames", "5", "--json"]);
    assert_eq!(lines.len(), 6);
    for (i, line) in lines.iter().enumerate() {
        assert_eq!(line["frame"], i as u64);
        for key in [
            "time",
            "inverted_tets",
            "min_volume_ratio",
            "volume_error",
            "max_edge_strain",
        ] {
            assert!(line[key].is_number(), "{key} in {line}");
        }
    }
    assert_eq!(
        (
            lines[0]["particles"].as_u64(),
            lines[0]["tets"].as_u64(),
            lines[0]["edges"].as_u64()
        ),
        (Some(4), Some(1), Some(6))
    );
    assert!(lines[1].get("particles").is_none(), "sizes only on frame 0");
    assert!((lines[5]["time"].as_f64().unwrap() - 5.0 / 60.0).abs() < 1e-12);
}

#[test]
fn frames_zero_prints_the_loaded_scene_only() {
    let lines = json_lines(&[
        "run",
        "--scene",
        "cube",
        "--resolution",
        "2",
        "--frames",
        "0",
        "--json",
    ]);
    assert_eq!(lines.len(), 1);
    assert_eq!(lines[0]["tets"], 48);
    assert_eq!(lines[0]["particles"], 27);
}

#[test]
fn the_defaults_are_those_documented() {
    let lines = json_lines(&["run", "--json"]);
    assert_eq!(lines.len(), 301, "300 frames by default");
    let output = tetlab(&["run", "--frames", "1"]);
    let text = stdout(&output);
    assert!(
        text.contains("scene tet: 4 particles, 1 tets, 6 edges"),
        "{text}"
    );
    assert!(
        text.contains(
            "xpbd, edges+volume, 100 substeps x 1 iteration, dt 0.016667 s, gravity 9.81"
        ),
        "{text}"
    );
}

#[test]
fn an_inverted_tet_recovers_in_the_summary_and_the_json() {
    let output = tetlab(&["run", "--perturb", "invert", "--frames", "30"]);
    assert!(
        stdout(&output).contains("no inverted tets from frame"),
        "{}",
        stdout(&output)
    );
    let lines = json_lines(&[
        "run",
        "--perturb",
        "invert",
        "--constraints",
        "edges",
        "--frames",
        "30",
        "--json",
    ]);
    assert!(
        lines.iter().all(|l| l["inverted_tets"] == 1),
        "edges alone never un-invert"
    );
}

#[test]
fn shared_meshes_run_and_report_their_sizes() {
    for (file, particles, tets) in [
        ("bunny.node", 333, 1351),
        ("armadillo_4k.ele", 1180, 3717),
        ("ball_v22.msh", 470, 1812),
        ("ball_v41.msh", 470, 1812),
        ("beam_v41.msh", 423, 1208),
    ] {
        let Some(path) = shared_meshes::for_test(file) else {
            return;
        };
        let path = path.to_str().unwrap();
        let lines = json_lines(&["run", "--scene", path, "--frames", "1", "--json"]);
        assert_eq!(
            (lines[0]["particles"].as_u64(), lines[0]["tets"].as_u64()),
            (Some(particles), Some(tets)),
            "{file}"
        );
    }
}

#[test]
fn bad_options_are_one_line_naming_the_option_with_status_2() {
    let cases: &[(&[&str], &str)] = &[
        (&["--scene", "nowhere"], "--scene"),
        (&["--resolution", "0"], "--resolution"),
        (&["--resolution", "x"], "--resolution"),
        (&["--perturb", "twist"], "--perturb"),
        (&["--perturb", "scramble:x"], "--perturb"),
        (&["--constraints", "edges,bend"], "--constraints"),
        (&["--solver", "verlet"], "--solver"),
        (&["--substeps", "0"], "--substeps"),
        (&["--iterations", "-1"], "--iterations"),
        (&["--frames", "-5"], "--frames"),
        (&["--dt", "0"], "--dt"),
        (&["--dt", "-0.01"], "--dt"),
        (&["--dt", "nan"], "--dt"),
        (&["--gravity", "inf"], "--gravity"),
        (&["--compliance", "edges"], "--compliance"),
        (&["--compliance", "edges=-1"], "--compliance"),
        (&["--stiffness", "volume=2"], "--stiffness"),
        (&["--damping", "-1"], "--damping"),
        (
            &["--compliance", "my-height=1e-6"],
            "--compliance my-height=0.000001",
        ),
        (
            &["--constraint-file", "/nonexistent.toml"],
            "--constraint-file /nonexistent.toml",
        ),
    ];
    for (args, option) in cases {
        let mut full = vec!["run"];
        full.extend_from_slice(args);
        assert_usage_error(&tetlab(&full), option);
    }
}

#[test]
fn a_broken_mesh_file_is_named_with_its_line() {
    let dir = std::env::temp_dir().join(format!("tetlab-run-cli-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("broken.msh");
    std::fs::write(
        &path,
        "$MeshFormat\n2.2 0 8\n$EndMeshFormat\n$Nodes\n1\n1 0 zero 0\n$EndNodes\n",
    )
    .unwrap();
    let output = tetlab(&["run", "--scene", path.to_str().unwrap()]);
    let line = assert_usage_error(&output, "broken.msh:6: y: 'zero' is not a number");
    assert!(line.starts_with("error: --scene: "), "{line}");
}

/// Values that would overflow inside the solver (α / h² = inf, h² = 0, coordinates whose fourth
/// power is beyond f32) are refused where they enter, naming the option or the file and line,
/// rather than accepted and reported as a divergence with advice that cannot help.
#[test]
fn values_that_would_overflow_are_refused_where_they_enter() {
    for (args, says) in [
        (
            &["--compliance", "edges=1e303"][..],
            "--compliance <FAMILY=α>': compliance 1e303 is out of range: expected 0 <= compliance <= 1e10",
        ),
        (
            &["--dt", "1e-320"],
            "dt 1e-320 is out of range: expected 1e-6 <= dt <= 1",
        ),
        (&["--gravity", "-1e300"], "gravity -1e300 is out of range"),
        (&["--damping", "1e300"], "damping 1e300 is out of range"),
    ] {
        let mut full = vec!["run"];
        full.extend_from_slice(args);
        let line = assert_usage_error(&tetlab(&full), says);
        assert!(!line.contains("diverged"), "{line}");
    }
    for (scene, resolution, tets, largest) in [
        ("ball", "128", 100_663_296, 70),
        ("beam", "128", 50_331_648, 88),
    ] {
        let output = tetlab(&["run", "--scene", scene, "--resolution", resolution]);
        assert_usage_error(
            &output,
            &format!(
                "{scene} at resolution 128 would have {tets} tets, more than the 16777216 tetlab simulates; {scene} goes up to resolution {largest}"
            ),
        );
    }
    let dir = std::env::temp_dir().join(format!("tetlab-run-far-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    std::fs::write(
        dir.join("far.node"),
        "4 3 0 0\n0 0 0 0\n1 1e31 0 0\n2 0 1 0\n3 0 0 1\n",
    )
    .unwrap();
    std::fs::write(dir.join("far.ele"), "1 4 0\n0 0 1 2 3\n").unwrap();
    let scene = dir.join("far.node");
    let output = tetlab(&["run", "--scene", scene.to_str().unwrap()]);
    assert_usage_error(&output, "far.node:3: x: 1e31 is beyond ±1e6");
}

#[test]
fn the_bipyramid_asset_inverts_one_tet_through_the_shared_face_and_recovers() {
    let path = format!(
        "{}/../assets/meshes/bipyramid.node",
        env!("CARGO_MANIFEST_DIR")
    );
    let output = tetlab(&[
        "run",
        "--scene",
        &path,
        "--perturb",
        "invert",
        "--frames",
        "60",
    ]);
    let text = stdout(&output);
    assert!(output.status.success(), "{}", stderr(&output));
    assert!(
        text.contains("scene bipyramid: 5 particles, 2 tets, 9 edges"),
        "{text}"
    );
    assert!(
        !text.contains("note:"),
        "both tets are written positively: {text}"
    );
    assert!(
        text.contains("frame      0: inverted tets      1"),
        "{text}"
    );
    assert!(text.contains("no inverted tets from frame"), "{text}");
}

/// The neo-Hookean family from the command line: one name for both constraints, its material in
/// Pa, what it measures, and every wrong way to give it.
#[test]
fn the_neo_hookean_family_takes_a_material_in_physical_units() {
    let lines = json_lines(&[
        "run",
        "--scene",
        "cube",
        "--perturb",
        "mirror",
        "--constraints",
        "neohookean",
        "--material",
        "nu=0.3, E=2e6",
        "--substeps",
        "20",
        "--frames",
        "120",
        "--json",
    ]);
    let last = lines.last().unwrap();
    assert_eq!(last["inverted_tets"], 0, "the mirrored cube recovers");
    for key in [
        "residual_neohookean-deviatoric",
        "residual_neohookean-hydrostatic",
    ] {
        assert!(last[key].as_f64().unwrap().is_finite(), "{key} in {last}");
    }
    let summary = tetlab(&["run", "--constraints", "neohookean", "--frames", "1"]);
    assert!(summary.status.success());
    assert!(
        stdout(&summary).contains("neohookean")
            && stdout(&summary).contains("material E=1e6,nu=0.3"),
        "{}",
        stdout(&summary)
    );
    for (material, says) in [
        ("E=1e6,nu=0.5", "nu 0.5 is out of range"),
        ("E=0,nu=0.3", "E 0 is out of range"),
        ("E=NaN,nu=0.3", "E NaN is not a number"),
        ("E=1e6", "nu is missing"),
        ("E=1e6,nu=0.3,rho=1000", "unknown material parameter 'rho'"),
        ("stiff", "'stiff' is not KEY=VALUE"),
    ] {
        let output = tetlab(&["run", "--material", material]);
        assert_usage_error(&output, "--material");
        assert!(
            stderr(&output).contains(says),
            "{material}: {}",
            stderr(&output)
        );
    }
    assert_usage_error(
        &tetlab(&["run", "--compliance", "neohookean=1e-6"]),
        "take their compliance from the material",
    );
    assert_usage_error(
        &tetlab(&["run", "--constraints", "edges,hydrostatic"]),
        "one of the constraints of neohookean",
    );
}

/// A material too stiff for the substeps is named, with how many it needs.
#[test]
fn a_material_too_stiff_for_the_substeps_is_warned_about() {
    let args = [
        "run",
        "--scene",
        "cube",
        "--constraints",
        "neohookean",
        "--frames",
        "1",
    ];
    let steel = [&args[..], &["--material", "E=2e11,nu=0.3"]].concat();
    let output = tetlab(&steel);
    assert!(output.status.success());
    assert!(
        stderr(&output).contains("warning: neohookean with material E=2e11,nu=0.3 needs at least"),
        "{}",
        stderr(&output)
    );
    assert!(
        !stderr(&tetlab(&args)).contains("warning"),
        "rubber at 10 substeps"
    );
}

/// A cantilever of the neo-Hookean material sags under gravity: its tip is the particle farthest
/// from rest, and a material four times stiffer deflects it about four times less.
#[test]
fn max_displacement_is_a_cantilevers_tip_deflection() {
    let tip = |material: &str| {
        let lines = json_lines(&[
            "run",
            "--scene",
            "beam",
            "--resolution",
            "1",
            "--constraints",
            "neohookean",
            "--material",
            material,
            "--substeps",
            "20",
            "--iterations",
            "4",
            "--damping",
            "20",
            "--frames",
            "200",
            "--json",
        ]);
        assert_eq!(lines[0]["max_displacement"], 0.0);
        lines.last().unwrap()["max_displacement"].as_f64().unwrap()
    };
    let (soft, stiff) = (tip("E=2.5e6,nu=0.3"), tip("E=1e7,nu=0.3"));
    assert!(stiff > 0.0 && soft < 0.5, "{soft} {stiff}");
    assert!((3.0..5.0).contains(&(soft / stiff)), "{soft} / {stiff}");
}

/// A constraint file's family runs like a built-in one: named on the command line and in the
/// JSON, its compliance set by its name, the source note's height recovering a mirrored cube
/// with the edges as the built-in heights do.
#[test]
fn a_constraint_files_family_runs_like_a_built_in_one() {
    let height = &asset("constraints/height.toml");
    let base = [
        "run",
        "--scene",
        "cube",
        "--resolution",
        "2",
        "--perturb",
        "mirror",
        "--gravity",
        "0",
        "--frames",
        "60",
        "--json",
    ];
    let mut args = base.to_vec();
    args.extend(["--constraints", "edges", "--constraint-file", height]);
    let file = json_lines(&args);
    let mut args = base.to_vec();
    args.extend(["--constraints", "edges,height"]);
    let builtin = json_lines(&args);
    assert_eq!(file[0]["inverted_tets"], 48);
    let (last, reference) = (&file[60], &builtin[60]);
    assert_eq!(last["inverted_tets"], 0, "recovered");
    assert_eq!(reference["inverted_tets"], 0);
    let residual = last["residual_my-height"]
        .as_f64()
        .expect("the file's family in the JSON");
    assert!(residual < 1e-3, "{residual}");

    // Named before the file that defines it, with a compliance; the summary names the file.
    let output = tetlab(&[
        "run",
        "--scene",
        "tet",
        "--frames",
        "1",
        "--constraints",
        "my-height,volume",
        "--compliance",
        "my-height=1e-4",
        "--constraint-file",
        height,
    ]);
    let text = stdout(&output);
    assert!(output.status.success(), "{}", stderr(&output));
    assert!(text.contains("volume+my-height"), "{text}");
    assert!(text.contains("compliance my-height=0.0001"), "{text}");
    assert!(
        text.contains("my-height from ") && text.contains("height.toml with the AD gradient"),
        "{text}"
    );
}

/// A constraint file with a mistake, or a name already taken, stops the run before it starts:
/// one line naming the file, its line and column, exit status 2.
#[test]
fn a_bad_constraint_file_is_named_at_its_line_and_column() {
    let dir = std::env::temp_dir().join(format!("tetlab-run-file-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let bad = dir.join("bad.toml");
    std::fs::write(
        &bad,
        "name = \"bad\"\napplies_to = \"edges\"\nvalue = \"length(p0 - p3) - rest\"\n",
    )
    .unwrap();
    let output = tetlab(&["run", "--constraint-file", bad.to_str().unwrap()]);
    let line = assert_usage_error(&output, "bad.toml:3:");
    assert!(line.contains("`p3`") && line.contains("p0…p1"), "{line}");

    let twin = dir.join("twin.toml");
    let text = std::fs::read_to_string(asset("constraints/volume.toml")).unwrap();
    std::fs::write(&twin, text.replace("det(", "0.5 * det(")).unwrap();
    let output = tetlab(&[
        "run",
        "--constraint-file",
        &asset("constraints/volume.toml"),
        "--constraint-file",
        twin.to_str().unwrap(),
    ]);
    let line = assert_usage_error(&output, "twin.toml");
    assert!(line.contains("already the name of"), "{line}");

    let builtin = dir.join("builtin.toml");
    std::fs::write(
        &builtin,
        "name = \"volume\"\napplies_to = \"tets\"\nvalue = \"1\"\n",
    )
    .unwrap();
    let line = assert_usage_error(
        &tetlab(&["run", "--constraint-file", builtin.to_str().unwrap()]),
        "builtin.toml",
    );
    assert!(line.contains("built-in"), "{line}");
}

/// The engine in use is chosen (`--engine`, `auto` by default: the reference one below 1000
/// tets, the fast one from there), named in frame 0 of the JSON and in the summary, and both
/// engines give the source note's result. (Without gravity, settling edits caps every speed at
/// zero: the recovery is then quasi-static, and on this cube of odd resolution it is a knife
/// edge, 14 and 15 of 16 orderings on the two engines; undone at speed, 16 of 16 on both, so
/// this runs with `--no-settle-edits`: `tetlab run --ensemble 16` with the same options.)
#[test]
fn the_engine_is_chosen_and_always_named() {
    let mirrored = |engine: &str| {
        json_lines(&[
            "run",
            "--no-settle-edits",
            "--scene",
            "cube",
            "--resolution",
            "3",
            "--perturb",
            "mirror",
            "--gravity",
            "0",
            "--constraints",
            "edges,height,volume",
            "--frames",
            "120",
            "--substeps",
            "10",
            "--engine",
            engine,
            "--json",
        ])
    };
    for engine in ["reference", "fast"] {
        let frames = mirrored(engine);
        assert_eq!(frames[0]["engine"], engine);
        assert_eq!(frames[0]["inverted_tets"], 162);
        assert_eq!(frames[120]["inverted_tets"], 0, "{engine}");
        assert!(frames[1].get("engine").is_none(), "frame 0 only");
    }
    let auto = |resolution: &str| {
        json_lines(&[
            "run",
            "--scene",
            "cube",
            "--resolution",
            resolution,
            "--frames",
            "0",
            "--json",
        ])[0]["engine"]
            .clone()
    };
    assert_eq!(auto("3"), "reference", "162 tets");
    assert_eq!(auto("6"), "fast", "1296 tets");
    let output = tetlab(&[
        "run",
        "--scene",
        "tet",
        "--frames",
        "1",
        "--engine",
        "fast",
        "--threads",
        "2",
    ]);
    let text = stdout(&output);
    assert!(text.contains("engine fast (f32, 2 threads)"), "{text}");
    assert_usage_error(&tetlab(&["run", "--engine", "cuda"]), "--engine");
    assert_usage_error(&tetlab(&["run", "--threads", "0"]), "--threads");
}

#[test]
fn every_frame_carries_its_energy_account_and_the_summary_its_ends() {
    let args = [
        "run",
        "--scene",
        "cube",
        "--resolution",
        "2",
        "--constraints",
        "neohookean",
        "--perturb",
        "flatten",
        "--frames",
        "20",
    ];
    let lines = json_lines(&[&args[..], &["--json"]].concat());
    for line in &lines {
        let part = |key: &str| {
            line[key]
                .as_f64()
                .unwrap_or_else(|| panic!("{key}: {line}"))
        };
        let sum = part("energy_kinetic")
            + part("energy_gravitational")
            + part("energy_external")
            + part("energy_elastic_neohookean-deviatoric")
            + part("energy_elastic_neohookean-hydrostatic");
        let total = part("energy_total");
        assert!((sum - total).abs() <= 1e-9 * total.abs(), "{line}");
    }
    // The flattened material holds energy at the start and lets it go: the total only falls.
    let totals: Vec<f64> = lines
        .iter()
        .map(|l| l["energy_total"].as_f64().unwrap())
        .collect();
    assert!(totals[0] > 0.0 && totals[20] < totals[0], "{totals:?}");
    let output = tetlab(&args);
    let text = stdout(&output);
    assert!(text.contains("energy: "), "{text}");
    assert!(!text.contains("the energy grew"), "{text}");
}

#[test]
fn exact_step_says_how_far_each_frame_is_from_the_implicit_step() {
    let run = |substeps: &str| {
        json_lines(&[
            "run",
            "--scene",
            "cube",
            "--resolution",
            "2",
            "--perturb",
            "scramble:7",
            "--constraints",
            "edges,volume",
            "--compliance",
            "edges=1e-3",
            "--compliance",
            "volume=1e-2",
            "--substeps",
            substeps,
            "--frames",
            "3",
            "--exact-step",
            "--json",
        ])
    };
    let largest = |lines: &[Value]| {
        (lines.iter().skip(1))
            .map(|l| l["exact_step_distance"].as_f64().unwrap())
            .fold(0.0, f64::max)
    };
    let (coarse, fine) = (largest(&run("5")), largest(&run("20")));
    // XPBD's distance from the exact step shrinks with the substep (its bias goes as h²).
    assert!(coarse > 0.0 && fine < coarse / 4.0, "{coarse} {fine}");
    let output = tetlab(&["run", "--frames", "2", "--exact-step", "--ensemble", "2"]);
    assert_usage_error(&output, "--exact-step");
}

#[test]
fn a_scene_file_of_several_bodies_is_run_and_measured_body_by_body() {
    let scene = asset("scenes/thrown.toml");
    let lines = json_lines(&["run", "--scene", &scene, "--frames", "2", "--json"]);
    let bodies = lines[2]["bodies"].as_array().expect("each body's metrics");
    let names: Vec<&str> = bodies.iter().map(|b| b["name"].as_str().unwrap()).collect();
    assert_eq!(names, ["cube", "ball", "beam"]);
    // The ball was thrown up: it is the one that moves.
    assert!(
        bodies[1]["max_speed"].as_f64().unwrap() > 2.0,
        "{}",
        bodies[1]
    );
    assert!(
        bodies[0]["max_speed"].as_f64().unwrap() < 0.1,
        "{}",
        bodies[0]
    );
    // Each body's energy, and they add up to the scene's.
    let part = |b: &Value, name: &str| b[name].as_f64().unwrap_or_else(|| panic!("{name}: {b}"));
    let sum: f64 = bodies.iter().map(|b| part(b, "energy_total")).sum();
    let whole = part(&lines[2], "energy_total");
    assert!((sum - whole).abs() <= 1e-9 * whole.abs(), "{sum} {whole}");
    assert!(
        part(&bodies[1], "energy_kinetic") > 100.0 * part(&bodies[0], "energy_kinetic"),
        "the thrown ball carries the motion: {}",
        lines[2]
    );
    // A scene of one body has none.
    let one = json_lines(&["run", "--frames", "1", "--json"]);
    assert!(one[1].get("bodies").is_none(), "{}", one[1]);

    let output = tetlab(&["run", "--scene", &scene, "--frames", "2"]);
    let text = stdout(&output);
    assert!(text.contains("scene thrown: 233 particles"), "{text}");
    assert!(text.contains("body ball: 0 inverted tets"), "{text}");

    // A mistake in the scene file: exit 2, named at its place.
    let dir = std::env::temp_dir().join(format!("tetlab-run-scene-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let bad = dir.join("bad.toml");
    std::fs::write(&bad, "[[body]]\nmesh = \"cube\"\nscale = -1\n").unwrap();
    let output = tetlab(&["run", "--scene", bad.to_str().unwrap(), "--frames", "1"]);
    let message = assert_usage_error(&output, "bad.toml:3:9: scale is -1");
    assert!(!message.contains("panicked"), "{message}");
    std::fs::remove_dir_all(&dir).ok();
}

/// Contact on the command line: the stacked cubes rest and `run` says how they touch; the
/// Newton reference, which solves a substep without contact, is refused for a family on
/// contacts, as is `--exact-step`, which steps against it.
#[test]
fn contact_is_reported_and_refused_where_it_cannot_run() {
    let scene = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../assets/scenes/stacked-cubes.toml"
    );
    let common = [
        "run",
        "--scene",
        scene,
        "--constraints",
        "edges,volume,contact",
    ];
    let output = tetlab(&[&common[..], &["--frames", "10"]].concat());
    let text = stdout(&output);
    assert!(output.status.success(), "{text}");
    assert!(
        text.contains("contact thickness 0.01 m, friction 0.5/0.4"),
        "{text}"
    );
    assert!(text.contains("contact: 13 touching at the end"), "{text}");
    let json = tetlab(&[&common[..], &["--frames", "1", "--json"]].concat());
    let last: serde_json::Value = stdout(&json)
        .lines()
        .last()
        .map(|l| serde_json::from_str(l).unwrap())
        .unwrap();
    assert!(last["contacts"].as_u64().unwrap() > 0, "{last}");
    assert!(last["max_penetration"].as_f64().unwrap() < 1e-3, "{last}");
    let newton = tetlab(&[&common[..], &["--engine", "newton", "--frames", "1"]].concat());
    assert_usage_error(
        &newton,
        "--engine newton: the Newton reference solves a substep without contact",
    );
    let exact = tetlab(&[&common[..], &["--exact-step", "--frames", "1"]].concat());
    assert_usage_error(&exact, "--exact-step: the Newton reference");
    let friction = tetlab(&[&common[..], &["--friction", "0.5,x", "--frames", "1"]].concat());
    assert_usage_error(&friction, "--friction");
    // A negative value is the value's mistake, not taken for an option.
    for (option, value, said) in [
        ("--thickness", "-1", "thickness -1 is out of range"),
        ("--friction", "-1", "friction -1 is out of range"),
        ("--friction", "0.2,-1", "friction -1 is out of range"),
    ] {
        let wrong = tetlab(&[&common[..], &[option, value, "--frames", "1"]].concat());
        assert_usage_error(&wrong, said);
    }
}

/// A particle under a surface is the solver's error, and `run` says so: a cube thrown down at
/// 8 m/s onto another goes 13 cm into it with one substep a frame, and is held a thickness
/// above it at the default 100.
#[test]
fn a_particle_under_a_surface_is_warned_about() {
    let scene = asset("scenes/dropped-cube.toml");
    let common = [
        "run",
        "--scene",
        &scene,
        "--constraints",
        "edges,volume,contact",
        "--frames",
        "20",
    ];
    let one = tetlab(&[&common[..], &["--substeps", "1"]].concat());
    let text = stdout(&one);
    assert!(one.status.success(), "{text}");
    let warning = (text.lines())
        .find(|line| line.starts_with("warning: contact let a particle"))
        .unwrap_or_else(|| panic!("a warning: {text}"));
    assert!(
        warning.contains("under a surface at frame") && warning.contains("the solver's error"),
        "{warning}"
    );
    let held = tetlab(&common);
    let text = stdout(&held);
    assert!(held.status.success(), "{text}");
    assert!(!text.contains("under a surface"), "{text}");
}
