//! `tetlab run`: a headless run, printing metrics per frame (`--json`) or a short summary; or,
//! with `--ensemble N`, the same run under N projection orders on both engines, reported as a
//! distribution.

use super::UsageError;
use super::simulation_args::SimulationArgs;
use serde::Serialize;
use std::collections::BTreeMap;
use std::io::Write;
use tetlab_core::input::limits::{self, Number};
use tetlab_core::measures::energy_account::{Energy, EnergyWatch};
use tetlab_core::measures::ensemble::{Ensemble, Member, Tally};
use tetlab_core::measures::exact_step::ExactStepGap;
use tetlab_core::measures::metrics::{Metrics, penetration_warning};
use tetlab_core::measures::outcome::Outcome;
use tetlab_core::simulation::newton::NewtonEngine;
use tetlab_core::simulation::{EngineChoice, Simulation};

/// Options of `tetlab run`.
#[derive(Debug, clap::Args)]
pub struct Args {
    #[command(flatten)]
    simulation: SimulationArgs,
    /// Print one JSON object per frame (frame 0 is the state before the first step); with
    /// --ensemble, one per member and then the tally.
    #[arg(long)]
    json: bool,
    /// Run the scene under N projection orders (order seeds 1..=N, 1..=1024) on both engines,
    /// or on the one --engine names, and report how many recover (no inverted tet at the end)
    /// [default: one run in the order of --order-seed].
    #[arg(long, value_name = "N", value_parser = |s: &str| limits::ENSEMBLE.parse(s), conflicts_with = "order_seed")]
    ensemble: Option<u64>,
    /// Also step every frame's start with the Newton reference (the implicit Euler steps XPBD
    /// approximates, solved exactly) and report how far XPBD's frame is from it: per frame in
    /// --json (exact_step_distance, m, and exact_step_relative, of the frame's motion), and the
    /// largest in the summary. Slow: for small scenes.
    #[arg(long, conflicts_with = "ensemble")]
    exact_step: bool,
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
    /// The largest particle speed, m/s.
    max_speed: f64,
    /// How far the centre of mass is from where it was at frame 0, m.
    centre_of_mass_displacement: f64,
    /// The same across the ground (x and z), m.
    centre_of_mass_horizontal_displacement: f64,
    /// `residual_<family>` for each active family, in the table's order.
    #[serde(flatten)]
    residuals: BTreeMap<String, f64>,
    /// `skipped_degenerate_<family>` and `skipped_too_long_<family>` for each active family:
    /// its projections skipped so far because ∇C was undefined, or because the step was beyond
    /// the reach (`tetlab_core::simulation::projection::DEFAULT_REACH`).
    #[serde(flatten)]
    skipped: BTreeMap<String, u64>,
    /// The energy account (`tetlab_core::measures::energy_account`), J: `energy_kinetic`,
    /// `energy_gravitational`, `energy_external`, `energy_elastic_<family>` for each active
    /// family, `energy_total`; and what left the body so far, `energy_taken_ground`,
    /// `energy_taken_damping`, `energy_taken_settling` (`tetlab_core::simulation::Taken`).
    #[serde(flatten)]
    energy: BTreeMap<String, f64>,
    /// With --exact-step: how far this frame is from the exact one from the same start
    /// (`tetlab_core::measures::exact_step`), m, and relative to that frame's motion.
    #[serde(skip_serializing_if = "Option::is_none")]
    exact_step_distance: Option<f64>,
    #[serde(skip_serializing_if = "Option::is_none")]
    exact_step_relative: Option<f64>,
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
    /// The order seed (frame 0; `null`: the mesh's order).
    #[serde(skip_serializing_if = "Option::is_none")]
    order_seed: Option<Option<u64>>,
    /// Whether edits settle (frame 0).
    #[serde(skip_serializing_if = "Option::is_none")]
    edits_settle: Option<bool>,
    /// Of a scene file of several bodies: each body's metrics.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    bodies: Vec<BodyRecord>,
    /// With a family that binds to contacts: the contacts touching
    /// (`tetlab_core::measures::Metrics::contacts`).
    #[serde(skip_serializing_if = "Option::is_none")]
    contacts: Option<usize>,
    /// With a family that binds to contacts: the largest penetration, m.
    #[serde(skip_serializing_if = "Option::is_none")]
    max_penetration: Option<f64>,
}

/// One body's metrics in a frame of a scene of several (`--scene FILE.toml`).
#[derive(Debug, Serialize)]
pub struct BodyRecord {
    name: String,
    inverted_tets: usize,
    min_volume_ratio: f64,
    volume_error: f64,
    max_edge_strain: f64,
    max_speed: f64,
    /// Its centre of mass, m.
    centre_of_mass: [f64; 3],
    /// With a family that binds to contacts: its particles' contacts touching, and the largest
    /// penetration among them, m.
    #[serde(skip_serializing_if = "Option::is_none")]
    contacts: Option<usize>,
    #[serde(skip_serializing_if = "Option::is_none")]
    max_penetration: Option<f64>,
    /// Its energy (`tetlab_core::measures::energy_account::Energy::measure_bodies`), J: kinetic,
    /// gravitational, external, elastic (every active family's) and their sum; the bodies'
    /// `energy_total` add up to the scene's.
    energy_kinetic: f64,
    energy_gravitational: f64,
    energy_external: f64,
    energy_elastic: f64,
    energy_total: f64,
}

impl BodyRecord {
    /// The records of each body of `simulation`'s scene; none for a scene of one body.
    pub fn of(simulation: &Simulation) -> Vec<BodyRecord> {
        let contact = has_contact(simulation);
        let families = simulation.families();
        (Metrics::measure_bodies(simulation).into_iter())
            .zip(Energy::measure_bodies(simulation))
            .map(|((name, m), (_, energy))| BodyRecord {
                name,
                inverted_tets: m.inverted_tets,
                min_volume_ratio: m.min_volume_ratio,
                volume_error: m.volume_error,
                max_edge_strain: m.max_edge_strain,
                max_speed: m.max_speed,
                centre_of_mass: m.centre_of_mass.to_array(),
                contacts: contact.then_some(m.contacts),
                max_penetration: contact.then_some(m.max_penetration),
                energy_kinetic: energy.kinetic,
                energy_gravitational: energy.gravitational,
                energy_external: energy.external,
                energy_elastic: energy.elastic_total(families),
                energy_total: energy.total,
            })
            .collect()
    }
}

/// Whether an active family of `simulation` binds to contacts.
fn has_contact(simulation: &Simulation) -> bool {
    let families = simulation.families();
    tetlab_core::simulation::contact::contact_families(families, simulation.active())
        .next()
        .is_some()
}

impl FrameRecord {
    /// The record of the simulation's current frame, with its `energy`; frame 0 also carries
    /// the sizes and the settings that decide the order and the settling. `start` is the centre
    /// of mass at frame 0.
    pub fn new(
        simulation: &Simulation,
        metrics: &Metrics,
        energy: &Energy,
        start: glam::DVec3,
    ) -> Self {
        let first = simulation.frame() == 0;
        let (settings, active) = (simulation.resolved(), simulation.active());
        let families = simulation.families();
        let moved = metrics.centre_of_mass - start;
        FrameRecord {
            frame: simulation.frame(),
            time: simulation.time(),
            inverted_tets: metrics.inverted_tets,
            min_volume_ratio: metrics.min_volume_ratio,
            volume_error: metrics.volume_error,
            max_edge_strain: metrics.max_edge_strain,
            max_displacement: metrics.max_displacement,
            max_speed: metrics.max_speed,
            centre_of_mass_displacement: moved.length(),
            centre_of_mass_horizontal_displacement: moved.x.hypot(moved.z),
            residuals: families
                .values(&metrics.residual)
                .filter(|&(family, _)| active[family])
                .map(|(family, value)| (format!("residual_{}", families.name(family)), value))
                .collect(),
            skipped: families
                .values(simulation.skipped())
                .filter(|&(family, _)| active[family])
                .flat_map(|(family, counts)| {
                    let name = families.name(family);
                    [
                        (format!("skipped_degenerate_{name}"), counts.degenerate),
                        (format!("skipped_too_long_{name}"), counts.too_long),
                    ]
                })
                .collect(),
            energy: [
                ("energy_kinetic".to_owned(), energy.kinetic),
                ("energy_gravitational".to_owned(), energy.gravitational),
                ("energy_external".to_owned(), energy.external),
                ("energy_total".to_owned(), energy.total),
                ("energy_taken_ground".to_owned(), energy.taken.ground),
                ("energy_taken_damping".to_owned(), energy.taken.damping),
                ("energy_taken_settling".to_owned(), energy.taken.settling),
            ]
            .into_iter()
            .chain(
                families
                    .values(&energy.elastic)
                    .filter(|&(family, _)| active[family])
                    .map(|(f, e)| (format!("energy_elastic_{}", families.name(f)), e)),
            )
            .collect(),
            exact_step_distance: None,
            exact_step_relative: None,
            particles: first.then(|| simulation.positions().len()),
            tets: first.then(|| simulation.tets().len()),
            edges: first.then(|| simulation.body().edges.len()),
            engine: first.then(|| simulation.engine().name()),
            threads: first.then(|| simulation.threads()),
            order_seed: first.then_some(settings.settings.order_seed),
            edits_settle: first.then(|| settings.edits_settle()),
            bodies: BodyRecord::of(simulation),
            contacts: has_contact(simulation).then_some(metrics.contacts),
            max_penetration: has_contact(simulation).then_some(metrics.max_penetration),
        }
    }
}

/// Runs the simulation for `--frames` frames and reports (or runs the ensemble).
pub fn run(args: &Args, out: &mut impl Write) -> Result<(), UsageError> {
    if let Some(n) = args.ensemble {
        return run_ensemble(args, n, out);
    }
    let (scene, mut simulation) = args.simulation.build()?;
    if args.exact_step && has_contact(&simulation) {
        return Err(UsageError(
            "--exact-step: the Newton reference it steps against solves a substep without \
             contact, so with a family on contacts there is no exact frame to compare with"
                .to_owned(),
        ));
    }
    let io = UsageError::stdout;
    let initial = Metrics::measure_sound(&simulation).map_err(|d| UsageError(d.to_string()))?;
    let mut outcome = Outcome::start(&simulation, &initial);
    let mut energy = EnergyWatch::start(&simulation);
    if args.json {
        let record = FrameRecord::new(&simulation, &initial, energy.last(), outcome.start);
        write_json(out, &record).map_err(io)?;
    } else {
        writeln!(
            out,
            "scene {}: {} particles, {} tets, {} edges",
            scene.name,
            simulation.positions().len(),
            simulation.tets().len(),
            simulation.body().edges.len()
        )
        .map_err(io)?;
        for note in &scene.notes {
            writeln!(out, "  note: {note}").map_err(io)?;
        }
        for body in &scene.bodies {
            if let Some(made_of) = body.made_of() {
                writeln!(out, "  body {}: {made_of}", body.name).map_err(io)?;
            }
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
    // The largest gap from the exact frame: (relative, metres, frame), and whether every
    // exact frame converged.
    let mut largest_gap: Option<(f64, f64, u64)> = None;
    let mut gaps_converged = true;
    for _ in 0..args.simulation.frames {
        let before = args.exact_step.then(|| simulation.clone());
        let metrics = SimulationArgs::step(&mut simulation)?;
        outcome.observe(&simulation, &metrics);
        let gap = before.map(|before| ExactStepGap::measure(&before, &simulation));
        if let Some(gap) = gap {
            gaps_converged &= gap.converged;
            if largest_gap.is_none_or(|(relative, _, _)| gap.relative > relative) {
                largest_gap = Some((gap.relative, gap.largest, simulation.frame()));
            }
        }
        let now = energy.observe(&simulation, simulation.frame());
        if args.json {
            let mut record = FrameRecord::new(&simulation, &metrics, now, outcome.start);
            record.exact_step_distance = gap.map(|g| g.largest);
            record.exact_step_relative = gap.map(|g| g.relative);
            write_json(out, &record).map_err(io)?;
        }
    }
    if !args.json {
        summary_line(out, simulation.frame(), &outcome.last).map_err(io)?;
        let verdict = match outcome.last_inverted_frame {
            _ if !outcome.recovered() => {
                format!(
                    "{} tets still inverted at the end",
                    outcome.last.inverted_tets
                )
            }
            Some(frame) => format!("no inverted tets from frame {} on", frame + 1),
            None => "no inverted tets at any frame".to_owned(),
        };
        writeln!(out, "{verdict}").map_err(io)?;
        let moved = outcome.displacement();
        writeln!(
            out,
            "largest speed {:.3} m/s (frame {}); centre of mass moved {:.3} m ({:.3} m across \
             the ground)",
            outcome.largest_speed.0,
            outcome.largest_speed.1,
            moved.length(),
            outcome.horizontal_displacement()
        )
        .map_err(io)?;
        if has_contact(&simulation) {
            let thickness = simulation.settings().contact.thickness;
            writeln!(
                out,
                "contact: {} touching at the end, largest penetration {:.3e} m (of the \
                 thickness {} m; over the run {:.3e} m, frame {})",
                outcome.last.contacts,
                outcome.last.max_penetration,
                thickness.show(),
                outcome.deepest.0,
                outcome.deepest.1
            )
            .map_err(io)?;
            let (depth, frame) = outcome.deepest;
            if let Some(warning) = penetration_warning(depth, frame, thickness) {
                writeln!(out, "{warning}").map_err(io)?;
            }
        }
        for body in BodyRecord::of(&simulation) {
            let [x, y, z] = body.centre_of_mass;
            writeln!(
                out,
                "body {}: {} inverted tets, min V/V0 {:.4}, max edge strain {:.3e}, largest speed \
                 {:.3} m/s, centre of mass at ({x:.3}, {y:.3}, {z:.3}) m, energy {:.4} J \
                 (kinetic {:.4} J)",
                body.name,
                body.inverted_tets,
                body.min_volume_ratio,
                body.max_edge_strain,
                body.max_speed,
                body.energy_total,
                body.energy_kinetic
            )
            .map_err(io)?;
            if let (Some(touching), Some(deepest)) = (body.contacts, body.max_penetration) {
                writeln!(
                    out,
                    "  {touching} contacts touching, largest penetration {deepest:.3e} m"
                )
                .map_err(io)?;
            }
        }
        for line in super::simulation_args::describe_skipped(&simulation) {
            writeln!(out, "{line}").map_err(io)?;
        }
        for line in energy.lines() {
            writeln!(out, "{line}").map_err(io)?;
        }
        if let Some((relative, metres, frame)) = largest_gap {
            let unconverged = if gaps_converged {
                ""
            } else {
                " (the Newton reference did not converge on every frame: there its answer is a local one)"
            };
            writeln!(
                out,
                "distance from the exact frame: at most {metres:.3e} m, {:.2e} of the frame's \
                 motion, at frame {frame}{unconverged}",
                relative
            )
            .map_err(io)?;
        }
        if let Some(warning) = simulation
            .engine_as::<NewtonEngine>()
            .and_then(|newton| newton.warning())
        {
            writeln!(out, "warning: {warning}").map_err(io)?;
        }
        if let Some(warning) = outcome.thrown_warning() {
            let advice = if simulation.resolved().edits_settle() {
                ""
            } else {
                " (--no-settle-edits: without it, edits settle and the body recovers where it lies)"
            };
            writeln!(out, "warning: {warning}{advice}").map_err(io)?;
        }
    }
    Ok(())
}

/// `--ensemble N`: the run under order seeds 1..=N on each engine asked for, side by side on
/// `--threads` workers; one line per member and the tally of each engine (or JSON).
fn run_ensemble(args: &Args, n: u64, out: &mut impl Write) -> Result<(), UsageError> {
    let io = UsageError::stdout;
    let (scene, simulation) = args.simulation.build()?;
    let engines = match args.simulation.solver.engine {
        Some(engine) if engine != EngineChoice::Auto => vec![engine],
        _ => EngineChoice::position_based().collect(),
    };
    let ensemble = Ensemble {
        scene: &scene,
        families: simulation.families(),
        settings: *simulation.settings(),
        perturbation: args.simulation.perturb,
        frames: args.simulation.frames,
    };
    if !args.json {
        let perturbation = args.simulation.perturb.map(|p| p.to_string());
        writeln!(
            out,
            "scene {}: {} particles, {} tets; perturbation {}; {} frames; {}",
            scene.name,
            simulation.positions().len(),
            simulation.tets().len(),
            perturbation.as_deref().unwrap_or("none"),
            args.simulation.frames,
            args.simulation
                .describe(&simulation)
                .replace(", the mesh's order", ""),
        )
        .map_err(io)?;
        writeln!(
            out,
            "ensemble: order seeds 1..={n} on {}",
            engines
                .iter()
                .map(|e| e.name())
                .collect::<Vec<_>>()
                .join(" and ")
        )
        .map_err(io)?;
    }
    let seeds: Vec<u64> = (1..=n).collect();
    let members = ensemble.run(&engines, &seeds, args.simulation.solver.threads());
    for member in &members {
        if args.json {
            write_json(out, &MemberRecord::new(member)).map_err(io)?;
        } else {
            let what = match &member.result {
                Ok(outcome) => outcome.describe(),
                Err(divergence) => divergence.to_string(),
            };
            writeln!(
                out,
                "  {:<9} seed {:>4}: {what}",
                member.engine.name(),
                member.order_seed
            )
            .map_err(io)?;
        }
    }
    let tallies: Vec<Tally> = engines.iter().map(|&e| Tally::of(&members, e)).collect();
    if args.json {
        let tally: BTreeMap<&str, TallyRecord> = tallies
            .iter()
            .map(|t| (t.engine.name(), TallyRecord::new(t)))
            .collect();
        serde_json::to_writer(&mut *out, &serde_json::json!({ "ensemble": tally }))
            .map_err(|e| UsageError(format!("stdout: {e}")))?;
        writeln!(out).map_err(io)?;
    } else {
        for tally in &tallies {
            writeln!(out, "{}: {}", tally.engine.name(), tally.describe()).map_err(io)?;
        }
    }
    Ok(())
}

/// One member of an ensemble in `--json`.
#[derive(Debug, Serialize)]
struct MemberRecord {
    engine: &'static str,
    order_seed: u64,
    /// Where it diverged, if it did.
    diverged: Option<String>,
    inverted_tets: Option<usize>,
    last_inverted_frame: Option<u64>,
    min_volume_ratio: Option<f64>,
    max_edge_strain: Option<f64>,
    max_speed: Option<f64>,
    centre_of_mass_horizontal_displacement: Option<f64>,
    thrown: Option<bool>,
}

impl MemberRecord {
    fn new(member: &Member) -> MemberRecord {
        let ok = member.result.as_ref().ok();
        MemberRecord {
            engine: member.engine.name(),
            order_seed: member.order_seed,
            diverged: member.result.as_ref().err().map(|d| d.to_string()),
            inverted_tets: ok.map(|o| o.last.inverted_tets),
            last_inverted_frame: ok.and_then(|o| o.last_inverted_frame),
            min_volume_ratio: ok.map(|o| o.last.min_volume_ratio),
            max_edge_strain: ok.map(|o| o.last.max_edge_strain),
            max_speed: ok.map(|o| o.largest_speed.0),
            centre_of_mass_horizontal_displacement: ok.map(Outcome::horizontal_displacement),
            thrown: ok.map(Outcome::thrown),
        }
    }
}

/// One engine's tally in `--json`.
#[derive(Debug, Serialize)]
struct TallyRecord {
    members: usize,
    recovered: usize,
    diverged: usize,
    thrown: usize,
    inverted_at_the_end: Vec<usize>,
    largest_strain: f64,
    summary: String,
}

impl TallyRecord {
    fn new(tally: &Tally) -> TallyRecord {
        TallyRecord {
            members: tally.members,
            recovered: tally.recovered,
            diverged: tally.diverged,
            thrown: tally.thrown,
            inverted_at_the_end: tally.inverted_at_the_end.clone(),
            largest_strain: tally.largest_strain,
            summary: tally.describe(),
        }
    }
}

fn write_json(out: &mut impl Write, record: &impl Serialize) -> std::io::Result<()> {
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
