//! `tetlab record`: the run of `tetlab run`, logged to a Rerun recording. This file is set-up
//! ([`main`]) plus the run ([`run`], as Rerun's own examples are written); what is logged and how
//! the file is written safely are in [`crate::record`].

use super::UsageError;
use super::simulation_args::SimulationArgs;
use crate::record::{ArrowsMode, Destination, Ending, Recorder, Session, send_layout};
use rerun::RecordingStream;
use std::io::Write;
use std::path::PathBuf;
use tetlab_core::measures::exact_step::ExactStepGap;
use tetlab_core::measures::metrics::Metrics;
use tetlab_core::scene::Scene;
use tetlab_core::simulation::Simulation;

/// The viewer address `--connect` uses when given no value.
pub const DEFAULT_VIEWER: &str = "rerun+http://127.0.0.1:9876/proxy";

/// Options of `tetlab record`.
#[derive(Debug, clap::Args)]
pub struct Args {
    #[command(flatten)]
    simulation: SimulationArgs,
    /// Write the recording to this file (.rrd).
    #[arg(
        long,
        value_name = "FILE.rrd",
        required_unless_present = "connect",
        conflicts_with = "connect"
    )]
    out: Option<PathBuf>,
    /// Stream to a running Rerun viewer instead of a file.
    #[arg(long, value_name = "ADDR", num_args = 0..=1, default_missing_value = DEFAULT_VIEWER)]
    connect: Option<String>,
    /// Gradient arrows to log: for the tet given by --tet (selected), every tet (all) or none.
    #[arg(long, value_enum, default_value_t = ArrowsMode::Selected)]
    arrows: ArrowsMode,
    /// The tet whose gradient arrows are logged with --arrows selected.
    #[arg(
        long,
        default_value_t = 0,
        value_name = "K",
        allow_hyphen_values = true
    )]
    tet: i64,
    /// Also log the eigenvalues of the energy Hessian of the tet given by --tet each frame
    /// (`modes/eigenvalues`, one series each) and its lowest mode but the translations as arrows
    /// (`world/modes/lowest`), as `tetlab modes` computes them for the active families.
    #[arg(long)]
    modes: bool,
    /// Also step each frame's start by the Newton reference and log how far the frame is from
    /// that exact one: `exact_step/distance` (the largest over the particles, m) and
    /// `exact_step/relative` (over the exact frame's largest motion), as `run --exact-step`.
    /// Slow beyond small scenes.
    #[arg(long)]
    exact_step: bool,
    /// No progress bar.
    #[arg(long)]
    quiet: bool,
}

/// Sets up (the simulation, the recording and its layout), records with [`run`], and writes or
/// streams the recording. Returns how it ended.
pub fn main(args: &Args, out: &mut impl Write) -> Result<Ending, UsageError> {
    let (scene, mut simulation) = args.simulation.build()?;
    let tets = simulation.tets().len() as i64;
    if !(0..tets).contains(&args.tet) {
        return Err(UsageError(format!(
            "--tet: {} is out of range: the scene has tets 0..={}",
            args.tet,
            tets - 1
        )));
    }
    let destination = match (&args.out, &args.connect) {
        (_, Some(address)) => Destination::Viewer(address.clone()),
        (Some(path), None) => Destination::File {
            path: path.clone(),
            flag: "--out",
        },
        (None, None) => unreachable!("clap requires --out or --connect"),
    };
    let session = Session::open(destination, args.simulation.frames, args.quiet)?;
    let rec = session.rec();
    let bodies = crate::record::body_parts::body_plots(&simulation);
    send_layout(rec, &[""], &bodies, args.modes, args.exact_step);
    describe(rec, &scene, &simulation, args);
    let initial = Metrics::measure_sound(&simulation).map_err(|d| UsageError(d.to_string()))?;
    match run(rec, &session, &scene, &mut simulation, &initial, args) {
        Ok(()) => session.close(simulation.frame(), out),
        Err(diverged) => Err(session.close_after(simulation.frame() - 1, diverged)),
    }
}

/// The run itself: the simulation logged frame by frame to `rec`, until `--frames` or Ctrl-C;
/// an error when it diverged (the frames before it are logged).
fn run(
    rec: &RecordingStream,
    session: &Session,
    scene: &Scene,
    simulation: &mut Simulation,
    initial: &Metrics,
    args: &Args,
) -> Result<(), UsageError> {
    let mut recorder = Recorder::new(rec, "", scene, simulation, args.arrows, args.tet as usize);
    if args.modes {
        recorder.log_modes();
    }
    recorder.log_frame(simulation, initial);
    for _ in 0..args.simulation.frames {
        if session.should_stop() {
            break;
        }
        let before = args.exact_step.then(|| simulation.clone());
        let metrics = SimulationArgs::step(simulation)?;
        recorder.log_frame(simulation, &metrics);
        if let Some(before) = before {
            let gap = ExactStepGap::measure(&before, simulation);
            rec.log("exact_step/distance", &rerun::Scalars::single(gap.largest))
                .ok();
            rec.log("exact_step/relative", &rerun::Scalars::single(gap.relative))
                .ok();
        }
        session.advance();
    }
    Ok(())
}

/// The static description of a run: scene, sizes, perturbation, settings, arrows.
fn describe(rec: &RecordingStream, scene: &Scene, simulation: &Simulation, args: &Args) {
    let perturbation = args
        .simulation
        .perturb
        .map(|p| p.to_string())
        .unwrap_or_else(|| "none".into());
    let notes: String = scene.notes.iter().map(|n| format!("\n- {n}")).collect();
    let text = format!(
        "# tetlab run\n\nscene **{}**: {} particles, {} tets, {} edges{notes}\n\nperturbation: {perturbation}\n\n{}\n\ngradient arrows: {:?}, tet {}",
        scene.name,
        simulation.positions().len(),
        simulation.tets().len(),
        simulation.body().edges.len(),
        args.simulation.describe(simulation),
        args.arrows,
        args.tet
    );
    rec.log_static("run", &rerun::TextDocument::from_markdown(text))
        .ok();
}
