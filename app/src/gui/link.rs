//! A link to a state of the workbench, in a URL fragment: the built-in scene and its resolution,
//! or a scene file that comes with tetlab (`scene=stacked-cubes.toml`), the solver settings (the active families among them), the lesson and its step, the camera, and
//! the edits made since the scene was loaded (inversions, mirroring, flattening, scrambling).
//!
//! The fragment is `key=value` pairs joined by `&`, URL-encoded (`form_urlencoded`, the `url`
//! crate's own), e.g. `#scene=cube&resolution=3&families=edges%2Bheight%2Bvolume&edits=mirror`.
//! Settings that equal the workbench's defaults (or, in a lesson, the lesson's own settings) are
//! left out, so that a link stays short, a later default reaches old links, and a hand-written
//! `#lesson=3&step=2` opens the lesson as the lesson sets it up. Every value is read back with the parser the command line
//! uses for it (`Method::parse`, `PerFamily::parse_list`, `Material::parse`, …) and checked as
//! the command line checks it ([`Settings::check`]). A particle dragged is not in a link: its
//! place comes from the simulation's motion, which a link cannot replay.

use super::camera::OrbitCamera;
use super::workbench::Edit;
use glam::Vec3;
use std::fmt;
use tetlab_core::constraints::Families;
use tetlab_core::constraints::material::Material;
use tetlab_core::scene::{Builtin, Perturbation, ShippedScene};
use tetlab_core::simulation::{EngineChoice, Method, Settings};

/// The address the desktop workbench puts before a fragment: where `scripts/web.sh` says to serve
/// the page. `TETLAB_PAGE_URL` replaces it (e.g. the address a class uses).
pub const DEFAULT_PAGE_URL: &str = "http://127.0.0.1:8000/";

/// Everything a link restores.
#[derive(Clone, Debug, PartialEq)]
pub struct Link {
    /// The built-in scene and its resolution, or a shipped scene file; `None` for a mesh file or
    /// a scene file of the user's, which a link cannot carry (the default scene is shown).
    pub scene: Option<LinkScene>,
    /// The solver settings.
    pub settings: Settings,
    /// A built-in lesson (its number, from 1) and the step shown (from 0).
    pub lesson: Option<(usize, usize)>,
    /// The camera.
    pub camera: Option<OrbitCamera>,
    /// The edits made since the scene was loaded, in order.
    pub edits: Vec<Edit>,
}

/// A fragment that could not be read: the key and why.
#[derive(Clone, Debug, PartialEq)]
pub struct LinkError {
    /// The key whose value is wrong, or the pair that is not `key=value`.
    pub key: String,
    /// Why.
    pub message: String,
}

impl fmt::Display for LinkError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "the link's '{}': {}", self.key, self.message)
    }
}

impl std::error::Error for LinkError {}

/// An edit as a link writes it: the perturbation as `--perturb` takes it (`mirror`,
/// `scramble:3`), or `tet:T:P` for particle P reflected through the opposite face of tet T.
fn edit_text(edit: &Edit) -> String {
    match edit {
        Edit::Perturb(perturbation) => perturbation.to_string(),
        Edit::InvertTet { tet, particle } => format!("tet:{tet}:{particle}"),
    }
}

fn parse_edit(text: &str) -> Result<Edit, String> {
    if let Some(rest) = text.strip_prefix("tet:") {
        let (tet, particle) = rest
            .split_once(':')
            .ok_or_else(|| format!("'{text}' is not tet:TET:PARTICLE"))?;
        let number = |what: &str, value: &str| {
            value
                .parse::<usize>()
                .map_err(|_| format!("'{value}' is not a {what} number in '{text}'"))
        };
        return Ok(Edit::InvertTet {
            tet: number("tet", tet)?,
            particle: number("particle", particle)?,
        });
    }
    Perturbation::parse(text).map(Edit::Perturb)
}

/// The most edits a link replays: every edit is a pass over the body.
pub const MAX_EDITS: usize = 64;

/// The scene a link names.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum LinkScene {
    /// A built-in scene at a resolution: `scene=cube&resolution=3`.
    Builtin(Builtin, u32),
    /// A scene file of `assets/scenes`, built into tetlab ([`ShippedScene`]):
    /// `scene=stacked-cubes.toml`.
    Shipped(&'static str),
}

impl Link {
    /// The fragment (without `#`).
    ///
    /// ```
    /// use tetlab::gui::link::{Link, LinkScene};
    /// use tetlab_core::scene::Builtin;
    /// let mut link = Link::parse("").unwrap();
    /// link.scene = Some(LinkScene::Builtin(Builtin::Cube, 3));
    /// link.settings.substeps = 20;
    /// assert_eq!(link.fragment(), "scene=cube&resolution=3&substeps=20");
    /// assert_eq!(Link::parse(&link.fragment()).unwrap(), link);
    /// link.scene = Some(LinkScene::Shipped("folded-bar.toml"));
    /// assert_eq!(link.fragment(), "scene=folded-bar.toml&substeps=20");
    /// assert_eq!(Link::parse(&link.fragment()).unwrap(), link);
    /// ```
    pub fn fragment(&self) -> String {
        let defaults = base_settings(self.lesson.map(|(lesson, _)| lesson));
        let s = &self.settings;
        let mut out = form_urlencoded::Serializer::new(String::new());
        match self.scene {
            Some(LinkScene::Builtin(builtin, resolution)) => {
                out.append_pair("scene", builtin.name());
                out.append_pair("resolution", &resolution.to_string());
            }
            Some(LinkScene::Shipped(file)) => {
                out.append_pair("scene", file);
            }
            None => {}
        }
        // Only built-in families travel in a link: the page it is opened on may not have a
        // constraint file that this one loaded.
        let families = Families::builtin();
        if s.active != defaults.active {
            out.append_pair("families", &families.describe(&s.active));
        }
        if s.method != defaults.method {
            out.append_pair("method", s.method.name());
        }
        if s.engine != defaults.engine {
            out.append_pair("engine", s.engine.name());
        }
        let numbers: [(&str, f64, f64); 6] = [
            ("substeps", s.substeps.into(), defaults.substeps.into()),
            (
                "iterations",
                s.iterations.into(),
                defaults.iterations.into(),
            ),
            ("dt", s.dt, defaults.dt),
            ("gravity", s.gravity, defaults.gravity),
            ("damping", s.damping, defaults.damping),
            ("grab", s.grab_compliance, defaults.grab_compliance),
        ];
        for (key, value, default) in numbers {
            if value != default {
                out.append_pair(key, &value.to_string());
            }
        }
        for (key, value, default) in [
            ("ground", s.ground, defaults.ground),
            ("settle", s.settle_edits, defaults.settle_edits),
        ] {
            if value != default {
                out.append_pair(key, if value { "1" } else { "0" });
            }
        }
        if s.material != defaults.material {
            out.append_pair("material", &s.material.describe());
        }
        for family in families.all() {
            // The material gives these; `material` carries them.
            if families.row(family).compliance_from_material.is_some() {
                continue;
            }
            if s.compliance[family] != defaults.compliance[family] {
                let key = format!("alpha.{}", families.name(family));
                out.append_pair(&key, &s.compliance[family].to_string());
            }
            if s.stiffness[family] != defaults.stiffness[family] {
                let key = format!("k.{}", families.name(family));
                out.append_pair(&key, &s.stiffness[family].to_string());
            }
        }
        if let Some((lesson, step)) = self.lesson {
            out.append_pair("lesson", &lesson.to_string());
            out.append_pair("step", &(step + 1).to_string());
        }
        if let Some(c) = &self.camera {
            let values = [
                c.yaw, c.pitch, c.distance, c.target.x, c.target.y, c.target.z,
            ];
            let text: Vec<String> = values.iter().map(f32::to_string).collect();
            out.append_pair("camera", &text.join(","));
        }
        if !self.edits.is_empty() {
            let text: Vec<String> = self.edits.iter().map(edit_text).collect();
            out.append_pair("edits", &text.join(";"));
        }
        out.finish()
    }

    /// Reads a fragment (with or without its `#`). The first key that is unknown, repeated or
    /// wrong is an error naming it; so are settings out of range.
    pub fn parse(fragment: &str) -> Result<Link, LinkError> {
        let fragment = fragment.strip_prefix('#').unwrap_or(fragment);
        // The settings start from the lesson's, when the link names one.
        let lesson_named = form_urlencoded::parse(fragment.as_bytes())
            .find(|(key, _)| key == "lesson")
            .and_then(|(_, value)| value.trim().parse::<usize>().ok());
        let mut link = Link {
            scene: None,
            settings: base_settings(lesson_named),
            lesson: None,
            camera: None,
            edits: Vec::new(),
        };
        let (mut builtin, mut resolution, mut lesson, mut step) = (None, None, None, None);
        let mut shipped = None;
        let mut seen: Vec<String> = Vec::new();
        let s = &mut link.settings;
        for (key, value) in form_urlencoded::parse(fragment.as_bytes()) {
            let (key, value) = (key.into_owned(), value.trim().to_owned());
            let wrong = |message: String| LinkError {
                key: key.clone(),
                message,
            };
            if seen.contains(&key) {
                return Err(wrong("given twice".into()));
            }
            seen.push(key.clone());
            let number = |text: &str| -> Result<f64, LinkError> {
                text.parse::<f64>()
                    .ok()
                    .filter(|x| x.is_finite())
                    .ok_or_else(|| wrong(format!("'{text}' is not a number")))
            };
            let count = |text: &str| -> Result<u32, LinkError> {
                text.parse::<u32>()
                    .map_err(|_| wrong(format!("'{text}' is not a whole number")))
            };
            let switch = |text: &str| match text {
                "1" => Ok(true),
                "0" => Ok(false),
                _ => Err(wrong(format!("'{text}' is not 0 or 1"))),
            };
            match key.as_str() {
                "scene" => {
                    match ShippedScene::named(&value) {
                        Some(file) => shipped = Some(file.file),
                        None => builtin = Some(Builtin::from_name(&value).ok_or_else(|| {
                            let files: Vec<&str> = ShippedScene::names().collect();
                            wrong(format!(
                                "'{value}' is not a built-in scene (tet, cube, beam or ball) nor \
                                 a scene file that comes with tetlab ({})",
                                files.join(", ")
                            ))
                        })?),
                    }
                }
                "resolution" => resolution = Some(count(&value)?),
                "families" => {
                    s.active = Families::builtin()
                        .parse_list(&value.replace('+', ","))
                        .map_err(wrong)?
                }
                "method" => s.method = Method::parse(&value).map_err(wrong)?,
                // A link made where the GPU engine runs may be opened where it cannot: the
                // workbench then runs the CPU's (`TetlabApp::open_link`).
                "engine" => s.engine = EngineChoice::parse(&value).map_err(wrong)?,
                "substeps" => s.substeps = count(&value)?,
                "iterations" => s.iterations = count(&value)?,
                "dt" => s.dt = number(&value)?,
                "gravity" => s.gravity = number(&value)?,
                "damping" => s.damping = number(&value)?,
                "grab" => s.grab_compliance = number(&value)?,
                "ground" => s.ground = switch(&value)?,
                "settle" => s.settle_edits = switch(&value)?,
                "material" => s.material = Material::parse(&value).map_err(wrong)?,
                "lesson" => lesson = Some(count(&value)? as usize),
                "step" => step = Some(count(&value)? as usize),
                "camera" => {
                    let values: Vec<f32> = value
                        .split(',')
                        .map(|x| x.trim().parse::<f32>().ok().filter(|x| x.is_finite()))
                        .collect::<Option<_>>()
                        .filter(|v: &Vec<f32>| v.len() == 6)
                        .ok_or_else(|| {
                            wrong(format!(
                                "'{value}' is not six numbers: yaw,pitch,distance,x,y,z"
                            ))
                        })?;
                    let mut camera = OrbitCamera {
                        target: Vec3::new(values[3], values[4], values[5]),
                        yaw: values[0],
                        pitch: values[1],
                        distance: values[2],
                    };
                    camera.keep_in_range();
                    link.camera = Some(camera);
                }
                "edits" => {
                    link.edits = value
                        .split(';')
                        .filter(|e| !e.trim().is_empty())
                        .map(|e| parse_edit(e.trim()).map_err(&wrong))
                        .collect::<Result<_, _>>()?;
                    if link.edits.len() > MAX_EDITS {
                        return Err(wrong(format!(
                            "{} edits: a link replays at most {MAX_EDITS}",
                            link.edits.len()
                        )));
                    }
                }
                _ => {
                    let per_family = key
                        .split_once('.')
                        .filter(|(kind, _)| *kind == "alpha" || *kind == "k");
                    let Some((kind, name)) = per_family else {
                        return Err(wrong("not a key of a tetlab link".into()));
                    };
                    let family = Families::builtin().parse(name).map_err(&wrong)?;
                    let value = number(&value)?;
                    match kind {
                        "alpha" => s.compliance[family] = value,
                        _ => s.stiffness[family] = value,
                    }
                }
            }
        }
        link.settings.check().map_err(|message| LinkError {
            key: "settings".into(),
            message,
        })?;
        link.scene = match (builtin, resolution) {
            (None, Some(_)) if shipped.is_some() => {
                return Err(LinkError {
                    key: "resolution".into(),
                    message: "given with a scene file, whose bodies say their own".into(),
                });
            }
            (None, None) => shipped.map(LinkScene::Shipped),
            (Some(builtin), resolution) => {
                let resolution = resolution.unwrap_or(3);
                tetlab_core::input::limits::RESOLUTION
                    .check(resolution)
                    .map_err(|message| LinkError {
                        key: "resolution".into(),
                        message,
                    })?;
                Some(LinkScene::Builtin(builtin, resolution))
            }
            (None, Some(_)) => {
                return Err(LinkError {
                    key: "resolution".into(),
                    message: "given without a scene".into(),
                });
            }
        };
        link.lesson = match (lesson, step) {
            (Some(lesson), step) => {
                let count = tetlab_core::teaching::lesson::BUILTIN.len();
                if !(1..=count).contains(&lesson) {
                    return Err(LinkError {
                        key: "lesson".into(),
                        message: format!("there is no lesson {lesson}: tetlab has 1 to {count}"),
                    });
                }
                let step = step.unwrap_or(1);
                if step == 0 {
                    return Err(LinkError {
                        key: "step".into(),
                        message: "steps are counted from 1".into(),
                    });
                }
                Some((lesson, step - 1))
            }
            (None, Some(_)) => {
                return Err(LinkError {
                    key: "step".into(),
                    message: "given without a lesson".into(),
                });
            }
            (None, None) => None,
        };
        Ok(link)
    }
}

/// What a link's settings are written against: built-in lesson `lesson`'s settings (as the
/// workbench opens it), or the workbench's defaults.
fn base_settings(lesson: Option<usize>) -> Settings {
    lesson
        .and_then(|number| tetlab_core::teaching::lesson::Lesson::builtin(number).ok())
        .map_or(super::Preferences::default().settings, |lesson| {
            lesson.settings
        })
}

/// The page address links are made for: `TETLAB_PAGE_URL`, or [`DEFAULT_PAGE_URL`].
pub fn page_url() -> String {
    std::env::var("TETLAB_PAGE_URL")
        .ok()
        .filter(|url| !url.trim().is_empty())
        .unwrap_or_else(|| DEFAULT_PAGE_URL.to_owned())
}

#[cfg(test)]
mod tests {
    use super::*;
    use tetlab_core::constraints::{Family, PerFamily};

    /// Every part of a link survives being written and read.
    #[test]
    fn a_link_round_trips() {
        let mut settings = crate::gui::Preferences::default().settings;
        settings.active = PerFamily::builtin_list("edges,height,neohookean").unwrap();
        settings.method = Method::Pbd;
        settings.engine = EngineChoice::Fast;
        settings.substeps = 37;
        settings.dt = 1.0 / 30.0;
        settings.gravity = 0.0;
        settings.ground = false;
        settings.settle_edits = false;
        settings.compliance[Family::EDGES] = 1e-4;
        settings.stiffness[Family::HEIGHT] = 0.5;
        settings.material = Material::parse("E=2e5,nu=0.45").unwrap();
        let link = Link {
            scene: Some(LinkScene::Builtin(Builtin::Ball, 2)),
            settings,
            lesson: Some((4, 2)),
            camera: Some(OrbitCamera {
                target: Vec3::new(0.1, 0.4, -0.2),
                yaw: 1.25,
                pitch: -0.3,
                distance: 4.5,
            }),
            edits: vec![
                Edit::Perturb(Perturbation::Mirror),
                Edit::InvertTet {
                    tet: 12,
                    particle: 7,
                },
                Edit::Perturb(Perturbation::Scramble(3)),
            ],
        };
        let fragment = link.fragment();
        assert_eq!(Link::parse(&format!("#{fragment}")), Ok(link), "{fragment}");
        assert!(
            fragment.contains("step=3"),
            "steps counted from 1: {fragment}"
        );
    }

    /// The defaults make an empty fragment, and an empty fragment gives the defaults.
    #[test]
    fn the_defaults_are_an_empty_fragment() {
        let link = Link::parse("").unwrap();
        assert_eq!(link.fragment(), "");
        assert_eq!(link.settings, crate::gui::Preferences::default().settings);
        assert_eq!(link.scene, None);
    }

    /// A link to a lesson writes only what differs from the lesson's own settings, and a
    /// hand-written one opens the lesson as it sets itself up.
    #[test]
    fn a_lesson_link_starts_from_the_lesson_settings() {
        let lesson = tetlab_core::teaching::lesson::Lesson::builtin(3).unwrap();
        let link = Link::parse("#lesson=3&step=2").unwrap();
        assert_eq!(link.settings, lesson.settings);
        assert_eq!(link.lesson, Some((3, 1)));
        assert_eq!(link.fragment(), "lesson=3&step=2");
        let mut changed = link.clone();
        changed.settings.substeps += 1;
        let fragment = changed.fragment();
        assert_eq!(
            fragment,
            format!("substeps={}&lesson=3&step=2", lesson.settings.substeps + 1)
        );
        assert_eq!(Link::parse(&fragment).unwrap(), changed);
    }

    /// Every kind of mistake names its key.
    #[test]
    fn a_wrong_fragment_names_its_key() {
        for (fragment, key, says) in [
            ("scene=teapot", "scene", "not a built-in scene"),
            ("scene=teapot.toml", "scene", "stacked-cubes.toml"),
            (
                "scene=stacked-cubes.toml&resolution=3",
                "resolution",
                "with a scene file",
            ),
            (
                "scene=cube&resolution=x",
                "resolution",
                "not a whole number",
            ),
            ("scene=cube&resolution=999", "resolution", "out of range"),
            ("resolution=3", "resolution", "without a scene"),
            ("families=edges,glue", "families", "glue"),
            ("substeps=0", "settings", "substeps"),
            ("dt=NaN", "dt", "not a number"),
            ("gravity=1e400", "gravity", "not a number"),
            ("ground=yes", "ground", "not 0 or 1"),
            ("alpha.glue=1", "alpha.glue", "glue"),
            ("alpha.edges=-1", "settings", "out of range"),
            ("lesson=99", "lesson", "no lesson 99"),
            ("lesson=1&step=0", "step", "from 1"),
            ("camera=1,2,3", "camera", "six numbers"),
            ("edits=mirror;tet:1", "edits", "tet:TET:PARTICLE"),
            ("edits=melt", "edits", "not a perturbation"),
            ("substeps=3&substeps=4", "substeps", "twice"),
            ("zoom=2", "zoom", "not a key"),
            ("%FF%FE=1", "\u{FFFD}\u{FFFD}", "not a key"),
        ] {
            let error = Link::parse(fragment).expect_err(fragment);
            assert_eq!(error.key, key, "{fragment}: {error}");
            assert!(error.message.contains(says), "{fragment}: {error}");
        }
    }
}
