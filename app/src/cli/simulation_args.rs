//! The scene and solver options shared by `tetlab run` (and every subcommand that runs the
//! simulation), and how they become a [`Simulation`].

use super::{UsageError, args};
use tetlab_core::constraints::Family;
use tetlab_core::scene::{Perturbation, Scene};
use tetlab_core::solver::{Method, PerFamily, Settings, Simulation};

/// Scene and solver options.
#[derive(Debug, Clone, clap::Args)]
pub struct SimulationArgs {
    /// A built-in scene (tet, cube, beam, ball) or a mesh file (.node, .ele, .msh).
    #[arg(long, default_value = "tet", value_name = "NAME|PATH")]
    pub scene: String,
    /// Cells along a side of cube and beam, half the cells across ball (1..=128).
    #[arg(long, default_value_t = 4, value_parser = clap::value_parser!(u32).range(1..=128), allow_hyphen_values = true)]
    pub resolution: u32,
    /// Deform the scene before the first frame: invert, mirror, flatten or scramble:SEED.
    #[arg(long, value_parser = Perturbation::parse)]
    pub perturb: Option<Perturbation>,
    /// Active constraint families, comma-separated: edges, plane, volume.
    #[arg(long, default_value = "edges,volume", value_parser = PerFamily::parse_list)]
    pub constraints: PerFamily<bool>,
    /// xpbd or pbd.
    #[arg(long, default_value = "xpbd", value_parser = Method::parse)]
    pub solver: Method,
    /// Substeps per frame (1..=1000).
    #[arg(long, default_value_t = 10, value_parser = clap::value_parser!(u32).range(1..=1000), allow_hyphen_values = true)]
    pub substeps: u32,
    /// Gauss–Seidel iterations per substep (1..=1000).
    #[arg(long, default_value_t = 1, value_parser = clap::value_parser!(u32).range(1..=1000), allow_hyphen_values = true)]
    pub iterations: u32,
    /// Frames to simulate (0..=10000000).
    #[arg(long, default_value_t = 300, value_parser = clap::value_parser!(u64).range(0..=10_000_000), allow_hyphen_values = true)]
    pub frames: u64,
    /// Frame length in seconds (0 < dt ≤ 1).
    #[arg(long, default_value_t = 1.0 / 60.0, value_parser = dt, allow_hyphen_values = true)]
    pub dt: f64,
    /// Gravity along −y in m/s²; 0 turns gravity and the ground off.
    #[arg(long, default_value_t = 9.81, value_parser = args::finite_number, allow_hyphen_values = true)]
    pub gravity: f64,
    /// XPBD compliance of a family, FAMILY=α (≥ 0; 0 is rigid, the default); repeatable.
    #[arg(long, value_name = "FAMILY=α", value_parser = compliance, allow_hyphen_values = true)]
    pub compliance: Vec<(Family, f64)>,
    /// PBD stiffness of a family, FAMILY=k with 0 ≤ k ≤ 1 (default 1); repeatable.
    #[arg(long, value_name = "FAMILY=k", value_parser = stiffness)]
    pub stiffness: Vec<(Family, f64)>,
    /// After the perturbation, let corrections move particles but not speed them up until the
    /// violation is undone (otherwise a large violation launches the body).
    #[arg(long)]
    pub settle_edits: bool,
    /// Velocity damping per second (≥ 0).
    #[arg(long, default_value_t = 0.0, value_parser = non_negative, allow_hyphen_values = true)]
    pub damping: f64,
}

impl SimulationArgs {
    /// The solver settings these options ask for.
    pub fn settings(&self) -> Settings {
        let mut settings = Settings {
            method: self.solver,
            active: self.constraints,
            substeps: self.substeps,
            iterations: self.iterations,
            dt: self.dt,
            gravity: self.gravity,
            ground: self.gravity != 0.0,
            damping: self.damping,
            settle_edits: self.settle_edits,
            ..Settings::default()
        };
        for &(family, alpha) in &self.compliance {
            settings.compliance.set(family, alpha);
        }
        for &(family, k) in &self.stiffness {
            settings.stiffness.set(family, k);
        }
        settings
    }

    /// Advances one frame; an error if the state overflowed (it can only with extreme options).
    pub fn step(simulation: &mut Simulation) -> Result<(), UsageError> {
        simulation.step();
        if simulation.is_sound() {
            Ok(())
        } else {
            Err(UsageError(format!(
                "the simulation diverged at frame {}: a coordinate or velocity passed 1e30 \
                 (try a smaller --dt or --gravity)",
                simulation.frame()
            )))
        }
    }

    /// Loads the scene, builds the simulation and applies the perturbation.
    pub fn build(&self) -> Result<(Scene, Simulation), UsageError> {
        let scene = Scene::from_spec(&self.scene, self.resolution)
            .map_err(|e| UsageError(format!("--scene: {e}")))?;
        let mut simulation = Simulation::new(&scene, self.settings());
        if let Some(perturbation) = self.perturb {
            simulation.perturb(perturbation);
        }
        Ok((scene, simulation))
    }

    /// "xpbd, edges+volume, 10 substeps × 1 iteration, dt 0.016667 s, gravity 9.81" and any
    /// non-default compliance or stiffness.
    pub fn describe(&self) -> String {
        let s = self.settings();
        let mut text = format!(
            "{}, {}, {} substeps x {} iteration{}, dt {:.6} s, gravity {}",
            s.method.name(),
            s.active.describe(),
            s.substeps,
            s.iterations,
            if s.iterations == 1 { "" } else { "s" },
            s.dt,
            short_number(s.gravity)
        );
        if self.settle_edits {
            text += ", settle edits";
        }
        for (family, alpha) in &self.compliance {
            text += &format!(", compliance {}={alpha}", family.short_name());
        }
        for (family, k) in &self.stiffness {
            text += &format!(", stiffness {}={k}", family.short_name());
        }
        text
    }
}

/// `x` as written by Rust when that is short (9.81), in scientific notation otherwise (1e300).
fn short_number(x: f64) -> String {
    let plain = x.to_string();
    if plain.len() <= 12 {
        plain
    } else {
        format!("{x:e}")
    }
}

fn dt(text: &str) -> Result<f64, String> {
    let value = args::finite_number(text)?;
    if value > 0.0 && value <= 1.0 {
        Ok(value)
    } else {
        Err(format!("{value} is out of range: expected 0 < dt <= 1"))
    }
}

fn non_negative(text: &str) -> Result<f64, String> {
    let value = args::finite_number(text)?;
    if value >= 0.0 {
        Ok(value)
    } else {
        Err(format!("{value} is negative"))
    }
}

fn family_value(text: &str) -> Result<(Family, f64), String> {
    let (name, value) = text
        .split_once('=')
        .ok_or_else(|| format!("'{text}' is not FAMILY=VALUE (e.g. edges=1e-6)"))?;
    Ok((Family::parse(name)?, args::finite_number(value)?))
}

fn compliance(text: &str) -> Result<(Family, f64), String> {
    let (family, alpha) = family_value(text)?;
    if alpha >= 0.0 {
        Ok((family, alpha))
    } else {
        Err(format!("compliance {alpha} is negative"))
    }
}

fn stiffness(text: &str) -> Result<(Family, f64), String> {
    let (family, k) = family_value(text)?;
    if (0.0..=1.0).contains(&k) {
        Ok((family, k))
    } else {
        Err(format!("stiffness {k} is outside 0..=1"))
    }
}
