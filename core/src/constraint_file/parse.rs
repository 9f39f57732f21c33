//! Reading a constraint file: the TOML ([`Raw`]), then each of its constraints compiled
//! ([`parse_all`]), every mistake placed at file:line:column of the file as written (offsets in a
//! TOML string's content mapped back through its escapes, [`file_offset`]).
//!
//! One constraint is written at the top level (`value = "…"`); several as `[[constraint]]`
//! tables, which share the top level's `define`, and may ask for two of them to be projected as
//! a pair (`pair = ["a", "b"]`). Each family is then named `FILE-CONSTRAINT`, and the file's name
//! names the group of them (`--constraints my-neohookean`).

use super::expression;
use super::program::{CompileError, Program, Type};
use super::selection::{Selection, SelectionError};
use super::{ConstraintFile, ConstraintFileError, GradeOnce, Stiffness};
use crate::constraints::Binding;
use crate::input::text_file;
use crate::input::text_file::position;
use std::collections::BTreeMap;
use std::path::Path;
use toml::Spanned;

#[derive(serde::Deserialize)]
#[serde(deny_unknown_fields)]
struct Raw {
    name: Spanned<String>,
    applies_to: Spanned<String>,
    /// Which particles, of a file on single particles: a condition on the rest position.
    #[serde(default, rename = "where")]
    condition: Option<Spanned<String>>,
    #[serde(default)]
    define: Option<Spanned<String>>,
    // A file of one constraint says it here; see RawConstraint.
    #[serde(default)]
    value: Option<Spanned<String>>,
    #[serde(default)]
    rest: Option<Spanned<String>>,
    #[serde(default)]
    gradient: BTreeMap<Spanned<String>, Spanned<String>>,
    #[serde(default)]
    use_gradient: bool,
    #[serde(default)]
    hessian: BTreeMap<Spanned<String>, Spanned<String>>,
    #[serde(default)]
    stiffness: Option<Spanned<String>>,
    #[serde(default)]
    constraint: Vec<RawNamed>,
    #[serde(default)]
    pair: Option<Spanned<Vec<Spanned<String>>>>,
}

/// What one constraint says: at the top level of a file of one, or in a `[[constraint]]`
/// ([`RawNamed`]; serde's `flatten` would lose `deny_unknown_fields`, so the fields are written
/// out in each).
#[derive(Default)]
struct RawConstraint {
    value: Option<Spanned<String>>,
    rest: Option<Spanned<String>>,
    gradient: BTreeMap<Spanned<String>, Spanned<String>>,
    use_gradient: bool,
    hessian: BTreeMap<Spanned<String>, Spanned<String>>,
    stiffness: Option<Spanned<String>>,
}

#[derive(serde::Deserialize)]
#[serde(deny_unknown_fields)]
struct RawNamed {
    name: Spanned<String>,
    #[serde(default)]
    value: Option<Spanned<String>>,
    #[serde(default)]
    rest: Option<Spanned<String>>,
    #[serde(default)]
    gradient: BTreeMap<Spanned<String>, Spanned<String>>,
    #[serde(default)]
    use_gradient: bool,
    #[serde(default)]
    hessian: BTreeMap<Spanned<String>, Spanned<String>>,
    #[serde(default)]
    stiffness: Option<Spanned<String>>,
}

impl RawNamed {
    fn constraint(&self) -> RawConstraint {
        RawConstraint {
            value: self.value.clone(),
            rest: self.rest.clone(),
            gradient: self.gradient.clone(),
            use_gradient: self.use_gradient,
            hessian: self.hessian.clone(),
            stiffness: self.stiffness.clone(),
        }
    }
}

/// Every constraint of the file `text` (`path` names it in errors), in the order written.
pub(super) fn parse_all(
    path: &Path,
    text: &str,
) -> Result<Vec<ConstraintFile>, ConstraintFileError> {
    let text = text_file::without_byte_order_mark(text);
    let error = |offset: Option<usize>, message: String| ConstraintFileError {
        path: path.to_owned(),
        at: offset.map(|o| position(text, o)),
        message,
    };
    let raw: Raw = toml::from_str(text).map_err(|e| {
        let message = e.message().trim().replace('\n', " ");
        error(e.span().map(|s| s.start), message)
    })?;
    let binding = match raw.applies_to.get_ref().as_str() {
        "edges" => Binding::Edges,
        "tets" => Binding::Tets,
        "tet-vertices" => Binding::TetVertices,
        "triangles" => Binding::Triangles,
        "hinges" => Binding::Hinges,
        "particles" => Binding::Particles,
        "contacts" => Binding::Contacts,
        other => {
            return Err(error(
                Some(raw.applies_to.span().start),
                format!(
                    "applies_to is \"{other}\": expected \"edges\" (p0 p1), \"tets\" \
                     (p0..p3), \"tet-vertices\" (p0..p3, four per tet), \"triangles\" (p0 p1 \
                     p2, the surface's, wound outwards), \"hinges\" (p0 p1 an edge of the \
                     surface, p2 p3 the wings), \"particles\" (p0, those `where` chooses) or \"contacts\" (p0 \
                     a particle, p1 p2 p3 a surface triangle it meets, wound outwards)"
                ),
            ));
        }
    };
    let checked_name = |name: &Spanned<String>| {
        let trimmed = name.get_ref().trim().to_owned();
        if trimmed.is_empty()
            || !trimmed
                .chars()
                .all(|c| c.is_ascii_alphanumeric() || c == '-' || c == '_')
        {
            return Err(error(
                Some(name.span().start),
                format!(
                    "name \"{trimmed}\": use letters, digits, - and _ (it names the family on the command line)"
                ),
            ));
        }
        Ok(trimmed)
    };
    let file_name = checked_name(&raw.name)?;
    let selection = match &raw.condition {
        None => None,
        Some(condition) if binding != Binding::Particles => {
            return Err(error(
                Some(condition.span().start),
                format!(
                    "`where` chooses single particles, and this file applies to \"{}\": write \
                     applies_to = \"particles\"",
                    raw.applies_to.get_ref()
                ),
            ));
        }
        Some(condition) => {
            let at = condition.span().start;
            let source = condition.get_ref();
            Some(Selection::compile(source).map_err(|e| match e {
                SelectionError::Syntax(e) => error(
                    Some(file_offset(text, at, e.offset)),
                    format!("in where: {}", e.message),
                ),
                SelectionError::Compile(e) => {
                    let snippet = source.get(e.span.start..e.span.end).unwrap_or("").trim();
                    error(
                        Some(file_offset(text, at, e.span.start)),
                        format!("in where: {} (`{snippet}`)", e.message),
                    )
                }
            })?)
        }
    };
    let shared = Shared {
        path,
        text,
        binding,
        define: raw.define.as_ref(),
        selection,
    };
    let single = RawConstraint {
        value: raw.value.clone(),
        rest: raw.rest.clone(),
        gradient: raw.gradient.clone(),
        use_gradient: raw.use_gradient,
        hessian: raw.hessian.clone(),
        stiffness: raw.stiffness.clone(),
    };
    if raw.constraint.is_empty() {
        if let Some(pair) = &raw.pair {
            return Err(error(
                Some(pair.span().start),
                "`pair` names two [[constraint]] tables, and this file has none".to_owned(),
            ));
        }
        let Some(value) = &single.value else {
            // Where it would go: after the last key before the first table (`[gradient]`).
            let keys_end = text
                .match_indices('\n')
                .map(|(i, _)| i + 1)
                .find(|&i| text[i..].trim_start_matches([' ', '\t']).starts_with('['))
                .unwrap_or(text.len());
            return Err(error(
                Some(keys_end),
                "no `value`: give C as `value = \"…\"` (before any [table]), or several as \
                 [[constraint]] tables"
                    .to_owned(),
            ));
        };
        let files = vec![shared.compile(file_name, None, value, &single)?];
        what_a_contact_has(&files, binding, &raw.applies_to, &error)?;
        return Ok(files);
    }
    let stray = [&raw.value, &raw.rest, &raw.stiffness]
        .into_iter()
        .flatten()
        .chain(raw.gradient.values())
        .chain(raw.hessian.values())
        .next();
    if let Some(value) = stray {
        return Err(error(
            Some(value.span().start),
            "this file has [[constraint]] tables: give each its own `value`, `rest`, `stiffness` and \
             [gradient] and [hessian] there, not at the top"
                .to_owned(),
        ));
    }
    let mut files = Vec::new();
    for (k, named) in raw.constraint.iter().enumerate() {
        let own = checked_name(&named.name)?;
        let constraint = named.constraint();
        // Named at the second of the two.
        if raw.constraint[..k]
            .iter()
            .any(|n| n.name.get_ref().trim() == own)
        {
            return Err(error(
                Some(named.name.span().start),
                format!("two [[constraint]] tables are named \"{own}\""),
            ));
        }
        let Some(value) = &constraint.value else {
            return Err(error(
                Some(named.name.span().start),
                format!("[[constraint]] \"{own}\" has no `value`: give its C as `value = \"…\"`"),
            ));
        };
        let mut file = shared.compile(
            format!("{file_name}-{own}"),
            Some(file_name.clone()),
            value,
            &constraint,
        )?;
        file.formula.insert(0, format!("[{own}]"));
        files.push(file);
    }
    if let Some(pair) = &raw.pair {
        // A pin's projection is one particle's, a contact's its own pair's: nothing to share
        // with another's.
        if binding == Binding::Contacts {
            return Err(error(
                Some(pair.span().start),
                "`pair` projects two constraints together, and a file on contacts \
                 (applies_to = \"contacts\") projects each alone"
                    .to_owned(),
            ));
        }
        if binding == Binding::Particles {
            return Err(error(
                Some(pair.span().start),
                "`pair` projects two constraints together, and a file on single particles \
                 (applies_to = \"particles\") projects each alone"
                    .to_owned(),
            ));
        }
        let names = pair.get_ref();
        if names.len() != 2 || names[0].get_ref() == names[1].get_ref() {
            return Err(error(
                Some(pair.span().start),
                "`pair` names two different constraints of the file: pair = [\"a\", \"b\"]"
                    .to_owned(),
            ));
        }
        let mut places = [0; 2];
        for (k, name) in names.iter().enumerate() {
            let wanted = format!("{file_name}-{}", name.get_ref().trim());
            places[k] = files.iter().position(|f| f.name == wanted).ok_or_else(|| {
                error(
                    Some(name.span().start),
                    format!(
                        "`pair` names \"{}\", and the file's constraints are {}",
                        name.get_ref(),
                        raw.constraint
                            .iter()
                            .map(|c| format!("\"{}\"", c.name.get_ref().trim()))
                            .collect::<Vec<_>>()
                            .join(", ")
                    ),
                )
            })?;
        }
        let [a, b] = places;
        let (name_a, name_b) = (files[a].name.clone(), files[b].name.clone());
        files[a].pair = Some(name_b);
        files[b].pair = Some(name_a);
    }
    what_a_contact_has(&files, binding, &raw.applies_to, &error)?;
    Ok(files)
}

/// A constraint on contacts is found where two surfaces meet, not laid on the rest shape: it
/// reads no rest shape (in C, its gradient or what it stores), gives no rest value of its own
/// (its `rest` is the contact's thickness) and no motion (friction is the contact's own). Any
/// of them is refused at `applies_to`.
fn what_a_contact_has(
    files: &[ConstraintFile],
    binding: Binding,
    applies_to: &Spanned<String>,
    error: &dyn Fn(Option<usize>, String) -> ConstraintFileError,
) -> Result<(), ConstraintFileError> {
    if binding != Binding::Contacts {
        return Ok(());
    }
    let at = Some(applies_to.span().start);
    for file in files {
        let c_reads_rest = [&file.value, &file.gradient, &file.yours]
            .iter()
            .any(|tape| tape.reads_rest_shape());
        if c_reads_rest || file.reads_rest_shape() || file.stored_len() > 0 || file.has_own_rest() {
            return Err(error(
                at,
                format!(
                    "{}: a constraint on contacts has no rest shape (q0…, Dm, V0) and no rest \
                     of its own: `rest` in C is the contact's thickness",
                    file.name
                ),
            ));
        }
        if file.reads_motion() {
            return Err(error(
                at,
                format!(
                    "{}: a constraint on contacts reads where its particles are, not where they \
                     were (start0…, h): friction is the contact's own",
                    file.name
                ),
            ));
        }
    }
    Ok(())
}

/// What the constraints of a file share: where it is, its text, its binding and `define`.
struct Shared<'a> {
    path: &'a Path,
    text: &'a str,
    binding: Binding,
    define: Option<&'a Spanned<String>>,
    /// The particles a file on single particles applies to (`where`).
    selection: Option<Selection>,
}

impl Shared<'_> {
    fn error(&self, offset: Option<usize>, message: String) -> ConstraintFileError {
        ConstraintFileError {
            path: self.path.to_owned(),
            at: offset.map(|o| position(self.text, o)),
            message,
        }
    }

    /// A program with the file's definitions (and `rest` when `with_rest`).
    fn program(&self, with_rest: bool) -> Result<Program, ConstraintFileError> {
        let mut program = Program::new(self.binding.arity(), with_rest);
        if let Some(define) = self.define {
            // An expression's errors are placed by where its TOML string starts (`at`).
            let at = define.span().start;
            let parsed = expression::parse_definitions(define.get_ref()).map_err(|e| {
                self.error(
                    Some(file_offset(self.text, at, e.offset)),
                    format!("in define: {}", e.message),
                )
            })?;
            program.at(at);
            for (name, span, expr) in &parsed {
                program
                    .define(name, *span, expr)
                    .map_err(|e| self.compile_error(at, e, define.get_ref(), "define"))?;
            }
        }
        Ok(program)
    }

    fn compile_error(
        &self,
        at: usize,
        e: CompileError,
        source: &str,
        what: &str,
    ) -> ConstraintFileError {
        let snippet = source.get(e.span.start..e.span.end).unwrap_or("").trim();
        self.error(
            Some(file_offset(self.text, at, e.span.start)),
            format!("in {what}: {} (`{snippet}`)", e.message),
        )
    }

    /// Compiles `spanned` into `program` as an output of type `ty`.
    fn output(
        &self,
        program: &mut Program,
        spanned: &Spanned<String>,
        ty: Type,
        what: &str,
    ) -> Result<usize, ConstraintFileError> {
        let at = spanned.span().start;
        let expr = expression::parse_expression(spanned.get_ref()).map_err(|e| {
            self.error(
                Some(file_offset(self.text, at, e.offset)),
                format!("in {what}: {}", e.message),
            )
        })?;
        program.at(at);
        program
            .output(&expr, ty, what)
            .map_err(|e| self.compile_error(at, e, spanned.get_ref(), what))
    }

    /// One constraint, named `name`, of the group `group` (a file of several).
    fn compile(
        &self,
        name: String,
        group: Option<String>,
        value: &Spanned<String>,
        raw: &RawConstraint,
    ) -> Result<ConstraintFile, ConstraintFileError> {
        let arity = self.binding.arity();
        let mut program = self.program(true)?;
        let c = self.output(&mut program, value, Type::Scalar, "value")?;
        let mut given = [None; 4];
        for (key, entry) in &raw.gradient {
            let particle = key
                .get_ref()
                .strip_prefix('p')
                .and_then(|k| k.parse::<usize>().ok())
                .filter(|&k| k < arity && key.get_ref().len() == 2);
            let Some(k) = particle else {
                return Err(self.error(
                    Some(key.span().start),
                    format!(
                        "gradient entry `{}`: this binding has {} only",
                        key.get_ref(),
                        particle_names(arity)
                    ),
                ));
            };
            let what = format!("gradient.{}", key.get_ref());
            given[k] = Some(self.output(&mut program, entry, Type::VECTOR, &what)?);
        }
        // The file's own Hessian blocks ∂²C/∂pᵢ∂pⱼ, each a matrix (three outputs).
        let mut blocks = Vec::new();
        for (key, entry) in &raw.hessian {
            let pair = hessian_key(key.get_ref(), arity).ok_or_else(|| {
                self.error(
                    Some(key.span().start),
                    format!(
                        "hessian entry `{}`: name a block pIpJ, I and J of the binding's {} \
                         (`p0p1` is ∂²C/∂p0∂p1, a matrix)",
                        key.get_ref(),
                        particle_names(arity)
                    ),
                )
            })?;
            if blocks
                .iter()
                .any(|&(p, _)| p == pair || p == (pair.1, pair.0))
            {
                return Err(self.error(
                    Some(key.span().start),
                    format!(
                        "hessian entry `{}`: that block is given twice (p{}p{} is the transpose of \
                         p{}p{})",
                        key.get_ref(),
                        pair.0,
                        pair.1,
                        pair.1,
                        pair.0
                    ),
                ));
            }
            let what = format!("hessian.{}", key.get_ref());
            blocks.push((pair, self.output(&mut program, entry, Type::MATRIX, &what)?));
        }
        // ∇C by AD, compiled: C's tape with it, and the file's own where it gives none.
        program.at(value.span().start);
        let automatic = program
            .differentiate(c)
            .map_err(|e| self.compile_error(value.span().start, e, value.get_ref(), "value"))?;
        let mut by_ad = vec![c];
        by_ad.extend(&automatic);
        let mut yours = vec![c];
        yours.extend((0..arity).map(|k| given[k].unwrap_or(automatic[k])));
        let hessian_outputs: Vec<usize> = blocks
            .iter()
            .flat_map(|&(_, first)| first..first + 3)
            .collect();
        let compiled = program
            .compiled(&[&[c], &by_ad, &yours])
            .map_err(|message| self.error(Some(value.span().start), message))?;
        let [value_tape, gradient, yours] =
            <[_; 3]>::try_from(compiled.tapes).expect("three groups");
        // The Hessian blocks only the check runs: one tape that reads the rest shape itself, so
        // that what they depend on costs no element any storage.
        let hessian = program.tape(&hessian_outputs);
        let rest = match &raw.rest {
            Some(rest) => {
                let mut program = self.program(false)?;
                let r = self.output(&mut program, rest, Type::Scalar, "rest")?;
                Some(program.tape(&[r]))
            }
            None => None,
        };
        let stiffness = match &raw.stiffness {
            None => None,
            Some(s) => Some(match s.get_ref().trim() {
                "mu" => Stiffness::Mu,
                "lambda" => Stiffness::Lambda,
                other => {
                    return Err(self.error(
                        Some(s.span().start),
                        format!(
                            "stiffness is \"{other}\": expected \"mu\" (compliance 1/μ) or \
                             \"lambda\" (compliance 1/λ), both from --material"
                        ),
                    ));
                }
            }),
        };
        let mut formula: Vec<String> = self
            .define
            .map(|d| {
                d.get_ref()
                    .lines()
                    .map(str::trim)
                    .filter(|l| !l.is_empty())
                    .map(str::to_owned)
                    .collect()
            })
            .unwrap_or_default();
        formula.push(format!(
            "C = {}",
            value
                .get_ref()
                .split_whitespace()
                .collect::<Vec<_>>()
                .join(" ")
        ));
        Ok(ConstraintFile {
            path: self.path.to_owned(),
            name,
            group,
            binding: self.binding,
            use_gradient: raw.use_gradient,
            stiffness,
            pair: None,
            source: self.text.to_owned(),
            formula,
            prelude: compiled.prelude,
            stored: compiled.stored,
            value: value_tape,
            gradient,
            yours,
            gives: given.map(|g| g.is_some()),
            hessian: (!blocks.is_empty()).then_some(hessian),
            hessian_blocks: blocks.iter().map(|&(pair, _)| pair).collect(),
            rest,
            selection: self.selection.clone(),
            grade: GradeOnce::default(),
        })
    }
}

/// The particles of a binding of `arity`: `particle p0` or `particles p0…p3`.
fn particle_names(arity: usize) -> String {
    match arity {
        1 => "particle p0".to_owned(),
        _ => format!("particles p0…p{}", arity - 1),
    }
}

/// The particles (i, j) of a Hessian block's key `pIpJ`, both below `arity`.
fn hessian_key(key: &str, arity: usize) -> Option<(usize, usize)> {
    let rest = key.strip_prefix('p')?;
    let (i, j) = rest.split_once('p')?;
    let (i, j) = (i.parse::<usize>().ok()?, j.parse::<usize>().ok()?);
    (i < arity && j < arity && key.len() == 4).then_some((i, j))
}

/// The byte of `text` that byte `offset` of a TOML string's content comes from, the string's
/// value starting at byte `value_start` (its opening quote). The content starts after `"`, `'`,
/// or `"""` / `'''` and the newline that may follow them; in a basic (double-quoted) string an
/// escape such as `\t` is two bytes of the file for one of the content, `\uXXXX` six, and a
/// backslash at the end of a line of a `"""` string stands for the white space after it.
pub(super) fn file_offset(text: &str, value_start: usize, offset: usize) -> usize {
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
