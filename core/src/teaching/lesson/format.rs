//! The lesson file: its TOML, read and checked into a [`Lesson`], with errors at file:line.

use super::*;

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
        let text = crate::input::text_file::read(path).map_err(|e| LessonError {
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
        let text = crate::input::text_file::without_byte_order_mark(text);
        let error = |span: Option<std::ops::Range<usize>>, message: String| LessonError {
            path: path.to_owned(),
            line: span.map(|s| line_of(text, s.start)),
            message,
        };
        let raw: RawLesson =
            toml::from_str(text).map_err(|e| error(e.span(), e.message().trim().to_owned()))?;
        let at = |span: std::ops::Range<usize>| move |message: String| error(Some(span), message);

        // The constraint files first: the settings and steps may name their families.
        let mut families = Families::builtin();
        let mut file_families = Vec::new();
        for file in &raw.constraint_files {
            let resolved = resolve_path(path, file.get_ref());
            let defined = ConstraintFile::load_all(Path::new(&resolved))
                .map_err(|e| e.to_string())
                .and_then(|files| families.define_all(files))
                .map_err(|e| error(Some(file.span()), format!("constraint file: {e}")))?;
            file_families.extend(defined);
        }
        let mut settings = Settings::default();
        let s = &raw.settings;
        if let Some(list) = &s.constraints {
            settings.active = families
                .parse_list(list.get_ref())
                .map_err(at(list.span()))?;
        }
        if let Some(solver) = &s.solver {
            settings.method = Method::parse(solver.get_ref()).map_err(at(solver.span()))?;
        }
        if let Some(engine) = &s.engine {
            settings.engine = EngineChoice::parse(engine.get_ref()).map_err(at(engine.span()))?;
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
            settings.material = material;
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
                let family = crate::simulation::settable_family(&families, name)
                    .map_err(at(value.span()))?;
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
                let parsed =
                    Action::parse(&families, action.get_ref()).map_err(at(action.span()))?;
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
                .map(|e| Expectation::parse(&families, e.get_ref()).map_err(at(e.span())))
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
            file_families,
            families,
            tet,
            settings,
            steps,
            built: mesh,
        })
    }

    /// The lesson's scene at rest, as it was built when the lesson was read (so a page that
    /// fetched the lesson's mesh builds it once, `Lesson::parse_with`).
    pub fn scene(&self) -> Scene {
        self.built.clone()
    }
}

/// A built-in name as it is; a mesh path relative to the lesson's folder.
pub(super) fn resolve_scene(lesson: &Path, scene: &str) -> String {
    if crate::scene::Builtin::from_name(scene).is_some() {
        return scene.to_owned();
    }
    resolve_path(lesson, scene)
}

/// A path a lesson names, relative to the lesson's folder unless it is absolute.
pub(super) fn resolve_path(lesson: &Path, path: &str) -> String {
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
pub(super) fn reflow(text: &str) -> String {
    text.trim()
        .split("\n\n")
        .map(|paragraph| paragraph.split_whitespace().collect::<Vec<_>>().join(" "))
        .filter(|paragraph| !paragraph.is_empty())
        .collect::<Vec<_>>()
        .join("\n\n")
}

/// The line (from 1) of byte offset `at`.
pub(super) fn line_of(text: &str, at: usize) -> usize {
    crate::input::text_file::position(text, at).0
}

pub(super) fn finite(text: &str) -> Result<f64, String> {
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
