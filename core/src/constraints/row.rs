//! What a constraint family is, as data: its [`Row`] (names, colour, formula lines, binding,
//! material, partner, and what its formula reads and stores), and [`Family`], its place in a
//! table. The built-in rows are in [`super::builtin`]; a constraint file's row is made when the
//! file joins a [`super::Families`] table.
//!
//! Everything the program asks about a family that is not its formula is a field here: one line
//! to read, never a visit of its type. A test (`core/tests/family_rows.rs`) holds every row to
//! what its type does, so that a row cannot say one thing while its formula does another.

use super::binding::Binding;
use super::material::Material;
use std::borrow::Cow;

/// How many families a table can hold: the built-in ones and those read from constraint files
/// ([`super::Families`]).
pub const MAX_FAMILIES: usize = 16;

/// A constraint family: a place in a table of families ([`super::Families`]), the built-in ones
/// first ([`super::TABLE`]).
#[derive(Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct Family(pub(super) u8);

impl Family {
    /// The family in place `index` of a table.
    pub(crate) fn from_index(index: usize) -> Family {
        debug_assert!(index < MAX_FAMILIES);
        Family(index as u8)
    }

    /// The family's place in the table: what [`super::PerFamily`] is indexed by.
    pub fn index(self) -> usize {
        self.0 as usize
    }
}

/// A family as people see it and as the program reads it. Every field is data; the formula
/// itself is the family's [`super::Constraint`] type, reached through [`super::Families::visit`]
/// in the solvers' loops and [`super::Families::constraint`] everywhere else.
#[derive(Clone, Debug)]
pub struct Row {
    /// Its name on the command line, in files, JSON keys and recordings' entity paths.
    pub name: Cow<'static, str>,
    /// Other spellings the command line and files accept.
    pub aliases: &'static [&'static str],
    /// A title for headings: "Edge distance".
    pub title: Cow<'static, str>,
    /// A short label for legends and buttons: "edges".
    pub label: Cow<'static, str>,
    /// The colour of its gradient arrows (sRGB and alpha), the same in the workbench and in
    /// recordings.
    pub colour: [u8; 4],
    /// The constraint and its gradients as lines of math (the inspector, lessons).
    pub formula: Formula,
    /// What the rest value is called in the formula: d or V.
    pub rest_symbol: &'static str,
    /// How many particles one constraint touches.
    pub arity: usize,
    /// How it binds to a mesh.
    pub binding: Binding,
    /// The name of the group it belongs to on the command line and in the workbench: its own
    /// name, or that of the families it comes with (`neohookean` names both neo-Hookean ones).
    pub group: Cow<'static, str>,
    /// Its XPBD compliance, when a [`Material`] gives it (per unit rest volume: the constraint is
    /// scaled by √V₀); otherwise the compliance is set per family.
    pub compliance_from_material: Option<fn(&Material) -> f64>,
    /// The family its constraints are projected together with, constraint by constraint (the
    /// same binding, so constraint c of each has the same particles), when both are active: one
    /// projection of two values ([`super::Projected`] with K = 2). The first of the two in the
    /// table leads.
    pub projected_with: Option<Family>,
    /// Whether its formula reads the rest shape of its particles (the neo-Hookean pair's Dm; a
    /// file that names q0…q3, Dm, F or V0): tools then ask for a rest shape beside the points.
    pub reads_rest_shape: bool,
    /// Whether its rest values depend on the material, so that they are measured again when it
    /// changes.
    pub rest_uses_material: bool,
    /// How many numbers each of its elements stores beyond its rest value
    /// ([`super::Constraint::store`]): what depends only on the rest shape and the material.
    pub stored_len: usize,
}

/// A family's constraint and gradients as lines of math: written in the code for a built-in
/// family, the file's `define` and `value` lines for a file's.
#[derive(Clone, Debug)]
pub enum Formula {
    /// Lines written in the code.
    Builtin(&'static [&'static str]),
    /// Lines read from a file.
    File(Vec<String>),
}

impl Formula {
    /// The lines, in order.
    pub fn lines(&self) -> impl Iterator<Item = &str> {
        let (builtin, file): (&[&str], &[String]) = match self {
            Formula::Builtin(lines) => (lines, &[]),
            Formula::File(lines) => (&[], lines),
        };
        builtin
            .iter()
            .copied()
            .chain(file.iter().map(String::as_str))
    }
}

impl Family {
    /// The built-in families, in projection order (a table with files has more:
    /// [`super::Families::all`]).
    pub fn builtins() -> impl DoubleEndedIterator<Item = Family> + Clone {
        (0..super::TABLE.len()).map(Family::from_index)
    }

    /// The row of a built-in family; `None` for a file's, whose row is its table's
    /// ([`super::Families::row`]).
    pub fn builtin_row(self) -> Option<&'static Row> {
        super::TABLE.get(self.index())
    }

    /// Every place a table can have, 0 to [`MAX_FAMILIES`] − 1, whether or not a family stands
    /// there.
    pub(crate) fn places() -> impl Iterator<Item = Family> {
        (0..MAX_FAMILIES).map(Family::from_index)
    }
}

/// A built-in family by its name; a file's by its place (its name is its table's:
/// [`super::Families::name`]).
impl std::fmt::Debug for Family {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self.builtin_row() {
            Some(row) => f.write_str(&row.name),
            None => write!(f, "family {}", self.index()),
        }
    }
}

impl std::fmt::Display for Family {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        std::fmt::Debug::fmt(self, f)
    }
}
