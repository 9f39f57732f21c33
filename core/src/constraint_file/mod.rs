//! A constraint written by a user in a file: C as an expression of the particles p0…p3, bound to a
//! mesh like a built-in family (per edge, per tet, per tet vertex), its gradient by automatic
//! differentiation ([`crate::dual`]) and, optionally, the user's own derivation of it, checked
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
pub mod program;

use crate::constraints::Binding;
use crate::dual::Tangent;
use crate::text_file;
use crate::vector::{Real, Vector3};
use glam::DVec3;
use program::{CompileError, Program, Type};
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
    program: Program,
    /// Output 0 is C; then the gradient entries given, by particle.
    gradient_outputs: [Option<usize>; 4],
    rest_program: Option<Program>,
}

/// C and the gradient a simulation uses (AD's, or the file's with `use_gradient`), in any
/// precision: [`ConstraintFile::evaluate_vectors`].
#[derive(Clone, Copy, Debug)]
pub struct VectorEvaluation<V: Vector3, const N: usize> {
    /// C.
    pub value: V::Real,
    /// ∇C per particle; zero where `degenerate`.
    pub gradients: [V; N],
    /// Where C or ∇C is not finite (a normalised zero vector, a division by zero).
    pub degenerate: <V::Real as Real>::Mask,
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

impl ConstraintFile {
    /// Reads and compiles `path`.
    pub fn load(path: &Path) -> Result<ConstraintFile, ConstraintFileError> {
        let text = text_file::read(path).map_err(|e| ConstraintFileError {
            path: path.to_owned(),
            at: e.line.map(|l| (l, 1)),
            message: e.message,
        })?;
        ConstraintFile::parse(path, &text)
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
            return Err(error(
                None,
                "no `value`: give C as `value = \"…\"`".to_owned(),
            ));
        };
        // The definitions compile into both programs: C (with `rest`) and the rest value.
        let definitions = match &raw.define {
            Some(define) => {
                let base = content_start(text, define.span().start);
                let parsed = expression::parse_definitions(define.get_ref()).map_err(|e| {
                    error(Some(base + e.offset), format!("in define: {}", e.message))
                })?;
                Some((base, parsed))
            }
            None => None,
        };
        let compile_error = |base: usize, e: CompileError, source: &str, what: &str| {
            let snippet = source.get(e.span.start..e.span.end).unwrap_or("").trim();
            error(
                Some(base + e.span.start),
                format!("in {what}: {} (`{snippet}`)", e.message),
            )
        };
        let build = |with_rest: bool| -> Result<Program, ConstraintFileError> {
            let mut program = Program::new(arity, with_rest);
            if let (Some((base, parsed)), Some(define)) = (&definitions, &raw.define) {
                for (name, span, expr) in parsed {
                    program
                        .define(name, *span, expr)
                        .map_err(|e| compile_error(*base, e, define.get_ref(), "define"))?;
                }
            }
            Ok(program)
        };
        let compile = |program: &mut Program,
                       spanned: &Spanned<String>,
                       ty: Type,
                       what: &str|
         -> Result<usize, ConstraintFileError> {
            let base = content_start(text, spanned.span().start);
            let expr = expression::parse_expression(spanned.get_ref())
                .map_err(|e| error(Some(base + e.offset), format!("in {what}: {}", e.message)))?;
            program
                .output(&expr, ty, what)
                .map_err(|e| compile_error(base, e, spanned.get_ref(), what))
        };
        let mut program = build(true)?;
        compile(&mut program, &value, Type::Scalar, "value")?;
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
            gradient_outputs[k] = Some(compile(&mut program, entry, Type::Vector, &what)?);
        }
        let rest_program = match &raw.rest {
            Some(rest) => {
                let mut program = build(false)?;
                compile(&mut program, rest, Type::Scalar, "rest")?;
                Some(program)
            }
            None => None,
        };
        Ok(ConstraintFile {
            path: path.to_owned(),
            name,
            binding,
            use_gradient: raw.use_gradient,
            program,
            gradient_outputs,
            rest_program,
        })
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
        let points: Vec<[f64; 3]> = points.iter().map(|p| p.to_array()).collect();
        let mut registers = vec![[0.0; 3]; self.program.registers()];
        self.program.run(0, &points, rest, &mut registers);
        self.program.scalar(0, &registers)
    }

    /// C, its gradient by AD and the file's own, at `points` with rest value `rest`.
    pub fn evaluate(&self, points: &[DVec3], rest: f64) -> Evaluation {
        let value = self.value(points, rest);
        let automatic = match self.arity() {
            2 => self.automatic::<2>(points, rest),
            _ => self.automatic::<4>(points, rest),
        };
        let mut registers = vec![[0.0; 3]; self.program.registers()];
        let flat: Vec<[f64; 3]> = points.iter().map(|p| p.to_array()).collect();
        let last = self.gradient_outputs.iter().flatten().max().copied();
        if let Some(last) = last {
            self.program.run(last, &flat, rest, &mut registers);
        }
        let yours = (0..self.arity())
            .map(|k| {
                self.gradient_outputs[k]
                    .map(|o| DVec3::from_array(self.program.vector(o, &registers)))
            })
            .collect();
        Evaluation {
            value,
            automatic: automatic.filter(|_| value.is_finite()),
            yours,
        }
    }

    /// C and ∇C at `p` with rest value `rest`, in the precision of `V` (f64, f32, the fast
    /// solver's lanes): by forward-mode AD over [`Tangent`] numbers, 3N passes of the compiled
    /// value, or, with `use_gradient`, the file's own gradient (a particle it gives none for gets
    /// zero). Allocates nothing: the registers are on the stack
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
    pub fn evaluate_vectors<V: Vector3, const N: usize>(
        &self,
        p: &[V; N],
        rest: V::Real,
    ) -> VectorEvaluation<V, N> {
        self.evaluate_with(p, rest, self.use_gradient)
    }

    /// ∇C by AD in f64, `None` where it is undefined.
    fn automatic<const N: usize>(&self, points: &[DVec3], rest: f64) -> Option<Vec<DVec3>> {
        let p: [DVec3; N] = std::array::from_fn(|k| points[k]);
        let e = self.evaluate_with(&p, rest, false);
        (!e.degenerate).then(|| e.gradients.to_vec())
    }

    /// [`ConstraintFile::evaluate_vectors`], with the file's gradient when `own`, AD's otherwise.
    fn evaluate_with<V: Vector3, const N: usize>(
        &self,
        p: &[V; N],
        rest: V::Real,
        own: bool,
    ) -> VectorEvaluation<V, N> {
        assert_eq!(
            N,
            self.arity(),
            "{} takes {} particles",
            self.name,
            self.arity()
        );
        let coordinates: [[V::Real; 3]; N] = std::array::from_fn(|i| p[i].to_array());
        let mut value = V::Real::ZERO;
        let mut gradients = [[V::Real::ZERO; 3]; N];
        if own {
            let mut registers = [[V::Real::ZERO; 3]; program::MAX_REGISTERS];
            let registers = &mut registers[..self.program.registers()];
            let last = self
                .gradient_outputs
                .iter()
                .flatten()
                .max()
                .copied()
                .unwrap_or(0);
            self.program.run(last, &coordinates, rest, registers);
            value = self.program.scalar(0, registers);
            for (k, output) in self.gradient_outputs.iter().take(N).enumerate() {
                if let Some(o) = output {
                    gradients[k] = self.program.vector(*o, registers);
                }
            }
        } else {
            let mut registers = [[Tangent::<V::Real>::ZERO; 3]; program::MAX_REGISTERS];
            let registers = &mut registers[..self.program.registers()];
            let constant = |x: V::Real| Tangent::new(x, V::Real::ZERO);
            let mut points: [[Tangent<V::Real>; 3]; N] = coordinates.map(|c| c.map(constant));
            for k in 0..N {
                for axis in 0..3 {
                    points[k][axis].slope = V::Real::ONE;
                    self.program.run(0, &points, constant(rest), registers);
                    points[k][axis].slope = V::Real::ZERO;
                    let c = self.program.scalar(0, registers);
                    value = c.value;
                    gradients[k][axis] = c.slope;
                }
            }
        }
        let mut sound = value.finite();
        for g in &gradients {
            for &x in g {
                sound = sound & x.finite();
            }
        }
        let gradients = gradients.map(|g| V::select(sound, V::from_array(g), V::ZERO));
        VectorEvaluation {
            value: V::Real::select(value.finite(), value, V::Real::ZERO),
            gradients,
            degenerate: !sound,
        }
    }

    /// The rest value for particles at rest at `rest_points`: `rest = "…"` when the file gives
    /// it, otherwise C there with rest = 0.
    pub fn rest_value(&self, rest_points: &[DVec3]) -> f64 {
        match &self.rest_program {
            Some(program) => {
                let points: Vec<[f64; 3]> = rest_points.iter().map(|p| p.to_array()).collect();
                let mut registers = vec![[0.0; 3]; program.registers()];
                program.run(0, &points, 0.0, &mut registers);
                program.scalar(0, &registers)
            }
            None => self.value(rest_points, 0.0),
        }
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

/// The byte where a TOML string's content starts, given where the value starts: after `"`, `'`,
/// or `"""` / `'''` and the newline that may follow them. Offsets within the content then map
/// one to one onto the file, except after an escape sequence in a basic string.
fn content_start(text: &str, value_start: usize) -> usize {
    let rest = &text[value_start.min(text.len())..];
    let quote = if rest.starts_with("\"\"\"") || rest.starts_with("'''") {
        3
    } else if rest.starts_with('"') || rest.starts_with('\'') {
        1
    } else {
        0
    };
    let after = value_start + quote;
    let tail = &text[after.min(text.len())..];
    if quote == 3 {
        if tail.starts_with("\r\n") {
            return after + 2;
        } else if tail.starts_with('\n') {
            return after + 1;
        }
    }
    after
}
