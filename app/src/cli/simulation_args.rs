//! The scene and solver options shared by `tetlab run` (and every subcommand that runs the
//! simulation), and how they become a [`Simulation`].

use super::UsageError;
use std::path::PathBuf;
use tetlab_core::constraint_file::ConstraintFile;
use tetlab_core::constraints::material::Material;
use tetlab_core::constraints::{Families, Family};
use tetlab_core::input::limits::{self, Number};
use tetlab_core::measures::metrics::Metrics;
use tetlab_core::scene::{Perturbation, Scene};
use tetlab_core::simulation::{EngineChoice, Method, Resolved, Settings, Simulation};

/// Scene and solver options.
#[derive(Debug, Clone, clap::Args)]
pub struct SimulationArgs {
    /// A built-in scene (tet, cube, beam, ball) or a mesh file (.node, .ele, .msh).
    #[arg(long, default_value = "tet", value_name = "NAME|PATH")]
    pub scene: String,
    /// Cells along a side of cube and beam, half the cells across ball (1..=128, and at most
    /// 16777216 tets).
    #[arg(long, default_value_t = 4, value_parser = |s: &str| limits::RESOLUTION.parse(s), allow_hyphen_values = true)]
    pub resolution: u32,
    /// Deform the scene before the first frame: invert, mirror, flatten or scramble:SEED.
    #[arg(long, value_parser = Perturbation::parse)]
    pub perturb: Option<Perturbation>,
    /// Frames to simulate (0..=10000000).
    #[arg(long, default_value_t = 300, value_parser = |s: &str| limits::FRAMES.parse(s), allow_hyphen_values = true)]
    pub frames: u64,
    /// The solver's options.
    #[command(flatten)]
    pub solver: SolverArgs,
    /// Let the perturbation launch the body: without this, corrections after it may move
    /// particles but not speed them up until the violation is undone (edits settle, as in the
    /// workbench); with it, rigid constraints undo a large violation within a substep and
    /// v = Δx/h throws the body.
    #[arg(long)]
    pub no_settle_edits: bool,
    /// Edits settle (the default; the option is kept for the commands that name it).
    #[arg(long, hide = true, conflicts_with = "no_settle_edits")]
    pub settle_edits: bool,
}

/// Which families, with which compliances and material: what every subcommand that simulates
/// takes (within [`SolverArgs`]), and `tetlab modes`. Family names are read once the constraint
/// files are loaded, so that `--constraints` and `--compliance` can name a file's family in any
/// order.
#[derive(Debug, Clone, clap::Args)]
pub struct FamilyArgs {
    /// Active constraint families, comma-separated: edges, height, volume, neohookean, the name
    /// of a --constraint-file's family, or none.
    #[arg(long, default_value = "edges,volume", value_name = "LIST")]
    pub constraints: String,
    /// A constraint file (TOML: C as an expression; assets/constraints/ has examples), whose
    /// family is added to the active ones; repeatable.
    #[arg(long = "constraint-file", value_name = "FILE")]
    pub constraint_files: Vec<PathBuf>,
    /// XPBD compliance of a family, FAMILY=α (0 <= α <= 1e10; 0 is rigid, the default);
    /// repeatable.
    #[arg(long, value_name = "FAMILY=α", value_parser = |s: &str| NamedValue::parse(s, &limits::COMPLIANCE), allow_hyphen_values = true)]
    pub compliance: Vec<NamedValue>,
    /// The material of the neohookean family: Young's modulus E in Pa (1e-3..=1e13) and
    /// Poisson's ratio nu (0 <= nu < 0.5), both required; gives its compliances 1/μ and 1/λ
    /// [default: E=1e6,nu=0.3].
    #[arg(long, value_name = "E=PA,nu=N", value_parser = Material::parse)]
    pub material: Option<Material>,
}

impl FamilyArgs {
    /// The table with every `--constraint-file`'s families, and `settings` with the active
    /// families, the material and the compliances these options ask for. An error names the
    /// option, and for a file the line and column of its mistake.
    pub fn apply(&self, mut settings: Settings) -> Result<(Settings, Families), UsageError> {
        let mut families = Families::builtin();
        let mut files = Vec::new();
        for path in &self.constraint_files {
            files.extend(load_constraint_file(path, |loaded| {
                families.register_all(loaded)
            })?);
        }
        settings.active = families
            .parse_list(&self.constraints)
            .map_err(|e| UsageError(format!("--constraints: {e}")))?;
        for family in files {
            settings.active.set(family, true);
        }
        if let Some(material) = self.material {
            settings.material = material;
        }
        for NamedValue { name, value } in &self.compliance {
            let family = tetlab_core::simulation::settable_family(&families, name)
                .map_err(|e| UsageError(format!("--compliance {name}={value}: {e}")))?;
            settings.compliance.set(family, *value);
        }
        Ok((settings, families))
    }
}

/// The solver's options, the same for every subcommand that simulates (`run`, `record`,
/// `bench`); each range is [`tetlab_core::input::limits`]'s, and the ground follows gravity
/// ([`Settings::set_gravity`]).
#[derive(Debug, Clone, clap::Args)]
pub struct SolverArgs {
    /// The families, their compliances and material.
    #[command(flatten)]
    pub families: FamilyArgs,
    /// xpbd or pbd.
    #[arg(long, default_value = "xpbd", value_parser = Method::parse)]
    pub solver: Method,
    /// Which solver steps the simulation: reference (f64, one constraint at a time), fast (f32,
    /// coloured, in SIMD lanes, on threads), newton (every substep's implicit Euler step solved
    /// exactly: the answer XPBD approximates; slow, for small scenes), gpu (the fast engine's
    /// model in compute shaders, where a GPU adapter is found) or auto (reference below 1000
    /// tets, fast from there) [default: auto; bench: fast].
    #[arg(long, value_parser = EngineChoice::parse)]
    pub engine: Option<EngineChoice>,
    /// Threads for the fast engine (1..=256; the results are the same for any count) [default:
    /// every core; bench: 1].
    #[arg(long, value_parser = clap::value_parser!(u64).range(1..=256))]
    pub threads: Option<u64>,
    /// Substeps per frame (1..=1000).
    #[arg(long, default_value_t = Settings::default().substeps, value_parser = |s: &str| limits::SUBSTEPS.parse(s), allow_hyphen_values = true)]
    pub substeps: u32,
    /// Gauss–Seidel iterations per substep (1..=1000).
    #[arg(long, default_value_t = Settings::default().iterations, value_parser = |s: &str| limits::ITERATIONS.parse(s), allow_hyphen_values = true)]
    pub iterations: u32,
    /// Frame length in seconds (1e-6 <= dt <= 1).
    #[arg(long, default_value_t = Settings::default().dt, value_parser = |s: &str| limits::DT.parse(s), allow_hyphen_values = true)]
    pub dt: f64,
    /// Gravity along −y in m/s² (-1e6..=1e6); 0 turns gravity and the ground off.
    #[arg(long, default_value_t = Settings::default().gravity, value_parser = |s: &str| limits::GRAVITY.parse(s), allow_hyphen_values = true)]
    pub gravity: f64,
    /// PBD stiffness of a family, FAMILY=k with 0 <= k <= 1 (default 1); repeatable.
    #[arg(long, value_name = "FAMILY=k", value_parser = |s: &str| NamedValue::parse(s, &limits::STIFFNESS))]
    pub stiffness: Vec<NamedValue>,
    /// Velocity damping per second (0..=1e6).
    #[arg(long, default_value_t = Settings::default().damping, value_parser = |s: &str| limits::DAMPING.parse(s), allow_hyphen_values = true)]
    pub damping: f64,
    /// Project each family's constraints in an order drawn from this seed (on the fast engine:
    /// its colours), instead of the mesh's; a result that changes with it hangs on the order
    /// [default: the mesh's order].
    #[arg(long, value_name = "S")]
    pub order_seed: Option<u64>,
    /// How far one projection may move a particle, in longest rest edges of its element
    /// (1..=1e9); a longer step is skipped and counted: where ∇C vanishes and C does not.
    #[arg(long, value_name = "K", default_value_t = Settings::default().reach, value_parser = |s: &str| limits::REACH.parse(s), allow_hyphen_values = true)]
    pub reach: f64,
    /// The thickness contact keeps between surfaces, in metres (1e-9..=1e3), for the contact
    /// family [default: 0.01].
    #[arg(long, value_name = "D", default_value_t = Settings::default().contact.thickness, value_parser = |s: &str| limits::THICKNESS.parse(s), allow_hyphen_values = true)]
    pub thickness: f64,
    /// Friction of contact: static and kinetic coefficients μs,μk (each 0..=10), or one number
    /// for both [default: 0.5,0.4].
    #[arg(long, value_name = "MU_S[,MU_K]", value_parser = parse_friction, allow_hyphen_values = true)]
    pub friction: Option<[f64; 2]>,
}

/// `μs,μk`, or `μ` for both, each in range.
fn parse_friction(text: &str) -> Result<[f64; 2], String> {
    let parts: Vec<&str> = text.split(',').collect();
    match parts[..] {
        [both] => {
            let mu = limits::FRICTION.parse(both)?;
            Ok([mu, mu])
        }
        [mu_static, mu_kinetic] => Ok([
            limits::FRICTION.parse(mu_static)?,
            limits::FRICTION.parse(mu_kinetic)?,
        ]),
        _ => Err(format!(
            "'{text}' is not μs,μk or one coefficient for both (e.g. 0.5,0.4)"
        )),
    }
}

/// `FAMILY=VALUE` as given, its value in range; the family is looked up later
/// ([`SolverArgs::settings`]), once the constraint files have added theirs.
#[derive(Debug, Clone, PartialEq)]
pub struct NamedValue {
    /// The family's name as written.
    pub name: String,
    /// The value.
    pub value: f64,
}

impl NamedValue {
    fn parse(text: &str, bounds: &limits::Bounds<f64>) -> Result<NamedValue, String> {
        let (name, value) = text
            .split_once('=')
            .ok_or_else(|| format!("'{text}' is not FAMILY=VALUE (e.g. edges=1e-6)"))?;
        Ok(NamedValue {
            name: name.trim().to_owned(),
            value: bounds.parse(value)?,
        })
    }
}

/// Ok where `engine` can run here; otherwise the usage error naming `--engine` (the GPU engine
/// without an adapter: "--engine gpu: no GPU adapter (…)").
pub fn available(engine: EngineChoice) -> Result<(), UsageError> {
    engine
        .available()
        .map_err(|why| UsageError(format!("--engine {}: {why}", engine.name())))
}

impl SolverArgs {
    /// The solver settings these options ask for: the constraint files loaded and their
    /// families added to the table and to the active ones, then every family name looked up.
    /// An error names the option, and for a file the line and column of its mistake.
    pub fn settings(&self) -> Result<(Settings, Families), UsageError> {
        let mut settings = Settings {
            method: self.solver,
            engine: self.engine.unwrap_or_default(),
            substeps: self.substeps,
            iterations: self.iterations,
            dt: self.dt,
            damping: self.damping,
            order_seed: self.order_seed,
            reach: self.reach,
            ..Settings::default()
        };
        settings.contact.thickness = self.thickness;
        if let Some([mu_static, mu_kinetic]) = self.friction {
            settings.contact.static_friction = mu_static;
            settings.contact.kinetic_friction = mu_kinetic;
        }
        settings.set_gravity(self.gravity);
        let (mut settings, families) = self.families.apply(settings)?;
        for NamedValue { name, value } in &self.stiffness {
            let family = tetlab_core::simulation::settable_family(&families, name)
                .map_err(|e| UsageError(format!("--stiffness {name}={value}: {e}")))?;
            settings.stiffness.set(family, *value);
        }
        let contact =
            tetlab_core::simulation::contact::contact_families(&families, &settings.active).next();
        if let (Some(family), Some(EngineChoice::Newton)) = (contact, self.engine) {
            return Err(UsageError(format!(
                "--engine newton: the Newton reference solves a substep without contact, and {} \
                 is a family on contacts: run it on the reference or the fast engine",
                families.name(family)
            )));
        }
        if let Some(engine) = self.engine {
            available(engine)?;
        }
        Ok((settings, families))
    }

    /// The threads the fast engine runs on: `--threads`, or every core the machine has.
    pub fn threads(&self) -> usize {
        self.threads.map_or_else(
            || std::thread::available_parallelism().map_or(1, |n| n.get()),
            |t| t as usize,
        )
    }

    /// "fast (f32, 2 threads), xpbd, edges+volume, 100 substeps × 1 iteration, dt 0.016667 s,
    /// gravity 9.81" and any non-default compliance or stiffness, for `simulation`, built from
    /// the settings [`SolverArgs::settings`] gave.
    pub fn describe(&self, simulation: &Simulation) -> String {
        let s = simulation.settings();
        let families = simulation.families();
        let mut text = format!(
            "engine {}, {}, {}, {} substeps x {} iteration{}, dt {:.6} s, gravity {}",
            simulation.describe_engine(),
            s.method.name(),
            families.describe(simulation.active()),
            s.substeps,
            s.iterations,
            if s.iterations == 1 { "" } else { "s" },
            s.dt,
            s.gravity.show()
        );
        for NamedValue { name, value } in &self.families.compliance {
            text += &format!(", compliance {name}={value}");
        }
        for NamedValue { name, value } in &self.stiffness {
            text += &format!(", stiffness {name}={value}");
        }
        let uses_material = simulation.resolved().material_family().is_some();
        if uses_material || self.families.material.is_some() {
            text += &format!(", material {}", s.material.describe());
        }
        text += &describe_order(s);
        if s.reach != Settings::default().reach {
            text += &format!(", reach {} rest edges", s.reach.show());
        }
        let active = simulation.active();
        if tetlab_core::simulation::contact::contact_families(families, active)
            .next()
            .is_some()
        {
            let c = s.contact;
            text += &format!(
                ", contact thickness {} m, friction {}/{}",
                c.thickness.show(),
                c.static_friction.show(),
                c.kinetic_friction.show()
            );
        }
        for family in simulation.active().families() {
            if let Some(file) = families.file(family) {
                let gradient = if file.use_gradient {
                    "its own gradient"
                } else {
                    "the AD gradient"
                };
                text += &format!(
                    ", {} from {} with {gradient}",
                    families.name(family),
                    file.path.display()
                );
                // Which particles a `where` chose on this mesh: none is said, not left silent.
                if families.binding(family) == tetlab_core::constraints::Binding::Particles {
                    text += &format!(
                        " on {} of {} particles",
                        simulation.constraint_count(family),
                        simulation.positions().len()
                    );
                }
            }
        }
        text
    }
}

impl SimulationArgs {
    /// The solver settings these options ask for ([`SolverArgs::settings`]).
    pub fn settings(&self) -> Result<(Settings, Families), UsageError> {
        let (settings, families) = self.solver.settings()?;
        let settings = Settings {
            settle_edits: !self.no_settle_edits,
            ..settings
        };
        Ok((settings, families))
    }

    /// Advances one frame and measures it; an error when the simulation diverged
    /// ([`Metrics::measure_sound`]), so that nothing that is not a number is reported.
    pub fn step(simulation: &mut Simulation) -> Result<Metrics, UsageError> {
        simulation.step();
        Metrics::measure_sound(simulation).map_err(|d| UsageError(d.to_string()))
    }

    /// Loads the scene, builds the simulation and applies the perturbation.
    pub fn build(&self) -> Result<(Scene, Simulation), UsageError> {
        let (settings, families) = self.settings()?;
        let scene = Scene::from_spec(&self.scene, self.resolution)
            .map_err(|e| UsageError(format!("--scene: {e}")))?;
        let mut simulation = Simulation::with_families(&scene, settings, families);
        simulation.set_threads(self.solver.threads());
        warn_if_unstable(&simulation);
        if let Some(perturbation) = self.perturb {
            simulation.perturb(perturbation);
        }
        Ok((scene, simulation))
    }

    /// What [`SolverArgs::describe`] says of `simulation`'s settings, and whether edits settle.
    pub fn describe(&self, simulation: &Simulation) -> String {
        self.solver.describe(simulation) + &describe_settling(simulation.resolved())
    }
}

/// ", order seed S" or ", the mesh's order": the order the constraints are projected in.
pub fn describe_order(settings: &Settings) -> String {
    match settings.order_seed {
        Some(seed) => format!(", order seed {seed}"),
        None => ", the mesh's order".to_owned(),
    }
}

/// ", edits settle" or ", edits do not settle (--no-settle-edits)" ([`Resolved::edits_settle`]).
pub fn describe_settling(resolved: &Resolved) -> String {
    if resolved.edits_settle() {
        ", edits settle".to_owned()
    } else {
        ", edits do not settle (--no-settle-edits)".to_owned()
    }
}

/// One line per family with projections skipped so far (∇C undefined, or a step beyond the
/// reach): "skipped projections of dihedral-cosine: 1204 with a step beyond 100 rest edges of
/// their element, 12 with ∇C undefined". None when nothing was skipped.
pub fn describe_skipped(simulation: &Simulation) -> Vec<String> {
    let families = simulation.families();
    families
        .values(simulation.skipped())
        .filter(|(_, counts)| !counts.is_zero())
        .map(|(family, counts)| {
            format!(
                "skipped projections of {}: {} with a step beyond {} rest edges of their \
                 element, {} with ∇C undefined",
                families.name(family),
                counts.too_long,
                simulation.settings().reach.show(),
                counts.degenerate
            )
        })
        .collect()
}

/// Loads the constraint file of `--constraint-file PATH` and adds its families (one per
/// constraint) to a table with `add` ([`Families::register_all`], or [`Families::define_all`]
/// to replace families of the same names).
pub fn load_constraint_file(
    path: &std::path::Path,
    add: impl FnOnce(Vec<ConstraintFile>) -> Result<Vec<Family>, String>,
) -> Result<Vec<Family>, UsageError> {
    let files =
        ConstraintFile::load_all(path).map_err(|e| UsageError(format!("--constraint-file {e}")))?;
    add(files).map_err(|e| UsageError(format!("--constraint-file {}: {e}", path.display())))
}

/// Prints [`Simulation::stability_warning`] on stderr, if there is one.
pub fn warn_if_unstable(simulation: &Simulation) {
    if let Some(warning) = simulation.stability_warning() {
        eprintln!("warning: {warning}");
    }
}
