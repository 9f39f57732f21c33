//! `tetlab bench`: how fast the solver runs a scene. Builds the scene, runs some frames to warm up,
//! then times `--frames` frames and reports the work (constraint projections) and the time it
//! took, per projection, per family and per frame, and the memory the solver's arrays take.

use super::UsageError;
use serde::Serialize;
use std::io::Write;
use std::time::{Duration, Instant};
use tetlab_core::constraints::Family;
use tetlab_core::fast::{FastSimulation, Order};
use tetlab_core::lanes::{LANES, REGISTERS};
use tetlab_core::limits;
use tetlab_core::metrics::Metrics;
use tetlab_core::scene::Scene;
use tetlab_core::solver::{Method, PerFamily, Settings, Simulation};

/// Options of `tetlab bench`.
#[derive(Debug, clap::Args)]
pub struct Args {
    /// A built-in scene (tet, cube, beam, ball) or a mesh file (.node, .ele, .msh).
    #[arg(long, default_value = "cube", value_name = "NAME|PATH")]
    scene: String,
    /// Cells along a side of cube and beam, half the cells across ball (1..=128, and at most
    /// 16777216 tets).
    #[arg(long, default_value_t = 10, value_parser = |s: &str| limits::RESOLUTION.parse(s))]
    resolution: u32,
    /// Active constraint families, comma-separated: edges, plane, volume.
    #[arg(long, default_value = "edges,volume", value_parser = PerFamily::parse_list)]
    constraints: PerFamily<bool>,
    /// xpbd or pbd.
    #[arg(long, default_value = "xpbd", value_parser = Method::parse)]
    solver: Method,
    /// Substeps per frame (1..=1000).
    #[arg(long, default_value_t = 10, value_parser = |s: &str| limits::SUBSTEPS.parse(s))]
    substeps: u32,
    /// Gauss–Seidel iterations per substep (1..=1000).
    #[arg(long, default_value_t = 1, value_parser = |s: &str| limits::ITERATIONS.parse(s))]
    iterations: u32,
    /// Frames timed (1..=100000).
    #[arg(long, default_value_t = 100, value_parser = clap::value_parser!(u64).range(1..=100_000))]
    frames: u64,
    /// Frames run before timing (0..=100000).
    #[arg(long, default_value_t = 10, value_parser = clap::value_parser!(u64).range(0..=100_000))]
    warmup: u64,
    /// Threads for the fast solver (1..=256).
    #[arg(long, default_value_t = 1, value_parser = clap::value_parser!(u64).range(1..=256))]
    threads: u64,
    /// Time the reference f64 solver (the workbench's and `tetlab run`'s) instead of the fast one.
    #[arg(long, conflicts_with_all = ["threads", "jacobi"])]
    reference: bool,
    /// Fast solver in Jacobi order: each family projected from the same positions, each particle
    /// then moved by ω × the mean of its corrections (instead of Gauss–Seidel).
    #[arg(long)]
    jacobi: bool,
    /// ω for --jacobi (0 < ω ≤ 2).
    #[arg(long, default_value_t = 1.0, requires = "jacobi", value_parser = relaxation)]
    relaxation: f32,
    /// End with one JSON object.
    #[arg(long)]
    json: bool,
}

/// ω: a finite number in (0, 2].
fn relaxation(text: &str) -> Result<f32, String> {
    match text.parse::<f32>() {
        Ok(omega) if omega > 0.0 && omega <= 2.0 => Ok(omega),
        _ => Err(format!("`{text}` is not a number in (0, 2]")),
    }
}

/// What `--json` prints.
#[derive(Debug, Serialize)]
struct Report {
    scene: String,
    solver: &'static str,
    threads: usize,
    particles: usize,
    tets: usize,
    edges: usize,
    constraints: String,
    substeps: u32,
    iterations: u32,
    frames: u64,
    projections_per_frame: u64,
    ns_per_projection: f64,
    ns_per_projection_by_family: Option<ByFamily>,
    ms_per_frame: f64,
    frames_per_second: f64,
    bytes_per_tet: f64,
    peak_rss_bytes: Option<u64>,
    colours: Option<ByFamily>,
    /// How the fast solver's SIMD lanes are held on this build.
    lanes: Option<String>,
    /// After the run, per active family: √(mean (C / rest value)²).
    relative_error: Option<PerFamily<Option<f64>>>,
}

#[derive(Debug, Serialize)]
struct ByFamily {
    edges: f64,
    plane: f64,
    volume: f64,
}

/// Runs the benchmark and prints the report.
pub fn run(args: &Args, out: &mut impl Write) -> Result<(), UsageError> {
    let scene = Scene::from_spec(&args.scene, args.resolution)
        .map_err(|e| UsageError(format!("--scene: {e}")))?;
    let settings = Settings {
        method: args.solver,
        active: args.constraints,
        substeps: args.substeps,
        iterations: args.iterations,
        ..Settings::default()
    };
    let mut simulation = Simulation::new(&scene, settings);
    let report = if args.reference {
        time_reference(args, &scene, &mut simulation)?
    } else {
        time_fast(args, &scene, &simulation)?
    };
    write_report(&report, args.json, out).map_err(UsageError::stdout)
}

fn time_reference(
    args: &Args,
    scene: &Scene,
    simulation: &mut Simulation,
) -> Result<Report, UsageError> {
    let elapsed = time(args, simulation, Simulation::step, |_| {});
    Metrics::measure_sound(simulation).map_err(|d| UsageError(d.to_string()))?;
    let projections = simulation.projections_per_frame();
    Ok(report(
        args,
        scene,
        "reference (f64)",
        1,
        projections,
        elapsed,
        None,
        simulation.heap_bytes(),
        None,
    ))
}

fn time_fast(args: &Args, scene: &Scene, simulation: &Simulation) -> Result<Report, UsageError> {
    let mut fast = FastSimulation::new(simulation, args.threads as usize);
    if args.jacobi {
        fast.set_order(Order::Jacobi {
            relaxation: args.relaxation,
        });
    }
    let elapsed = time(
        args,
        &mut fast,
        FastSimulation::step,
        FastSimulation::reset_timings,
    );
    fast.check().map_err(|d| UsageError(d.to_string()))?;
    let timings = fast.timings();
    let per = |k: usize| {
        let n = timings.projections[k];
        if n == 0 {
            0.0
        } else {
            timings.time[k].as_nanos() as f64 / n as f64
        }
    };
    let by_family = ByFamily {
        edges: per(0),
        plane: per(1),
        volume: per(2),
    };
    let colours = ByFamily {
        edges: fast.edges.colours.len() as f64,
        plane: fast.planes.colours.len() as f64,
        volume: fast.volumes.colours.len() as f64,
    };
    let solver = if args.jacobi {
        "fast (f32), Jacobi"
    } else {
        "fast (f32)"
    };
    let mut report = report(
        args,
        scene,
        solver,
        fast.threads(),
        fast.projections_per_frame(),
        elapsed,
        Some(by_family),
        fast.heap_bytes(),
        Some(colours),
    );
    report.lanes = Some(format!("{LANES} f32 per batch, in {REGISTERS}"));
    let relative_error = fast.relative_error();
    for family in Family::ALL {
        if let Some(error) = relative_error.get(family)
            && !error.is_finite()
        {
            return Err(UsageError(format!(
                "the f32 engine could not measure how well the {} constraints hold (their \
                 relative error is {error}); the scene is beyond what f32 resolves",
                family.short_name()
            )));
        }
    }
    report.relative_error = Some(relative_error);
    Ok(report)
}

/// Runs `--warmup` frames, then `warmed` (e.g. to start per-family timings afresh), then times
/// `--frames` frames.
fn time<S>(args: &Args, solver: &mut S, step: fn(&mut S), warmed: fn(&mut S)) -> Duration {
    for _ in 0..args.warmup {
        step(solver);
    }
    warmed(solver);
    let started = Instant::now();
    for _ in 0..args.frames {
        step(solver);
    }
    started.elapsed()
}

#[allow(clippy::too_many_arguments)]
fn report(
    args: &Args,
    scene: &Scene,
    solver: &'static str,
    threads: usize,
    projections_per_frame: u64,
    elapsed: Duration,
    by_family: Option<ByFamily>,
    heap_bytes: usize,
    colours: Option<ByFamily>,
) -> Report {
    let seconds = elapsed.as_secs_f64();
    let frames = args.frames as f64;
    let tets = scene.mesh.tets.len();
    Report {
        scene: scene.name.clone(),
        solver,
        threads,
        particles: scene.mesh.positions.len(),
        tets,
        edges: scene.mesh.edges().len(),
        constraints: args.constraints.describe(),
        substeps: args.substeps,
        iterations: args.iterations,
        frames: args.frames,
        projections_per_frame,
        ns_per_projection: seconds * 1e9 / (frames * projections_per_frame.max(1) as f64),
        ns_per_projection_by_family: by_family,
        ms_per_frame: seconds * 1e3 / frames,
        // A clock reads at least a nanosecond, which keeps the rate finite.
        frames_per_second: frames / seconds.max(1e-9),
        bytes_per_tet: heap_bytes as f64 / tets.max(1) as f64,
        peak_rss_bytes: peak_rss(),
        colours,
        lanes: None,
        relative_error: None,
    }
}

fn write_report(r: &Report, json: bool, out: &mut impl Write) -> std::io::Result<()> {
    writeln!(
        out,
        "scene {}: {} particles, {} tets, {} edges",
        r.scene, r.particles, r.tets, r.edges
    )?;
    writeln!(
        out,
        "{} solver, {} thread{}; {}, {} substeps x {} iteration{}; {} frames timed",
        r.solver,
        r.threads,
        if r.threads == 1 { "" } else { "s" },
        r.constraints,
        r.substeps,
        r.iterations,
        if r.iterations == 1 { "" } else { "s" },
        r.frames
    )?;
    writeln!(out, "projections per frame  {}", r.projections_per_frame)?;
    writeln!(
        out,
        "time per frame         {:.3} ms ({:.1} frames per second)",
        r.ms_per_frame, r.frames_per_second
    )?;
    write!(out, "ns per projection      {:.2}", r.ns_per_projection)?;
    if let Some(f) = &r.ns_per_projection_by_family {
        write!(
            out,
            " (edges {:.2}, plane {:.2}, volume {:.2}; inside the sweeps)",
            f.edges, f.plane, f.volume
        )?;
    }
    writeln!(out)?;
    write!(
        out,
        "memory                 {:.0} bytes per tet",
        r.bytes_per_tet
    )?;
    if let Some(rss) = r.peak_rss_bytes {
        write!(out, "; peak resident {:.1} MB", rss as f64 / 1e6)?;
    }
    writeln!(out)?;
    if let Some(c) = &r.colours {
        writeln!(
            out,
            "colours                edges {}, plane {}, volume {}",
            c.edges, c.plane, c.volume
        )?;
    }
    if let Some(lanes) = &r.lanes {
        writeln!(out, "SIMD lanes             {lanes}")?;
    }
    if let Some(error) = &r.relative_error {
        let families = [
            ("edges", error.edges),
            ("plane", error.plane),
            ("volume", error.volume),
        ];
        let shown: Vec<String> = families
            .iter()
            .filter_map(|(name, e)| e.map(|e| format!("{name} {e:.2e}")))
            .collect();
        writeln!(
            out,
            "error at the end       {} (RMS of C / rest value)",
            shown.join(", ")
        )?;
    }
    if json {
        writeln!(
            out,
            "{}",
            serde_json::to_string(r).expect("a report serialises")
        )?;
    }
    Ok(())
}

/// The process's peak resident memory (VmHWM), where the system tells it (Linux).
fn peak_rss() -> Option<u64> {
    let status = std::fs::read_to_string("/proc/self/status").ok()?;
    let line = status.lines().find(|l| l.starts_with("VmHWM:"))?;
    let kb: u64 = line.split_whitespace().nth(1)?.parse().ok()?;
    Some(kb * 1024)
}
