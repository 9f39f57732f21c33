//! The built-in constraint families, one entry each: its place, its [`Family`] constant, its
//! [`Constraint`](super::Constraint) type (and, for a family that leads a pair, its partner's),
//! and its [`Row`]. Adding a family is its formula's file and one entry here: the entry makes the
//! row of [`TABLE`], the constant, and the arms of the dispatch ([`super::Families::visit`],
//! [`super::Families::visit_unit`], [`super::Families::constraint`]), so that no `match` elsewhere
//! names a family. `core/tests/family_rows.rs` holds each row to its type.

use super::any::{AnyConstraint, Typed};
use super::binding::Binding;
use super::contact::Contact;
use super::distance::Distance;
use super::height::Height;
use super::neohookean::{Deviatoric, Hydrostatic};
use super::row::{Family, Formula, Row};
use super::visit::{Pair, Visit, VisitProjected};
use super::volume::Volume;
use std::borrow::Cow;

/// The built-in families: each entry is `PLACE CONSTANT: Type, ARITY` (`, with PARTNER:
/// PartnerType` for the lead of a pair) `=> Row`, in projection order, places counted from 0.
macro_rules! builtin_families {
    ($(
        $(#[$doc:meta])*
        $index:literal $constant:ident: $constraint:ident, $arity:literal
        $(, with $partner:ident: $partner_constraint:ident)?
        => $row:expr;
    )*) => {
        impl Family {
            $( $(#[$doc])* pub const $constant: Family = Family($index); )*
        }

        /// The built-in families' rows, in projection order (edges, heights, volumes, the
        /// neo-Hookean pair, then contact).
        pub static TABLE: [Row; [$($index),*].len()] = [$($row),*];

        // The places are 0, 1, 2, … in the order of the entries.
        const _: () = {
            let mut expected = 0u8;
            $( assert!($index == expected, "built-in places count from 0 in order"); expected += 1; )*
            let _ = expected;
        };

        /// Calls `visitor` with built-in `family`'s type.
        #[inline]
        pub(super) fn visit<T: Visit>(family: Family, visitor: T) -> T::Output {
            match family.0 {
                $( $index => visitor.visit(family, &$constraint), )*
                _ => unreachable!("{family:?} is not a built-in family"),
            }
        }

        /// Calls `visitor` with the [`Pair`] that built-in `lead` leads with `partner`.
        #[inline]
        pub(super) fn visit_pair<T: VisitProjected>(
            lead: Family,
            partner: Family,
            visitor: T,
        ) -> T::Output {
            $($(
                if lead == Family::$constant && partner == Family::$partner {
                    return visitor.visit([lead, partner], &Pair(&$constraint, &$partner_constraint));
                }
            )?)*
            panic!("{lead:?} does not lead a pair with {partner:?}")
        }

        /// Built-in `family`'s constraint in f64, for tools.
        pub(super) fn constraint(family: Family) -> &'static dyn AnyConstraint {
            match family.0 {
                $( $index => &Typed::<$arity, $constraint>($constraint), )*
                _ => unreachable!("{family:?} is not a built-in family"),
            }
        }
    };
}

builtin_families! {
    /// Edge distance ([`super::distance`]).
    0 EDGES: Distance, 2 => Row {
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
        reads_rest_shape: false,
        rest_uses_material: false,
        stored_len: 0,
    };
    /// The four heights of each tet ([`super::height`]).
    1 HEIGHT: Height, 4 => Row {
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
        reads_rest_shape: false,
        rest_uses_material: false,
        stored_len: 0,
    };
    /// Signed volume ([`super::volume`]).
    2 VOLUME: Volume, 4 => Row {
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
        reads_rest_shape: false,
        rest_uses_material: false,
        stored_len: 0,
    };
    /// The deviatoric half of a neo-Hookean tet ([`super::neohookean`]); it leads the pair.
    3 NEOHOOKEAN_DEVIATORIC: Deviatoric, 4, with NEOHOOKEAN_HYDROSTATIC: Hydrostatic => Row {
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
        reads_rest_shape: true,
        rest_uses_material: false,
        stored_len: 0,
    };
    /// The hydrostatic half of a neo-Hookean tet ([`super::neohookean`]).
    4 NEOHOOKEAN_HYDROSTATIC: Hydrostatic, 4 => Row {
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
        reads_rest_shape: true,
        rest_uses_material: true,
        stored_len: 0,
    };
    /// Contact between surfaces ([`super::contact`]): found every frame, projected after the
    /// other families of each sweep.
    5 CONTACT: Contact, 4 => Row {
        name: Cow::Borrowed("contact"),
        aliases: &["contacts", "collision"],
        title: Cow::Borrowed("Contact: height above another surface"),
        label: Cow::Borrowed("contact"),
        colour: [220, 40, 120, 255],
        formula: Formula::Builtin(super::contact::FORMULA),
        rest_symbol: "d",
        arity: 4,
        binding: Binding::Contacts,
        group: Cow::Borrowed("contact"),
        compliance_from_material: None,
        projected_with: None,
        reads_rest_shape: false,
        rest_uses_material: false,
        stored_len: 0,
    };
}
