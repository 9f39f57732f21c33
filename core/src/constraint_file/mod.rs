//! A constraint written by a user in a file: C as an expression of the particles p0…p3, bound to a
//! mesh like a built-in family (per edge, per tet, per tet vertex, per surface triangle or hinge), its gradient by automatic
//! differentiation ([`crate::numbers::dual`]) and, optionally, the user's own derivation of it, checked
//! against that ([`check`]).
//!
//! # The file
//! TOML, e.g. `assets/constraints/height.toml`:
//! ```toml
//! name = "my-height"
//! applies_to = "tet-vertices"   # or edges, tets, triangles, hinges, particles
//! define = """
//! e1 = p1 - p0
//! c = cross(p2 - p0, p3 - p0)
//! n = c / length(c)
//! """
//! value = "dot(e1, n) - rest"
//! [gradient]                    # optional, each entry too: checked against AD
//! p1 = "n"
//! ```
//! `rest` is `value` with rest = 0 on the rest configuration, unless `rest = "…"` gives it.
//! Expressions ([`expression`], `program`) over scalars, 3-vectors and 3×3 matrices, over several
//! lines if need be: `+ − * /`, components (`v.x`, `M.xy`), the functions `dot cross length
//! normalize det vec3 mat3 outer transpose inverse trace norm sqrt cbrt pow exp log sin cos tan
//! asin acos atan2 abs sign min max clamp if`, the rest shape (`q0`…, `Dm`, `Ds`, `F`, `V0`) and
//! the material (`mu`, `lambda`, `gamma`). The bindings are `edges`, `tets`, `tet-vertices`,
//! `triangles`, `hinges` and `particles` ([`Binding`]), the last with a `where` that chooses
//! which by their rest positions ([`ConstraintFile::chooses`]). Several constraints go in `[[constraint]]` tables,
//! each with its `stiffness`, two of them projected together as a `pair`
//! ([`ConstraintFile::parse_all`];
//! `assets/constraints/neohookean.toml`). Every mistake is reported at file:line:column; the
//! whole language is in docs/gradients.md, "The constraint language".

pub mod check;
pub mod expression;
pub mod grade;
mod moving;
mod parse;
mod program;
mod selection;
pub use moving::Moving;
pub use program::RESTING_H;

use crate::constraints::Binding;
use crate::constraints::material::Material;
use crate::input::text_file;
use crate::input::text_file::position;
use crate::numbers::vector::{Real, Vector3};
use arrayvec::ArrayVec;
use glam::DVec3;
use parse::file_offset;
use program::{Inputs, MAX_STORED, Tape};
use std::fmt;
use std::path::{Path, PathBuf};

/// A mistake in a constraint file: where (line and column from 1, when one is to blame) and what,
/// quoting the offending text. Shown on one line, `FILE:LINE:COLUMN: message`.
#[derive(Clone, Debug, PartialEq)]
pub struct ConstraintFileError {
    /// The file.
    pub path: PathBuf,
    /// Line and column, from 1.
    pub at: Option<(usize, usize)>,
    /// What is wrong, naming the offending text.
    pub message: String,
}

impl fmt::Display for ConstraintFileError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self.at {
            Some((line, column)) => write!(
                f,
                "{}:{line}:{column}: {}",
                self.path.display(),
                self.message
            ),
            None => write!(f, "{}: {}", self.path.display(), self.message),
        }
    }
}

impl std::error::Error for ConstraintFileError {}

/// A loaded, compiled constraint file.
#[derive(Clone, Debug, PartialEq)]
pub struct ConstraintFile {
    /// Where it was read from.
    pub path: PathBuf,
    /// Its family's name: the file's `name`, or `FILE-CONSTRAINT` for one of several.
    pub name: String,
    /// The file's `name` when it holds several constraints: the group of their families.
    pub group: Option<String>,
    /// How it binds to a mesh (`applies_to`).
    pub binding: Binding,
    /// Whether the simulation uses the file's gradient rather than AD's (`use_gradient`).
    pub use_gradient: bool,
    /// Where its compliance comes from (`stiffness`): 1/μ or 1/λ of `--material`.
    pub stiffness: Option<Stiffness>,
    /// The constraint of the same file it is projected together with (`pair`).
    pub pair: Option<String>,
    /// The file's text, as read.
    pub source: String,
    /// The lines of `define` and `value`, as written (what the workbench shows as its formula).
    pub formula: Vec<String>,
    /// What an element stores, worked out once from its rest shape and the material.
    prelude: Tape,
    /// How many numbers that is.
    stored: usize,
    /// C alone: what forward-mode AD differentiates, and where C is undefined or kinked.
    value: Tape,
    /// C, then ∇C of each particle by AD, compiled ([`program::Program::differentiate`]).
    gradient: Tape,
    /// C, then ∇C of each particle as the file gives it (AD's for a particle it gives none for).
    yours: Tape,
    /// Per particle, whether the file gives its gradient.
    gives: [bool; 4],
    /// The file's own Hessian blocks (`[hessian]`), each three outputs (its columns) in the
    /// order of `hessian_blocks`; `None` when it gives none.
    hessian: Option<Tape>,
    /// The particles (i, j) of each block: ∂²C/∂pᵢ∂pⱼ.
    hessian_blocks: Vec<(usize, usize)>,
    rest: Option<Tape>,
    /// Which particles it applies to, when it binds to single particles (`where`).
    selection: Option<selection::Selection>,
    /// Its grade as an exercise, worked out the first time it is asked for ([`ConstraintFile::grade`]).
    grade: GradeOnce,
}

/// Where a constraint's compliance comes from: `stiffness = "mu"` gives α = 1/μ, `"lambda"`
/// α = 1/λ, of the material (`--material`), as the built-in neo-Hookean pair's.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Stiffness {
    /// α = 1/μ.
    Mu,
    /// α = 1/λ.
    Lambda,
}

impl Stiffness {
    /// The compliance it gives.
    pub fn compliance(self) -> fn(&Material) -> f64 {
        match self {
            Stiffness::Mu => |m| 1.0 / m.mu(),
            Stiffness::Lambda => |m| 1.0 / m.lambda(),
        }
    }
}

pub use crate::constraints::Stored;

/// A grade worked out once per compiled file: a cache that belongs to the file, so that a file
/// redefined (the editor, as a student types) starts with none and the old one goes with the old
/// file. It is not part of what the file is: two files equal in all else are equal.
#[derive(Clone, Debug, Default)]
struct GradeOnce(std::sync::OnceLock<std::sync::Arc<grade::Grade>>);

impl PartialEq for GradeOnce {
    fn eq(&self, _: &GradeOnce) -> bool {
        true
    }
}

/// C at a configuration, by AD and as the file derives it.
#[derive(Clone, Debug, PartialEq)]
pub struct Evaluation {
    /// C, or NaN where it is not defined.
    pub value: f64,
    /// ∇C by automatic differentiation; `None` where it is undefined (degenerate).
    pub automatic: Option<Vec<DVec3>>,
    /// The file's gradient for each particle it gives one for.
    pub yours: Vec<Option<DVec3>>,
}

/// An example constraint file that comes with tetlab: a file of `assets/constraints`, built into
/// the library.
#[derive(Clone, Copy, Debug)]
pub struct Example {
    /// Its file name, e.g. `height.toml`.
    pub file: &'static str,
    /// Where the file was when tetlab was built.
    pub path: &'static str,
    /// The file's text.
    pub text: &'static str,
}

include!(concat!(env!("OUT_DIR"), "/constraint_examples.rs"));

impl Example {
    /// Where the file sits in the repository, `assets/constraints/FILE`: the name the workbench
    /// shows and its errors give, the same wherever tetlab was built.
    ///
    /// ```
    /// use tetlab_core::constraint_file::EXAMPLES;
    /// assert!(EXAMPLES.iter().all(|e| e.shown().starts_with("assets/constraints")));
    /// ```
    pub fn shown(&self) -> PathBuf {
        Path::new("assets/constraints").join(self.file)
    }

    /// The example whose path (as tetlab was built) `path` names, `..` and `.` resolved.
    ///
    /// ```
    /// use std::path::Path;
    /// use tetlab_core::constraint_file::{EXAMPLES, Example};
    /// let height = EXAMPLES.iter().find(|e| e.file == "height.toml").unwrap();
    /// let lessons = Path::new(height.path).parent().unwrap().with_file_name("lessons");
    /// let found = Example::at(&lessons.join("../constraints/height.toml")).unwrap();
    /// assert_eq!(found.file, "height.toml");
    /// ```
    pub fn at(path: &Path) -> Option<&'static Example> {
        let wanted = lexically_normal(path);
        EXAMPLES
            .iter()
            .find(|example| lexically_normal(Path::new(example.path)) == wanted)
    }
}

/// `path` with `.` left out and each `..` taking away the name before it.
fn lexically_normal(path: &Path) -> PathBuf {
    use std::path::Component;
    let mut out = PathBuf::new();
    for component in path.components() {
        match component {
            Component::CurDir => {}
            Component::ParentDir if out.file_name().is_some() => {
                out.pop();
            }
            other => out.push(other),
        }
    }
    out
}

impl ConstraintFile {
    /// Reads and compiles `path`. A path to one of the [`EXAMPLES`] that is not on disk (in the
    /// browser, or a tetlab built elsewhere) reads the copy built into tetlab.
    pub fn load(path: &Path) -> Result<ConstraintFile, ConstraintFileError> {
        let text = ConstraintFile::read(path)?;
        ConstraintFile::parse(path, &text)
    }

    /// The text of `path`, or of the example it names.
    fn read(path: &Path) -> Result<String, ConstraintFileError> {
        Ok(match text_file::read(path) {
            Ok(text) => text,
            Err(e) => match Example::at(path) {
                Some(example) => example.text.to_owned(),
                None => {
                    return Err(ConstraintFileError {
                        path: path.to_owned(),
                        at: e.line.map(|l| (l, 1)),
                        message: e.message,
                    });
                }
            },
        })
    }

    /// Whether TOML `text` is meant as a constraint file (it says what it `applies_to`) rather
    /// than a lesson, even when it has a mistake.
    ///
    /// ```
    /// use tetlab_core::constraint_file::ConstraintFile;
    /// assert!(ConstraintFile::looks_like("name = \"e\"\napplies_to = \"edges\"\n"));
    /// assert!(ConstraintFile::looks_like("applies_to = \"edges\"\nvalue = \"1 +\n"));
    /// assert!(!ConstraintFile::looks_like("title = \"A lesson\"\nscene = \"tet\"\n"));
    /// ```
    pub fn looks_like(text: &str) -> bool {
        match toml::from_str::<toml::Table>(text_file::without_byte_order_mark(text)) {
            Ok(table) => table.contains_key("applies_to"),
            Err(_) => text
                .lines()
                .any(|line| line.trim_start().starts_with("applies_to")),
        }
    }

    /// Compiles the text of a constraint file of one constraint (`path` names it in errors);
    /// [`ConstraintFile::parse_all`] reads one of several.
    pub fn parse(path: &Path, text: &str) -> Result<ConstraintFile, ConstraintFileError> {
        let mut all = parse::parse_all(path, text)?;
        if all.len() > 1 {
            return Err(ConstraintFileError {
                path: path.to_owned(),
                at: None,
                message: format!(
                    "the file holds {} constraints ({}): this asks for one",
                    all.len(),
                    all.iter()
                        .map(|f| f.name.as_str())
                        .collect::<Vec<_>>()
                        .join(", ")
                ),
            });
        }
        Ok(all.remove(0))
    }

    /// Every constraint of a constraint file, in the order written: one, or one per
    /// `[[constraint]]` table.
    ///
    /// ```
    /// use std::path::Path;
    /// use tetlab_core::constraint_file::ConstraintFile;
    /// let text = r#"
    /// name = "two"
    /// applies_to = "edges"
    /// define = "d = length(p1 - p0)"
    /// pair = ["stretch", "squash"]
    /// [[constraint]]
    /// name = "stretch"
    /// value = "max(d - rest, 0)"
    /// [[constraint]]
    /// name = "squash"
    /// value = "min(d - rest, 0)"
    /// "#;
    /// let files = ConstraintFile::parse_all(Path::new("two.toml"), text).unwrap();
    /// assert_eq!(files[0].name, "two-stretch");
    /// assert_eq!(files[1].pair.as_deref(), Some("two-stretch"));
    /// assert_eq!(files[1].group.as_deref(), Some("two"));
    /// ```
    pub fn parse_all(path: &Path, text: &str) -> Result<Vec<ConstraintFile>, ConstraintFileError> {
        parse::parse_all(path, text)
    }

    /// Reads and compiles every constraint of `path` ([`ConstraintFile::load`] for one).
    pub fn load_all(path: &Path) -> Result<Vec<ConstraintFile>, ConstraintFileError> {
        let text = ConstraintFile::read(path)?;
        parse::parse_all(path, &text)
    }

    /// Its grade as an exercise ([`grade::Grade::of`]), worked out once for this file: the
    /// lesson panel shows it every frame.
    pub fn grade(&self) -> std::sync::Arc<grade::Grade> {
        std::sync::Arc::clone(
            self.grade
                .0
                .get_or_init(|| std::sync::Arc::new(grade::Grade::of(self))),
        )
    }

    /// How many particles a constraint of this file has.
    pub fn arity(&self) -> usize {
        self.binding.arity()
    }

    /// How many numbers an element of this constraint stores ([`ConstraintFile::store`]).
    pub fn stored_len(&self) -> usize {
        self.stored
    }

    /// Whether what an element stores, or its rest value, reads the rest shape (q0…, Dm, F,
    /// V0): then the rest positions must be given, not the current ones.
    pub fn reads_rest_shape(&self) -> bool {
        self.prelude.reads_rest_shape() || self.rest.as_ref().is_some_and(Tape::reads_rest_shape)
    }

    /// Whether the file gives its rest value itself (`rest = …`), rather than C at rest.
    pub fn has_own_rest(&self) -> bool {
        self.rest.is_some()
    }

    /// Whether C reads where the particles were at the start of the substep (`start0`…) or the
    /// substep's length `h`: then a solver gathers them for it.
    pub fn reads_motion(&self) -> bool {
        [&self.value, &self.gradient, &self.yours]
            .iter()
            .any(|tape| tape.reads_motion())
    }

    /// What an element at rest at `rest_shape` stores: the parts of C that depend only on the
    /// rest shape and `material`, worked out once (for `F = Ds inverse(Dm)`, inverse(Dm)).
    pub fn store(&self, rest_shape: &[DVec3], material: &Material) -> Stored {
        self.store_in(&self.coordinates(rest_shape), material)
    }

    /// [`ConstraintFile::store`] in any precision.
    pub(crate) fn store_in<T: Real>(
        &self,
        rest_shape: &[[T; 3]],
        material: &Material,
    ) -> ArrayVec<T, MAX_STORED> {
        let mut out = ArrayVec::new();
        for _ in 0..self.stored {
            out.push(T::ZERO);
        }
        if self.stored > 0 {
            let inputs = Inputs {
                material: material_values(material).map(T::from_f64),
                ..Inputs::of(rest_shape, T::ZERO)
            };
            self.prelude.run(&inputs, |r| r.write_all(&mut out));
        }
        out
    }

    /// Whether the file gives its own gradient for particle `k`.
    pub fn gives_gradient(&self, k: usize) -> bool {
        self.gives.get(k).copied().unwrap_or(false)
    }

    /// The Hessian blocks the file gives (`[hessian]`), ∂²C/∂pᵢ∂pⱼ at `points` with rest value
    /// `rest`, rest shape `rest_shape` and `material`: each (i, j) and the 3 × 3 block, entry
    /// (r, c) = ∂²C/∂pᵢ[r]∂pⱼ[c]. Empty when the file gives none. Only the check reads them, so
    /// their tape works out what it needs of the rest shape itself: an element stores nothing for
    /// them, however many blocks a file gives.
    pub(crate) fn your_hessian(
        &self,
        points: &[DVec3],
        rest: f64,
        (rest_shape, material): (&[DVec3], &Material),
    ) -> Vec<((usize, usize), glam::DMat3)> {
        let Some(tape) = &self.hessian else {
            return Vec::new();
        };
        let points = self.coordinates(points);
        let shape = self.coordinates(rest_shape);
        let inputs = Inputs {
            shape: &shape,
            material: material_values(material),
            ..Inputs::of(&points, rest)
        };
        tape.run(&inputs, |r| {
            self.hessian_blocks
                .iter()
                .enumerate()
                .map(|(k, &pair)| {
                    let [c0, c1, c2] = [0, 1, 2].map(|c| DVec3::from_array(r.vector(3 * k + c)));
                    (pair, glam::DMat3::from_cols(c0, c1, c2))
                })
                .collect()
        })
    }

    /// The inputs of a tape that runs at each projection: the particles, where they were at the
    /// start of the substep and its h, the rest value and what the element stores.
    fn inputs<'a, T: Real>(
        &self,
        points: &'a [[T; 3]],
        (start, h): (&'a [[T; 3]], T),
        rest: T,
        stored: &'a [T],
    ) -> Inputs<'a, T> {
        assert!(
            stored.len() >= self.stored,
            "{} stores {} numbers per element, and {} are given",
            self.name,
            self.stored,
            stored.len()
        );
        Inputs {
            stored,
            start,
            h,
            ..Inputs::of(points, rest)
        }
    }

    /// C and ∇C at `p` with rest value `rest`, in the precision of `V` (f64, f32, the fast
    /// solver's lanes), as a simulation uses them: ∇C by reverse-mode AD
    /// (the gradient tape `Program::differentiate` compiles) or, with `use_gradient`, the file's own (a particle it gives
    /// none for gets AD's). Where C or ∇C is not finite, the evaluation is degenerate: C is 0
    /// there and ∇C zero. Allocates nothing: the registers are on the stack
    /// (`program::MAX_REGISTERS`).
    ///
    /// # Panics
    /// When `N` is not the file's arity.
    ///
    /// ```
    /// use glam::DVec3;
    /// use std::path::Path;
    /// use tetlab_core::constraint_file::ConstraintFile;
    /// let text = "name = \"e\"\napplies_to = \"edges\"\nvalue = \"length(p0 - p1) - rest\"\n";
    /// let file = ConstraintFile::parse(Path::new("e.toml"), text).unwrap();
    /// // The 3-4-5 edge: C = 5 − 1, ∇p0 C the unit vector from p1 to p0, in f64 and in f32.
    /// let e = file.evaluate_vectors(&[DVec3::new(3.0, 0.0, 4.0), DVec3::ZERO], 1.0, &[]);
    /// assert_eq!(e.value, 4.0);
    /// assert!((e.gradients[0] - DVec3::new(0.6, 0.0, 0.8)).length() < 1e-15);
    /// let e = file.evaluate_vectors(&[glam::Vec3::new(3.0, 0.0, 4.0), glam::Vec3::ZERO], 1.0, &[]);
    /// assert!((e.gradients[1] + glam::Vec3::new(0.6, 0.0, 0.8)).length() < 1e-6);
    /// ```
    #[inline(always)]
    pub fn evaluate_vectors<V: Vector3, const N: usize>(
        &self,
        p: &[V; N],
        rest: V::Real,
        stored: &[V::Real],
    ) -> crate::constraints::Evaluation<V, N> {
        self.evaluate_by(p, rest, stored, self.use_gradient)
    }

    /// [`ConstraintFile::evaluate_vectors`] with the file's own gradient (`own`) or AD's,
    /// whichever the file asks the simulation to use: what the workbench shows beside the one in
    /// use.
    #[inline(always)]
    pub fn evaluate_by<V: Vector3, const N: usize>(
        &self,
        p: &[V; N],
        rest: V::Real,
        stored: &[V::Real],
        own: bool,
    ) -> crate::constraints::Evaluation<V, N> {
        let h = V::Real::from_f64(RESTING_H);
        self.evaluate_by_moving(p, (p, h), rest, stored, own)
    }

    /// [`ConstraintFile::evaluate_by`] with the particles at `start` at the start of the substep
    /// and its length `h`: what the solvers call for a file that reads them
    /// ([`ConstraintFile::reads_motion`]).
    #[inline(always)]
    pub fn evaluate_by_moving<V: Vector3, const N: usize>(
        &self,
        p: &[V; N],
        (start, h): (&[V; N], V::Real),
        rest: V::Real,
        stored: &[V::Real],
        own: bool,
    ) -> crate::constraints::Evaluation<V, N> {
        let coordinates: [[V::Real; 3]; N] = std::array::from_fn(|i| p[i].to_array());
        let start: [[V::Real; 3]; N] = std::array::from_fn(|i| start[i].to_array());
        let (value, gradients) =
            self.value_and_gradient(&coordinates, (&start, h), rest, stored, own);
        sound(value, gradients)
    }

    /// C and ∇C at the particles `points` (coordinates in any [`Real`]: a number, lanes, a
    /// [`crate::numbers::block::Block`] of lanes), the particles having been at `start` at the
    /// start of the substep of length h, as they come, not finite where they are undefined: what
    /// [`ConstraintFile::evaluate_by`] makes an evaluation of.
    ///
    /// # Panics
    /// When `N` is not the file's arity.
    #[inline(always)]
    pub(crate) fn value_and_gradient<T: Real, const N: usize>(
        &self,
        points: &[[T; 3]; N],
        motion: (&[[T; 3]], T),
        rest: T,
        stored: &[T],
        own: bool,
    ) -> (T, [[T; 3]; N]) {
        assert_eq!(
            N,
            self.arity(),
            "{} takes {} particles",
            self.name,
            self.arity()
        );
        let inputs = self.inputs(points, motion, rest, stored);
        let tape = if own { &self.yours } else { &self.gradient };
        tape.run(&inputs, read_gradient)
    }

    /// How many numbers the registers of the tape of C and ∇C are ([`program::Tape::slots`]):
    /// what [`ConstraintFile::gradient_placed`]'s registers must hold.
    pub(crate) fn gradient_slots(&self, own: bool) -> usize {
        if own { &self.yours } else { &self.gradient }.slots()
    }

    /// Runs the tape of C and ∇C (the file's own with `own`, else AD's) in the caller's
    /// `registers`, at least [`ConstraintFile::gradient_slots`] numbers, with the inputs placed
    /// there by `place` ([`program::Tape::run_placed`]), and reads it with `read`: output 0 is C,
    /// output 1 + k the gradient of particle k. For a caller that evaluates many times on wide
    /// numbers, and whose inputs come in another layout.
    ///
    /// # Panics
    /// When `registers` is too short.
    #[inline(always)]
    pub(crate) fn gradient_placed<T: Real, R>(
        &self,
        (own, registers): (bool, &mut [T]),
        motion: (&[[T; 3]], T),
        place: impl FnOnce(&mut [T], &[u8]),
        read: impl FnOnce(&program::Registers<'_, T>) -> R,
    ) -> R {
        let tape = if own { &self.yours } else { &self.gradient };
        tape.run_placed(registers, motion, place, read)
    }

    /// ∇C in f64 as `ConstraintFile::evaluate_by` gives it (the file's own with `own`, else
    /// AD's), for `points` given as a slice of the file's arity, padded to four.
    pub fn gradients_of(
        &self,
        points: &[DVec3],
        rest: f64,
        stored: &[f64],
        own: bool,
    ) -> [DVec3; 4] {
        fn padded<const N: usize>(
            file: &ConstraintFile,
            points: &[DVec3],
            rest: f64,
            stored: &[f64],
            own: bool,
        ) -> [DVec3; 4] {
            let p: [DVec3; N] = std::array::from_fn(|k| points[k]);
            let e = file.evaluate_by(&p, rest, stored, own);
            std::array::from_fn(|k| e.gradients.get(k).copied().unwrap_or(DVec3::ZERO))
        }
        crate::constraints::for_arity!(self.arity(), |N| padded::<N>(
            self, points, rest, stored, own
        ))
    }

    /// The rest value for particles at rest at `rest_points`: `rest = "…"` when the file gives
    /// it, otherwise C there with rest = 0; 0 where that is not finite (a rest shape on which C
    /// is undefined, such as a flat tet's height).
    pub fn rest_value(&self, rest_points: &[DVec3], material: &Material) -> f64 {
        let rest = match &self.rest {
            Some(tape) => {
                let shape = self.coordinates(rest_points);
                let inputs = Inputs {
                    material: material_values(material),
                    ..Inputs::of(&shape, 0.0)
                };
                tape.run(&inputs, |r| r.scalar(0))
            }
            None => self.value(rest_points, 0.0, &self.store(rest_points, material)),
        };
        if rest.is_finite() { rest } else { 0.0 }
    }

    /// C and ∇C at `points` with rest value `rest` by AD alone, in any [`Real`]: on [`Tangent`](crate::numbers::dual::Tangent)
    /// numbers whose slopes are a direction, the slopes of ∇C are the Hessian of C times that
    /// direction (forward mode over the compiled reverse mode).
    pub fn automatic_gradient<T: Real, const N: usize>(
        &self,
        points: &[[T; 3]; N],
        rest: T,
        stored: &[T],
    ) -> (T, [[T; 3]; N]) {
        self.value_and_gradient(
            points,
            (points, T::from_f64(RESTING_H)),
            rest,
            stored,
            false,
        )
    }

    /// Where and why C is undefined at `points` with rest value `rest`: the first expression, in
    /// the order C is worked out, whose value is not finite while what it reads is, named at
    /// file:line:column (`acos of 1.0000001`, `division by zero`). `None` where C is finite.
    pub fn undefined_at(
        &self,
        points: &[DVec3],
        rest: f64,
        stored: &[f64],
    ) -> Option<ConstraintFileError> {
        let points = self.coordinates(points);
        let u =
            self.value
                .undefined_at(&self.inputs(&points, (&points, RESTING_H), rest, stored))?;
        Some(ConstraintFileError {
            path: self.path.clone(),
            at: Some(self.place(u.base, u.offset)),
            message: u.message,
        })
    }

    /// Where C may have a kink or a jump (`abs`, `sign`, `min`, `max`, `clamp`, `if`), each at
    /// its line and column, with the value at `points` whose zero is the kink.
    pub fn switches_at(
        &self,
        points: &[DVec3],
        rest: f64,
        stored: &[f64],
    ) -> Vec<((usize, usize), &'static str, f64)> {
        let points = self.coordinates(points);
        self.value
            .switches_at(&self.inputs(&points, (&points, RESTING_H), rest, stored))
            .into_iter()
            .map(|s| (self.place(s.base, s.offset), s.what, s.decides))
            .collect()
    }

    /// Line and column of byte `offset` of the expression whose TOML value starts at `base`.
    fn place(&self, base: usize, offset: usize) -> (usize, usize) {
        position(&self.source, file_offset(&self.source, base, offset))
    }

    fn coordinates(&self, points: &[DVec3]) -> ArrayVec<[f64; 3], 4> {
        points.iter().take(4).map(|p| p.to_array()).collect()
    }
}

/// C and ∇C from the outputs of a tape of C then ∇C of each particle.
#[inline(always)]
fn read_gradient<T: Real, const N: usize>(r: &program::Registers<'_, T>) -> (T, [[T; 3]; N]) {
    (r.scalar(0), std::array::from_fn(|k| r.vector(1 + k)))
}

/// C and ∇C as a simulation takes them: where either is not finite, degenerate, with C = 0 and
/// ∇C = 0.
#[inline(always)]
pub(crate) fn sound<V: Vector3, const N: usize>(
    value: V::Real,
    gradients: [[V::Real; 3]; N],
) -> crate::constraints::Evaluation<V, N> {
    let mut sound = value.finite();
    for g in &gradients {
        for &x in g {
            sound = sound & x.finite();
        }
    }
    crate::constraints::Evaluation {
        value: V::Real::select(value.finite(), value, V::Real::ZERO),
        gradients: gradients.map(|g| V::select(sound, V::from_array(g), V::ZERO)),
        degenerate: !sound,
    }
}

/// μ, λ and γ = 1 + μ/λ of `material`, as a tape reads them.
fn material_values(material: &Material) -> [f64; 3] {
    let (mu, lambda) = (material.mu(), material.lambda());
    [mu, lambda, 1.0 + mu / lambda]
}
