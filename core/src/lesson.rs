//! Lessons: a scene, solver settings and a sequence of steps, written as TOML files so that a
//! teacher can make one without Rust. Each step has text, the actions that show its point, how
//! many frames to run after them, and the observations it expects, which are checked against the
//! metrics (live in the workbench, at the end of the step when run headless).
//!
//! ```toml
//! title = "Why edges alone cannot un-invert a tet"
//! scene = "tet"              # a built-in (tet, cube, beam, ball) or a mesh path, relative to the file
//! resolution = 1             # optional, for built-ins
//! tet = 0                    # optional: the tet whose arrows are shown
//!
//! [settings]                 # optional; the names of the command line
//! constraints = "edges"      # engine = "reference" if the lesson needs the f64 solver
//! gravity = 0
//!
//! [[step]]
//! text = "Mirror the tet: every edge keeps its length."
//! actions = ["mirror"]
//! frames = 60
//! expect = ["inverted_tets == 1", "max_edge_strain < 1e-6"]
//! ```
//!
//! A lesson may bring constraint files (`constraint_files = ["../constraints/height.toml"]`,
//! relative to the lesson): their families join the table when it is read, and its settings and
//! steps name them like the built-in ones; `gradient_error.NAME` measures how far such a file's
//! gradient is from automatic differentiation ([`GRADIENT_ERROR`]).
//!
//! Actions: `reset`, `invert` (the lesson's tet, through its first corner), `invert:K`, `mirror`,
//! `flatten`, `scramble:SEED`, `select:K`, `constraints:LIST`, `solver:xpbd|pbd`,
//! `compliance:FAMILY=α`, `stiffness:FAMILY=k`, `substeps:N`, `iterations:N`, `gravity:G`,
//! `compare:LIST` (show a second simulation of the same scene with other constraint families
//! beside the first) and `compare:off`. Expectations: `METRIC OP NUMBER` with a metric of
//! [`Metrics::headline`] (`compare.METRIC` for the comparison's) and OP one of `==`, `!=`, `<`,
//! `<=`, `>`, `>=`.

use crate::constraint_file::ConstraintFile;
use crate::constraints::{Family, PerFamily};
use crate::divergence::Divergence;
use crate::limits::{self, Bounds};
use crate::material::Material;
use crate::metrics::Metrics;
use crate::scene::{Perturbation, Scene, SceneError, reflect_through_opposite_face};
use crate::solver::{Engine, Method, Settings, Simulation};
use std::collections::BTreeMap;
use std::fmt;
use std::ops::ControlFlow;
use std::path::{Path, PathBuf};
use toml::Spanned;

/// A lesson, parsed and checked.
#[derive(Clone, Debug, PartialEq)]
pub struct Lesson {
    /// Its title.
    pub title: String,
    /// The file it came from (or the name it was given).
    pub source: PathBuf,
    /// The scene: a built-in name or a mesh path (already resolved against the lesson's folder).
    pub scene: String,
    /// The resolution of a built-in scene.
    pub resolution: u32,
    /// The families of the constraint files the lesson names (`constraint_files`), defined in
    /// the table when the lesson was read ([`Family::define`]).
    pub families: Vec<Family>,
    /// The tet whose arrows are shown at the start.
    pub tet: usize,
    /// The solver settings at the start.
    pub settings: Settings,
    /// The steps, in order.
    pub steps: Vec<Step>,
    /// The scene as it was built when the lesson was read ([`Lesson::scene`] gives it again).
    built: Scene,
}

/// One step of a lesson.
#[derive(Clone, Debug, PartialEq)]
pub struct Step {
    /// What the step explains and asks the reader to try.
    pub text: String,
    /// What the step does when run ("Do it" in the workbench, always when headless).
    pub actions: Vec<Action>,
    /// Frames to run after the actions.
    pub frames: u64,
    /// What should be observed after the actions and frames.
    pub expect: Vec<Expectation>,
}

/// Something a lesson step does.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Action {
    /// Back to the rest shape.
    Reset,
    /// A perturbation of the whole body (mirror, flatten, scramble) or of tet 0 (invert).
    Perturb(Perturbation),
    /// Invert tet K by reflecting its first corner through the opposite face.
    InvertTet(usize),
    /// Select tet K (its arrows are shown).
    Select(usize),
    /// Set the active constraint families.
    Constraints(PerFamily<bool>),
    /// XPBD or PBD.
    Solver(Method),
    /// XPBD compliance of a family.
    Compliance(Family, f64),
    /// PBD stiffness of a family.
    Stiffness(Family, f64),
    /// Substeps per frame.
    Substeps(u32),
    /// Iterations per substep.
    Iterations(u32),
    /// Gravity (0 also turns the ground off).
    Gravity(f64),
    /// Show a second simulation beside the first with these constraint families (`None`: stop).
    Compare(Option<PerFamily<bool>>),
}

/// A relation a step expects between a metric and a number.
#[derive(Clone, Debug, PartialEq)]
pub struct Expectation {
    /// Whether the metric is the comparison simulation's (written `compare.METRIC`).
    pub of_comparison: bool,
    /// The metric's name, one of [`Metrics::headline`], or [`GRADIENT_ERROR`].
    pub metric: String,
    /// For [`GRADIENT_ERROR`]: the family (of a constraint file) whose gradient it is about.
    pub gradient_of: Option<Family>,
    /// The comparison.
    pub op: Op,
    /// The number compared with.
    pub value: f64,
}

/// A comparison.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Op {
    /// ==
    Equal,
    /// !=
    NotEqual,
    /// <
    Less,
    /// <=
    LessOrEqual,
    /// >
    Greater,
    /// >=
    GreaterOrEqual,
}

impl Op {
    const ALL: [(&'static str, Op); 6] = [
        ("==", Op::Equal),
        ("!=", Op::NotEqual),
        ("<=", Op::LessOrEqual),
        (">=", Op::GreaterOrEqual),
        ("<", Op::Less),
        (">", Op::Greater),
    ];

    fn symbol(self) -> &'static str {
        Op::ALL
            .iter()
            .find(|(_, op)| *op == self)
            .map(|(s, _)| *s)
            .expect("every op has a symbol")
    }

    /// Whether `a OP b`.
    pub fn holds(self, a: f64, b: f64) -> bool {
        match self {
            Op::Equal => a == b,
            Op::NotEqual => a != b,
            Op::Less => a < b,
            Op::LessOrEqual => a <= b,
            Op::Greater => a > b,
            Op::GreaterOrEqual => a >= b,
        }
    }
}

/// The measure of how far a constraint file's gradient is from automatic differentiation, as a
/// lesson expects it: `gradient_error.NAME < 1e-6`, NAME a family read from a constraint file
/// ([`crate::constraint_file::grade::Grade::error`]: the largest relative error over random
/// configurations; infinite when the file leaves a particle's gradient out).
pub const GRADIENT_ERROR: &str = "gradient_error";

impl Expectation {
    /// The metric's current value, and whether the expectation holds for it (never for a value
    /// that is not finite); `None` when it is about the comparison and there is none.
    pub fn check(&self, metrics: &Metrics, comparison: Option<&Metrics>) -> Option<(f64, bool)> {
        if let Some(family) = self.gradient_of {
            let value = gradient_error(family);
            return Some((value, value.is_finite() && self.op.holds(value, self.value)));
        }
        let metrics = if self.of_comparison {
            comparison?
        } else {
            metrics
        };
        let value = metrics
            .headline()
            .into_iter()
            .find(|(name, _)| *name == self.metric)
            .map(|(_, v)| v)
            .expect("the metric name was checked when the lesson was read");
        Some((value, value.is_finite() && self.op.holds(value, self.value)))
    }

    fn parse(text: &str) -> Result<Expectation, String> {
        let (symbol, op, at) = Op::ALL
            .iter()
            .find_map(|&(symbol, op)| text.find(symbol).map(|at| (symbol, op, at)))
            .ok_or_else(|| format!("'{text}' is not METRIC OP NUMBER (e.g. inverted_tets == 0)"))?;
        let metric = text[..at].trim();
        let number = text[at + symbol.len()..].trim();
        let value = finite(number)?;
        if let Some(name) = metric
            .strip_prefix(GRADIENT_ERROR)
            .and_then(|m| m.strip_prefix('.'))
        {
            let family = Family::parse(name)?;
            if family.file().is_none() {
                return Err(format!(
                    "{GRADIENT_ERROR}.{name}: {name} is a built-in family; {GRADIENT_ERROR} is about \
                     the gradient a constraint file gives (name one in constraint_files)"
                ));
            }
            return Ok(Expectation {
                of_comparison: false,
                metric: GRADIENT_ERROR.to_owned(),
                gradient_of: Some(family),
                op,
                value,
            });
        }
        let (of_comparison, metric) = match metric.strip_prefix("compare.") {
            Some(metric) => (true, metric),
            None => (false, metric),
        };
        let names = Metrics::default().headline().map(|(name, _)| name);
        if !names.contains(&metric) {
            return Err(format!(
                "'{metric}' is not a metric: expected one of {}, or {GRADIENT_ERROR}.FAMILY",
                names.join(", ")
            ));
        }
        Ok(Expectation {
            of_comparison,
            metric: metric.to_owned(),
            gradient_of: None,
            op,
            value,
        })
    }
}

/// The error of `family`'s gradient against AD as its grade gives it
/// ([`crate::constraint_file::grade::Grade::error`], worked out once per definition of the
/// family); infinite for a family without a file.
fn gradient_error(family: Family) -> f64 {
    crate::constraint_file::grade::of_family(family).map_or(f64::INFINITY, |g| g.error())
}

impl fmt::Display for Expectation {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let prefix = match self.gradient_of {
            Some(family) => format!("{GRADIENT_ERROR}.{}", family.name()),
            None if self.of_comparison => format!("compare.{}", self.metric),
            None => self.metric.clone(),
        };
        let v = self.value;
        let number = if v != 0.0 && (v.abs() < 1e-3 || v.abs() >= 1e6) {
            format!("{v:e}")
        } else {
            v.to_string()
        };
        write!(f, "{prefix} {} {number}", self.op.symbol())
    }
}

impl Action {
    fn parse(text: &str) -> Result<Action, String> {
        let (name, argument) = match text.split_once(':') {
            Some((name, argument)) => (name.trim(), Some(argument.trim())),
            None => (text.trim(), None),
        };
        let need =
            |what: &str| argument.ok_or_else(|| format!("'{text}' needs a value: {name}:{what}"));
        let whole = |what: &str| -> Result<u64, String> {
            let argument = need(what)?;
            argument
                .parse()
                .map_err(|_| format!("'{argument}' is not a whole number in '{text}'"))
        };
        let family_value = |what: &str, bounds: &Bounds<f64>| -> Result<(Family, f64), String> {
            let argument = need(what)?;
            limits::family_value(argument, bounds).map_err(|e| format!("{e} in '{text}'"))
        };
        let setting = |what: &str, bounds: &Bounds<u32>| -> Result<u32, String> {
            bounds
                .parse(need(what)?)
                .map_err(|e| format!("{e} in '{text}'"))
        };
        let action = match name {
            "reset" => match argument {
                None => Action::Reset,
                Some(_) => return Err(format!("'{text}': reset takes no value")),
            },
            "invert" => match argument {
                None => Action::Perturb(Perturbation::Invert),
                Some(_) => Action::InvertTet(whole("K")? as usize),
            },
            "mirror" | "flatten" | "scramble" => Action::Perturb(Perturbation::parse(text.trim())?),
            "select" => Action::Select(whole("K")? as usize),
            "constraints" => Action::Constraints(PerFamily::parse_list(need("LIST")?)?),
            "solver" => Action::Solver(Method::parse(need("xpbd|pbd")?)?),
            "compliance" => {
                let (family, alpha) = family_value("FAMILY=α", &limits::COMPLIANCE)?;
                Action::Compliance(family, alpha)
            }
            "stiffness" => {
                let (family, k) = family_value("FAMILY=k", &limits::STIFFNESS)?;
                Action::Stiffness(family, k)
            }
            "substeps" => Action::Substeps(setting("N", &limits::SUBSTEPS)?),
            "iterations" => Action::Iterations(setting("N", &limits::ITERATIONS)?),
            "gravity" => Action::Gravity(
                limits::GRAVITY
                    .parse(need("G")?)
                    .map_err(|e| format!("{e} in '{text}'"))?,
            ),
            "compare" => match need("LIST|off")? {
                "off" => Action::Compare(None),
                list => Action::Compare(Some(PerFamily::parse_list(list)?)),
            },
            _ => {
                return Err(format!(
                    "'{text}' is not an action: expected reset, invert, invert:K, mirror, \
                     flatten, scramble:SEED, select:K, constraints:LIST, solver:NAME, \
                     compliance:FAMILY=α, stiffness:FAMILY=k, substeps:N, iterations:N, \
                     gravity:G or compare:LIST|off"
                ));
            }
        };
        Ok(action)
    }

    /// Applies the action to `simulation`. [`Action::Select`] sets `selected_tet`;
    /// [`Action::Compare`] is for the front end and changes nothing here.
    pub fn apply(self, simulation: &mut Simulation, selected_tet: &mut usize) {
        let mut settings = *simulation.settings();
        match self {
            Action::Reset => simulation.reset(),
            Action::Perturb(perturbation) => simulation.perturb(perturbation),
            Action::InvertTet(tet) => {
                let corners = simulation.tets()[tet];
                let mut positions = simulation.positions().to_vec();
                reflect_through_opposite_face(&mut positions, &corners, 0);
                simulation.place(corners[0] as usize, positions[corners[0] as usize]);
            }
            Action::Select(tet) => *selected_tet = tet,
            Action::Constraints(active) => settings.active = active,
            Action::Solver(method) => settings.method = method,
            Action::Compliance(family, alpha) => settings.compliance.set(family, alpha),
            Action::Stiffness(family, k) => settings.stiffness.set(family, k),
            Action::Substeps(n) => settings.substeps = n,
            Action::Iterations(n) => settings.iterations = n,
            Action::Gravity(g) => settings.set_gravity(g),
            Action::Compare(_) => {}
        }
        simulation.set_settings(settings);
    }

    /// Whether a comparison shown beside the lesson's simulation gets this action too: every
    /// action but [`Action::Constraints`] (each side keeps its own families) and
    /// [`Action::Compare`] itself.
    pub fn applies_to_comparison(self) -> bool {
        !matches!(self, Action::Constraints(_) | Action::Compare(_))
    }

    /// The tet this action refers to, if any (to check it against the scene).
    fn tet(self) -> Option<usize> {
        match self {
            Action::InvertTet(tet) | Action::Select(tet) => Some(tet),
            _ => None,
        }
    }
}

/// Why a lesson could not be read: the file, the line, and what is wrong there.
#[derive(Clone, Debug, PartialEq)]
pub struct LessonError {
    /// The lesson file.
    pub path: PathBuf,
    /// The line (from 1), when the problem has one.
    pub line: Option<usize>,
    /// What is wrong.
    pub message: String,
}

impl fmt::Display for LessonError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self.line {
            Some(line) => write!(f, "{}:{line}: {}", self.path.display(), self.message),
            None => write!(f, "{}: {}", self.path.display(), self.message),
        }
    }
}

impl std::error::Error for LessonError {}

/// The file as written.
#[derive(serde::Deserialize)]
#[serde(deny_unknown_fields)]
struct RawLesson {
    title: String,
    scene: Spanned<String>,
    resolution: Option<Spanned<u32>>,
    tet: Option<Spanned<usize>>,
    #[serde(default)]
    constraint_files: Vec<Spanned<String>>,
    #[serde(default)]
    settings: RawSettings,
    #[serde(default)]
    step: Vec<RawStep>,
}

#[derive(serde::Deserialize, Default)]
#[serde(deny_unknown_fields)]
struct RawSettings {
    constraints: Option<Spanned<String>>,
    solver: Option<Spanned<String>>,
    engine: Option<Spanned<String>>,
    substeps: Option<Spanned<u32>>,
    iterations: Option<Spanned<u32>>,
    dt: Option<Spanned<f64>>,
    gravity: Option<Spanned<f64>>,
    damping: Option<Spanned<f64>>,
    settle_edits: Option<bool>,
    material: Option<Spanned<String>>,
    #[serde(default)]
    compliance: BTreeMap<String, Spanned<f64>>,
    #[serde(default)]
    stiffness: BTreeMap<String, Spanned<f64>>,
}

#[derive(serde::Deserialize)]
#[serde(deny_unknown_fields)]
struct RawStep {
    text: String,
    #[serde(default)]
    actions: Vec<Spanned<String>>,
    frames: Option<Spanned<u64>>,
    #[serde(default)]
    expect: Vec<Spanned<String>>,
}

/// A lesson that comes with tetlab: a file of `assets/lessons`, built into the library.
#[derive(Clone, Copy, Debug)]
pub struct BuiltinLesson {
    /// Its file name, e.g. `01-distance.toml`.
    pub file: &'static str,
    /// Where the file was when tetlab was built (mesh scenes are found relative to it).
    pub path: &'static str,
    /// The file's text.
    pub text: &'static str,
}

include!(concat!(env!("OUT_DIR"), "/lessons.rs"));

/// What a lesson file says about itself before its scene is built: its title and its scene, so
/// that a lesson can be listed (and its missing mesh named) even when it cannot be opened.
#[derive(Clone, Debug, PartialEq)]
pub struct LessonHeader {
    /// Its title.
    pub title: String,
    /// Its scene: a built-in name, or a mesh path resolved against the lesson's folder.
    pub scene: String,
}

/// The two fields [`LessonHeader`] reads; the rest of the file is left to [`Lesson::parse`].
#[derive(serde::Deserialize)]
struct RawHeader {
    title: String,
    scene: String,
}

impl LessonHeader {
    /// The title and scene of lesson `text` from `path`.
    pub fn parse(path: &Path, text: &str) -> Result<LessonHeader, LessonError> {
        let text = crate::text_file::without_byte_order_mark(text);
        let raw: RawHeader = toml::from_str(text).map_err(|e| LessonError {
            path: path.to_owned(),
            line: e.span().map(|s| line_of(text, s.start)),
            message: e.message().trim().to_owned(),
        })?;
        Ok(LessonHeader {
            title: raw.title,
            scene: resolve_scene(path, &raw.scene),
        })
    }

    /// The mesh file the lesson needs, when it needs one that is not there.
    pub fn missing_mesh(&self) -> Option<&str> {
        let builtin = crate::scene::Builtin::from_name(&self.scene).is_some();
        let here = crate::text_file::available(Path::new(&self.scene));
        (!builtin && !here).then_some(self.scene.as_str())
    }
}

impl BuiltinLesson {
    /// Its title and scene ([`LessonHeader::parse`]).
    pub fn header(&self) -> Result<LessonHeader, LessonError> {
        LessonHeader::parse(Path::new(self.path), self.text)
    }
}

/// The most frames one step may run.
pub const MAX_STEP_FRAMES: u64 = 100_000;

impl Lesson {
    /// Built-in lesson `number` (from 1), or a lesson file: what `tetlab lesson N|FILE` reads.
    pub fn find(spec: &str) -> Result<Lesson, LessonError> {
        match spec.parse::<usize>() {
            Ok(number) => Lesson::builtin(number),
            Err(_) => Lesson::load(Path::new(spec)),
        }
    }

    /// Built-in lesson `number`, from 1 ([`BUILTIN`]).
    pub fn builtin(number: usize) -> Result<Lesson, LessonError> {
        let builtin = number
            .checked_sub(1)
            .and_then(|k| BUILTIN.get(k))
            .ok_or_else(|| LessonError {
                path: PathBuf::from(format!("lesson {number}")),
                line: None,
                message: format!(
                    "no such lesson: the built-in lessons are 1..={}",
                    BUILTIN.len()
                ),
            })?;
        Lesson::parse(Path::new(builtin.path), builtin.text)
    }

    /// Reads a lesson file; a mesh scene path is taken relative to the file's folder.
    pub fn load(path: &Path) -> Result<Lesson, LessonError> {
        let text = crate::text_file::read(path).map_err(|e| LessonError {
            path: path.to_owned(),
            line: e.line,
            message: e.message,
        })?;
        Lesson::parse(path, &text)
    }

    /// Parses lesson `text` that came from `path` (used for messages and relative scene paths).
    pub fn parse(path: &Path, text: &str) -> Result<Lesson, LessonError> {
        Lesson::parse_with(path, text, &Scene::from_spec)
    }

    /// [`Lesson::parse`], with the lesson's scene made by `make_scene` from its name (resolved
    /// against the lesson's folder) and resolution instead of [`Scene::from_spec`]: a fuzzer
    /// gives one that builds only small scenes.
    pub fn parse_with(
        path: &Path,
        text: &str,
        make_scene: &dyn Fn(&str, u32) -> Result<Scene, SceneError>,
    ) -> Result<Lesson, LessonError> {
        let text = crate::text_file::without_byte_order_mark(text);
        let error = |span: Option<std::ops::Range<usize>>, message: String| LessonError {
            path: path.to_owned(),
            line: span.map(|s| line_of(text, s.start)),
            message,
        };
        let raw: RawLesson =
            toml::from_str(text).map_err(|e| error(e.span(), e.message().trim().to_owned()))?;
        let at = |span: std::ops::Range<usize>| move |message: String| error(Some(span), message);

        // The constraint files first: the settings and steps may name their families.
        let mut families = Vec::new();
        for file in &raw.constraint_files {
            let resolved = resolve_path(path, file.get_ref());
            let family = ConstraintFile::load(Path::new(&resolved))
                .map_err(|e| e.to_string())
                .and_then(Family::define)
                .map_err(|e| error(Some(file.span()), format!("constraint file: {e}")))?;
            families.push(family);
        }
        let mut settings = Settings::default();
        let s = &raw.settings;
        if let Some(list) = &s.constraints {
            settings.active = PerFamily::parse_list(list.get_ref()).map_err(at(list.span()))?;
        }
        if let Some(solver) = &s.solver {
            settings.method = Method::parse(solver.get_ref()).map_err(at(solver.span()))?;
        }
        if let Some(engine) = &s.engine {
            settings.engine = Engine::parse(engine.get_ref()).map_err(at(engine.span()))?;
        }
        // Each setting checked against its range; a failure names the file and line of the value.
        fn checked<T: limits::Number>(
            bounds: &Bounds<T>,
            value: &Option<Spanned<T>>,
            error: impl Fn(Option<std::ops::Range<usize>>, String) -> LessonError,
        ) -> Result<Option<T>, LessonError> {
            value
                .as_ref()
                .map(|v| {
                    bounds
                        .check(*v.get_ref())
                        .map_err(|e| error(Some(v.span()), format!("in [settings]: {e}")))
                })
                .transpose()
        }
        if let Some(n) = checked(&limits::SUBSTEPS, &s.substeps, error)? {
            settings.substeps = n;
        }
        if let Some(n) = checked(&limits::ITERATIONS, &s.iterations, error)? {
            settings.iterations = n;
        }
        if let Some(dt) = checked(&limits::DT, &s.dt, error)? {
            settings.dt = dt;
        }
        if let Some(g) = checked(&limits::GRAVITY, &s.gravity, error)? {
            settings.set_gravity(g);
        }
        if let Some(d) = checked(&limits::DAMPING, &s.damping, error)? {
            settings.damping = d;
        }
        // Edits settle unless the lesson says otherwise, as in the workbench and `tetlab run`.
        settings.settle_edits = s.settle_edits.unwrap_or(true);
        if let Some(material) = &s.material {
            let material = Material::parse(material.get_ref()).map_err(|e| {
                error(
                    Some(material.span()),
                    format!("in [settings] material: {e}"),
                )
            })?;
            settings.set_material(material);
        }
        for (table, bounds, values, per_family) in [
            (
                "compliance",
                &limits::COMPLIANCE,
                &s.compliance,
                &mut settings.compliance,
            ),
            (
                "stiffness",
                &limits::STIFFNESS,
                &s.stiffness,
                &mut settings.stiffness,
            ),
        ] {
            for (name, value) in values {
                let family = limits::settable_family(name).map_err(at(value.span()))?;
                let v = bounds.check(*value.get_ref()).map_err(|e| {
                    error(
                        Some(value.span()),
                        format!("in [settings] {table}.{name}: {e}"),
                    )
                })?;
                per_family.set(family, v);
            }
        }

        let resolution = raw.resolution.as_ref().map_or(1, |r| *r.get_ref());
        let scene = resolve_scene(path, raw.scene.get_ref());
        let mesh = make_scene(&scene, resolution).map_err(|e| {
            // A resolution out of range is the resolution's mistake, anything else the scene's.
            let span = match (&e, &raw.resolution) {
                (SceneError::Resolution(_) | SceneError::TooLarge { .. }, Some(r)) => r.span(),
                _ => raw.scene.span(),
            };
            error(Some(span), format!("scene '{}': {e}", raw.scene.get_ref()))
        })?;
        let tets = mesh.mesh.tets.len();
        let check_tet = |tet: usize, span| {
            if tet < tets {
                Ok(())
            } else {
                Err(error(
                    Some(span),
                    format!(
                        "tet {tet} is out of range: the scene has tets 0..={}",
                        tets - 1
                    ),
                ))
            }
        };
        let tet = match &raw.tet {
            Some(tet) => {
                check_tet(*tet.get_ref(), tet.span())?;
                *tet.get_ref()
            }
            None => 0,
        };

        if raw.step.is_empty() {
            return Err(error(None, "a lesson needs at least one [[step]]".into()));
        }
        let mut steps = Vec::new();
        for step in &raw.step {
            let mut actions = Vec::new();
            for action in &step.actions {
                let parsed = Action::parse(action.get_ref()).map_err(at(action.span()))?;
                if let Some(tet) = parsed.tet() {
                    check_tet(tet, action.span())?;
                }
                actions.push(parsed);
            }
            let frames = step.frames.as_ref().map_or(0, |f| *f.get_ref());
            if frames > MAX_STEP_FRAMES {
                return Err(error(
                    step.frames.as_ref().map(|f| f.span()),
                    format!("frames = {frames} is more than {MAX_STEP_FRAMES}"),
                ));
            }
            let expect = step
                .expect
                .iter()
                .map(|e| Expectation::parse(e.get_ref()).map_err(at(e.span())))
                .collect::<Result<Vec<_>, _>>()?;
            steps.push(Step {
                text: reflow(&step.text),
                actions,
                frames,
                expect,
            });
        }
        Ok(Lesson {
            title: raw.title,
            source: path.to_owned(),
            scene,
            resolution,
            families,
            tet,
            settings,
            steps,
            built: mesh,
        })
    }

    /// The lesson's scene at rest, as it was built when the lesson was read (so a page that
    /// fetched the lesson's mesh builds it once, [`Lesson::parse_with`]).
    pub fn scene(&self) -> Scene {
        self.built.clone()
    }
}

/// A built-in name as it is; a mesh path relative to the lesson's folder.
fn resolve_scene(lesson: &Path, scene: &str) -> String {
    if crate::scene::Builtin::from_name(scene).is_some() {
        return scene.to_owned();
    }
    resolve_path(lesson, scene)
}

/// A path a lesson names, relative to the lesson's folder unless it is absolute.
fn resolve_path(lesson: &Path, path: &str) -> String {
    if Path::new(path).is_absolute() {
        return path.to_owned();
    }
    match lesson.parent() {
        Some(folder) if !folder.as_os_str().is_empty() => {
            folder.join(path).to_string_lossy().into_owned()
        }
        _ => path.to_owned(),
    }
}

/// Paragraphs as written (separated by blank lines), each joined into one line, so that the
/// front end wraps them to its own width.
fn reflow(text: &str) -> String {
    text.trim()
        .split("\n\n")
        .map(|paragraph| paragraph.split_whitespace().collect::<Vec<_>>().join(" "))
        .filter(|paragraph| !paragraph.is_empty())
        .collect::<Vec<_>>()
        .join("\n\n")
}

/// The line (from 1) of byte offset `at`.
fn line_of(text: &str, at: usize) -> usize {
    text[..at.min(text.len())].matches('\n').count() + 1
}

fn finite(text: &str) -> Result<f64, String> {
    let value: f64 = text
        .trim()
        .parse()
        .map_err(|_| format!("'{}' is not a number", text.trim()))?;
    if value.is_finite() {
        Ok(value)
    } else {
        Err(format!("'{}' is not a finite number", text.trim()))
    }
}

/// One step's outcome when a lesson runs headless.
#[derive(Clone, Debug, PartialEq)]
pub struct StepOutcome {
    /// Each expectation with the metric's value at the end of the step (`None`: about a
    /// comparison that is not shown) and whether it held.
    pub checks: Vec<(Expectation, Option<f64>, bool)>,
}

impl Step {
    /// The families whose gradient this step expects to agree with automatic differentiation
    /// (`gradient_error.NAME < …`): the step is an exercise about their files.
    pub fn exercises(&self) -> impl Iterator<Item = Family> + '_ {
        self.expect.iter().filter_map(|e| {
            e.gradient_of
                .filter(|_| matches!(e.op, Op::Less | Op::LessOrEqual))
        })
    }
}

/// A lesson running headless: the simulation, the selected tet, and the comparison simulation
/// when a step asked for one.
pub struct LessonRun {
    /// The lesson's simulation.
    pub simulation: Simulation,
    /// The second simulation, with other constraint families, while a step compares.
    pub comparison: Option<Simulation>,
    /// The selected tet.
    pub tet: usize,
    scene: Scene,
    /// The metrics of both simulations, as last measured by [`LessonRun::measure`].
    metrics: (Metrics, Option<Metrics>),
    /// Answers handed in ([`LessonRun::hand_in`]) not yet taken up.
    answers: Vec<ConstraintFile>,
}

impl LessonRun {
    /// The lesson's scene at rest with its settings.
    pub fn new(lesson: &Lesson) -> LessonRun {
        let scene = lesson.scene();
        let simulation = Simulation::new(&scene, lesson.settings);
        LessonRun {
            metrics: (Metrics::measure(&simulation), None),
            simulation,
            comparison: None,
            tet: lesson.tet,
            scene,
            answers: Vec::new(),
        }
    }

    /// A student's answer to an exercise of the lesson: a constraint file with the name of one
    /// the lesson brings. It replaces that file's family from the first step that expects its
    /// gradient to agree ([`Step::exercises`]), as the student's edits in the workbench would:
    /// the steps before it still show the lesson's own file.
    ///
    /// An error when no step of `lesson` is an exercise about a family of that name.
    pub fn hand_in(&mut self, lesson: &Lesson, answer: ConstraintFile) -> Result<(), String> {
        let asked = lesson
            .steps
            .iter()
            .flat_map(Step::exercises)
            .any(|family| family.name() == answer.name);
        if !asked {
            return Err(format!(
                "{} defines {}, and no step of this lesson is an exercise about {0}",
                answer.path.display(),
                answer.name
            ));
        }
        self.answers.push(answer);
        Ok(())
    }

    /// Applies one action to the simulation and to the comparison.
    pub fn apply(&mut self, action: Action) {
        if let Action::Compare(families) = action {
            self.comparison = families.map(|active| {
                let mut comparison = self.simulation.clone();
                let settings = Settings {
                    active,
                    ..*self.simulation.settings()
                };
                comparison.set_settings(settings);
                comparison
            });
            return;
        }
        let mut ignored = self.tet;
        action.apply(&mut self.simulation, &mut self.tet);
        if let Some(comparison) = &mut self.comparison
            && action.applies_to_comparison()
        {
            action.apply(comparison, &mut ignored);
        }
    }

    /// Advances both simulations one frame.
    pub fn step(&mut self) {
        self.simulation.step();
        if let Some(comparison) = &mut self.comparison {
            comparison.step();
        }
    }

    /// Measures both simulations ([`Metrics::measure_sound`]): an error naming the one that
    /// diverged, if one did.
    pub fn measure(&mut self) -> Result<(), Divergence> {
        let main = Metrics::measure_sound(&self.simulation)?;
        let comparison = match &self.comparison {
            Some(c) => Some(Metrics::measure_sound(c).map_err(|d| d.of("the comparison"))?),
            None => None,
        };
        self.metrics = (main, comparison);
        Ok(())
    }

    /// The metrics of the simulation and of the comparison (if one is shown) at the last
    /// [`LessonRun::measure`]: finite, since it checked them.
    pub fn metrics(&self) -> (&Metrics, Option<&Metrics>) {
        (&self.metrics.0, self.metrics.1.as_ref())
    }

    /// The scene.
    pub fn scene(&self) -> &Scene {
        &self.scene
    }

    /// Runs a whole step: actions, frames (measuring both simulations after each, then calling
    /// `on_frame`, which may stop the step early by returning [`ControlFlow::Break`]), then the
    /// checks. `Ok(None)` when stopped early; an error when a simulation diverged, so that
    /// nothing after it is shown or checked.
    pub fn run_step(
        &mut self,
        step: &Step,
        mut on_frame: impl FnMut(&LessonRun) -> ControlFlow<()>,
    ) -> Result<Option<StepOutcome>, Divergence> {
        let exercises: Vec<Family> = step.exercises().collect();
        let (taken, kept): (Vec<_>, Vec<_>) = std::mem::take(&mut self.answers)
            .into_iter()
            .partition(|a| exercises.iter().any(|f| f.name() == a.name));
        self.answers = kept;
        for answer in taken {
            // Its name is a family's already (hand_in checked): it is redefined in place, which
            // cannot fail.
            let _ = Family::define(answer);
            self.simulation.refresh_families();
            if let Some(comparison) = &mut self.comparison {
                comparison.refresh_families();
            }
        }
        for &action in &step.actions {
            self.apply(action);
        }
        self.measure()?;
        for _ in 0..step.frames {
            self.step();
            self.measure()?;
            if on_frame(self).is_break() {
                return Ok(None);
            }
        }
        Ok(Some(self.check(step)))
    }

    /// The step's expectations against the metrics of the last [`LessonRun::measure`].
    pub fn check(&self, step: &Step) -> StepOutcome {
        let (metrics, comparison) = self.metrics();
        StepOutcome {
            checks: step
                .expect
                .iter()
                .map(|e| match e.check(metrics, comparison) {
                    Some((value, holds)) => (e.clone(), Some(value), holds),
                    None => (e.clone(), None, false),
                })
                .collect(),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn parse(text: &str) -> Result<Lesson, LessonError> {
        Lesson::parse(Path::new("lessons/x.toml"), text)
    }

    #[test]
    fn a_small_lesson_reads_and_runs() {
        let lesson = parse(
            r#"
title = "mirror"
scene = "tet"
[settings]
constraints = "edges"
gravity = 0
[[step]]
text = "mirror it"
actions = ["mirror"]
frames = 30
expect = ["inverted_tets == 1", "max_edge_strain < 1e-9"]
"#,
        )
        .unwrap();
        assert_eq!(
            lesson.settings.active,
            PerFamily::parse_list("edges").unwrap()
        );
        assert!(!lesson.settings.ground);
        let mut run = LessonRun::new(&lesson);
        let outcome = run
            .run_step(&lesson.steps[0], |_| ControlFlow::Continue(()))
            .unwrap()
            .unwrap();
        assert!(
            outcome.checks.iter().all(|(_, _, holds)| *holds),
            "{outcome:?}"
        );
        assert_eq!(run.simulation.frame(), 30);
    }

    #[test]
    fn mistakes_name_the_file_and_line() {
        let cases = [
            ("title = 1\nscene = \"tet\"\n", 1, "invalid type"),
            (
                "title = \"t\"\nscene = \"tet\"\n[[step]]\ntext = \"x\"\nactions = [\"mirror\", \"twirl\"]\n",
                5,
                "'twirl' is not an action",
            ),
            (
                "title = \"t\"\nscene = \"tet\"\n[[step]]\ntext = \"x\"\n\nexpect = [\"speed > 1\"]\n",
                6,
                "'speed' is not a metric",
            ),
            (
                "title = \"t\"\nscene = \"nowhere.node\"\n[[step]]\ntext = \"x\"\n",
                2,
                "scene 'nowhere.node'",
            ),
            (
                "title = \"t\"\nscene = \"tet\"\n[settings]\nconstraints = \"edges,glue\"\n[[step]]\ntext = \"x\"\n",
                4,
                "'glue' is not a constraint family",
            ),
            (
                "title = \"t\"\nscene = \"tet\"\n[[step]]\ntext = \"x\"\nactions = [\"select:4\"]\n",
                5,
                "tet 4 is out of range",
            ),
            (
                "title = \"t\"\nscene = \"tet\"\ncolour = \"red\"\n",
                3,
                "unknown field",
            ),
            (
                "title = \"t\"\nscene = \"tet\"\n",
                0,
                "at least one [[step]]",
            ),
            (
                "title = \"t\"\nscene = \"tet\"\n[settings]\ndt = nan\n[[step]]\ntext = \"x\"\n",
                4,
                "in [settings]: dt NaN is not a number",
            ),
            (
                "title = \"t\"\nscene = \"tet\"\n[settings]\n\nsubsteps = 0\n[[step]]\ntext = \"x\"\n",
                5,
                "in [settings]: substeps 0 is out of range: expected 1 <= substeps <= 1000",
            ),
            (
                "title = \"t\"\nscene = \"tet\"\n[settings]\ncompliance = { volume = inf }\n[[step]]\ntext = \"x\"\n",
                4,
                "compliance.volume: compliance inf is out of range",
            ),
            (
                "title = \"t\"\nscene = \"tet\"\n[settings]\ncompliance = { edges = nan }\n[[step]]\ntext = \"x\"\n",
                4,
                "compliance.edges: compliance NaN is not a number",
            ),
            (
                "title = \"t\"\nscene = \"tet\"\n[[step]]\ntext = \"x\"\nactions = [\"reset:whatever\"]\n",
                5,
                "'reset:whatever': reset takes no value",
            ),
            (
                "title = \"t\"\nscene = \"tet\"\n[[step]]\ntext = \"x\"\nactions = [\"compliance:edges=1e303\"]\n",
                5,
                "compliance 1e303 is out of range",
            ),
            (
                "title = \"t\"\nscene = \"ball\"\nresolution = 128\n[[step]]\ntext = \"x\"\n",
                3,
                "ball at resolution 128 would have 100663296 tets",
            ),
            (
                "\u{feff}title = \"t\"\nscene = \"tet\"\ncolour = 1\n",
                3,
                "unknown field `colour`",
            ),
        ];
        for (text, line, message) in cases {
            let error = parse(text).unwrap_err();
            assert_eq!(error.line.unwrap_or(0), line, "{error}");
            assert!(error.to_string().contains(message), "{error}");
            assert!(error.to_string().starts_with("lessons/x.toml:"), "{error}");
        }
    }

    #[test]
    fn a_lesson_file_that_is_not_text_names_the_line() {
        let path = std::env::temp_dir().join(format!("tetlab-lesson-{}.toml", std::process::id()));
        std::fs::write(&path, b"title = \"t\"\nscene = \"tet\xff\"\n").unwrap();
        let error = Lesson::load(&path).unwrap_err();
        std::fs::remove_file(&path).ok();
        assert_eq!(error.line, Some(2), "{error}");
        assert!(error.message.contains("not text"), "{error}");
    }

    /// The comparison is checked like the main simulation: when it diverges the step is an
    /// error, never "observed" (a NaN metric holds no expectation either).
    #[test]
    fn a_comparison_that_diverges_stops_the_step() {
        let lesson = parse(
            r#"
title = "t"
scene = "tet"
[settings]
constraints = "edges"
[[step]]
text = "x"
actions = ["compare:edges,volume", "invert"]
frames = 30
expect = ["compare.volume_error < 0.001"]
"#,
        )
        .unwrap();
        let mut run = LessonRun::new(&lesson);
        // What no accepted setting can do: a compliance past the limits, so α / h² is infinite.
        run.apply(Action::Compare(Some(
            PerFamily::parse_list("edges,volume").unwrap(),
        )));
        let comparison = run.comparison.as_mut().unwrap();
        let mut settings = *comparison.settings();
        settings.compliance[Family::VOLUME] = 1e305;
        comparison.set_settings(settings);
        let step = Step {
            actions: vec![Action::Perturb(Perturbation::Invert)],
            ..lesson.steps[0].clone()
        };
        let divergence = run
            .run_step(&step, |_| ControlFlow::Continue(()))
            .unwrap_err();
        assert_eq!(divergence.subject, "the comparison", "{divergence}");
        let nan = Metrics {
            volume_error: f64::NAN,
            ..Metrics::default()
        };
        let expectation = Expectation::parse("volume_error != 0").unwrap();
        assert!(!expectation.check(&nan, None).unwrap().1);
    }

    /// A lesson can be listed, and its missing mesh named, even when it cannot be opened.
    #[test]
    fn a_lesson_whose_mesh_is_missing_still_has_a_title() {
        let text = "title = \"t\"\nscene = \"../nowhere/bunny.node\"\n[[step]]\ntext = \"x\"\n";
        let header = LessonHeader::parse(Path::new("lessons/x.toml"), text).unwrap();
        assert_eq!(header.title, "t");
        assert_eq!(header.missing_mesh(), Some("lessons/../nowhere/bunny.node"));
        assert!(parse(text).unwrap_err().message.contains("bunny.node"));
        let cube = LessonHeader::parse(Path::new("x.toml"), "title = \"c\"\nscene = \"cube\"\n");
        assert_eq!(cube.unwrap().missing_mesh(), None);
    }

    #[test]
    fn paragraphs_are_reflowed_into_lines() {
        assert_eq!(reflow("\n one\ntwo  \n\n\nthree\n"), "one two\n\nthree");
    }

    #[test]
    fn a_mesh_scene_is_found_next_to_the_lesson() {
        assert_eq!(
            resolve_scene(Path::new("assets/lessons/6.toml"), "../meshes/a.node"),
            "assets/lessons/../meshes/a.node"
        );
        assert_eq!(
            resolve_scene(Path::new("assets/lessons/6.toml"), "cube"),
            "cube"
        );
    }

    #[test]
    fn the_comparison_gets_the_same_edits_and_keeps_its_families() {
        let lesson = parse(
            "title = \"t\"\nscene = \"cube\"\n[settings]\nconstraints = \"edges\"\n[[step]]\ntext = \"x\"\n",
        )
        .unwrap();
        let mut run = LessonRun::new(&lesson);
        run.apply(Action::Compare(Some(PerFamily::splat(true))));
        run.apply(Action::Perturb(Perturbation::Mirror));
        run.apply(Action::Substeps(3));
        let comparison = run.comparison.as_ref().unwrap();
        assert_eq!(comparison.positions(), run.simulation.positions());
        assert_eq!(comparison.settings().active, PerFamily::splat(true));
        assert_eq!(comparison.settings().substeps, 3);
        run.apply(Action::Compare(None));
        assert!(run.comparison.is_none());
    }
}
