//! The constraint families, described in one place: one row of [`TABLE`] per family holds its
//! names, how it is drawn and written, its arity and how it binds to a mesh, and which
//! [`Constraint`] type evaluates it. Everything that handles a family (parsing, both solvers, the
//! stepper, the inspector, what is drawn and recorded, the workbench, lessons) reads the row, and
//! reaches the family's formula through [`Family::visit`], the one place that dispatches on the
//! family. Adding a family is a file with its [`Constraint`] type plus a row here.
//!
//! Per-family data has one shape, [`PerFamily`], indexed by [`Family`].

pub use super::table::{Binding, Family, MAX_FAMILIES, Row, TABLE};

use super::file::FileConstraint;
use super::neohookean::{Deviatoric, Hydrostatic};
use super::registry;
use super::table::Kind;
use super::{Constraint, Evaluation, distance::Distance, height::Height, volume::Volume};
use crate::constraints::material::Material;
use crate::scene::mesh::{TET_EDGES, TetMesh};
use glam::DVec3;
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
    /// Every family of the table, in projection order: the built-in ones, then those read from
    /// constraint files ([`Family::register`]).
    pub fn all() -> impl DoubleEndedIterator<Item = Family> + Clone {
        (0..registry::count()).map(Family::from_index)
    }

    /// Its row of the table.
    pub fn row(self) -> &'static Row {
        match TABLE.get(self.index()) {
            Some(row) => row,
            None => registry::row(self.index() - TABLE.len()),
        }
    }

    /// The constraint file it was read from, for a family that was.
    pub fn file(self) -> Option<std::sync::Arc<crate::constraint_file::ConstraintFile>> {
        (self.index() >= TABLE.len()).then(|| registry::file(self.index() - TABLE.len()))
    }

    /// Which definition of the family is in force: 0 for a built-in family, a number that
    /// changes whenever a file's family is (re)defined ([`Family::define`]), so that constraints
    /// built from an older definition are rebuilt.
    pub fn generation(self) -> u64 {
        match self.index().checked_sub(TABLE.len()) {
            Some(slot) => registry::generation(slot),
            None => 0,
        }
    }

    /// Its name ([`Row::name`]).
    pub fn name(self) -> &'static str {
        self.row().name
    }

    /// How many particles one of its constraints touches.
    pub fn arity(self) -> usize {
        self.row().arity
    }

    /// Its formula, as lines of math.
    pub fn formula(self) -> &'static [&'static str] {
        self.row().formula
    }

    /// The family a user means, by its name or one of its aliases (spaces around allowed), as
    /// the command line and lesson files write it.
    ///
    /// ```
    /// use tetlab_core::constraints::Family;
    /// assert_eq!(Family::parse(" edges"), Ok(Family::EDGES));
    /// assert_eq!(Family::parse("plane"), Ok(Family::HEIGHT));
    /// assert!(Family::parse("edgy").unwrap_err().contains("'edgy'"));
    /// ```
    pub fn parse(text: &str) -> Result<Family, String> {
        let text = text.trim();
        Family::all()
            .find(|f| f.name() == text || f.row().aliases.contains(&text))
            .ok_or_else(|| {
                let names: Vec<&str> = Family::all().map(Family::name).collect();
                if Family::groups().any(|(group, _)| group == text) {
                    return format!(
                        "'{text}' names several families here: give one of {}",
                        names.join(", ")
                    );
                }
                format!(
                    "'{text}' is not a constraint family: expected {}",
                    names.join(", ")
                )
            })
    }

    /// Calls `visitor` with the family's [`Constraint`] type.
    #[inline]
    pub fn visit<T: Visit>(self, visitor: T) -> T::Output {
        match self.row().kind {
            Kind::Distance => visitor.visit(self, &Distance),
            Kind::Height => visitor.visit(self, &Height),
            Kind::Volume => visitor.visit(self, &Volume),
            Kind::Deviatoric => visitor.visit(self, &Deviatoric),
            Kind::Hydrostatic => visitor.visit(self, &Hydrostatic),
            Kind::File => {
                let file = self.file().expect("a family of kind File has a file");
                match file.arity() {
                    2 => visitor.visit(self, &FileConstraint::<2>(&file)),
                    _ => visitor.visit(self, &FileConstraint::<4>(&file)),
                }
            }
        }
    }

    /// Calls `visitor` with this family's [`Constraint`] type and `second`'s (two nested
    /// [`Family::visit`]s).
    #[inline]
    pub fn visit_pair<W: VisitPair>(self, second: Family, visitor: W) -> W::Output {
        struct Outer<W> {
            second: Family,
            visitor: W,
        }
        struct Inner<'c, W, A, const N: usize> {
            visitor: W,
            first: &'c A,
        }
        impl<W: VisitPair, const N: usize, A: Constraint<N>> Visit for Inner<'_, W, A, N> {
            type Output = W::Output;
            #[inline]
            fn visit<const M: usize, B: Constraint<M>>(self, _: Family, second: &B) -> W::Output {
                self.visitor.visit_pair::<N, A, M, B>(self.first, second)
            }
        }
        impl<W: VisitPair> Visit for Outer<W> {
            type Output = W::Output;
            #[inline]
            fn visit<const N: usize, A: Constraint<N>>(self, _: Family, first: &A) -> W::Output {
                self.second.visit(Inner::<W, A, N> {
                    visitor: self.visitor,
                    first,
                })
            }
        }
        self.visit(Outer { second, visitor })
    }

    /// C and ∇C in f64 at `points` (the family's arity of them), with rest value `rest` and the
    /// constraint's particles at rest at `rest_shape`: the gradients padded to four, for tools
    /// (the gradient check, `tetlab gradient`).
    ///
    /// # Panics
    /// If the number of points is not the family's arity; callers check it first.
    pub fn evaluate(
        self,
        points: &[DVec3],
        rest: f64,
        rest_shape: &[DVec3],
    ) -> Evaluation<DVec3, 4> {
        struct At<'a>(&'a [DVec3], f64, &'a [DVec3]);
        impl Visit for At<'_> {
            type Output = Evaluation<DVec3, 4>;
            fn visit<const N: usize, C: Constraint<N>>(self, _: Family, c: &C) -> Self::Output {
                let (p, rest, shape) = (self.0, self.1, self.2);
                let p: [DVec3; N] = std::array::from_fn(|k| p[k]);
                let shape: [DVec3; N] = std::array::from_fn(|k| shape[k]);
                let e = c.evaluate(&p, rest, &shape);
                let mut gradients = [DVec3::ZERO; 4];
                gradients[..N].copy_from_slice(&e.gradients);
                Evaluation {
                    value: e.value,
                    gradients,
                    degenerate: e.degenerate,
                }
            }
        }
        assert!(
            points.len() == self.arity() && rest_shape.len() == self.arity(),
            "wrong number of points for {self:?}"
        );
        self.visit(At(points, rest, rest_shape))
    }

    /// Whether its formula reads the rest shape ([`Constraint::USES_REST_SHAPE`]).
    pub fn uses_rest_shape(self) -> bool {
        struct Uses;
        impl Visit for Uses {
            type Output = bool;
            fn visit<const N: usize, C: Constraint<N>>(self, _: Family, _: &C) -> bool {
                C::USES_REST_SHAPE
            }
        }
        self.visit(Uses)
    }

    /// The rest value (d, V, …) of a rest configuration ([`Constraint::rest_value`]: C there
    /// with rest value 0, unless the family says otherwise).
    ///
    /// # Panics
    /// If the number of points is not the family's arity.
    pub fn rest_value(self, points: &[DVec3], material: &Material) -> f64 {
        struct Rest<'a>(&'a [DVec3], &'a Material);
        impl Visit for Rest<'_> {
            type Output = f64;
            fn visit<const N: usize, C: Constraint<N>>(self, _: Family, c: &C) -> f64 {
                let shape: [DVec3; N] = std::array::from_fn(|k| self.0[k]);
                c.rest_value(&shape, self.1)
            }
        }
        assert_eq!(
            points.len(),
            self.arity(),
            "wrong number of points for {self:?}"
        );
        self.visit(Rest(points, material))
    }

    /// Among `active` families, the one this family is projected together with, if this one
    /// leads the pair ([`Row::projected_with`]).
    pub fn partner_in(self, active: &PerFamily<bool>) -> Option<Family> {
        self.row()
            .projected_with
            .filter(|&partner| active[partner] && self < partner)
    }

    /// Whether, among `active` families, this one is projected by the family it is paired with
    /// (which comes first in the table) rather than on its own.
    pub fn projected_by_partner(self, active: &PerFamily<bool>) -> bool {
        self.row()
            .projected_with
            .is_some_and(|partner| active[partner] && partner < self)
    }

    /// [`Constraint::describe_state`] of one of its constraints, its particles at `points` and
    /// at rest at `rest_shape`.
    pub fn describe_state(self, points: &[DVec3], rest_shape: &[DVec3]) -> Vec<String> {
        struct State<'a>(&'a [DVec3], &'a [DVec3]);
        impl Visit for State<'_> {
            type Output = Vec<String>;
            fn visit<const N: usize, C: Constraint<N>>(self, _: Family, c: &C) -> Vec<String> {
                let p: [DVec3; N] = std::array::from_fn(|k| self.0[k]);
                let shape: [DVec3; N] = std::array::from_fn(|k| self.1[k]);
                c.describe_state(&p, &shape)
            }
        }
        assert_eq!(
            points.len(),
            self.arity(),
            "wrong number of points for {self:?}"
        );
        self.visit(State(points, rest_shape))
    }

    /// Whether its rest values depend on the material ([`Constraint::REST_USES_MATERIAL`]).
    pub fn rest_uses_material(self) -> bool {
        struct Uses;
        impl Visit for Uses {
            type Output = bool;
            fn visit<const N: usize, C: Constraint<N>>(self, _: Family, _: &C) -> bool {
                C::REST_USES_MATERIAL
            }
        }
        self.visit(Uses)
    }

    /// The groups of families as the command line and the workbench show them, in table order:
    /// each group's name and its families (`neohookean`: both neo-Hookean families).
    ///
    /// ```
    /// use tetlab_core::constraints::Family;
    /// let names: Vec<&str> = Family::groups().map(|(name, _)| name).collect();
    /// assert_eq!(names, ["edges", "height", "volume", "neohookean"]);
    /// let (_, pair) = Family::groups().last().unwrap();
    /// assert_eq!(pair.families().count(), 2);
    /// ```
    pub fn groups() -> impl Iterator<Item = (&'static str, PerFamily<bool>)> {
        // A group is named where its first family stands; nothing is allocated (the panels ask
        // every frame).
        Family::all()
            .filter(|&family| {
                let group = family.row().group;
                Family::all()
                    .take_while(|&earlier| earlier != family)
                    .all(|earlier| earlier.row().group != group)
            })
            .map(|first| {
                let name = first.row().group;
                (name, PerFamily::from_fn(|f| f.row().group == name))
            })
    }
}

impl fmt::Debug for Family {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

impl fmt::Display for Family {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

impl Binding {
    /// The particles of every constraint of this binding on `mesh`, flat: `arity` indices per
    /// constraint, in constraint order.
    pub fn particles(self, mesh: &TetMesh) -> Vec<u32> {
        match self {
            Binding::Edges => mesh.edges().into_iter().flatten().collect(),
            Binding::Tets => mesh.tets.iter().flatten().copied().collect(),
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
    /// `f(family)` for each family of the table (and the default in the places beyond it).
    pub fn build(mut f: impl FnMut(Family) -> T) -> Self
    where
        T: Default,
    {
        PerFamily(std::array::from_fn(|i| {
            if i < registry::count() {
                f(Family::from_index(i))
            } else {
                T::default()
            }
        }))
    }

    /// Each family of the table with a reference to its value, in projection order.
    pub fn iter_ref(&self) -> impl Iterator<Item = (Family, &T)> + '_ {
        Family::all().map(|f| (f, &self.0[f.index()]))
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

    /// `f(family)` for each family of the table.
    pub fn from_fn(f: impl Fn(Family) -> T) -> Self
    where
        T: Default,
    {
        PerFamily::build(f)
    }

    /// Each family of the table with its value, in projection order.
    pub fn iter(&self) -> impl Iterator<Item = (Family, T)> + '_ {
        Family::all().map(|f| (f, self.get(f)))
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
            .entries(self.iter_ref().map(|(k, v)| (k.name(), v)))
            .finish()
    }
}

impl PerFamily<bool> {
    /// The families named in a comma-separated list (`edges,volume`), each as [`Family::parse`]
    /// reads it.
    ///
    /// ```
    /// use tetlab_core::constraints::{Family, PerFamily};
    /// let active = PerFamily::parse_list("edges, plane").unwrap();
    /// assert!(active[Family::EDGES] && active[Family::HEIGHT] && !active[Family::VOLUME]);
    /// assert_eq!(active.describe(), "edges+height");
    /// ```
    ///
    /// A group's name stands for all its families ([`Family::groups`]), and `none` for none:
    ///
    /// ```
    /// use tetlab_core::constraints::{Family, PerFamily};
    /// let active = PerFamily::parse_list("edges,neohookean").unwrap();
    /// assert!(active[Family::NEOHOOKEAN_DEVIATORIC] && active[Family::NEOHOOKEAN_HYDROSTATIC]);
    /// assert_eq!(active.describe(), "edges+neohookean");
    /// assert_eq!(PerFamily::parse_list("none").unwrap().describe(), "none");
    /// ```
    pub fn parse_list(text: &str) -> Result<PerFamily<bool>, String> {
        let mut active = PerFamily::splat(false);
        if text.trim() == "none" {
            return Ok(active);
        }
        for name in text.split(',') {
            for family in PerFamily::parse_group(name)?.families() {
                active.set(family, true);
            }
        }
        Ok(active)
    }

    /// The families one name stands for where families are switched on and set (lists,
    /// `--compliance FAMILY=…`): a family of its own, by [`Family::parse`], or a group by its
    /// name; a family that belongs to a larger group is not named on its own.
    ///
    /// ```
    /// use tetlab_core::constraints::{Family, PerFamily};
    /// assert!(PerFamily::parse_group("neohookean").unwrap()[Family::NEOHOOKEAN_HYDROSTATIC]);
    /// assert!(PerFamily::parse_group("hydrostatic").unwrap_err().contains("neohookean"));
    /// ```
    pub fn parse_group(name: &str) -> Result<PerFamily<bool>, String> {
        let name = name.trim();
        if let Some((_, members)) = Family::groups().find(|(group, _)| *group == name) {
            return Ok(members);
        }
        let family = Family::parse(name)?;
        let group = family.row().group;
        if group != family.name() {
            return Err(format!(
                "'{name}' is one of the constraints of {group}: name {group} for all of them"
            ));
        }
        Ok(PerFamily::from_fn(|f| f == family))
    }

    /// The active families as `edges+height+volume`, or `none`; a group whose families are all
    /// active by its name (`neohookean`).
    pub fn describe(&self) -> String {
        let mut names: Vec<&str> = Vec::new();
        for (group, members) in Family::groups() {
            if members.families().all(|f| self[f]) {
                names.push(group);
            } else {
                names.extend(members.families().filter(|&f| self[f]).map(Family::name));
            }
        }
        if names.is_empty() {
            "none".into()
        } else {
            names.join("+")
        }
    }

    /// The active families, in projection order.
    pub fn families(&self) -> impl Iterator<Item = Family> + '_ {
        self.iter().filter(|&(_, on)| on).map(|(f, _)| f)
    }
}

/// Written as a map from family name to value (`{"edges": …, "height": …}`), so that what is
/// stored (the workbench's preferences) reads back whatever the table holds then: a family it
/// does not know is left out, and one it lacks keeps its default.
impl<T: serde::Serialize + Copy> serde::Serialize for PerFamily<T> {
    fn serialize<S: serde::Serializer>(&self, serializer: S) -> Result<S::Ok, S::Error> {
        use serde::ser::SerializeMap;
        let mut map = serializer.serialize_map(Some(registry::count()))?;
        for (family, value) in self.iter() {
            map.serialize_entry(family.name(), &value)?;
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
    /// default, and a name the table does not know is left out.
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
            if let Ok(family) = Family::parse(&name) {
                defaults.set(family, value);
            }
        }
        Ok(defaults)
    }
}
