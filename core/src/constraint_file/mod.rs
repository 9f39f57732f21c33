//! A constraint written by a user in a file: C as an expression of the particles p0…p3, bound to a
//! mesh like a built-in family (per edge, per tet, per tet vertex), its gradient by automatic
//! differentiation ([`crate::numbers::dual`]) and, optionally, the user's own derivation of it, checked
//! against that ([`check`]).
//!
//! # The file
//! TOML, e.g. `assets/constraints/height.toml`:
//! ```toml
//! name = "my-height"
//! applies_to = "tet-vertices"   # "edges": p0 p1; "tets": p0..p3; "tet-vertices": four per tet
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
//! Expressions: numbers, names, `+ − * /`, unary −, parentheses, and `dot cross length normalize
//! sqrt abs min max det` ([`program`]). Every mistake is reported at file:line:column.

pub mod check;
pub mod expression;
pub mod grade;
pub mod program;

use crate::constraints::Binding;
use crate::input::text_file;
use crate::numbers::dual::Tangent;
use crate::numbers::vector::{Real, Vector3};
use arrayvec::ArrayVec;
use glam::DVec3;
use program::{CompileError, Program, Tape, Type};
use std::collections::BTreeMap;
use std::fmt;
use std::path::{Path, PathBuf};
use toml::Spanned;

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

#[derive(serde::Deserialize)]
#[serde(deny_unknown_fields)]
struct Raw {
    name: Spanned<String>,
    applies_to: Spanned<String>,
    #[serde(default)]
    define: Option<Spanned<String>>,
    value: Option<Spanned<String>>,
    #[serde(default)]
    rest: Option<Spanned<String>>,
    #[serde(default)]
    gradient: BTreeMap<Spanned<String>, Spanned<String>>,
    #[serde(default)]
    use_gradient: bool,
}

/// A loaded, compiled constraint file.
#[derive(Clone, Debug, PartialEq)]
pub struct ConstraintFile {
    /// Where it was read from.
    pub path: PathBuf,
    /// Its `name`.
    pub name: String,
    /// How it binds to a mesh (`applies_to`).
    pub binding: Binding,
    /// Whether the simulation uses the file's gradient rather than AD's (`use_gradient`).
    pub use_gradient: bool,
    /// The file's text, as read.
    pub source: String,
    /// The lines of `define` and `value`, as written (what the workbench shows as its formula).
    pub formula: Vec<String>,
    /// C alone: what AD differentiates.
    value: Tape,
    /// C, then the gradient entries the file gives.
    yours: Tape,
    /// Per particle, the output of `yours` that is the file's gradient for it.
    gradient_outputs: [Option<usize>; 4],
    rest: Option<Tape>,
    /// Its grade as an exercise, worked out the first time it is asked for ([`ConstraintFile::grade`]).
    grade: GradeOnce,
}

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
        let text = match text_file::read(path) {
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
        };
        ConstraintFile::parse(path, &text)
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

    /// Compiles the text of a constraint file (`path` names it in errors).
    pub fn parse(path: &Path, text: &str) -> Result<ConstraintFile, ConstraintFileError> {
        let text = text_file::without_byte_order_mark(text);
        let error = |offset: Option<usize>, message: String| {
            let at = offset.map(|o| position(text, o));
            ConstraintFileError {
                path: path.to_owned(),
                at,
                message,
            }
        };
        let raw: Raw = toml::from_str(text).map_err(|e| {
            let message = e.message().trim().replace('\n', " ");
            error(e.span().map(|s| s.start), message)
        })?;
        let binding = match raw.applies_to.get_ref().as_str() {
            "edges" => Binding::Edges,
            "tets" => Binding::Tets,
            "tet-vertices" => Binding::TetVertices,
            other => {
                return Err(error(
                    Some(raw.applies_to.span().start),
                    format!(
                        "applies_to is \"{other}\": expected \"edges\" (p0 p1), \"tets\" \
                         (p0..p3) or \"tet-vertices\" (p0..p3, four per tet)"
                    ),
                ));
            }
        };
        let name = raw.name.get_ref().trim().to_owned();
        if name.is_empty()
            || !name
                .chars()
                .all(|c| c.is_ascii_alphanumeric() || c == '-' || c == '_')
        {
            return Err(error(
                Some(raw.name.span().start),
                format!(
                    "name \"{name}\": use letters, digits, - and _ (it names the family on the command line)"
                ),
            ));
        }
        let arity = match binding {
            Binding::Edges => 2,
            Binding::Tets | Binding::TetVertices => 4,
        };
        let Some(value) = raw.value else {
            // Where it would go: after the last key before the first table (`[gradient]`).
            let keys_end = text
                .match_indices('\n')
                .map(|(i, _)| i + 1)
                .find(|&i| text[i..].trim_start_matches([' ', '\t']).starts_with('['))
                .unwrap_or(text.len());
            return Err(error(
                Some(keys_end),
                "no `value`: give C as `value = \"…\"` (before any [table])".to_owned(),
            ));
        };
        // The definitions compile into both programs: C (with `rest`) and the rest value. An
        // expression's errors are placed by where its TOML string starts (`at`).
        let definitions = match &raw.define {
            Some(define) => {
                let at = define.span().start;
                let parsed = expression::parse_definitions(define.get_ref()).map_err(|e| {
                    error(
                        Some(file_offset(text, at, e.offset)),
                        format!("in define: {}", e.message),
                    )
                })?;
                Some((at, parsed))
            }
            None => None,
        };
        let compile_error = |at: usize, e: CompileError, source: &str, what: &str| {
            let snippet = source.get(e.span.start..e.span.end).unwrap_or("").trim();
            error(
                Some(file_offset(text, at, e.span.start)),
                format!("in {what}: {} (`{snippet}`)", e.message),
            )
        };
        let build = |with_rest: bool| -> Result<Program, ConstraintFileError> {
            let mut program = Program::new(arity, with_rest);
            if let (Some((at, parsed)), Some(define)) = (&definitions, &raw.define) {
                program.at(*at);
                for (name, span, expr) in parsed {
                    program
                        .define(name, *span, expr)
                        .map_err(|e| compile_error(*at, e, define.get_ref(), "define"))?;
                }
            }
            Ok(program)
        };
        let compile = |program: &mut Program,
                       spanned: &Spanned<String>,
                       ty: Type,
                       what: &str|
         -> Result<usize, ConstraintFileError> {
            let at = spanned.span().start;
            let expr = expression::parse_expression(spanned.get_ref()).map_err(|e| {
                error(
                    Some(file_offset(text, at, e.offset)),
                    format!("in {what}: {}", e.message),
                )
            })?;
            program.at(at);
            program
                .output(&expr, ty, what)
                .map_err(|e| compile_error(at, e, spanned.get_ref(), what))
        };
        let mut program = build(true)?;
        let c = compile(&mut program, &value, Type::Scalar, "value")?;
        let mut outputs = vec![c];
        let mut gradient_outputs = [None; 4];
        for (key, entry) in &raw.gradient {
            let particle = key
                .get_ref()
                .strip_prefix('p')
                .and_then(|k| k.parse::<usize>().ok())
                .filter(|&k| k < arity && key.get_ref().len() == 2);
            let Some(k) = particle else {
                return Err(error(
                    Some(key.span().start),
                    format!(
                        "gradient entry `{}`: this binding has particles p0…p{} only",
                        key.get_ref(),
                        arity - 1
                    ),
                ));
            };
            let what = format!("gradient.{}", key.get_ref());
            outputs.push(compile(&mut program, entry, Type::Vector, &what)?);
            gradient_outputs[k] = Some(outputs.len() - 1);
        }
        let rest = match &raw.rest {
            Some(rest) => {
                let mut program = build(false)?;
                let r = compile(&mut program, rest, Type::Scalar, "rest")?;
                Some(program.tape(&[r]))
            }
            None => None,
        };
        let mut formula: Vec<String> = raw
            .define
            .as_ref()
            .map(|d| {
                d.get_ref()
                    .lines()
                    .map(str::trim)
                    .filter(|l| !l.is_empty())
                    .map(str::to_owned)
                    .collect()
            })
            .unwrap_or_default();
        formula.push(format!("C = {}", value.get_ref().trim()));
        Ok(ConstraintFile {
            path: path.to_owned(),
            name,
            binding,
            use_gradient: raw.use_gradient,
            source: text.to_owned(),
            formula,
            value: program.tape(&[c]),
            yours: program.tape(&outputs),
            gradient_outputs,
            rest,
            grade: GradeOnce::default(),
        })
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
        match self.binding {
            Binding::Edges => 2,
            Binding::Tets | Binding::TetVertices => 4,
        }
    }

    /// Whether the file gives its own gradient for particle `k`.
    pub fn gives_gradient(&self, k: usize) -> bool {
        self.gradient_outputs.get(k).is_some_and(Option::is_some)
    }

    /// C at `points` with rest value `rest` (NaN where it is undefined).
    pub fn value(&self, points: &[DVec3], rest: f64) -> f64 {
        let points = self.coordinates(points);
        self.value.run(&points, rest, |r| r.scalar(0))
    }

    /// C, its gradient by forward-mode AD and the file's own, at `points` with rest value `rest`:
    /// what `tetlab check-gradients` and `tetlab gradient` compare.
    pub fn evaluate(&self, points: &[DVec3], rest: f64) -> Evaluation {
        let value = self.value(points, rest);
        let automatic = match self.arity() {
            2 => self.forward_mode::<2>(points, rest),
            _ => self.forward_mode::<4>(points, rest),
        };
        Evaluation {
            value,
            automatic: automatic.filter(|_| value.is_finite()),
            yours: self.yours(points, rest)[..self.arity()].to_vec(),
        }
    }

    /// The file's own gradient for each particle it gives one for, at `points` with rest value
    /// `rest`.
    pub fn yours(&self, points: &[DVec3], rest: f64) -> [Option<DVec3>; 4] {
        let points = self.coordinates(points);
        self.yours.run(&points, rest, |r| {
            self.gradient_outputs
                .map(|o| o.map(|o| DVec3::from_array(r.vector(o))))
        })
    }

    /// C and ∇C at `p` with rest value `rest`, in the precision of `V` (f64, f32, the fast
    /// solver's lanes), as a simulation uses them: ∇C by reverse-mode AD
    /// ([`program::Tape::gradient`]) or, with `use_gradient`, the file's own (a particle it gives
    /// none for gets AD's). Where C or ∇C is not finite, the evaluation is degenerate: C is 0
    /// there and ∇C zero. Allocates nothing: the registers are on the stack
    /// ([`program::MAX_REGISTERS`]).
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
    /// let e = file.evaluate_vectors(&[DVec3::new(3.0, 0.0, 4.0), DVec3::ZERO], 1.0);
    /// assert_eq!(e.value, 4.0);
    /// assert!((e.gradients[0] - DVec3::new(0.6, 0.0, 0.8)).length() < 1e-15);
    /// let e = file.evaluate_vectors(&[glam::Vec3::new(3.0, 0.0, 4.0), glam::Vec3::ZERO], 1.0);
    /// assert!((e.gradients[1] + glam::Vec3::new(0.6, 0.0, 0.8)).length() < 1e-6);
    /// ```
    #[inline]
    pub fn evaluate_vectors<V: Vector3, const N: usize>(
        &self,
        p: &[V; N],
        rest: V::Real,
    ) -> crate::constraints::Evaluation<V, N> {
        self.evaluate_by(p, rest, self.use_gradient)
    }

    /// [`ConstraintFile::evaluate_vectors`] with the file's own gradient (`own`) or AD's,
    /// whichever the file asks the simulation to use: what the workbench shows beside the one in
    /// use.
    #[inline]
    pub fn evaluate_by<V: Vector3, const N: usize>(
        &self,
        p: &[V; N],
        rest: V::Real,
        own: bool,
    ) -> crate::constraints::Evaluation<V, N> {
        assert_eq!(
            N,
            self.arity(),
            "{} takes {} particles",
            self.name,
            self.arity()
        );
        let coordinates: [[V::Real; 3]; N] = std::array::from_fn(|i| p[i].to_array());
        let (value, gradients) = if own {
            // Where the file gives no gradient, AD's: a student may write one particle's at a
            // time (the exercise of lesson 9 starts with none).
            let missing = self.gradient_outputs[..N].iter().any(Option::is_none);
            let automatic = missing.then(|| self.value.gradient(&coordinates, rest).1);
            self.yours.run(&coordinates, rest, |r| {
                let gradients = std::array::from_fn(|k| match self.gradient_outputs[k] {
                    Some(o) => r.vector(o),
                    None => automatic.map_or([V::Real::ZERO; 3], |g: [[V::Real; 3]; N]| g[k]),
                });
                (r.scalar(0), gradients)
            })
        } else {
            self.value.gradient(&coordinates, rest)
        };
        sound(value, gradients)
    }

    /// ∇C by forward-mode AD in f64 over [`Tangent`] numbers, one pass per coordinate; `None`
    /// where it is undefined.
    fn forward_mode<const N: usize>(&self, points: &[DVec3], rest: f64) -> Option<Vec<DVec3>> {
        let rest = Tangent::new(rest, 0.0);
        let gradients = crate::numbers::dual::gradient(points, |p| {
            let p: [[Tangent<f64>; 3]; N] = std::array::from_fn(|k| p[k].to_array());
            self.value.run(&p, rest, |r| r.scalar(0))
        })?;
        let gradients: [[f64; 3]; N] = std::array::from_fn(|k| gradients[k].to_array());
        let e = sound::<DVec3, N>(self.value(points, rest.value), gradients);
        (!e.degenerate).then(|| e.gradients.to_vec())
    }

    /// The rest value for particles at rest at `rest_points`: `rest = "…"` when the file gives
    /// it, otherwise C there with rest = 0; 0 where that is not finite (a rest shape on which C
    /// is undefined, such as a flat tet's height).
    pub fn rest_value(&self, rest_points: &[DVec3]) -> f64 {
        let rest = match &self.rest {
            Some(tape) => tape.run(&self.coordinates(rest_points), 0.0, |r| r.scalar(0)),
            None => self.value(rest_points, 0.0),
        };
        if rest.is_finite() { rest } else { 0.0 }
    }

    /// C and ∇C at `points` with rest value `rest` by reverse-mode AD alone, in any [`Real`]:
    /// on [`Tangent`] numbers whose slopes are a direction, the slopes of ∇C are the Hessian of C
    /// times that direction (forward over reverse).
    pub fn reverse_gradient<T: Real, const N: usize>(
        &self,
        points: &[[T; 3]; N],
        rest: T,
    ) -> (T, [[T; 3]; N]) {
        self.value.gradient(points, rest)
    }

    /// Where and why C is undefined at `points` with rest value `rest`: the first expression, in
    /// the order C is worked out, whose value is not finite while what it reads is, named at
    /// file:line:column (`acos of 1.0000001`, `division by zero`). `None` where C is finite.
    pub fn undefined_at(&self, points: &[DVec3], rest: f64) -> Option<ConstraintFileError> {
        let u = self.value.undefined_at(&self.coordinates(points), rest)?;
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
    ) -> Vec<((usize, usize), &'static str, f64)> {
        self.value
            .switches_at(&self.coordinates(points), rest)
            .into_iter()
            .map(|s| (self.place(s.base, s.offset), s.what, s.decides))
            .collect()
    }

    /// Line and column of byte `offset` of the expression whose TOML value starts at `base`.
    fn place(&self, base: usize, offset: usize) -> (usize, usize) {
        position(&self.source, file_offset(&self.source, base, offset))
    }

    /// The instructions of C's tape and of the tape with the file's gradients, for the record
    /// of what an evaluation costs.
    pub fn tape_lengths(&self) -> (usize, usize) {
        (self.value.len(), self.yours.len())
    }

    fn coordinates(&self, points: &[DVec3]) -> ArrayVec<[f64; 3], 4> {
        points.iter().take(4).map(|p| p.to_array()).collect()
    }
}

/// C and ∇C as a simulation takes them: where either is not finite, degenerate, with C = 0 and
/// ∇C = 0.
#[inline]
fn sound<V: Vector3, const N: usize>(
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

/// Line and column (from 1, in characters) of byte `offset` of `text`.
fn position(text: &str, offset: usize) -> (usize, usize) {
    let offset = offset.min(text.len());
    let before = &text[..text.floor_char_boundary(offset)];
    let line = before.matches('\n').count() + 1;
    let column = before.rsplit('\n').next().map_or(0, |l| l.chars().count()) + 1;
    (line, column)
}

/// The byte of `text` that byte `offset` of a TOML string's content comes from, the string's
/// value starting at byte `value_start` (its opening quote). The content starts after `"`, `'`,
/// or `"""` / `'''` and the newline that may follow them; in a basic (double-quoted) string an
/// escape such as `\t` is two bytes of the file for one of the content, `\uXXXX` six, and a
/// backslash at the end of a line of a `"""` string stands for the white space after it.
fn file_offset(text: &str, value_start: usize, offset: usize) -> usize {
    let rest = &text[value_start.min(text.len())..];
    let (quote, escapes) = if rest.starts_with("\"\"\"") {
        (3, true)
    } else if rest.starts_with("'''") {
        (3, false)
    } else if rest.starts_with('"') {
        (1, true)
    } else if rest.starts_with('\'') {
        (1, false)
    } else {
        (0, false)
    };
    let mut at = value_start + quote;
    if quote == 3 {
        let tail = &text[at.min(text.len())..];
        if tail.starts_with("\r\n") {
            at += 2;
        } else if tail.starts_with('\n') {
            at += 1;
        }
    }
    let bytes = text.as_bytes();
    let mut content = 0;
    while content < offset && at < bytes.len() {
        if escapes && bytes[at] == b'\\' {
            match bytes.get(at + 1) {
                Some(b'u') => {
                    content += decoded_len(text.get(at + 2..).unwrap_or(""), 4);
                    at += 6;
                }
                Some(b'U') => {
                    content += decoded_len(text.get(at + 2..).unwrap_or(""), 8);
                    at += 10;
                }
                Some(b' ' | b'\t' | b'\r' | b'\n') => {
                    at += 1;
                    while at < bytes.len() && matches!(bytes[at], b' ' | b'\t' | b'\r' | b'\n') {
                        at += 1;
                    }
                }
                _ => {
                    content += 1;
                    at += 2;
                }
            }
        } else {
            let width = text[at..].chars().next().map_or(1, char::len_utf8);
            content += width;
            at += width;
        }
    }
    at.min(text.len())
}

/// The UTF-8 length of the character whose `digits` hex digits start `hex` (1 if they are not).
fn decoded_len(hex: &str, digits: usize) -> usize {
    hex.get(..digits)
        .and_then(|h| u32::from_str_radix(h, 16).ok())
        .and_then(char::from_u32)
        .map_or(1, char::len_utf8)
}
