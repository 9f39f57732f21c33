//! The table of families that a simulation, the checker, a lesson and the workbench each own: the
//! built-in families ([`TABLE`]) and the constraint files loaded into it, as a value. Cloning it
//! is cheap (the files are shared behind an [`Arc`]); defining a family makes a new table and
//! leaves the old one to whoever still holds it, so nothing is leaked and nothing is global.
//!
//! A file's family takes the next place after the built-in ones ([`Family`] is a place in a
//! table); loading a file of the same name again ([`Families::define`]: the workbench's editor, a
//! file opened twice) redefines it in that place. A simulation given the new table
//! ([`crate::simulation::Simulation::set_families`]) rebuilds the constraints of the families
//! whose definition changed ([`Families::same_definition`]).

use super::file::FileConstraint;
use super::neohookean::{Deviatoric, Hydrostatic};
use super::table::{Formula, Kind};
use super::{
    Binding, Constraint, Evaluation, Family, MAX_FAMILIES, PerFamily, Row, TABLE, Visit, VisitPair,
    distance::Distance, height::Height, volume::Volume,
};
use crate::constraint_file::ConstraintFile;
use crate::constraints::material::Material;
use glam::DVec3;
use std::borrow::Cow;
use std::sync::Arc;

/// The colours of file families' arrows, in the order they are loaded (then again): teal, rose,
/// lime and slate, apart from the built-in families' (orange, green, blue, brown, purple), the
/// red of inverted tets, the yellow of the selection, the magenta of corrections and the cyan of
/// step-by-step mode.
pub const COLOURS: [[u8; 4]; 4] = [
    [0, 150, 150, 255],
    [235, 100, 160, 255],
    [140, 170, 30, 255],
    [110, 110, 140, 255],
];

/// How many families files can add to one table.
pub const MAX_FILE_FAMILIES: usize = MAX_FAMILIES - TABLE.len();

/// Values keyed by family name, in table order ([`Families::named`]); written as a map.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Named<T>(pub Vec<(String, T)>);

impl<T: serde::Serialize> serde::Serialize for Named<T> {
    fn serialize<S: serde::Serializer>(&self, serializer: S) -> Result<S::Ok, S::Error> {
        use serde::ser::SerializeMap;
        let mut map = serializer.serialize_map(Some(self.0.len()))?;
        for (name, value) in &self.0 {
            map.serialize_entry(name, value)?;
        }
        map.end()
    }
}

/// A table of constraint families: the built-in ones, then those of the constraint files loaded
/// into it.
#[derive(Clone, Default)]
pub struct Families {
    files: Arc<Vec<FileFamily>>,
}

/// A file's family: its row and its compiled file.
#[derive(Clone)]
struct FileFamily {
    row: Row,
    file: Arc<ConstraintFile>,
}

impl std::fmt::Debug for Families {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_list()
            .entries(self.all().map(|family| self.name(family)))
            .finish()
    }
}

impl PartialEq for Families {
    /// The same families, each of the same definition.
    fn eq(&self, other: &Families) -> bool {
        self.len() == other.len() && self.all().all(|f| self.same_definition(other, f))
    }
}

/// The row a file's family gets in place `slot` (counted after the built-in ones).
fn row_of(file: &ConstraintFile, slot: usize) -> Row {
    Row {
        name: Cow::Owned(file.name.clone()),
        aliases: &[],
        title: Cow::Owned(format!("{} ({})", file.name, file.path.display())),
        label: Cow::Owned(file.name.clone()),
        colour: COLOURS[slot % COLOURS.len()],
        formula: Formula::File(file.formula.clone()),
        rest_symbol: "rest",
        arity: file.arity(),
        binding: file.binding,
        group: Cow::Owned(file.group.clone().unwrap_or_else(|| file.name.clone())),
        compliance_from_material: file.stiffness.map(|s| s.compliance()),
        projected_with: None,
        kind: Kind::File,
    }
}

/// Why a file's family cannot join the table under its name, if a built-in family or group
/// already has it.
fn clashes_with_builtin(name: &str) -> Option<String> {
    let builtin = TABLE
        .iter()
        .any(|row| row.name == name || row.aliases.contains(&name) || row.group == name);
    builtin.then(|| {
        format!("name \"{name}\" is a built-in constraint family's: give the file another name")
    })
}

impl Families {
    /// The built-in families alone.
    pub fn builtin() -> Families {
        Families::default()
    }

    /// How many families the table has: the built-in ones and those from files.
    pub fn len(&self) -> usize {
        TABLE.len() + self.files.len()
    }

    /// Whether it has no family (never: the built-in ones are always there).
    pub fn is_empty(&self) -> bool {
        false
    }

    /// Every family of the table, in projection order: the built-in ones, then those read from
    /// constraint files.
    pub fn all(&self) -> impl DoubleEndedIterator<Item = Family> + Clone + use<> {
        (0..self.len()).map(Family::from_index)
    }

    /// Whether `family` is a place of this table.
    pub fn has(&self, family: Family) -> bool {
        family.index() < self.len()
    }

    /// The file family in place `family`, if it is one of this table's.
    fn file_family(&self, family: Family) -> Option<&FileFamily> {
        family
            .index()
            .checked_sub(TABLE.len())
            .and_then(|slot| self.files.get(slot))
    }

    /// The row of `family`.
    ///
    /// # Panics
    /// If `family` is not a place of this table.
    pub fn row(&self, family: Family) -> &Row {
        match TABLE.get(family.index()) {
            Some(row) => row,
            None => match self.file_family(family) {
                Some(file) => &file.row,
                None => panic!("family {} is not in this table", family.index()),
            },
        }
    }

    /// Its name ([`Row::name`]).
    pub fn name(&self, family: Family) -> &str {
        &self.row(family).name
    }

    /// How many particles one of its constraints touches.
    pub fn arity(&self, family: Family) -> usize {
        self.row(family).arity
    }

    /// The constraint file `family` was read from, for a family that was.
    pub fn file(&self, family: Family) -> Option<&Arc<ConstraintFile>> {
        self.file_family(family).map(|f| &f.file)
    }

    /// Whether `family` has the same definition here as in `other`: built-in in both, or read
    /// from the same compiled file (not merely an equal one: a redefinition is a new file).
    pub fn same_definition(&self, other: &Families, family: Family) -> bool {
        match (self.file(family), other.file(family)) {
            (None, None) => family.index() < TABLE.len(),
            (Some(a), Some(b)) => Arc::ptr_eq(a, b),
            _ => false,
        }
    }

    /// Adds the family of a constraint file: its place, or the place it already has when the
    /// same file (same path and text) was added before. An error when another family has its
    /// name (a built-in one, or another file's: two files may not share a name) or the table is
    /// full ([`MAX_FILE_FAMILIES`]).
    ///
    /// ```
    /// use std::path::Path;
    /// use tetlab_core::constraint_file::ConstraintFile;
    /// use tetlab_core::constraints::Families;
    /// let text = "name = \"doc-edge\"\napplies_to = \"edges\"\nvalue = \"length(p0 - p1) - rest\"\n";
    /// let file = ConstraintFile::parse(Path::new("doc-edge.toml"), text).unwrap();
    /// let mut families = Families::builtin();
    /// let family = families.register(file.clone()).unwrap();
    /// assert_eq!(families.register(file).unwrap(), family, "the same file, the same family");
    /// // It is a family like the others: by name on the command line, in lists, in the table.
    /// assert_eq!(families.parse("doc-edge"), Ok(family));
    /// assert!(families.parse_list("volume,doc-edge").unwrap()[family]);
    /// assert_eq!((families.arity(family), families.name(family)), (2, "doc-edge"));
    /// // A table without the file does not know it.
    /// assert!(Families::builtin().parse("doc-edge").is_err());
    /// ```
    pub fn register(&mut self, file: ConstraintFile) -> Result<Family, String> {
        self.add(file, false)
    }

    /// [`Families::register`], except that a file of a name already in the table (from
    /// another path or with another text) redefines that family in its place: the workbench's
    /// editor, or a file edited and opened again.
    pub fn define(&mut self, file: ConstraintFile) -> Result<Family, String> {
        self.add(file, true)
    }

    /// [`Families::register`] for every constraint of one file ([`ConstraintFile::load_all`]),
    /// in order; a `pair` of the file joins its two families.
    pub fn register_all(&mut self, files: Vec<ConstraintFile>) -> Result<Vec<Family>, String> {
        files.into_iter().map(|file| self.register(file)).collect()
    }

    /// [`Families::define`] for every constraint of one file.
    pub fn define_all(&mut self, files: Vec<ConstraintFile>) -> Result<Vec<Family>, String> {
        files.into_iter().map(|file| self.define(file)).collect()
    }

    fn add(&mut self, file: ConstraintFile, redefine: bool) -> Result<Family, String> {
        let family = self.add_one(file, redefine)?;
        self.link_pairs();
        Ok(family)
    }

    /// Sets each file family's partner ([`Row::projected_with`]) to the family its file's
    /// `pair` names, when the table has it.
    fn link_pairs(&mut self) {
        let partners: Vec<Option<Family>> = self
            .files
            .iter()
            .map(|f| {
                let wanted = f.file.pair.as_deref()?;
                let slot = self.files.iter().position(|g| g.row.name == wanted)?;
                Some(Family::from_index(TABLE.len() + slot))
            })
            .collect();
        if partners
            .iter()
            .zip(self.files.iter())
            .any(|(p, f)| *p != f.row.projected_with)
        {
            for (f, partner) in Arc::make_mut(&mut self.files).iter_mut().zip(partners) {
                f.row.projected_with = partner;
            }
        }
    }

    fn add_one(&mut self, file: ConstraintFile, redefine: bool) -> Result<Family, String> {
        if let Some(why) = clashes_with_builtin(&file.name) {
            return Err(why);
        }
        if let Some(slot) = self.files.iter().position(|f| f.row.name == file.name) {
            let family = Family::from_index(TABLE.len() + slot);
            let known = &self.files[slot].file;
            if known.path == file.path && known.source == file.source {
                return Ok(family);
            }
            if !redefine {
                return Err(format!(
                    "name \"{}\" is already the name of {}: give this file another name",
                    file.name,
                    known.path.display()
                ));
            }
            let row = row_of(&file, slot);
            Arc::make_mut(&mut self.files)[slot] = FileFamily {
                row,
                file: Arc::new(file),
            };
            return Ok(family);
        }
        let slot = self.files.len();
        if slot >= MAX_FILE_FAMILIES {
            return Err(format!(
                "at most {MAX_FILE_FAMILIES} constraint files can be loaded at once"
            ));
        }
        let row = row_of(&file, slot);
        Arc::make_mut(&mut self.files).push(FileFamily {
            row,
            file: Arc::new(file),
        });
        Ok(Family::from_index(TABLE.len() + slot))
    }

    /// The family a user means, by its name or one of its aliases (spaces around allowed), as
    /// the command line and lesson files write it.
    ///
    /// ```
    /// use tetlab_core::constraints::{Families, Family};
    /// let families = Families::builtin();
    /// assert_eq!(families.parse(" edges"), Ok(Family::EDGES));
    /// assert_eq!(families.parse("plane"), Ok(Family::HEIGHT));
    /// assert!(families.parse("edgy").unwrap_err().contains("'edgy'"));
    /// ```
    pub fn parse(&self, text: &str) -> Result<Family, String> {
        let text = text.trim();
        self.all()
            .find(|&f| self.name(f) == text || self.row(f).aliases.contains(&text))
            .ok_or_else(|| {
                let names: Vec<&str> = self.all().map(|f| self.name(f)).collect();
                if self.groups().any(|(group, _)| group == text) {
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

    /// The groups of families as the command line and the workbench show them, in table order:
    /// each group's name and its families (`neohookean`: both neo-Hookean families).
    ///
    /// ```
    /// use tetlab_core::constraints::Families;
    /// let families = Families::builtin();
    /// let names: Vec<&str> = families.groups().map(|(name, _)| name).collect();
    /// assert_eq!(names, ["edges", "height", "volume", "neohookean"]);
    /// let (_, pair) = families.groups().last().unwrap();
    /// assert_eq!(pair.families().count(), 2);
    /// ```
    pub fn groups(&self) -> impl Iterator<Item = (&str, PerFamily<bool>)> + '_ {
        // A group is named where its first family stands; nothing is allocated (the panels ask
        // every frame).
        self.all()
            .filter(|&family| {
                let group = &self.row(family).group;
                self.all()
                    .take_while(|&earlier| earlier != family)
                    .all(|earlier| self.row(earlier).group != *group)
            })
            .map(|first| {
                let name: &str = &self.row(first).group;
                (name, self.per_family(|f| self.row(f).group == name))
            })
    }

    /// `f(family)` for each family of the table (and the default in the places beyond it).
    pub fn per_family<T: Default>(&self, mut f: impl FnMut(Family) -> T) -> PerFamily<T> {
        let len = self.len();
        PerFamily::from_slots(|i| {
            if i < len {
                f(Family::from_index(i))
            } else {
                T::default()
            }
        })
    }

    /// Each family of the table with its value in `values`, in projection order.
    pub fn values<'a, T: Copy>(
        &self,
        values: &'a PerFamily<T>,
    ) -> impl Iterator<Item = (Family, T)> + 'a + use<'a, T> {
        self.all().map(move |f| (f, values[f]))
    }

    /// The families named in a comma-separated list (`edges,volume`), each as
    /// [`Families::parse`] reads it; a group's name stands for all its families
    /// ([`Families::groups`]), and `none` for none.
    ///
    /// ```
    /// use tetlab_core::constraints::{Families, Family};
    /// let families = Families::builtin();
    /// let active = families.parse_list("edges, plane").unwrap();
    /// assert!(active[Family::EDGES] && active[Family::HEIGHT] && !active[Family::VOLUME]);
    /// assert_eq!(families.describe(&active), "edges+height");
    /// let active = families.parse_list("edges,neohookean").unwrap();
    /// assert!(active[Family::NEOHOOKEAN_DEVIATORIC] && active[Family::NEOHOOKEAN_HYDROSTATIC]);
    /// assert_eq!(families.describe(&active), "edges+neohookean");
    /// assert_eq!(families.describe(&families.parse_list("none").unwrap()), "none");
    /// ```
    pub fn parse_list(&self, text: &str) -> Result<PerFamily<bool>, String> {
        let mut active = PerFamily::splat(false);
        if text.trim() == "none" {
            return Ok(active);
        }
        for name in text.split(',') {
            for family in self.parse_group(name)?.families() {
                active.set(family, true);
            }
        }
        Ok(active)
    }

    /// The families one name stands for where families are switched on and set (lists,
    /// `--compliance FAMILY=…`): a family of its own, by [`Families::parse`], or a group by its
    /// name; a family that belongs to a larger group is not named on its own.
    ///
    /// ```
    /// use tetlab_core::constraints::{Families, Family};
    /// let families = Families::builtin();
    /// assert!(families.parse_group("neohookean").unwrap()[Family::NEOHOOKEAN_HYDROSTATIC]);
    /// assert!(families.parse_group("hydrostatic").unwrap_err().contains("neohookean"));
    /// ```
    pub fn parse_group(&self, name: &str) -> Result<PerFamily<bool>, String> {
        let name = name.trim();
        if let Some((_, members)) = self.groups().find(|(group, _)| *group == name) {
            return Ok(members);
        }
        let family = self.parse(name)?;
        let group = &self.row(family).group;
        if group != self.name(family) {
            return Err(format!(
                "'{name}' is one of the constraints of {group}: name {group} for all of them"
            ));
        }
        Ok(self.per_family(|f| f == family))
    }

    /// The active families as `edges+height+volume`, or `none`; a group whose families are all
    /// active by its name (`neohookean`).
    pub fn describe(&self, active: &PerFamily<bool>) -> String {
        let mut names: Vec<&str> = Vec::new();
        for (group, members) in self.groups() {
            if members.families().all(|f| active[f]) {
                names.push(group);
            } else {
                names.extend(
                    members
                        .families()
                        .filter(|&f| active[f])
                        .map(|f| self.name(f)),
                );
            }
        }
        if names.is_empty() {
            "none".into()
        } else {
            names.join("+")
        }
    }

    /// `values` keyed by family name, in table order, for what is written out (JSON): every
    /// family of the table, files' included.
    pub fn named<T: Copy>(&self, values: &PerFamily<T>) -> Named<T> {
        Named(
            self.all()
                .map(|f| (self.name(f).to_owned(), values[f]))
                .collect(),
        )
    }

    /// Calls `visitor` with `family`'s [`Constraint`] type.
    #[inline]
    pub fn visit<T: Visit>(&self, family: Family, visitor: T) -> T::Output {
        match self.row(family).kind {
            Kind::Distance => visitor.visit(family, &Distance),
            Kind::Height => visitor.visit(family, &Height),
            Kind::Volume => visitor.visit(family, &Volume),
            Kind::Deviatoric => visitor.visit(family, &Deviatoric),
            Kind::Hydrostatic => visitor.visit(family, &Hydrostatic),
            Kind::File => {
                let file = self.file(family).expect("a family of kind File has a file");
                match file.arity() {
                    2 => visitor.visit(family, &FileConstraint::<2>(file)),
                    3 => visitor.visit(family, &FileConstraint::<3>(file)),
                    _ => visitor.visit(family, &FileConstraint::<4>(file)),
                }
            }
        }
    }

    /// Calls `visitor` with `first`'s [`Constraint`] type and `second`'s (two nested
    /// [`Families::visit`]s).
    #[inline]
    pub fn visit_pair<W: VisitPair>(&self, first: Family, second: Family, visitor: W) -> W::Output {
        struct Outer<'t, W> {
            families: &'t Families,
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
                // Only two types that can be a pair get pair code: the branch not taken is not
                // compiled, since its condition is a constant of the two types.
                if IsPair::<N, A, M, B>::VALUE {
                    self.visitor.visit_pair::<N, A, M, B>(self.first, second)
                } else {
                    unreachable!("visit_pair of two families that are not a pair")
                }
            }
        }
        struct IsPair<const N: usize, A, const M: usize, B>(std::marker::PhantomData<(A, B)>);
        impl<const N: usize, A: Constraint<N>, const M: usize, B: Constraint<M>> IsPair<N, A, M, B> {
            const VALUE: bool = super::pairs::<N, A, M, B>();
        }
        impl<W: VisitPair> Visit for Outer<'_, W> {
            type Output = W::Output;
            #[inline]
            fn visit<const N: usize, A: Constraint<N>>(self, _: Family, first: &A) -> W::Output {
                self.families.visit(
                    self.second,
                    Inner::<W, A, N> {
                        visitor: self.visitor,
                        first,
                    },
                )
            }
        }
        self.visit(
            first,
            Outer {
                families: self,
                second,
                visitor,
            },
        )
    }

    /// C and ∇C of `family` in f64 at `points` (its arity of them), with rest value `rest` and
    /// the constraint's particles at rest at `rest_shape`: the gradients padded to four, for tools
    /// (the gradient check, `tetlab gradient`).
    ///
    /// # Panics
    /// If the number of points is not the family's arity; callers check it first.
    pub fn evaluate(
        &self,
        family: Family,
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
            points.len() == self.arity(family) && rest_shape.len() == self.arity(family),
            "wrong number of points for {}",
            self.name(family)
        );
        self.visit(family, At(points, rest, rest_shape))
    }

    /// Whether `family`'s formula reads the rest shape ([`Constraint::uses_rest_shape`]).
    pub fn uses_rest_shape(&self, family: Family) -> bool {
        struct Uses;
        impl Visit for Uses {
            type Output = bool;
            fn visit<const N: usize, C: Constraint<N>>(self, _: Family, c: &C) -> bool {
                c.uses_rest_shape()
            }
        }
        self.visit(family, Uses)
    }

    /// Whether `family`'s rest values depend on the material
    /// ([`Constraint::REST_USES_MATERIAL`]).
    pub fn rest_uses_material(&self, family: Family) -> bool {
        struct Uses;
        impl Visit for Uses {
            type Output = bool;
            fn visit<const N: usize, C: Constraint<N>>(self, _: Family, _: &C) -> bool {
                C::REST_USES_MATERIAL
            }
        }
        self.visit(family, Uses)
    }

    /// The rest value (d, V, …) of `family` at a rest configuration
    /// ([`Constraint::rest_value`]: C there with rest value 0, unless the family says otherwise).
    ///
    /// # Panics
    /// If the number of points is not the family's arity.
    pub fn rest_value(&self, family: Family, points: &[DVec3], material: &Material) -> f64 {
        struct Rest<'a>(&'a [DVec3], &'a Material);
        impl Visit for Rest<'_> {
            type Output = f64;
            fn visit<const N: usize, C: Constraint<N>>(self, _: Family, c: &C) -> f64 {
                let shape: [DVec3; N] = std::array::from_fn(|k| self.0[k]);
                c.rest_value(&shape, self.1)
            }
        }
        assert_eq!(points.len(), self.arity(family), "wrong number of points");
        self.visit(family, Rest(points, material))
    }

    /// [`Constraint::describe_state`] of one of `family`'s constraints, its particles at
    /// `points` and at rest at `rest_shape`.
    pub fn describe_state(
        &self,
        family: Family,
        points: &[DVec3],
        rest_shape: &[DVec3],
    ) -> Vec<String> {
        struct State<'a>(&'a [DVec3], &'a [DVec3]);
        impl Visit for State<'_> {
            type Output = Vec<String>;
            fn visit<const N: usize, C: Constraint<N>>(self, _: Family, c: &C) -> Vec<String> {
                let p: [DVec3; N] = std::array::from_fn(|k| self.0[k]);
                let shape: [DVec3; N] = std::array::from_fn(|k| self.1[k]);
                c.describe_state(&p, &shape)
            }
        }
        assert_eq!(points.len(), self.arity(family), "wrong number of points");
        self.visit(family, State(points, rest_shape))
    }

    /// Among `active` families, the one `family` is projected together with, if `family` leads
    /// the pair ([`Row::projected_with`]: the built-in neo-Hookean pair, a file's `pair`).
    pub fn partner_in(&self, family: Family, active: &PerFamily<bool>) -> Option<Family> {
        self.row(family)
            .projected_with
            .filter(|&partner| active[partner] && family < partner)
    }

    /// Whether, among `active` families, `family` is projected by the family it is paired with
    /// (which comes first in the table) rather than on its own.
    pub fn projected_by_partner(&self, family: Family, active: &PerFamily<bool>) -> bool {
        self.row(family)
            .projected_with
            .is_some_and(|partner| active[partner] && partner < family)
    }

    /// The compliance of `family` when the material gives it ([`Row::compliance_from_material`]:
    /// the built-in neo-Hookean pair's, and a file's `stiffness`).
    pub fn compliance_from_material(&self, family: Family) -> Option<fn(&Material) -> f64> {
        self.row(family).compliance_from_material
    }

    /// `compliance` with that of every file family that has a `stiffness` taken from
    /// `material` (the built-in ones are by [`crate::simulation::Settings::set_material`]).
    pub fn with_file_stiffness(
        &self,
        mut compliance: PerFamily<f64>,
        material: &Material,
    ) -> PerFamily<f64> {
        for family in self.all().skip(TABLE.len()) {
            if let Some(c) = self.compliance_from_material(family) {
                compliance[family] = c(material);
            }
        }
        compliance
    }

    /// Which of its families take their compliance from the material.
    pub fn from_material(&self) -> PerFamily<bool> {
        self.per_family(|f| self.compliance_from_material(f).is_some())
    }

    /// How `family` binds to a mesh.
    pub fn binding(&self, family: Family) -> Binding {
        self.row(family).binding
    }
}
