//! `tetlab bench`: the report's numbers are there and consistent with the scene, for the fast and
//! the reference solver; bad options are usage errors. (How fast is measured, not asserted: the
//! figures are in docs/performance.md.)

mod support;

use serde_json::Value;
use support::{assert_usage_error, asset, stderr, stdout, tetlab};
use tetlab_core::simulation::DEFAULT_SUBSTEPS;

fn bench_json(args: &[&str]) -> Value {
    let mut all = vec!["bench", "--json"];
    all.extend_from_slice(args);
    let output = tetlab(&all);
    assert!(output.status.success(), "{}", stderr(&output));
    let text = stdout(&output);
    serde_json::from_str(text.lines().last().unwrap()).unwrap()
}

#[test]
fn the_report_counts_the_work_of_a_frame() {
    for extra in [&["--threads", "2"][..], &["--reference"][..]] {
        let mut args = vec![
            "--scene",
            "cube",
            "--resolution",
            "3",
            "--frames",
            "5",
            "--warmup",
            "1",
        ];
        args.extend_from_slice(extra);
        let report = bench_json(&args);
        let tets = report["tets"].as_u64().unwrap();
        let edges = report["edges"].as_u64().unwrap();
        assert_eq!(tets, 162);
        assert_eq!(
            report["projections_per_frame"].as_u64().unwrap(),
            (edges + tets) * DEFAULT_SUBSTEPS as u64,
            "edges + volume, the default substeps of 1 iteration"
        );
        for key in [
            "ns_per_projection",
            "frames_per_second",
            "bytes_per_tet",
            "ms_per_frame",
        ] {
            let value = report[key].as_f64().unwrap();
            assert!(value.is_finite() && value > 0.0, "{key}: {value}");
        }
    }
    let report = bench_json(&["--scene", "tet", "--frames", "2", "--threads", "2"]);
    assert_eq!(report["threads"], 2);
    assert_eq!(report["solver"], "fast (f32)");
    assert!(
        report["lanes"]
            .as_str()
            .unwrap()
            .starts_with("8 f32 per batch"),
        "{}",
        report["lanes"]
    );
    let error = &report["relative_error"];
    assert!(error["edges"].as_f64().unwrap().is_finite());
    assert!(error["height"].is_null(), "heights not active");
}

#[test]
fn jacobi_order_is_reported_with_how_well_it_holds_the_constraints() {
    let run = |extra: &[&str]| {
        let mut args = vec!["--scene", "cube", "--resolution", "4", "--frames", "30"];
        args.extend_from_slice(extra);
        bench_json(&args)
    };
    let gauss_seidel = run(&[]);
    let jacobi = run(&["--jacobi", "--relaxation", "1.2"]);
    assert_eq!(jacobi["solver"], "fast (f32), Jacobi");
    assert_eq!(
        jacobi["projections_per_frame"],
        gauss_seidel["projections_per_frame"]
    );
    for family in ["edges", "volume"] {
        let gs = gauss_seidel["relative_error"][family].as_f64().unwrap();
        let j = jacobi["relative_error"][family].as_f64().unwrap();
        assert!(j > gs, "{family}: Jacobi {j}, Gauss–Seidel {gs}");
    }
    let reference = bench_json(&["--scene", "tet", "--frames", "2", "--reference"]);
    assert!(reference["relative_error"].is_null());
}

#[test]
fn the_heights_are_counted_and_timed_on_their_own() {
    let report = bench_json(&[
        "--scene",
        "cube",
        "--resolution",
        "2",
        "--constraints",
        "edges,height,volume",
        "--frames",
        "3",
    ]);
    let tets = report["tets"].as_u64().unwrap();
    let edges = report["edges"].as_u64().unwrap();
    assert_eq!(
        report["projections_per_frame"].as_u64().unwrap(),
        (edges + 4 * tets + tets) * DEFAULT_SUBSTEPS as u64
    );
    let by_family = &report["ns_per_projection_by_family"];
    for family in ["edges", "height", "volume"] {
        assert!(by_family[family].as_f64().unwrap() > 0.0, "{family}");
    }
}

/// A constraint file's family is benchmarked like the others, on both engines: counted, timed on
/// its own, and named in the report.
#[test]
fn a_constraint_files_family_is_benchmarked_on_both_engines() {
    let height = asset("constraints/height.toml");
    for engine in [&[][..], &["--reference"][..]] {
        let mut args = vec![
            "--scene",
            "cube",
            "--resolution",
            "2",
            "--constraints",
            "none",
            "--constraint-file",
            &height,
            "--frames",
            "3",
        ];
        args.extend_from_slice(engine);
        let report = bench_json(&args);
        assert_eq!(report["constraints"], "my-height", "{engine:?}");
        let tets = report["tets"].as_u64().unwrap();
        assert_eq!(
            report["projections_per_frame"].as_u64().unwrap(),
            4 * tets * DEFAULT_SUBSTEPS as u64
        );
        assert!(report["ns_per_projection"].as_f64().unwrap() > 0.0);
        if engine.is_empty() {
            let by_family = &report["ns_per_projection_by_family"]["my-height"];
            assert!(by_family.as_f64().unwrap() > 0.0);
            assert!(
                report["relative_error"]["my-height"]
                    .as_f64()
                    .unwrap()
                    .is_finite()
            );
        }
    }
}

/// A mesh wider than the f32 engine can hold (its volumes overflowed, and the report showed
/// inf, NaN and null) is refused when it loads, with its file and line; and nothing the bench
/// prints is ever anything but a number.
#[test]
fn a_mesh_beyond_f32_is_refused_and_every_figure_is_a_number() {
    let dir = std::env::temp_dir().join(format!("tetlab-bench-wide-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    std::fs::write(
        dir.join("wide.node"),
        "4 3 0 0\n0 0 0 0\n1 2e12 0 0\n2 0 2e12 0\n3 0 0 2e12\n",
    )
    .unwrap();
    std::fs::write(dir.join("wide.ele"), "1 4 0\n0 0 1 2 3\n").unwrap();
    let scene = dir.join("wide.node");
    assert_usage_error(
        &tetlab(&["bench", "--scene", scene.to_str().unwrap()]),
        "wide.node:3: x: 2e12 is beyond ±1e6",
    );
    std::fs::write(
        dir.join("wide.node"),
        "4 3 0 0\n0 0 0 0\n1 1e6 0 0\n2 0 1e6 0\n3 0 0 1e6\n",
    )
    .unwrap();
    let output = tetlab(&[
        "bench",
        "--scene",
        scene.to_str().unwrap(),
        "--constraints",
        "edges,height,volume",
        "--frames",
        "20",
        "--json",
    ]);
    assert!(output.status.success(), "{}", stderr(&output));
    let text = stdout(&output);
    for word in ["NaN", "inf", "null"] {
        assert!(!text.contains(word), "{word} in {text}");
    }
}

#[test]
fn bad_options_are_usage_errors() {
    assert_usage_error(&tetlab(&["bench", "--frames", "0"]), "--frames");
    assert_usage_error(&tetlab(&["bench", "--scene", "nowhere.msh"]), "--scene");
    assert_usage_error(&tetlab(&["bench", "--threads", "0"]), "--threads");
    assert_usage_error(&tetlab(&["bench", "--constraints", "glue"]), "glue");
    assert_usage_error(
        &tetlab(&["bench", "--reference", "--threads", "2"]),
        "--threads",
    );
    assert_usage_error(&tetlab(&["bench", "--reference", "--jacobi"]), "--jacobi");
    assert_usage_error(&tetlab(&["bench", "--relaxation", "1.5"]), "--jacobi");
    for omega in ["0", "2.5", "NaN", "-1", "x"] {
        assert_usage_error(
            &tetlab(&["bench", "--jacobi", &format!("--relaxation={omega}")]),
            "--relaxation",
        );
    }
}

/// `--engine reference` times the f64 solver; `--reference` says the same. Jacobi order is the
/// fast engine's only.
#[test]
fn the_reference_engine_is_timed_by_either_name() {
    for flag in [&["--reference"][..], &["--engine", "reference"][..]] {
        let mut args = vec!["--scene", "tet", "--frames", "2"];
        args.extend_from_slice(flag);
        let report = bench_json(&args);
        assert_eq!(report["solver"], "reference (f64)", "{flag:?}");
    }
    assert_eq!(
        bench_json(&["--scene", "tet", "--frames", "2"])["solver"],
        "fast (f32)"
    );
    assert_usage_error(
        &tetlab(&["bench", "--engine", "reference", "--jacobi"]),
        "--jacobi",
    );
}
