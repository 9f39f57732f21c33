//! The table of families that a simulation, the checker, a lesson and the workbench each own
//! ([`Families`]): the built-in families ([`TABLE`]) and the constraint files loaded into it, as
//! a value. Cloning it is cheap (the files are shared behind an [`Arc`]); defining a family makes a
//! new table and leaves the old one to whoever still holds it, so nothing is leaked and nothing is
//! global.
//!
//! A file's family takes the next place after the built-in ones ([`Family`] is a place in a
//! table); loading a file of the same name again ([`Families::define`]: the workbench's editor, a
//! file opened twice) redefines it in that place. A simulation given the new table
//! ([`crate::simulation::Simulation::set_families`]) rebuilds the constraints of the families
//! whose definition changed ([`Families::same_definition`]).

use super::any::{AnyConstraint, Typed};
use super::file::FileConstraint;
use super::row::Formula;
use super::{Binding, Family, MAX_FAMILIES, PerFamily, Row, TABLE, builtin};
use crate::constraint_file::ConstraintFile;
use crate::scene::mesh::TetMesh;
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

/// A file's family: its row, its compiled file, and the file as a constraint of its arity.
#[derive(Clone)]
struct FileFamily {
    row: Row,
    file: Arc<ConstraintFile>,
    code: Arc<FileCode>,
}

/// A constraint file as the [`super::Constraint`] type of its arity.
pub(super) enum FileCode {
    /// On one particle (a pin, a handle).
    One(Typed<1, FileConstraint<1>>),
    /// On two particles (edges, hinges' ends).
    Two(Typed<2, FileConstraint<2>>),
    /// On three (surface triangles).
    Three(Typed<3, FileConstraint<3>>),
    /// On four (tets, heights, hinges).
    Four(Typed<4, FileConstraint<4>>),
}

impl FileFamily {
    fn new(file: ConstraintFile, slot: usize) -> FileFamily {
        let row = row_of(&file, slot);
        let file = Arc::new(file);
        let code = match row.arity {
            1 => FileCode::One(Typed(FileConstraint(file.clone()))),
            2 => FileCode::Two(Typed(FileConstraint(file.clone()))),
            3 => FileCode::Three(Typed(FileConstraint(file.clone()))),
            _ => FileCode::Four(Typed(FileConstraint(file.clone()))),
        };
        FileFamily {
            row,
            file,
            code: Arc::new(code),
        }
    }
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
        reads_rest_shape: file.reads_rest_shape(),
        // μ and λ may appear in what an element stores and in its rest value.
        rest_uses_material: true,
        stored_len: file.stored_len(),
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
            Arc::make_mut(&mut self.files)[slot] = FileFamily::new(file, slot);
            return Ok(family);
        }
        let slot = self.files.len();
        if slot >= MAX_FILE_FAMILIES {
            return Err(format!(
                "at most {MAX_FILE_FAMILIES} constraint files can be loaded at once"
            ));
        }
        Arc::make_mut(&mut self.files).push(FileFamily::new(file, slot));
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
    /// assert_eq!(names, ["edges", "height", "volume", "neohookean", "contact"]);
    /// let (_, pair) = families.groups().nth(3).unwrap();
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

    /// `family`'s constraint in f64, for tools and readers ([`AnyConstraint`]): C and ∇C at
    /// given points, its rest value, what it stores, what else the inspector shows.
    ///
    /// ```
    /// use glam::DVec3;
    /// use tetlab_core::constraints::{Families, Family};
    /// let families = Families::builtin();
    /// let tet = [DVec3::ZERO, DVec3::X, DVec3::Y, DVec3::Z];
    /// let volume = families.constraint(Family::VOLUME);
    /// // The rest value of a volume is the rest tet's volume, 1/6; C there is zero.
    /// let v = volume.rest_value(&tet, &Default::default());
    /// assert!((v - 1.0 / 6.0).abs() < 1e-15);
    /// assert_eq!(volume.evaluate(&tet, v, &tet).value, 0.0);
    /// ```
    pub fn constraint(&self, family: Family) -> &dyn AnyConstraint {
        if family.index() < TABLE.len() {
            return builtin::constraint(family);
        }
        match self.file_code(family) {
            FileCode::One(c) => c,
            FileCode::Two(c) => c,
            FileCode::Three(c) => c,
            FileCode::Four(c) => c,
        }
    }

    /// A file family's constraint type.
    ///
    /// # Panics
    /// If `family` is not a file family of this table.
    pub(super) fn file_code(&self, family: Family) -> &FileCode {
        match self.file_family(family) {
            Some(file) => &file.code,
            None => panic!(
                "family {} is not a file family of this table",
                family.index()
            ),
        }
    }

    /// How `family` binds to a mesh.
    pub fn binding(&self, family: Family) -> Binding {
        self.row(family).binding
    }

    /// The particles of every constraint of `family` on `mesh`, flat, its arity per constraint:
    /// its binding's ([`Binding::particles`]); of a file on single particles, those its `where`
    /// chooses ([`ConstraintFile::chooses`]).
    pub fn particles_on(&self, family: Family, mesh: &TetMesh) -> Vec<u32> {
        match (self.binding(family), self.file(family)) {
            (Binding::Particles, Some(file)) => file.chooses(&mesh.positions),
            (binding, _) => binding.particles(mesh),
        }
    }
}
