//! One value per family of a table ([`PerFamily`]), indexed by [`Family`]: which families are
//! active, their compliances, their skip counts. Written out (preferences, links) as a map from
//! built-in family name to value.

use super::TABLE;
use super::row::{Family, MAX_FAMILIES};
use std::fmt;
use std::ops::{Index, IndexMut};

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

    /// The value in every place, mutable.
    pub(crate) fn every_place_mut(&mut self) -> impl Iterator<Item = &mut T> {
        self.0.iter_mut()
    }

    /// `f` of the value in every place.
    pub fn map<U>(&self, mut f: impl FnMut(&T) -> U) -> PerFamily<U> {
        PerFamily(std::array::from_fn(|i| f(&self.0[i])))
    }

    /// The values of `K` different families, each mutable.
    ///
    /// # Panics
    /// If two of `families` are the same.
    pub(crate) fn get_disjoint_mut<const K: usize>(
        &mut self,
        families: [Family; K],
    ) -> [&mut T; K] {
        self.0
            .get_disjoint_mut(families.map(Family::index))
            .expect("different families")
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
    pub(crate) fn deserialize_over<'de, D: serde::Deserializer<'de>>(
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
