//! `tetlab record` end to end: the file it writes is read back with Rerun's decoder (through
//! `tetlab inspect`) and compared with the simulation that `tetlab run` reports.

mod support;

use serde_json::Value;
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};
use support::{assert_usage_error, asset, stderr, stdout, tetlab};

fn scratch(test: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("tetlab-record-{}-{test}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// Runs `command` to its end, but for at most `limit`: a run that takes longer is killed and
/// fails the test (a hang would otherwise hold CI for its whole time limit).
fn watched(command: &mut Command, limit: Duration) -> std::process::Output {
    let mut child = command
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let started = Instant::now();
    while child.try_wait().unwrap().is_none() {
        if started.elapsed() > limit {
            child.kill().ok();
            let output = child.wait_with_output().unwrap();
            panic!(
                "still running after {limit:?}, killed: {command:?}; stderr: {}",
                stderr(&output)
            );
        }
        std::thread::sleep(Duration::from_millis(20));
    }
    child.wait_with_output().unwrap()
}

/// `tetlab record ARGS --out PATH` under a file-size limit of `blocks` KiB (`ulimit -f`: a full
/// disk fails a write the same way, EFBIG or ENOSPC), watched for 20 s.
#[cfg(unix)]
fn record_under_a_size_limit(blocks: u32, path: &Path, args: &str) -> std::process::Output {
    watched(
        Command::new("sh")
            .arg("-c")
            .arg(format!(
                "ulimit -f {blocks} && exec \"$0\" record {args} --quiet --out \"$1\""
            ))
            .arg(env!("CARGO_BIN_EXE_tetlab"))
            .arg(path),
        Duration::from_secs(20),
    )
}

fn inspect(path: &Path) -> Value {
    let output = tetlab(&["inspect", path.to_str().unwrap(), "--json"]);
    assert!(output.status.success(), "{}", stderr(&output));
    serde_json::from_str(&stdout(&output)).unwrap()
}

fn strings(value: &Value) -> Vec<&str> {
    value
        .as_array()
        .unwrap()
        .iter()
        .map(|v| v.as_str().unwrap())
        .collect()
}

const RUN: [&str; 10] = [
    "--scene",
    "cube",
    "--resolution",
    "2",
    "--perturb",
    "mirror",
    "--constraints",
    "edges,height,volume",
    "--frames",
    "20",
];

#[test]
fn a_recording_holds_every_entity_frame_particle_and_metric_of_the_run() {
    let path = scratch("full").join("cube.rrd");
    let mut args = vec!["record", "--out", path.to_str().unwrap()];
    args.extend(RUN);
    let output = tetlab(&args);
    assert!(output.status.success(), "{}", stderr(&output));
    assert!(
        stdout(&output).contains("frames 0..=20"),
        "{}",
        stdout(&output)
    );
    assert!(
        !path.with_extension("rrd.partial").exists(),
        "the partial file was moved into place"
    );

    let summary = inspect(&path);
    assert_eq!(summary["frames"], serde_json::json!([0, 20]));
    let entities = summary["entities"].as_object().unwrap();
    for entity in [
        "world",
        "world/particles",
        "world/mesh",
        "world/edges",
        "world/gradients/edges",
        "world/gradients/height",
        "world/gradients/volume",
        "world/corrections",
        "metrics/inverted_tets",
        "metrics/volume_error",
        "metrics/max_edge_strain",
        "metrics/min_volume_ratio",
    ] {
        assert!(entities.contains_key(entity), "missing {entity}");
    }
    for per_frame in [
        "world/particles",
        "world/mesh",
        "world/edges",
        "world/gradients/volume",
        "world/corrections",
        "metrics/volume_error",
    ] {
        assert_eq!(
            entities[per_frame]["frame_rows"], 21,
            "{per_frame}: one row per frame"
        );
    }
    // Unchanging data only once: topology and styles are static and never repeated per frame.
    let mesh = &entities["world/mesh"];
    assert_eq!(
        strings(&mesh["static_components"]),
        ["Mesh3D:triangle_indices"]
    );
    assert!(!strings(&mesh["frame_components"]).contains(&"Mesh3D:triangle_indices"));
    assert_eq!(
        strings(&entities["world"]["static_components"]),
        ["ViewCoordinates:xyz"]
    );

    let particles = summary["particles"].as_array().unwrap();
    assert_eq!(particles.len(), 21);
    assert!(
        particles.iter().all(|p| p[1] == 27),
        "every particle, every frame"
    );

    // The metrics are the very numbers `tetlab run --json` prints for the same options.
    let mut run_args = vec!["run", "--json"];
    run_args.extend(RUN);
    let run = tetlab(&run_args);
    let frames: Vec<Value> = stdout(&run)
        .lines()
        .map(|l| serde_json::from_str(l).unwrap())
        .collect();
    for name in [
        "inverted_tets",
        "volume_error",
        "max_edge_strain",
        "min_volume_ratio",
    ] {
        let series = summary["metrics"][name].as_array().unwrap();
        assert_eq!(series.len(), 21, "{name}");
        for (recorded, printed) in series.iter().zip(&frames) {
            assert_eq!(recorded[0], printed["frame"]);
            assert_eq!(
                recorded[1].as_f64(),
                printed[name].as_f64(),
                "{name} at frame {}",
                printed["frame"]
            );
        }
    }
    let inverted = &summary["metrics"]["inverted_tets"];
    assert_eq!(
        inverted[0][1], 48.0,
        "mirrored: every tet inverted at frame 0"
    );
    assert_eq!(inverted[20][1], 0.0, "recovered by frame 20");
}

#[test]
fn arrows_none_logs_no_gradients_and_all_logs_every_tet() {
    let dir = scratch("arrows");
    let none = dir.join("none.rrd");
    let all = dir.join("all.rrd");
    for (path, mode) in [(&none, "none"), (&all, "all")] {
        let output = tetlab(&[
            "record",
            "--scene",
            "cube",
            "--resolution",
            "1",
            "--frames",
            "2",
            "--arrows",
            mode,
            "--out",
            path.to_str().unwrap(),
        ]);
        assert!(output.status.success(), "{}", stderr(&output));
    }
    assert_eq!(
        inspect(&none)["entities"]["world/gradients/volume"]["frame_rows"],
        0
    );
    assert_eq!(
        inspect(&all)["entities"]["world/gradients/volume"]["frame_rows"],
        3
    );
}

/// A constraint file's family is recorded like the built-in ones: its arrows every frame, the
/// file's text once, and, for a file that gives its own gradient (here wrong, and in use), the
/// other one where they differ.
#[test]
fn a_constraint_files_family_is_recorded_with_its_text_and_both_gradients() {
    let dir = scratch("constraint-file");
    let path = dir.join("file.rrd");
    let output = tetlab(&[
        "record",
        "--scene",
        "tet",
        "--perturb",
        "invert",
        "--constraints",
        "edges",
        "--constraint-file",
        &asset("constraints/height-wrong-sign.toml"),
        "--frames",
        "3",
        "--quiet",
        "--out",
        path.to_str().unwrap(),
    ]);
    assert!(output.status.success(), "{}", stderr(&output));
    let entities = &inspect(&path)["entities"];
    assert_eq!(
        entities["world/gradients/height-wrong-sign"]["frame_rows"],
        4
    );
    assert_eq!(
        entities["world/gradients/height-wrong-sign-ad"]["frame_rows"],
        4
    );
    assert_eq!(entities["constraints/height-wrong-sign"]["static_rows"], 1);
    let run = tetlab(&["inspect", path.to_str().unwrap()]);
    assert!(stdout(&run).contains("constraints/height-wrong-sign"));
}

/// `--modes` logs the eigenvalues of the tet's energy Hessian each frame (twelve series in one
/// entity) and its lowest mode as arrows, beside the rest; without it, neither.
#[test]
fn modes_logs_the_tets_eigenvalues_and_lowest_mode_each_frame() {
    let dir = scratch("modes");
    for (modes, name) in [(true, "modes.rrd"), (false, "plain.rrd")] {
        let path = dir.join(name);
        let mut args = vec![
            "record",
            "--scene",
            "tet",
            "--perturb",
            "invert",
            "--constraints",
            "volume",
            "--frames",
            "5",
            "--quiet",
            "--out",
            path.to_str().unwrap(),
        ];
        if modes {
            args.push("--modes");
        }
        let output = tetlab(&args);
        assert!(output.status.success(), "{}", stderr(&output));
        let summary = inspect(&path);
        let entities = summary["entities"].as_object().unwrap();
        for entity in ["modes/eigenvalues", "world/modes/lowest"] {
            if modes {
                assert_eq!(
                    entities[entity]["frame_rows"], 6,
                    "{entity}: one row a frame"
                );
            } else {
                assert!(!entities.contains_key(entity), "{entity} without --modes");
            }
        }
    }
}

/// `--exact-step` logs each frame's distance from the exact frame (the Newton reference's from
/// the same start), absolute and relative, one row a stepped frame; without it, neither.
#[test]
fn exact_step_logs_each_frames_distance_from_the_exact_one() {
    let dir = scratch("exact-step");
    for (exact, name) in [(true, "exact.rrd"), (false, "plain.rrd")] {
        let path = dir.join(name);
        let mut args = vec![
            "record",
            "--scene",
            "tet",
            "--frames",
            "4",
            "--quiet",
            "--out",
            path.to_str().unwrap(),
        ];
        if exact {
            args.push("--exact-step");
        }
        let output = tetlab(&args);
        assert!(output.status.success(), "{}", stderr(&output));
        let entities = inspect(&path)["entities"].as_object().unwrap().clone();
        for entity in ["exact_step/distance", "exact_step/relative"] {
            if exact {
                assert_eq!(
                    entities[entity]["frame_rows"], 4,
                    "{entity}: one row a frame"
                );
            } else {
                assert!(
                    !entities.contains_key(entity),
                    "{entity} without --exact-step"
                );
            }
        }
    }
}

/// Ctrl-C (SIGINT) and SIGTERM stop after the current frame, within 5 s, with a message, and
/// leave a complete recording of every finished frame and no partial file.
#[cfg(unix)]
#[test]
fn an_interrupted_recording_is_complete_up_to_the_last_frame() {
    for signal in ["INT", "TERM"] {
        let path = scratch(&format!("interrupt-{signal}")).join("long.rrd");
        let partial = path.with_extension("rrd.partial");
        let child = Command::new(env!("CARGO_BIN_EXE_tetlab"))
            .args([
                "record",
                "--scene",
                "cube",
                "--frames",
                "10000000",
                "--quiet",
                "--out",
                path.to_str().unwrap(),
            ])
            .stdout(Stdio::piped())
            .stderr(Stdio::piped())
            .spawn()
            .unwrap();
        let started = Instant::now();
        while std::fs::metadata(&partial).map(|m| m.len()).unwrap_or(0) < 200_000 {
            assert!(
                started.elapsed() < Duration::from_secs(120),
                "the recording never grew"
            );
            std::thread::sleep(Duration::from_millis(50));
        }
        let status = Command::new("kill")
            .args([&format!("-{signal}"), &child.id().to_string()])
            .status()
            .unwrap();
        assert!(status.success());
        let signalled = Instant::now();
        let mut child = child;
        while child.try_wait().unwrap().is_none() {
            if signalled.elapsed() > Duration::from_secs(5) {
                child.kill().ok();
                panic!("SIG{signal}: still running 5 s after the signal");
            }
            std::thread::sleep(Duration::from_millis(20));
        }
        let output = child.wait_with_output().unwrap();
        assert_eq!(output.status.code(), Some(130), "{}", stderr(&output));
        assert!(stderr(&output).contains("interrupted: the recording holds frames 0..="));
        assert!(!partial.exists(), "SIG{signal}: no partial file left");

        let summary = inspect(&path);
        let (first, last) = (
            summary["frames"][0].as_i64().unwrap(),
            summary["frames"][1].as_i64().unwrap(),
        );
        assert_eq!(first, 0);
        assert!(last > 0);
        for name in ["inverted_tets", "volume_error"] {
            assert_eq!(
                summary["metrics"][name].as_array().unwrap().len() as i64,
                last + 1,
                "{name}: every finished frame"
            );
        }
        assert_eq!(
            summary["particles"].as_array().unwrap().len() as i64,
            last + 1
        );
    }
}

/// A full disk never hangs `record`: Rerun's own file writer, at its first failed write, left a
/// flush waiting forever in 27 of 30 runs like these (src/record/file_writer.rs says why). Fifty
/// runs under a file-size limit, each watched for 20 s, each ending with the one-line error and
/// nothing left behind.
#[cfg(unix)]
#[test]
fn a_full_disk_never_hangs_a_recording() {
    let dir = scratch("full-disk");
    for run in 0..50 {
        let path = dir.join(format!("run-{run}.rrd"));
        let output =
            record_under_a_size_limit(64, &path, "--scene cube --resolution 2 --frames 20");
        let line = assert_usage_error(&output, "could not be written completely");
        assert!(line.contains("File too large"), "run {run}: {line}");
        assert!(
            !path.exists() && !path.with_extension("rrd.partial").exists(),
            "run {run}: {line}"
        );
    }
}

#[test]
fn bad_options_and_unwritable_paths_are_one_line_errors() {
    let dir = scratch("errors");
    let ok = dir.join("ok.rrd");
    let ok = ok.to_str().unwrap();
    let cases: Vec<(Vec<&str>, &str)> = vec![
        (
            vec!["--out", "/nonexistent/dir/x.rrd"],
            "--out /nonexistent/dir/x.rrd: cannot create the file",
        ),
        (vec!["--out", dir.to_str().unwrap()], "is a directory"),
        (vec!["--out", ok, "--tet", "1"], "--tet: 1 is out of range"),
        (vec!["--out", ok, "--arrows", "some"], "--arrows"),
        (vec![], "--out"),
        (vec!["--out", ok, "--connect"], "cannot be used with"),
        (vec!["--out", ok, "--scene", "nowhere"], "--scene"),
        (vec!["--out", ok, "--frames", "-1"], "--frames"),
    ];
    for (args, names) in cases {
        let mut full = vec!["record"];
        full.extend(args);
        assert_usage_error(&tetlab(&full), names);
    }
    assert!(!Path::new(ok).exists());
}

/// A write that fails part way (here the file-size limit of `ulimit -f`, in 1 KiB blocks, whose
/// signal would otherwise kill tetlab before it cleans up; a full disk fails the same way) is
/// one line naming the cause, and leaves neither the recording nor its partial file behind.
#[cfg(unix)]
#[test]
fn a_failed_write_is_reported_and_leaves_nothing_behind() {
    for blocks in [0, 40] {
        let path = scratch(&format!("limit-{blocks}")).join("x.rrd");
        let partial = path.with_extension("rrd.partial");
        let output = record_under_a_size_limit(blocks, &path, "--scene cube --frames 50");
        // At 0 the first write, made when the file is created, fails; at 40 a later one.
        let says = if blocks == 0 {
            "cannot create the file: File too large"
        } else {
            "could not be written completely"
        };
        let line = assert_usage_error(&output, says);
        assert!(line.contains("File too large"), "{line}");
        assert!(
            !path.exists() && !partial.exists(),
            "limit {blocks}: {line}"
        );
    }
}

/// `--out` never replaces what is not a regular file (as root, `--out /dev/null` replaced
/// /dev/null with a recording): a named pipe, a device, a link to either, or a link to nothing
/// is refused before anything is written; a link to a regular file writes through it.
#[cfg(unix)]
#[test]
fn out_refuses_what_is_not_a_regular_file() {
    use std::os::unix::fs::{FileTypeExt, symlink};
    let dir = scratch("special");
    let fifo = dir.join("pipe.rrd");
    let _ = std::fs::remove_file(&fifo);
    assert!(
        Command::new("mkfifo")
            .arg(&fifo)
            .status()
            .unwrap()
            .success()
    );
    let mut cases = vec![(fifo.clone(), "is a named pipe (FIFO)")];
    // A character device of our own (the same numbers as /dev/null), when we may make one.
    let device = dir.join("null.rrd");
    let _ = std::fs::remove_file(&device);
    let made = Command::new("mknod")
        .args([device.to_str().unwrap(), "c", "1", "3"])
        .status()
        .is_ok_and(|s| s.success());
    if made {
        cases.push((device.clone(), "is a device"));
    }
    let to_fifo = dir.join("to-pipe.rrd");
    let dangling = dir.join("dangling.rrd");
    for link in [&to_fifo, &dangling] {
        let _ = std::fs::remove_file(link);
    }
    symlink(&fifo, &to_fifo).unwrap();
    symlink(dir.join("nothing-here"), &dangling).unwrap();
    cases.push((to_fifo, "is a symbolic link to a named pipe (FIFO)"));
    cases.push((dangling, "is a symbolic link to nothing"));
    for (target, says) in &cases {
        let output = tetlab(&["record", "--frames", "1", "--out", target.to_str().unwrap()]);
        assert_usage_error(&output, says);
    }
    assert!(
        std::fs::symlink_metadata(&fifo)
            .unwrap()
            .file_type()
            .is_fifo()
    );
    if made {
        assert!(
            std::fs::symlink_metadata(&device)
                .unwrap()
                .file_type()
                .is_char_device()
        );
    }

    // A link to a regular file: the file gets the recording, the link stays a link.
    let real = dir.join("real.rrd");
    let link = dir.join("link.rrd");
    std::fs::write(&real, "old").unwrap();
    let _ = std::fs::remove_file(&link);
    symlink(&real, &link).unwrap();
    let output = tetlab(&["record", "--frames", "1", "--out", link.to_str().unwrap()]);
    assert!(output.status.success(), "{}", stderr(&output));
    assert!(
        std::fs::symlink_metadata(&link)
            .unwrap()
            .file_type()
            .is_symlink()
    );
    assert_eq!(inspect(&real)["frames"], serde_json::json!([0, 1]));
}

/// Damage in the middle of a recording (64 bytes zeroed, as the fuzzing pass did; one in five
/// such damages used to panic inside Rerun's arrow decoding) is one line naming the file, with
/// exit status 2, wherever it falls.
#[test]
fn inspect_reports_a_damaged_recording_without_panicking() {
    let dir = scratch("damaged");
    let path = dir.join("whole.rrd");
    let output = tetlab(&[
        "record",
        "--scene",
        "tet",
        "--frames",
        "0",
        "--arrows",
        "none",
        "--quiet",
        "--out",
        path.to_str().unwrap(),
    ]);
    assert!(output.status.success(), "{}", stderr(&output));
    let bytes = std::fs::read(&path).unwrap();
    let damaged = dir.join("damaged.rrd");
    let mut refused = 0;
    for offset in (0..bytes.len() - 64).step_by(997) {
        let mut copy = bytes.clone();
        copy[offset..offset + 64].fill(0);
        std::fs::write(&damaged, &copy).unwrap();
        let output = tetlab(&["inspect", damaged.to_str().unwrap()]);
        if output.status.success() {
            continue; // some bytes (padding, a value) can be zeroed without breaking the file
        }
        let line = assert_usage_error(&output, "damaged.rrd: ");
        assert!(!line.contains("panicked"), "offset {offset}: {line}");
        refused += 1;
    }
    assert!(refused > 10, "most damage is noticed ({refused})");
    // A length field claiming far more than the file holds is refused before anything is
    // allocated for it.
    let mut huge = bytes.clone();
    huge[12 + 8..12 + 16].copy_from_slice(&u64::MAX.to_le_bytes());
    std::fs::write(&damaged, &huge).unwrap();
    assert_usage_error(
        &tetlab(&["inspect", damaged.to_str().unwrap()]),
        "claims 18446744073709551615 bytes",
    );
}

#[test]
fn a_viewer_that_is_not_there_is_reported() {
    let output = tetlab(&["record", "--frames", "1", "--connect", "127.0.0.1:9"]);
    assert_usage_error(&output, "--connect rerun+http://127.0.0.1:9/proxy");
}

#[test]
fn inspect_refuses_what_is_not_a_recording() {
    let path = scratch("inspect").join("not.rrd");
    std::fs::write(&path, "hello").unwrap();
    assert_usage_error(
        &tetlab(&["inspect", path.to_str().unwrap()]),
        "not.rrd: not a Rerun recording",
    );
    assert_usage_error(
        &tetlab(&["inspect", "/nonexistent.rrd"]),
        "/nonexistent.rrd: cannot read",
    );
}

#[test]
fn inspect_refuses_a_cut_off_recording() {
    let dir = scratch("cut");
    let path = dir.join("whole.rrd");
    let output = tetlab(&[
        "record",
        "--scene",
        "cube",
        "--frames",
        "30",
        "--out",
        path.to_str().unwrap(),
    ]);
    assert!(output.status.success());
    let bytes = std::fs::read(&path).unwrap();
    let cut = dir.join("cut.rrd");
    std::fs::write(&cut, &bytes[..bytes.len() * 2 / 3]).unwrap();
    assert_usage_error(
        &tetlab(&["inspect", cut.to_str().unwrap()]),
        "incomplete recording",
    );
}

/// A scene of several bodies is recorded body by body: each body's mesh and edges under
/// `world/bodies/<name>/`, its metrics and energy under `bodies/<name>/`, the very numbers
/// `tetlab run --json` prints for it; the scene's particles and metrics stay whole.
#[test]
fn a_scene_of_several_bodies_is_recorded_body_by_body() {
    let path = scratch("bodies").join("stack.rrd");
    let scene = asset("scenes/stacked-cubes.toml");
    let run = [
        "--scene",
        scene.as_str(),
        "--constraints",
        "neohookean,contact",
        "--frames",
        "3",
    ];
    let mut args = vec!["record", "--quiet", "--out", path.to_str().unwrap()];
    args.extend(run);
    let output = tetlab(&args);
    assert!(output.status.success(), "{}", stderr(&output));
    let summary = inspect(&path);
    let entities = summary["entities"].as_object().unwrap();
    for body in ["lower", "upper"] {
        for entity in ["mesh", "edges"] {
            let entity = format!("world/bodies/{body}/{entity}");
            assert_eq!(entities[&entity]["frame_rows"], 4, "{entity}");
        }
        let mesh = &entities[&format!("world/bodies/{body}/mesh")];
        assert_eq!(
            strings(&mesh["static_components"]),
            ["Mesh3D:triangle_indices"]
        );
    }
    assert!(
        !entities.contains_key("world/mesh"),
        "the mesh is the bodies'"
    );
    assert_eq!(entities["world/particles"]["frame_rows"], 4);
    let mut run_args = vec!["run", "--json"];
    run_args.extend(run);
    let printed: Vec<Value> = stdout(&tetlab(&run_args))
        .lines()
        .map(|l| serde_json::from_str(l).unwrap())
        .collect();
    for (b, body) in ["lower", "upper"].into_iter().enumerate() {
        for (recorded, printed_as) in [
            ("energy/total", "energy_total"),
            ("energy/kinetic", "energy_kinetic"),
            ("energy/elastic", "energy_elastic"),
            ("metrics/inverted_tets", "inverted_tets"),
            ("metrics/max_edge_strain", "max_edge_strain"),
            ("metrics/contacts", "contacts"),
            ("metrics/max_penetration", "max_penetration"),
        ] {
            let name = format!("bodies/{body}/{recorded}");
            let series = summary["metrics"][&name]
                .as_array()
                .unwrap_or_else(|| panic!("{name}"));
            assert_eq!(series.len(), 4, "{name}");
            for (value, line) in series.iter().zip(&printed) {
                assert_eq!(
                    value[1].as_f64(),
                    line["bodies"][b][printed_as].as_f64(),
                    "{name} at frame {}",
                    line["frame"]
                );
            }
        }
    }
}
