//! The table of constraint families: one [`Row`] per family, in projection order, for the
//! built-in families ([`TABLE`]); the families of constraint files join it at run time
//! ([`super::Families`]). A [`Family`] is a place in it.

use super::material::Material;
use std::borrow::Cow;

/// How many families the table can hold: the built-in ones and those read from constraint files
/// ([`super::Families`]).
pub const MAX_FAMILIES: usize = 16;

/// A constraint family: a row of [`TABLE`].
#[derive(Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct Family(u8);

/// How a family's constraints bind to a tet mesh, and so how many it has.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Binding {
    /// One constraint per edge of the mesh: (p0, p1), the edge's ends, smaller index first; in the
    /// order of [`crate::scene::mesh::TetMesh::edges`].
    Edges,
    /// One per tet: (p0, p1, p2, p3), the tet's corners in its own order.
    Tets,
    /// Four per tet, one per corner k: (p0, p1, p2, p3) with p1 = corner k, in the orders of
    /// [`super::height::tet_vertex_order`]; tet t's are constraints 4t..4t+4.
    TetVertices,
    /// One per triangle of the surface: (p0, p1, p2) wound so that (p1 − p0) × (p2 − p0) points
    /// out of the body ([`crate::scene::mesh::TetMesh::surface_faces`]).
    Triangles,
    /// One per edge of the surface that two surface triangles share: (p0, p1) the edge, as the
    /// first triangle (p0, p1, p2) winds it, p2 and p3 the wings, so that the second triangle
    /// is (p1, p0, p3), both wound outwards ([`crate::scene::mesh::TetMesh::surface_hinges`]).
    /// An edge of one surface triangle or of three or more (non-manifold) makes no hinge.
    Hinges,
}

/// A family as people see it, and as the code reaches it.
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
    /// same binding, so constraint c of each has the same particles), when both are active:
    /// [`crate::simulation::projection::pair_correction_lanes`]. The first of the two in the table leads.
    pub projected_with: Option<Family>,
    pub(super) kind: Kind,
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

/// Which [`super::Constraint`] type evaluates a family: the one `match` over families.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum Kind {
    Distance,
    Height,
    Volume,
    Deviatoric,
    Hydrostatic,
    /// A constraint file's compiled program ([`super::file::FileConstraint`]).
    File,
}

/// The families, in projection order (edges, heights, volumes, then the neo-Hookean pair).
pub static TABLE: [Row; 5] = [
    Row {
        name: Cow::Borrowed("edges"),
        aliases: &["edge", "distance"],
        title: Cow::Borrowed("Edge distance"),
        label: Cow::Borrowed("edges"),
        colour: [240, 150, 20, 255],
        formula: Formula::Builtin(super::distance::FORMULA),
        rest_symbol: "d",
        arity: 2,
        binding: Binding::Edges,
        group: Cow::Borrowed("edges"),
        compliance_from_material: None,
        projected_with: None,
        kind: Kind::Distance,
    },
    Row {
        name: Cow::Borrowed("height"),
        aliases: &["heights", "plane"],
        title: Cow::Borrowed("Heights above the opposite face"),
        label: Cow::Borrowed("heights"),
        colour: [40, 170, 60, 255],
        formula: Formula::Builtin(super::height::FORMULA),
        rest_symbol: "d",
        arity: 4,
        binding: Binding::TetVertices,
        group: Cow::Borrowed("height"),
        compliance_from_material: None,
        projected_with: None,
        kind: Kind::Height,
    },
    Row {
        name: Cow::Borrowed("volume"),
        aliases: &[],
        title: Cow::Borrowed("Signed volume"),
        label: Cow::Borrowed("volume"),
        colour: [50, 100, 230, 255],
        formula: Formula::Builtin(super::volume::FORMULA),
        rest_symbol: "V",
        arity: 4,
        binding: Binding::Tets,
        group: Cow::Borrowed("volume"),
        compliance_from_material: None,
        projected_with: None,
        kind: Kind::Volume,
    },
    Row {
        name: Cow::Borrowed("neohookean-deviatoric"),
        aliases: &["deviatoric"],
        title: Cow::Borrowed("Neo-Hookean, deviatoric"),
        label: Cow::Borrowed("neo-Hookean dev."),
        colour: [160, 95, 40, 255],
        formula: Formula::Builtin(super::neohookean::DEVIATORIC_FORMULA),
        rest_symbol: "0",
        arity: 4,
        binding: Binding::Tets,
        group: Cow::Borrowed("neohookean"),
        compliance_from_material: Some(|m| 1.0 / m.mu()),
        projected_with: Some(Family::NEOHOOKEAN_HYDROSTATIC),
        kind: Kind::Deviatoric,
    },
    Row {
        name: Cow::Borrowed("neohookean-hydrostatic"),
        aliases: &["hydrostatic"],
        title: Cow::Borrowed("Neo-Hookean, hydrostatic"),
        label: Cow::Borrowed("neo-Hookean hyd."),
        colour: [135, 80, 225, 255],
        formula: Formula::Builtin(super::neohookean::HYDROSTATIC_FORMULA),
        rest_symbol: "s γ",
        arity: 4,
        binding: Binding::Tets,
        group: Cow::Borrowed("neohookean"),
        compliance_from_material: Some(|m| 1.0 / m.lambda()),
        projected_with: Some(Family::NEOHOOKEAN_DEVIATORIC),
        kind: Kind::Hydrostatic,
    },
];

// The neo-Hookean pair is led by its deviatoric half ([`super::PairGroup`]): pair code is compiled
// only in that order, so the table must keep that half first.
const _: () = assert!(Family::NEOHOOKEAN_DEVIATORIC.0 < Family::NEOHOOKEAN_HYDROSTATIC.0);

impl Family {
    /// Edge distance ([`super::distance`]).
    pub const EDGES: Family = Family(0);
    /// The four heights of each tet ([`super::height`]).
    pub const HEIGHT: Family = Family(1);
    /// Signed volume ([`super::volume`]).
    pub const VOLUME: Family = Family(2);
    /// The deviatoric half of a neo-Hookean tet ([`super::neohookean`]).
    pub const NEOHOOKEAN_DEVIATORIC: Family = Family(3);
    /// The hydrostatic half of a neo-Hookean tet ([`super::neohookean`]).
    pub const NEOHOOKEAN_HYDROSTATIC: Family = Family(4);

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
