//! `--engine gpu` as a user runs it: the mirrored cube recovers on the GPU engine and the summary
//! names the adapter; `bench --engine gpu` prints its dispatches; without an adapter the choice
//! is a one-line usage error naming `--engine gpu` (exit 2). The runs need an adapter (Mesa's
//! software Vulkan here and in CI): without one they skip, saying so; under `CI=true` they must run.

mod support;

use std::process::{Command, Output};
use support::{assert_usage_error, stderr, stdout};
use tetlab_core::simulation::EngineChoice;

/// `tetlab ARGS…` with `env` set.
fn tetlab_with(env: &[(&str, &str)], args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_tetlab"))
        .args(args)
        .envs(env.iter().copied())
        .output()
        .expect("tetlab runs")
}

#[test]
fn without_an_adapter_the_gpu_engine_is_a_usage_error() {
    // wgpu looks for adapters on the backends WGPU_BACKEND names: on Linux there is no DirectX.
    let no_gpu = [("WGPU_BACKEND", "dx12")];
    for args in [
        &["run", "--engine", "gpu", "--frames", "1"][..],
        &["bench", "--engine", "gpu", "--frames", "1"][..],
        &["validate", "--engine", "gpu"][..],
    ] {
        let output = tetlab_with(&no_gpu, args);
        let line = assert_usage_error(&output, "--engine gpu");
        assert!(line.contains("no GPU adapter"), "{args:?}: {line}");
    }
}

#[test]
fn the_mirrored_cube_recovers_on_the_gpu_engine() {
    if !EngineChoice::Gpu.for_test() {
        return;
    }
    let output = tetlab_with(
        &[],
        &[
            "run",
            "--scene",
            "cube",
            "--resolution",
            "4",
            "--perturb",
            "mirror",
            "--constraints",
            "edges,height,volume",
            "--engine",
            "gpu",
            "--order-seed",
            "1",
            "--frames",
            "20",
        ],
    );
    let out = stdout(&output);
    assert!(output.status.success(), "{}\n{out}", stderr(&output));
    assert!(out.contains("engine gpu (f32, "), "{out}");
    assert!(out.contains("no inverted tets from frame"), "{out}");
}

#[test]
fn bench_on_the_gpu_engine_counts_its_dispatches() {
    if !EngineChoice::Gpu.for_test() {
        return;
    }
    let output = tetlab_with(
        &[],
        &[
            "bench",
            "--engine",
            "gpu",
            "--scene",
            "cube",
            "--resolution",
            "3",
            "--substeps",
            "5",
            "--frames",
            "2",
            "--warmup",
            "1",
            "--json",
        ],
    );
    let out = stdout(&output);
    assert!(output.status.success(), "{}\n{out}", stderr(&output));
    let json: serde_json::Value =
        serde_json::from_str(out.lines().last().expect("a JSON line")).expect("JSON");
    assert_eq!(json["solver"], "gpu (f32)");
    let dispatches = json["dispatches_per_frame"].as_u64().expect("dispatches");
    // Five substeps, each at least the prediction, a colour of each family and the velocities.
    assert!(dispatches >= 5 * 4, "{json}");
    assert!(
        json["us_per_dispatch"].as_f64().is_some_and(|us| us > 0.0),
        "{json}"
    );
    assert!(
        json["gpu"].as_str().is_some_and(|g| !g.is_empty()),
        "{json}"
    );
}
