//! The one dispatch on a family: [`Families::visit`] hands a visitor a family's [`Constraint`]
//! type, [`Families::visit_unit`] the [`super::Projected`] type of what one projection moves (a family
//! alone, or a [`Pair`]), and [`Families::units`] says what a sweep projects. What a family *is*
//! (its arity, what it reads and stores) is data in its [`super::Row`].

use super::builtin;
use super::family_table::FileCode;
use super::visit::{Pair, Unit, Visit, VisitProjected};
use super::{Constraint, Families, Family, PerFamily, TABLE};

impl Families {
    /// Calls `visitor` with `family`'s [`Constraint`] type.
    #[inline]
    pub fn visit<T: Visit>(&self, family: Family, visitor: T) -> T::Output {
        if family.index() < TABLE.len() {
            return builtin::visit(family, visitor);
        }
        match self.file_code(family) {
            FileCode::One(c) => visitor.visit(family, &c.0),
            FileCode::Two(c) => visitor.visit(family, &c.0),
            FileCode::Three(c) => visitor.visit(family, &c.0),
            FileCode::Four(c) => visitor.visit(family, &c.0),
        }
    }

    /// Calls `visitor` with the [`super::Projected`] type of `unit`: the family's own constraint when it
    /// is alone, a [`Pair`] when it leads one.
    ///
    /// # Panics
    /// If the unit's two families cannot be a pair (the table links only the neo-Hookean halves,
    /// and a file's two constraints, which have one arity of two or more: a file on single
    /// particles is refused a `pair`, so that no pair's code is compiled for one particle).
    #[inline]
    pub fn visit_unit<T: VisitProjected>(&self, unit: Unit, visitor: T) -> T::Output {
        let Some(partner) = unit.partner else {
            /// A visit of one family as a projection of one value.
            struct Alone<T>(T);
            impl<T: VisitProjected> Visit for Alone<T> {
                type Output = T::Output;
                #[inline(always)]
                fn visit<const N: usize, C: Constraint<N>>(self, f: Family, c: &C) -> T::Output {
                    self.0.visit::<N, 1, C>([f], c)
                }
            }
            return self.visit(unit.lead, Alone(visitor));
        };
        let lead = unit.lead;
        if lead.index() < TABLE.len() {
            return builtin::visit_pair(lead, partner, visitor);
        }
        match (self.file_code(lead), self.file_code(partner)) {
            (FileCode::Two(a), FileCode::Two(b)) => {
                visitor.visit([lead, partner], &Pair(&a.0, &b.0))
            }
            (FileCode::Three(a), FileCode::Three(b)) => {
                visitor.visit([lead, partner], &Pair(&a.0, &b.0))
            }
            (FileCode::Four(a), FileCode::Four(b)) => {
                visitor.visit([lead, partner], &Pair(&a.0, &b.0))
            }
            _ => panic!("{lead:?} and {partner:?} have different arities: not a pair"),
        }
    }

    /// What one sweep projects, in order, among `active` families: each active family alone,
    /// or with the partner it leads; a family that its partner leads is projected there.
    ///
    /// ```
    /// use tetlab_core::constraints::{Families, Family, PerFamily};
    /// let families = Families::builtin();
    /// let active = families.parse_list("edges,neohookean").unwrap();
    /// let units: Vec<_> = families.units(&active).collect();
    /// assert_eq!(units.len(), 2, "the edges, then the neo-Hookean pair as one projection");
    /// assert_eq!(units[1].partner, Some(Family::NEOHOOKEAN_HYDROSTATIC));
    /// ```
    pub fn units<'a>(&'a self, active: &'a PerFamily<bool>) -> impl Iterator<Item = Unit> + 'a {
        self.all()
            .filter(|&f| active[f] && !self.projected_by_partner(f, active))
            // Contacts are found every frame and projected after the sweep's families
            // (`crate::simulation::contact`).
            .filter(|&f| self.binding(f) != super::Binding::Contacts)
            .map(|lead| Unit {
                lead,
                partner: self.partner_in(lead, active),
            })
    }

    /// The projection `family` takes part in among `active` families: its own, or its pair's.
    pub fn unit_of(&self, family: Family, active: &PerFamily<bool>) -> Unit {
        match self.row(family).projected_with {
            Some(partner) if active[partner] && partner < family => Unit {
                lead: partner,
                partner: Some(family),
            },
            _ => Unit {
                lead: family,
                partner: self.partner_in(family, active),
            },
        }
    }

    /// Among `active` families, the one `family` is projected together with, if `family` leads
    /// the pair ([`super::Row::projected_with`]).
    fn partner_in(&self, family: Family, active: &PerFamily<bool>) -> Option<Family> {
        self.row(family)
            .projected_with
            .filter(|&partner| active[partner] && family < partner)
    }

    /// Whether, among `active` families, `family` is projected by the family it is paired with
    /// (which comes first in the table) rather than on its own.
    fn projected_by_partner(&self, family: Family, active: &PerFamily<bool>) -> bool {
        self.row(family)
            .projected_with
            .is_some_and(|partner| active[partner] && partner < family)
    }
}
