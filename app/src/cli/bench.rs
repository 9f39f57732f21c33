//! `tetlab bench`: how fast the solver runs a scene. Builds the scene, runs some frames to warm up,
//! then times `--frames` frames and reports the work (constraint projections) and the time it
//! took, per projection, per family and per frame, and the memory the solver's arrays take.

use super::UsageError;
use super::simulation_args::SolverArgs;
use serde::Serialize;
use std::io::Write;
use std::time::{Duration, Instant};
use tetlab_core::constraints::{Families, Family, Named, PerFamily};
use tetlab_core::input::limits;
use tetlab_core::measures::metrics::Metrics;
use tetlab_core::numbers::lanes::{LANES, REGISTERS};
use tetlab_core::scene::Scene;
use tetlab_core::simulation::fast::{FastSimulation, Order};
use tetlab_core::simulation::{EngineChoice, Simulation};

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
    /// The solver's options, as for `tetlab run`.
    #[command(flatten)]
    solver: SolverArgs,
    /// Frames timed (1..=100000).
    #[arg(long, default_value_t = 100, value_parser = clap::value_parser!(u64).range(1..=100_000))]
    frames: u64,
    /// Frames run before timing (0..=100000).
    #[arg(long, default_value_t = 10, value_parser = clap::value_parser!(u64).range(0..=100_000))]
    warmup: u64,
    /// The same as --engine reference: time the f64 solver instead of the fast one.
    #[arg(long, conflicts_with_all = ["engine", "threads", "jacobi"])]
    reference: bool,
    /// Fast solver in Jacobi order: each family projected from the same positions, each particle
    /// then moved by ω × the mean of its corrections (instead of Gauss–Seidel).
    #[arg(long)]
    jacobi: bool,
    /// ω for --jacobi (0 < ω ≤ 2).
    #[arg(long, default_value_t = 1.0, requires = "jacobi", value_parser = relaxation)]
    relaxation: f32,
    /// Time a frame of the workbench instead, on the CPU and without a window: the simulation's
    /// step and metrics, what the 3D view draws, and the upload (rasterising is not counted), on
    /// the engine and threads the workbench would use (--engine and --threads change them).
    #[arg(long, conflicts_with_all = ["jacobi", "reference"])]
    workbench: bool,
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
    /// The active families' names, in table order.
    #[serde(skip)]
    active: Vec<String>,
    substeps: u32,
    iterations: u32,
    frames: u64,
    projections_per_frame: u64,
    ns_per_projection: f64,
    ns_per_projection_by_family: Option<Named<f64>>,
    ms_per_frame: f64,
    frames_per_second: f64,
    bytes_per_tet: f64,
    peak_rss_bytes: Option<u64>,
    colours: Option<Named<usize>>,
    /// How the fast solver's SIMD lanes are held on this build.
    lanes: Option<String>,
    /// With tetlab-core's feature `share-timers`: the large colours' and each thread's share's
    /// mean time (a diagnostic of the threads; docs/performance.md).
    #[serde(skip_serializing_if = "Option::is_none")]
    share_timings: Option<String>,
    /// How many regions the fast solver cuts the body into (docs/performance.md, "Two threads").
    #[serde(skip_serializing_if = "Option::is_none")]
    regions: Option<usize>,
    /// With two threads or more, per family, over one sweep: of the particles' cache lines the
    /// threads touch (each line counted once per thread and step: a level of groups, or a
    /// thread's part of a shared colour), how many another thread wrote since (fast engine):
    /// [from another thread, lines].
    #[serde(skip_serializing_if = "Option::is_none")]
    lines_from_other_threads: Option<Named<[usize; 2]>>,
    /// After the run, per active family: √(mean (C / rest value)²).
    #[serde(serialize_with = "active_only")]
    relative_error: Option<Named<Option<f64>>>,
    /// The GPU engine's adapter ("NVIDIA H100 (Vulkan)").
    #[serde(skip_serializing_if = "Option::is_none")]
    gpu: Option<String>,
    /// The GPU engine's dispatches a frame (one per colour of each family, sweep and substep,
    /// and the per-particle stages).
    #[serde(skip_serializing_if = "Option::is_none")]
    dispatches_per_frame: Option<u64>,
    /// A frame's time over its dispatches, in µs (the submission and the read-back included).
    #[serde(skip_serializing_if = "Option::is_none")]
    us_per_dispatch: Option<f64>,
}

/// A map of the families that have a value (the active ones), so that none is written `null`.
fn active_only<S: serde::Serializer>(
    values: &Option<Named<Option<f64>>>,
    serializer: S,
) -> Result<S::Ok, S::Error> {
    use serde::ser::SerializeMap;
    let Some(values) = values else {
        return serializer.serialize_none();
    };
    let mut map = serializer.serialize_map(None)?;
    for (family, value) in &values.0 {
        if let Some(value) = value {
            map.serialize_entry(family, &value)?;
        }
    }
    map.end()
}

/// Runs the benchmark and prints the report. Both engines are timed through the one
/// [`Simulation`] every front end drives, its fast engine's writing back included.
pub fn run(args: &Args, out: &mut impl Write) -> Result<(), UsageError> {
    let scene = Scene::from_spec(&args.scene, args.resolution)
        .map_err(|e| UsageError(format!("--scene: {e}")))?;
    let (mut settings, families) = args.solver.settings()?;
    if args.workbench {
        // The workbench's own settings: edits settle; the engine and threads as it picks them.
        settings.settle_edits = true;
        let threads = args
            .solver
            .threads
            .map_or_else(crate::gui::workbench::threads, |t| t as usize);
        let tets = scene.mesh.tets.len();
        let name = scene.name.clone();
        let engine = settings.engine.resolve(tets).name();
        let cost = super::workbench_frame::measure(
            scene,
            settings,
            families,
            threads,
            args.frames,
            args.warmup,
        )?;
        return super::workbench_frame::write(out, &name, tets, engine, &cost, args.json)
            .map_err(UsageError::stdout);
    }
    settings.engine = match (args.reference, args.solver.engine) {
        (true, _) => EngineChoice::Reference,
        (false, Some(engine)) => engine.resolve(scene.mesh.tets.len()),
        (false, None) => EngineChoice::Fast,
    };
    if args.jacobi && settings.engine != EngineChoice::Fast {
        return Err(UsageError(
            "--jacobi: only the fast engine projects in Jacobi order".into(),
        ));
    }
    let mut simulation = Simulation::with_families(&scene, settings, families);
    simulation.set_threads(args.solver.threads.unwrap_or(1) as usize);
    super::simulation_args::warn_if_unstable(&simulation);
    let report = match settings.engine {
        EngineChoice::Fast => time_fast(args, &scene, &mut simulation)?,
        EngineChoice::Gpu => time_gpu(args, &scene, &mut simulation)?,
        _ => time_reference(args, &scene, &mut simulation)?,
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
        simulation.families(),
        *simulation.active(),
        "reference (f64)",
        1,
        projections,
        elapsed,
        None,
        simulation.heap_bytes(),
        None,
    ))
}

/// The GPU engine: the frame's time, its dispatches, and the adapter. A frame that ran on the
/// CPU instead (contact, or no GPU) is an error: it is not the GPU's time.
fn time_gpu(args: &Args, scene: &Scene, simulation: &mut Simulation) -> Result<Report, UsageError> {
    use tetlab_core::simulation::gpu::{GpuEngine, gpu};
    let elapsed = time(args, simulation, Simulation::step, |_| {});
    Metrics::measure_sound(simulation).map_err(|d| UsageError(d.to_string()))?;
    let projections = simulation.projections_per_frame();
    let described = simulation.describe_engine();
    let engine = (simulation.engine_as::<GpuEngine>()).expect("bench runs the GPU engine");
    if let Err(why) = engine.ready() {
        return Err(UsageError(format!("--engine gpu: {why}")));
    }
    if engine.dispatches() == 0 {
        return Err(UsageError(format!(
            "--engine gpu: the frames ran on the CPU ({described})"
        )));
    }
    let dispatches = engine.dispatches();
    let bytes = usize::try_from(engine.device_bytes()).unwrap_or(usize::MAX);
    let mut report = report(
        args,
        scene,
        simulation.families(),
        *simulation.active(),
        "gpu (f32)",
        1,
        projections,
        elapsed,
        None,
        bytes,
        None,
    );
    report.gpu = gpu().ok().map(|g| g.details());
    report.dispatches_per_frame = Some(dispatches);
    report.us_per_dispatch = Some(report.ms_per_frame * 1e3 / dispatches as f64);
    Ok(report)
}

/// The fast engine `simulation` steps on (its settings choose it).
fn fast_engine(simulation: &mut Simulation) -> &mut FastSimulation {
    (simulation.engine_as::<FastSimulation>())
        .expect("bench runs the fast engine when asked for it")
}

fn time_fast(
    args: &Args,
    scene: &Scene,
    simulation: &mut Simulation,
) -> Result<Report, UsageError> {
    if args.jacobi {
        fast_engine(simulation).set_order(Order::Jacobi {
            relaxation: args.relaxation,
        });
    }
    let elapsed = time(args, simulation, Simulation::step, |s| {
        fast_engine(s).reset_timings();
    });
    Metrics::measure_sound(simulation).map_err(|d| UsageError(d.to_string()))?;
    let families = simulation.families().clone();
    let fast = fast_engine(simulation);
    // The fast solver's own arrays (the simulation it steps keeps its f64 state beside them).
    let heap_bytes = fast.heap_bytes();
    fast.check().map_err(|d| UsageError(d.to_string()))?;
    let timings = fast.timings();
    let active = fast.resolved().active;
    let per = |f: Family| {
        let n = timings.projections[f];
        if n == 0 {
            0.0
        } else {
            timings.time[f].as_nanos() as f64 / n as f64
        }
    };
    let by_family = families.named(&families.per_family(|f| if active[f] { per(f) } else { 0.0 }));
    let colours = families.named(&families.per_family(|f| fast.batches(f).colour_count()));
    let solver = if args.jacobi {
        "fast (f32), Jacobi"
    } else {
        "fast (f32)"
    };
    let mut report = report(
        args,
        scene,
        &families,
        active,
        solver,
        fast.threads(),
        fast.projections_per_frame(),
        elapsed,
        Some(by_family),
        heap_bytes,
        Some(colours),
    );
    report.lanes = Some(format!("{LANES} f32 per batch, in {REGISTERS}"));
    report.share_timings = fast.share_timings();
    report.regions = families
        .all()
        .find(|&f| active[f])
        .map(|f| fast.batches(f).regions());
    if fast.threads() > 1 {
        let lines = |family| {
            let (other, lines) = fast.lines_from_other_threads(family, fast.threads());
            [other, lines]
        };
        report.lines_from_other_threads = Some(
            families.named(&families.per_family(|f| if active[f] { lines(f) } else { [0, 0] })),
        );
    }
    let relative_error = fast.relative_error();
    for family in families.all() {
        if let Some(error) = relative_error.get(family)
            && !error.is_finite()
        {
            return Err(UsageError(format!(
                "the f32 engine could not measure how well the {} constraints hold (their \
                 relative error is {error}); the scene is beyond what f32 resolves",
                families.name(family)
            )));
        }
    }
    report.relative_error = Some(families.named(&relative_error));
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
    families: &Families,
    active: PerFamily<bool>,
    solver: &'static str,
    threads: usize,
    projections_per_frame: u64,
    elapsed: Duration,
    by_family: Option<Named<f64>>,
    heap_bytes: usize,
    colours: Option<Named<usize>>,
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
        constraints: families.describe(&active),
        active: active
            .families()
            .map(|f| families.name(f).to_owned())
            .collect(),
        substeps: args.solver.substeps,
        iterations: args.solver.iterations,
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
        share_timings: None,
        regions: None,
        lines_from_other_threads: None,
        relative_error: None,
        gpu: None,
        dispatches_per_frame: None,
        us_per_dispatch: None,
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
    let of_active = |values: Vec<(&String, String)>| -> String {
        values
            .into_iter()
            .filter(|(f, _)| r.active.contains(f))
            .map(|(f, v)| format!("{f} {v}"))
            .collect::<Vec<_>>()
            .join(", ")
    };
    if let Some(f) = &r.ns_per_projection_by_family {
        let each = of_active(f.0.iter().map(|(n, v)| (n, format!("{v:.2}"))).collect());
        write!(out, " ({each}; inside the sweeps)")?;
    }
    writeln!(out)?;
    write!(
        out,
        "memory                 {:.0} bytes per tet",
        r.bytes_per_tet
    )?;
    if r.gpu.is_some() {
        write!(out, " on the GPU")?;
    }
    if let Some(rss) = r.peak_rss_bytes {
        write!(out, "; peak resident {:.1} MB", rss as f64 / 1e6)?;
    }
    writeln!(out)?;
    if let Some(c) = &r.colours {
        let each = of_active(c.0.iter().map(|(n, v)| (n, v.to_string())).collect());
        writeln!(out, "colours                {each}")?;
    }
    if let Some(gpu) = &r.gpu {
        writeln!(out, "GPU                    {gpu}")?;
    }
    if let (Some(n), Some(us)) = (r.dispatches_per_frame, r.us_per_dispatch) {
        writeln!(
            out,
            "dispatches per frame   {n} ({us:.2} us each, all told)"
        )?;
    }
    if let Some(lanes) = &r.lanes {
        writeln!(out, "SIMD lanes             {lanes}")?;
    }
    if let Some(regions) = r.regions {
        writeln!(out, "regions                {regions}")?;
    }
    if let Some(lines) = &r.lines_from_other_threads {
        let each = of_active(
            lines
                .0
                .iter()
                .map(|(n, [other, all])| (n, format!("{other} of {all}")))
                .collect(),
        );
        writeln!(out, "other thread's lines   {each} a sweep")?;
    }
    if let Some(timings) = &r.share_timings {
        writeln!(out, "shared colours         {timings}")?;
    }
    if let Some(error) = &r.relative_error {
        let shown: Vec<String> = error
            .0
            .iter()
            .filter_map(|(family, e)| e.map(|e| format!("{family} {e:.2e}")))
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
