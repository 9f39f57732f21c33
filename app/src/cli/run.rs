//! `tetlab run`: a headless run, printing metrics per frame (`--json`) or a short summary.

use super::UsageError;
use super::simulation_args::SimulationArgs;
use serde::Serialize;
use std::collections::BTreeMap;
use std::io::Write;
use tetlab_core::constraints::Family;
use tetlab_core::metrics::Metrics;
use tetlab_core::solver::Simulation;

/// Options of `tetlab run`.
#[derive(Debug, clap::Args)]
pub struct Args {
    #[command(flatten)]
    simulation: SimulationArgs,
    /// Print one JSON object per frame (frame 0 is the state before the first step).
    #[arg(long)]
    json: bool,
}

/// One line of `--json` output.
#[derive(Debug, Serialize)]
pub struct FrameRecord {
    frame: u64,
    time: f64,
    inverted_tets: usize,
    min_volume_ratio: f64,
    volume_error: f64,
    max_edge_strain: f64,
    max_displacement: f64,
    /// `residual_<family>` for each family of the table, in its order.
    #[serde(flatten)]
    residuals: BTreeMap<String, f64>,
    #[serde(skip_serializing_if = "Option::is_none")]
    particles: Option<usize>,
    #[serde(skip_serializing_if = "Option::is_none")]
    tets: Option<usize>,
    #[serde(skip_serializing_if = "Option::is_none")]
    edges: Option<usize>,
    /// Which engine steps the run: `reference` or `fast`.
    #[serde(skip_serializing_if = "Option::is_none")]
    engine: Option<&'static str>,
    /// Threads of the fast engine.
    #[serde(skip_serializing_if = "Option::is_none")]
    threads: Option<usize>,
}

impl FrameRecord {
    /// The record of the simulation's current frame; frame 0 also carries the sizes.
    pub fn new(simulation: &Simulation, metrics: &Metrics) -> Self {
        let first = simulation.frame() == 0;
        FrameRecord {
            frame: simulation.frame(),
            time: simulation.time(),
            inverted_tets: metrics.inverted_tets,
            min_volume_ratio: metrics.min_volume_ratio,
            volume_error: metrics.volume_error,
            max_edge_strain: metrics.max_edge_strain,
            max_displacement: metrics.max_displacement,
            residuals: metrics
                .residual
                .iter()
                .map(|(family, value)| (format!("residual_{}", family.name()), value))
                .collect(),
            particles: first.then(|| simulation.positions().len()),
            tets: first.then(|| simulation.tets().len()),
            edges: first.then(|| simulation.constraint_count(Family::EDGES)),
            engine: first.then(|| simulation.engine().name()),
            threads: first.then(|| simulation.threads()),
        }
    }
}

/// Runs the simulation for `--frames` frames and reports.
pub fn run(args: &Args, out: &mut impl Write) -> Result<(), UsageError> {
    let (scene, mut simulation) = args.simulation.build()?;
    let io = UsageError::stdout;
    let initial = Metrics::measure_sound(&simulation).map_err(|d| UsageError(d.to_string()))?;
    if args.json {
        write_json(out, &FrameRecord::new(&simulation, &initial)).map_err(io)?;
    } else {
        writeln!(
            out,
            "scene {}: {} particles, {} tets, {} edges",
            scene.name,
            simulation.positions().len(),
            simulation.tets().len(),
            simulation.constraint_count(Family::EDGES)
        )
        .map_err(io)?;
        for note in &scene.notes {
            writeln!(out, "  note: {note}").map_err(io)?;
        }
        let perturbation = args.simulation.perturb.map(|p| p.to_string());
        writeln!(
            out,
            "perturbation {}; {}",
            perturbation.as_deref().unwrap_or("none"),
            args.simulation.describe(&simulation)
        )
        .map_err(io)?;
        summary_line(out, 0, &initial).map_err(io)?;
    }
    let mut last_inverted_frame = (initial.inverted_tets > 0).then_some(0);
    let mut last = initial;
    for _ in 0..args.simulation.frames {
        last = SimulationArgs::step(&mut simulation)?;
        if last.inverted_tets > 0 {
            last_inverted_frame = Some(simulation.frame());
        }
        if args.json {
            write_json(out, &FrameRecord::new(&simulation, &last)).map_err(io)?;
        }
    }
    if !args.json {
        summary_line(out, simulation.frame(), &last).map_err(io)?;
        let verdict = match last_inverted_frame {
            _ if last.inverted_tets > 0 => {
                format!("{} tets still inverted at the end", last.inverted_tets)
            }
            Some(frame) => format!("no inverted tets from frame {} on", frame + 1),
            None => "no inverted tets at any frame".to_owned(),
        };
        writeln!(out, "{verdict}").map_err(io)?;
    }
    Ok(())
}

fn write_json(out: &mut impl Write, record: &FrameRecord) -> std::io::Result<()> {
    serde_json::to_writer(&mut *out, record)?;
    writeln!(out)
}

fn summary_line(out: &mut impl Write, frame: u64, m: &Metrics) -> std::io::Result<()> {
    writeln!(
        out,
        "frame {frame:>6}: inverted tets {:>6}, min V/V0 {:>9.4}, volume error {:>9.3e}, max edge strain {:>9.3e}",
        m.inverted_tets, m.min_volume_ratio, m.volume_error, m.max_edge_strain
    )
}
