//! What code says about a family without a table: the [`Visit`] traits through which a family's
//! [`Constraint`] type is reached ([`super::Families::visit`], the one place that dispatches on
//! the family), what a built-in family is ([`Family::builtins`], its row), how a binding lays
//! constraints on a mesh ([`Binding`]), and per-family data, [`PerFamily`], indexed by
//! [`Family`]. The rows are in [`super::table`]; the table of families a simulation uses, files
//! included, is a [`super::Families`] value.

pub use super::table::{Binding, Family, MAX_FAMILIES, Row, TABLE};

use super::Constraint;
use crate::scene::mesh::{TET_EDGES, TetMesh};
use std::fmt;
use std::ops::{Index, IndexMut};

/// Code that works on one family's constraints with the family's [`Constraint`] type known at
/// compile time (so that the formula is inlined into the loop, and into SIMD lanes).
pub trait Visit {
    /// What the visit gives.
    type Output;
    /// Works on `family`, whose constraints `constraint` evaluates, `N` particles each.
    fn visit<const N: usize, C: Constraint<N>>(
        self,
        family: Family,
        constraint: &C,
    ) -> Self::Output;
}

/// Code that works on the constraints of two families together (a pair projected as one,
/// [`Row::projected_with`]) with both [`Constraint`] types known at compile time.
pub trait VisitPair {
    /// What the visit gives.
    type Output;
    /// Works on the pair: `first` and `second` evaluate the constraints of each family.
    fn visit_pair<const N: usize, A: Constraint<N>, const M: usize, B: Constraint<M>>(
        self,
        first: &A,
        second: &B,
    ) -> Self::Output;
}

impl Family {
    /// The built-in families, in projection order (a table with files has more:
    /// [`super::Families::all`]).
    pub fn builtins() -> impl DoubleEndedIterator<Item = Family> + Clone {
        (0..TABLE.len()).map(Family::from_index)
    }

    /// The row of a built-in family; `None` for a file's, whose row is its table's
    /// ([`super::Families::row`]).
    pub fn builtin_row(self) -> Option<&'static Row> {
        TABLE.get(self.index())
    }

    /// Every place a table can have, 0 to [`MAX_FAMILIES`] − 1, whether or not a family stands
    /// there.
    pub(crate) fn places() -> impl Iterator<Item = Family> {
        (0..MAX_FAMILIES).map(Family::from_index)
    }

    /// Its XPBD compliance, when a [`super::material::Material`] gives it
    /// ([`Row::compliance_from_material`]; a built-in family's, never a file's).
    pub fn compliance_from_material(self) -> Option<fn(&super::material::Material) -> f64> {
        self.builtin_row()?.compliance_from_material
    }
}

/// A built-in family by its name; a file's by its place (its name is its table's:
/// [`super::Families::name`]).
impl fmt::Debug for Family {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self.builtin_row() {
            Some(row) => f.write_str(&row.name),
            None => write!(f, "family {}", self.index()),
        }
    }
}

impl fmt::Display for Family {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        fmt::Debug::fmt(self, f)
    }
}

impl Binding {
    /// How many particles each of its constraints has.
    pub fn arity(self) -> usize {
        match self {
            Binding::Edges => 2,
            Binding::Triangles => 3,
            Binding::Tets | Binding::TetVertices | Binding::Hinges => 4,
        }
    }

    /// The particles of every constraint of this binding on `mesh`, flat: `arity` indices per
    /// constraint, in constraint order.
    pub fn particles(self, mesh: &TetMesh) -> Vec<u32> {
        match self {
            Binding::Edges => mesh.edges().into_iter().flatten().collect(),
            Binding::Tets => mesh.tets.iter().flatten().copied().collect(),
            Binding::Triangles => mesh.surface_faces().into_iter().flatten().collect(),
            Binding::Hinges => mesh.surface_hinges().into_iter().flatten().collect(),
            Binding::TetVertices => mesh
                .tets
                .iter()
                .flat_map(|t| {
                    super::height::tet_vertex_order()
                        .into_iter()
                        .flat_map(move |order| order.map(|k| t[k]))
                })
                .collect(),
        }
    }

    /// The constraints of this binding on tet `tet` (whose corners are `corners`), as indices
    /// among them; `edges` are the particles of an [`Binding::Edges`] family (sorted pairs,
    /// flat), which are looked up.
    pub fn of_tet<'a>(
        self,
        tet: usize,
        corners: [u32; 4],
        edges: &'a [u32],
    ) -> impl Iterator<Item = usize> + 'a {
        let (range, look_up) = match self {
            Binding::Edges => (0..0, true),
            Binding::Tets => (tet..tet + 1, false),
            Binding::TetVertices => (4 * tet..4 * tet + 4, false),
            // Of the surface, not of a tet.
            Binding::Triangles | Binding::Hinges => (0..0, false),
        };
        let pairs = pairs(edges);
        let looked_up = TET_EDGES
            .iter()
            .filter(move |_| look_up)
            .filter_map(move |&(a, b)| {
                let key = [corners[a].min(corners[b]), corners[a].max(corners[b])];
                pairs.binary_search(&key).ok()
            });
        range.chain(looked_up)
    }
}

/// Flat pairs as pairs.
fn pairs(flat: &[u32]) -> &[[u32; 2]] {
    let (pairs, rest) = flat.as_chunks::<2>();
    debug_assert!(rest.is_empty(), "pairs come in twos");
    pairs
}

/// One value per family of the table, indexed by [`Family`].
#[derive(Clone, Copy, PartialEq)]
pub struct PerFamily<T>([T; MAX_FAMILIES]);

impl<T: Default> Default for PerFamily<T> {
    fn default() -> Self {
        PerFamily(std::array::from_fn(|_| T::default()))
    }
}

impl<T> PerFamily<T> {
    /// The value in every place of a table, those where no family stands included (there it is
    /// what it was made with: the default, or a splat).
    pub fn every_place(&self) -> impl Iterator<Item = &T> {
        self.0.iter()
    }

    /// `f(i)` for each place i of a table, 0 to [`MAX_FAMILIES`] − 1
    /// ([`super::Families::per_family`] gives the places beyond its families the default).
    pub(super) fn from_slots(f: impl FnMut(usize) -> T) -> Self {
        PerFamily(std::array::from_fn(f))
    }
}

impl<T: Copy> PerFamily<T> {
    /// The same value for every family.
    pub const fn splat(value: T) -> Self {
        PerFamily([value; MAX_FAMILIES])
    }

    /// The value for `family`.
    pub fn get(&self, family: Family) -> T {
        self.0[family.index()]
    }

    /// Sets the value for `family`.
    pub fn set(&mut self, family: Family, value: T) {
        self.0[family.index()] = value;
    }

    /// `f(family)` for each built-in family, the default for the rest (a table's families:
    /// [`super::Families::per_family`]).
    pub fn builtin_from_fn(f: impl Fn(Family) -> T) -> Self
    where
        T: Default,
    {
        PerFamily::from_slots(|i| {
            if i < TABLE.len() {
                f(Family::from_index(i))
            } else {
                T::default()
            }
        })
    }
}

impl<T> PerFamily<T> {
    /// The values of two different families, both mutable.
    ///
    /// # Panics
    /// If `a` and `b` are the same family.
    pub fn pair_mut(&mut self, a: Family, b: Family) -> (&mut T, &mut T) {
        let (i, j) = (a.index(), b.index());
        assert_ne!(i, j, "a pair of two different families");
        if i < j {
            let (low, high) = self.0.split_at_mut(j);
            (&mut low[i], &mut high[0])
        } else {
            let (low, high) = self.0.split_at_mut(i);
            (&mut high[0], &mut low[j])
        }
    }
}

impl<T> Index<Family> for PerFamily<T> {
    type Output = T;
    fn index(&self, family: Family) -> &T {
        &self.0[family.index()]
    }
}

impl<T> IndexMut<Family> for PerFamily<T> {
    fn index_mut(&mut self, family: Family) -> &mut T {
        &mut self.0[family.index()]
    }
}

impl<T: fmt::Debug> fmt::Debug for PerFamily<T> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_map()
            .entries((0..MAX_FAMILIES).map(|i| (Family::from_index(i), &self.0[i])))
            .finish()
    }
}

impl PerFamily<bool> {
    /// The built-in families named in a comma-separated list (`edges,volume`), as
    /// [`super::Families::parse_list`] of the built-in table reads it: for code and tests that
    /// name built-in families; what a user writes is read by the table in use.
    ///
    /// ```
    /// use tetlab_core::constraints::{Family, PerFamily};
    /// let active = PerFamily::builtin_list("edges, plane").unwrap();
    /// assert!(active[Family::EDGES] && active[Family::HEIGHT] && !active[Family::VOLUME]);
    /// ```
    pub fn builtin_list(text: &str) -> Result<PerFamily<bool>, String> {
        super::Families::builtin().parse_list(text)
    }

    /// The active families, in projection order.
    pub fn families(&self) -> impl Iterator<Item = Family> + '_ {
        (0..MAX_FAMILIES)
            .filter(|&i| self.0[i])
            .map(Family::from_index)
    }
}

/// Written as a map from built-in family name to value (`{"edges": …, "height": …}`), so that
/// what is stored (the workbench's preferences, a link) reads back whatever the table holds
/// then. The families of constraint files are not written: they belong to a table the reader may
/// not have (a front end that writes them names them from its table,
/// [`super::Families::named`]).
impl<T: serde::Serialize + Copy> serde::Serialize for PerFamily<T> {
    fn serialize<S: serde::Serializer>(&self, serializer: S) -> Result<S::Ok, S::Error> {
        use serde::ser::SerializeMap;
        let mut map = serializer.serialize_map(Some(TABLE.len()))?;
        for family in Family::builtins() {
            map.serialize_entry(&*TABLE[family.index()].name, &self[family])?;
        }
        map.end()
    }
}

impl<'de, T: serde::Deserialize<'de> + Copy + Default> serde::Deserialize<'de> for PerFamily<T> {
    fn deserialize<D: serde::Deserializer<'de>>(deserializer: D) -> Result<Self, D::Error> {
        PerFamily::deserialize_over(deserializer, PerFamily::default())
    }
}

impl<T: Copy> PerFamily<T> {
    /// Reads the map that `Serialize` writes over `defaults`: a family the map lacks keeps its
    /// default, and a name that is not a built-in family's is left out.
    pub fn deserialize_over<'de, D: serde::Deserializer<'de>>(
        deserializer: D,
        mut defaults: PerFamily<T>,
    ) -> Result<Self, D::Error>
    where
        T: serde::Deserialize<'de>,
    {
        let map: std::collections::BTreeMap<String, T> =
            serde::Deserialize::deserialize(deserializer)?;
        for (name, value) in map {
            if let Ok(family) = super::Families::builtin().parse(&name) {
                defaults.set(family, value);
            }
        }
        Ok(defaults)
    }
}
