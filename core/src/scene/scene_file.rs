//! A scene of several bodies written as a file (TOML): each body a built-in scene or a mesh file,
//! placed (scaled, turned, moved) and launched with a velocity of its own ([`Scene::load_file`]).
//! The bodies become one mesh whose parts share no particle, so that every engine, metric and
//! front end runs them as it runs one body; [`SceneBody`] says which particles and tets are
//! whose.
//!
//! # The file
//! ```toml
//! name = "two cubes"          # optional: the file's name without .toml otherwise
//! [[body]]
//! name = "lower"              # optional: body1, body2, … otherwise
//! mesh = "cube"               # a built-in (tet, cube, beam, ball) or a mesh file, relative to this file
//! resolution = 2              # optional, for cube, beam and ball (4 otherwise)
//! scale = 1.0                 # optional: about the mesh's centre (its box's), > 0; or [x, y, z]
//! rotate = [0, 0, 0]          # optional: degrees about x, then y, then z, about the centre
//! translate = [0, 0, 0]       # optional: metres, from where the mesh puts it
//! velocity = [0, 0, 0]        # optional: m/s, every particle of the body at the start
//! fixed = false               # optional: true pins every particle (a floor, a ramp, a wall)
//! free = false                # optional: true lets go of the particles the mesh holds (the beam's end)
//! bend = [180, 0.02]          # optional: degrees in (0, 180], inner radius in m: folds the body,
//!                             # laid along x, upwards about z over its middle (after the scale,
//!                             # before the turn; a hairpin at 180°, [`super::Bend`])
//! density = 1000              # optional: kg/m³, its masses (1000 otherwise)
//! material = "E=1e5,nu=0.3"   # optional: its own material, for the families a material gives
//!                             # (the neo-Hookean pair, a file's `stiffness`); the scene's otherwise
//! constraints = "neohookean"  # optional: the built-in families laid on it, as --constraints
//!                             # writes them (all otherwise); each runs where the scene switches it on
//! [[body]]
//! mesh = "cube"
//! translate = [0, 1.5, 0]
//! ```
//! A scene that reaches below the ground (y < 0) is lifted as a whole to rest on it, and the
//! notes say so. Every mistake is named at file:line:column.

use super::mesh::TetMesh;
use super::{Bend, Builtin, Scene, SceneError};
use crate::constraints::material::Material;
use crate::constraints::{Binding, Families, Family, PerFamily};
use crate::input::limits;
use crate::input::text_file;
use glam::{DMat3, DVec3};
use std::ops::Range;
use std::path::{Path, PathBuf};
use toml::Spanned;

/// One body of a scene of several: its name, which particles and tets of the scene's mesh are
/// its, and the velocity it starts with.
#[derive(Clone, Debug, PartialEq)]
pub struct SceneBody {
    /// Its name (the file's `name`, or `body1`, `body2`, …).
    pub name: String,
    /// Its particles, consecutive in the scene's mesh.
    pub particles: Range<u32>,
    /// Its tets, consecutive in the scene's mesh.
    pub tets: Range<u32>,
    /// The velocity of each of its particles at the start, in m/s.
    pub velocity: DVec3,
    /// Its density in kg/m³, which its masses are lumped from ([`crate::simulation::DENSITY`]
    /// unless the file gives one).
    pub density: f64,
    /// Its own material, for the families whose compliance and rest values a material gives
    /// ([`crate::constraints::Row::compliance_from_material`]); `None`: the settings'.
    pub material: Option<Material>,
    /// The built-in families whose constraints are laid on it; `None`: every family. A family
    /// is projected on it where it is also switched on for the scene
    /// ([`crate::simulation::Settings::active`]); a constraint file's family is laid on every
    /// body.
    pub constraints: Option<PerFamily<bool>>,
}

impl SceneBody {
    /// The body among `bodies` (consecutive, in order, as a scene keeps them) that owns
    /// particle `i`: the one a constraint whose first particle is `i` belongs to. `None` for a
    /// particle beyond them (or no bodies at all).
    ///
    /// ```
    /// use tetlab_core::scene::{SceneBody, Scene};
    /// let text = "[[body]]\nmesh = \"tet\"\n[[body]]\nmesh = \"tet\"\ntranslate = [0, 2, 0]\n";
    /// let scene = Scene::parse_file("two.toml".as_ref(), text).unwrap();
    /// assert_eq!(SceneBody::owner(&scene.bodies, 3), Some(0));
    /// assert_eq!(SceneBody::owner(&scene.bodies, 4), Some(1));
    /// assert_eq!(SceneBody::owner(&scene.bodies, 8), None);
    /// ```
    pub fn owner(bodies: &[SceneBody], i: u32) -> Option<usize> {
        let k = bodies
            .partition_point(|b| b.particles.start <= i)
            .checked_sub(1)?;
        bodies[k].particles.contains(&i).then_some(k)
    }

    /// What the body is made of where the file says so, for a reader: `500 kg/m³, material
    /// E=100000,nu=0.3, constraints neohookean`; `None` where it says nothing of it.
    ///
    /// ```
    /// use tetlab_core::scene::Scene;
    /// let text = "[[body]]\nmesh = \"tet\"\ndensity = 500\nconstraints = \"edges,volume\"\n\
    ///             [[body]]\nmesh = \"tet\"\ntranslate = [2, 0, 0]\n";
    /// let scene = Scene::parse_file("two.toml".as_ref(), text).unwrap();
    /// let made_of = scene.bodies[0].made_of().unwrap();
    /// assert_eq!(made_of, "500 kg/m³, constraints edges+volume");
    /// assert_eq!(scene.bodies[1].made_of(), None);
    /// ```
    pub fn made_of(&self) -> Option<String> {
        let mut parts = Vec::new();
        if self.density != crate::simulation::DENSITY {
            parts.push(format!("{} kg/m³", self.density));
        }
        if let Some(material) = &self.material {
            parts.push(format!("material {}", material.describe()));
        }
        if let Some(listed) = &self.constraints {
            parts.push(format!(
                "constraints {}",
                Families::builtin().describe(listed)
            ));
        }
        (!parts.is_empty()).then(|| parts.join(", "))
    }

    /// Whether `family` of `families` is laid on this body ([`SceneBody::constraints`]).
    pub fn takes(&self, families: &Families, family: Family) -> bool {
        match &self.constraints {
            Some(listed) => families.file(family).is_some() || listed[family],
            None => true,
        }
    }
}

#[derive(serde::Deserialize)]
#[serde(deny_unknown_fields)]
struct RawScene {
    #[serde(default)]
    name: Option<Spanned<String>>,
    #[serde(default)]
    body: Vec<RawBody>,
}

#[derive(serde::Deserialize)]
#[serde(deny_unknown_fields)]
struct RawBody {
    #[serde(default)]
    name: Option<Spanned<String>>,
    mesh: Spanned<String>,
    #[serde(default)]
    resolution: Option<Spanned<u32>>,
    #[serde(default)]
    scale: Option<Spanned<Scale>>,
    #[serde(default)]
    rotate: Option<Spanned<[f64; 3]>>,
    #[serde(default)]
    translate: Option<Spanned<[f64; 3]>>,
    #[serde(default)]
    velocity: Option<Spanned<[f64; 3]>>,
    #[serde(default)]
    fixed: bool,
    #[serde(default)]
    bend: Option<Spanned<[f64; 2]>>,
    #[serde(default)]
    free: bool,
    #[serde(default)]
    density: Option<Spanned<f64>>,
    #[serde(default)]
    material: Option<Spanned<String>>,
    #[serde(default)]
    constraints: Option<Spanned<String>>,
}

/// A body's scale: one factor, or one per axis.
#[derive(serde::Deserialize)]
#[serde(try_from = "toml::Value")]
enum Scale {
    One(f64),
    Axes([f64; 3]),
}

impl TryFrom<toml::Value> for Scale {
    type Error = String;

    /// `2`, `0.5` or `[1, 2, 1]`; anything else is told what a scale is.
    fn try_from(value: toml::Value) -> Result<Self, String> {
        let number = |v: &toml::Value| match v {
            toml::Value::Float(k) => Some(*k),
            toml::Value::Integer(k) => Some(*k as f64),
            _ => None,
        };
        let wrong = || {
            format!(
                "scale is {}: it is one factor (`scale = 2`) or one per axis \
                 (`scale = [1, 2, 1]`, three numbers)",
                written(&value)
            )
        };
        if let Some(k) = number(&value) {
            return Ok(Scale::One(k));
        }
        match &value {
            toml::Value::Array(items) if items.len() == 3 => {
                let axes: Option<Vec<f64>> = items.iter().map(number).collect();
                let axes = axes.ok_or_else(wrong)?;
                Ok(Scale::Axes([axes[0], axes[1], axes[2]]))
            }
            _ => Err(wrong()),
        }
    }
}

/// A TOML value as it would be written in the file, for a message.
fn written(value: &toml::Value) -> String {
    match value {
        toml::Value::String(text) => format!("{text:?}"),
        toml::Value::Integer(k) => k.to_string(),
        toml::Value::Float(k) => k.to_string(),
        toml::Value::Boolean(b) => b.to_string(),
        toml::Value::Datetime(d) => d.to_string(),
        toml::Value::Array(items) => {
            let items: Vec<String> = items.iter().map(written).collect();
            format!("[{}]", items.join(", "))
        }
        toml::Value::Table(_) => "a table".to_string(),
    }
}

/// The largest |coordinate| a placement or a velocity may give, in metres or m/s: far beyond any
/// scene, and far inside what f32 (the fast engine) holds with room for its products.
pub const MAX_PLACEMENT: f64 = 1e6;

impl Scene {
    /// Whether `spec` names a scene file (`.toml`) rather than a built-in scene or a mesh.
    pub fn is_scene_file(spec: &str) -> bool {
        Path::new(spec)
            .extension()
            .is_some_and(|e| e.eq_ignore_ascii_case("toml"))
    }

    /// Whether TOML `text` is meant as a scene file (it has `[[body]]` tables) rather than a
    /// lesson or a constraint file; also when it has a mistake, so that the mistake is reported
    /// as a scene file's.
    ///
    /// ```
    /// use tetlab_core::scene::Scene;
    /// assert!(Scene::looks_like_file("[[body]]\nmesh = \"cube\"\n"));
    /// assert!(Scene::looks_like_file("[[body]]\nmesh = \n"));
    /// assert!(!Scene::looks_like_file("title = \"a lesson\"\nscene = \"cube\"\n"));
    /// ```
    pub fn looks_like_file(text: &str) -> bool {
        match toml::from_str::<toml::Table>(text) {
            Ok(table) => table.contains_key("body"),
            Err(_) => text.lines().any(|line| line.trim() == "[[body]]"),
        }
    }

    /// Reads a scene of several bodies from `path` (see the module).
    ///
    /// ```
    /// use tetlab_core::scene::Scene;
    /// let text = "[[body]]\nmesh = \"cube\"\nresolution = 1\n\
    ///             [[body]]\nmesh = \"cube\"\nresolution = 1\ntranslate = [0, 2, 0]\nvelocity = [0, -1, 0]\n";
    /// let scene = Scene::parse_file(std::path::Path::new("two.toml"), text).unwrap();
    /// assert_eq!(scene.bodies.len(), 2);
    /// assert_eq!(scene.mesh.positions.len(), 16, "two cubes of one cell");
    /// assert_eq!(scene.bodies[1].particles, 8..16);
    /// assert_eq!(scene.mesh.positions[8].y, 2.0);
    /// ```
    pub fn load_file(path: &Path) -> Result<Scene, SceneError> {
        let text = text_file::read(path).map_err(|e| SceneError::File {
            path: path.to_owned(),
            at: e.line.map(|l| (l, 1)),
            message: e.message,
        })?;
        Scene::parse_file(path, &text)
    }

    /// [`Scene::load_file`] of the text `text` (`path` names it in errors and is where its mesh
    /// files are looked for).
    pub fn parse_file(path: &Path, text: &str) -> Result<Scene, SceneError> {
        let folder = path.parent().unwrap_or(Path::new(""));
        Scene::parse_file_with(path, text, &|spec, resolution| {
            body_mesh(spec, resolution, folder)
        })
    }

    /// [`Scene::parse_file`] with each body's mesh made by `make_mesh` from its `mesh` and
    /// `resolution` (4 when not given) rather than from the built-ins and the files beside
    /// `path`: what a fuzzer or a browser, which has no folder to look in, gives.
    ///
    /// ```
    /// use std::path::Path;
    /// use tetlab_core::scene::{Builtin, Scene, SceneError};
    /// // Built-ins only: a mesh file is refused, at the body's `mesh`.
    /// let builtins = |spec: &str, resolution: u32| match Builtin::from_name(spec) {
    ///     Some(builtin) => Scene::builtin(builtin, resolution),
    ///     None => Err(SceneError::Unknown(spec.to_owned())),
    /// };
    /// let text = "[[body]]\nmesh = \"tet\"\n[[body]]\nmesh = \"../bunny.node\"\n";
    /// let e = Scene::parse_file_with(Path::new("s.toml"), text, &builtins).unwrap_err();
    /// assert!(e.to_string().starts_with("s.toml:4:8: "), "{e}");
    /// let one = Scene::parse_file_with(Path::new("s.toml"), "[[body]]\nmesh = \"tet\"\n", &builtins);
    /// assert_eq!(one.unwrap().mesh.tets.len(), 1);
    /// ```
    pub fn parse_file_with(
        path: &Path,
        text: &str,
        make_mesh: &dyn Fn(&str, u32) -> Result<Scene, SceneError>,
    ) -> Result<Scene, SceneError> {
        let text = text_file::without_byte_order_mark(text);
        let error = |offset: Option<usize>, message: String| SceneError::File {
            path: path.to_owned(),
            at: offset.map(|o| text_file::position(text, o)),
            message,
        };
        let raw: RawScene = toml::from_str(text).map_err(|e| {
            let message = e.message().trim().replace('\n', " ");
            error(e.span().map(|s| s.start), message)
        })?;
        if raw.body.is_empty() {
            return Err(error(
                None,
                "no body: give each as a [[body]] table with its mesh (mesh = \"cube\")".into(),
            ));
        }
        let mut scene = Scene {
            name: match &raw.name {
                Some(name) => name.get_ref().trim().to_owned(),
                None => path
                    .file_stem()
                    .map_or_else(|| "scene".to_owned(), |s| s.to_string_lossy().into_owned()),
            },
            mesh: TetMesh {
                positions: Vec::new(),
                tets: Vec::new(),
            },
            pinned: Vec::new(),
            notes: Vec::new(),
            bodies: Vec::new(),
        };
        for (k, body) in raw.body.iter().enumerate() {
            let name = match &body.name {
                Some(name) if !name.get_ref().trim().is_empty() => name.get_ref().trim().to_owned(),
                Some(name) => return Err(error(Some(name.span().start), "an empty name".into())),
                None => format!("body{}", k + 1),
            };
            if scene.bodies.iter().any(|b: &SceneBody| b.name == name) {
                let at = body.name.as_ref().map(|n| n.span().start);
                return Err(error(at, format!("two bodies are named \"{name}\"")));
            }
            let resolution = body.resolution.as_ref().map_or(4, |r| *r.get_ref());
            let part = make_mesh(body.mesh.get_ref().trim(), resolution).map_err(|e| match e {
                // A mistake of the mesh file is its own file's, with its own place.
                SceneError::Mesh(e) => SceneError::Mesh(e),
                other => error(Some(body.mesh.span().start), other.to_string()),
            })?;
            let placement = placement(body).map_err(|(at, message)| error(Some(at), message))?;
            let velocity = match &body.velocity {
                Some(v) => finite_vector(v, "velocity", "m/s")
                    .map_err(|(at, message)| error(Some(at), message))?,
                None => DVec3::ZERO,
            };
            let total = scene.mesh.tets.len() + part.mesh.tets.len();
            if total > limits::MAX_TETS {
                return Err(error(
                    Some(body.mesh.span().start),
                    format!(
                        "with this body the scene has {total} tets, more than the {} tetlab \
                         simulates",
                        limits::MAX_TETS
                    ),
                ));
            }
            let fixed = body.fixed;
            let mut part = part;
            if body.free {
                part.pinned.clear();
            }
            let made_of = made_of(body).map_err(|(at, message)| error(Some(at), message))?;
            scene.add(name, part, placement, velocity);
            let added = scene.bodies.last_mut().expect("the body just added");
            (added.density, added.material, added.constraints) = made_of;
            if fixed {
                let body = scene.bodies.last().expect("the body just added");
                scene.pinned.extend(body.particles.clone());
                scene.pinned.sort_unstable();
                scene.pinned.dedup();
            }
        }
        scene.lift_onto_the_ground();
        Ok(scene)
    }

    /// Appends `part` as a body named `name`, placed by `placement`, starting at `velocity`.
    pub(super) fn add(&mut self, name: String, part: Scene, placement: Placement, velocity: DVec3) {
        let first = self.mesh.positions.len() as u32;
        let first_tet = self.mesh.tets.len() as u32;
        let (lo, hi) = super::mesh::bounds(&part.mesh.positions);
        let centre = 0.5 * (lo + hi);
        let mut local: Vec<DVec3> = (part.mesh.positions.iter())
            .map(|&p| placement.scale * (p - centre))
            .collect();
        if let Some(bend) = placement.bend {
            bend.apply(&mut local);
        }
        self.mesh
            .positions
            .extend((local.iter()).map(|&q| centre + placement.translate + placement.rotation * q));
        self.mesh
            .tets
            .extend(part.mesh.tets.iter().map(|t| t.map(|i| i + first)));
        self.pinned.extend(part.pinned.iter().map(|&i| i + first));
        self.notes
            .extend(part.notes.iter().map(|note| format!("{name}: {note}")));
        self.bodies.push(SceneBody {
            name,
            particles: first..self.mesh.positions.len() as u32,
            tets: first_tet..self.mesh.tets.len() as u32,
            velocity,
            density: crate::simulation::DENSITY,
            material: None,
            constraints: None,
        });
    }

    /// Lifts the whole scene to rest on the ground when a part of it is below (y < 0).
    fn lift_onto_the_ground(&mut self) {
        let lowest = (self.mesh.positions.iter()).fold(f64::INFINITY, |low, p| low.min(p.y));
        if lowest < 0.0 {
            for p in &mut self.mesh.positions {
                p.y -= lowest;
            }
            self.notes.push(format!(
                "the scene reached {lowest:.4} below the ground: lifted as a whole to rest on it"
            ));
        }
    }
}

/// How a body is placed: x ↦ centre + translate + R bend(scale (x − centre)).
pub(super) struct Placement {
    pub(super) scale: DMat3,
    pub(super) bend: Option<Bend>,
    pub(super) rotation: DMat3,
    pub(super) translate: DVec3,
}

/// A body's mesh `spec` as a scene of its own: a built-in at `resolution`, or a mesh file found
/// in `folder` (the scene file's).
fn body_mesh(spec: &str, resolution: u32, folder: &Path) -> Result<Scene, SceneError> {
    if let Some(builtin) = Builtin::from_name(spec) {
        return Scene::builtin(builtin, resolution);
    }
    let path: PathBuf = folder.join(spec);
    if !text_file::available(&path) {
        return Err(SceneError::Unknown(path.display().to_string()));
    }
    Scene::load(&path).map_err(SceneError::Mesh)
}

fn placement(body: &RawBody) -> Result<Placement, (usize, String)> {
    let scale = match &body.scale {
        Some(s) => {
            let (value, written) = match s.get_ref() {
                Scale::One(k) => (DVec3::splat(*k), format!("{k}")),
                Scale::Axes([x, y, z]) => (DVec3::new(*x, *y, *z), format!("[{x}, {y}, {z}]")),
            };
            let fine = |k: f64| k.is_finite() && k > 0.0 && k <= MAX_PLACEMENT;
            if !(fine(value.x) && fine(value.y) && fine(value.z)) {
                return Err((
                    s.span().start,
                    format!(
                        "scale is {written}: each factor must be above 0 (a mirror is a \
                         perturbation, not a placement) and at most {MAX_PLACEMENT:e}"
                    ),
                ));
            }
            value
        }
        None => DVec3::ONE,
    };
    let degrees = match &body.rotate {
        Some(r) => finite_vector(r, "rotate", "degrees")?,
        None => DVec3::ZERO,
    };
    let radians = degrees * (std::f64::consts::PI / 180.0);
    let rotation = DMat3::from_rotation_z(radians.z)
        * DMat3::from_rotation_y(radians.y)
        * DMat3::from_rotation_x(radians.x);
    let translate = match &body.translate {
        Some(t) => finite_vector(t, "translate", "m")?,
        None => DVec3::ZERO,
    };
    let bend = match &body.bend {
        Some(b) => {
            let [degrees, radius] = *b.get_ref();
            let fine = degrees > 0.0 && degrees <= 180.0 && radius > 0.0 && radius <= MAX_PLACEMENT;
            if !fine {
                return Err((
                    b.span().start,
                    format!(
                        "bend is [{degrees}, {radius}]: it is [degrees, inner radius], the \
                         degrees above 0 and at most 180, the radius in m above 0 and at most \
                         {MAX_PLACEMENT:e}"
                    ),
                ));
            }
            Some(Bend { degrees, radius })
        }
        None => None,
    };
    Ok(Placement {
        scale: DMat3::from_diagonal(scale),
        bend,
        rotation,
        translate,
    })
}

/// What a body is made of: its density, its own material and its families, each checked.
type MadeOf = (f64, Option<Material>, Option<PerFamily<bool>>);

fn made_of(body: &RawBody) -> Result<MadeOf, (usize, String)> {
    let density = match &body.density {
        Some(d) => {
            limits::DENSITY
                .check(*d.get_ref())
                .map_err(|e| (d.span().start, format!("{e} (kg/m³)")))?;
            *d.get_ref()
        }
        None => crate::simulation::DENSITY,
    };
    let material = match &body.material {
        Some(m) => Some(
            Material::parse(m.get_ref()).map_err(|e| (m.span().start, format!("material: {e}")))?,
        ),
        None => None,
    };
    let constraints = match &body.constraints {
        Some(list) => {
            let families = Families::builtin();
            let at = list.span().start;
            let listed = families
                .parse_list(list.get_ref())
                .map_err(|e| (at, format!("constraints: {e}")))?;
            if let Some(f) = listed
                .families()
                .find(|&f| families.binding(f) == Binding::Contacts)
            {
                return Err((
                    at,
                    format!(
                        "constraints: {} is found between bodies, not laid on one: switch it on \
                         for the scene (--constraints, or the solver panel)",
                        families.name(f)
                    ),
                ));
            }
            Some(listed)
        }
        None => None,
    };
    Ok((density, material, constraints))
}

/// A vector of the file, each component finite and within [`MAX_PLACEMENT`].
fn finite_vector(v: &Spanned<[f64; 3]>, what: &str, unit: &str) -> Result<DVec3, (usize, String)> {
    let value = DVec3::from_array(*v.get_ref());
    if value.is_finite() && value.abs().max_element() <= MAX_PLACEMENT {
        return Ok(value);
    }
    Err((
        v.span().start,
        format!(
            "{what} is {:?}: each component must be a finite number of {unit} within ±{MAX_PLACEMENT:e}",
            v.get_ref()
        ),
    ))
}
