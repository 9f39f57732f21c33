//! A family is data plus one formula: its row says what its formula does (how many particles,
//! whether it reads the rest shape, whether its rest value depends on the material, how many
//! numbers it stores), and every program reads the row instead of asking the type. These tests
//! hold every row, the built-in ones and those of every example constraint file, to its formula,
//! so that a row cannot be incomplete or wrong about it.

#[path = "support/example_files.rs"]
mod example_files;

use glam::DVec3;
use tetlab_core::constraint_file::ConstraintFile;
use tetlab_core::constraints::material::Material;
use tetlab_core::constraints::{Families, Family, PerFamily, TABLE, Unit, VisitProjected};
use tetlab_core::numbers::random::SplitMix64;

/// Every family to check, each with a table it is in: the built-in ones, then each example
/// file's (a table of the built-in families and that file).
fn every_family() -> Vec<(Families, Family)> {
    let builtin = Families::builtin();
    let mut all: Vec<(Families, Family)> = builtin.all().map(|f| (builtin.clone(), f)).collect();
    for path in example_files::example_files() {
        let mut families = Families::builtin();
        let files = ConstraintFile::load_all(&path).unwrap();
        for family in families.register_all(files).unwrap() {
            all.push((families.clone(), family));
        }
    }
    all
}

/// `n` points in a unit cube about `centre`.
fn points(random: &mut SplitMix64, n: usize, centre: DVec3) -> Vec<DVec3> {
    (0..n).map(|_| centre + random.in_cube(1.0)).collect()
}

#[test]
fn every_row_names_and_draws_its_family() {
    let every = every_family();
    assert!(every.len() > TABLE.len() + 10, "the example files joined");
    for (families, family) in every {
        let row = families.row(family);
        let name = &row.name;
        for (what, text) in [
            ("name", &row.name),
            ("title", &row.title),
            ("label", &row.label),
            ("group", &row.group),
        ] {
            assert!(!text.trim().is_empty(), "{name}: no {what}");
        }
        assert!(!row.rest_symbol.is_empty(), "{name}: no rest symbol");
        assert!(row.formula.lines().next().is_some(), "{name}: no formula");
        assert_eq!(row.arity, row.binding.arity(), "{name}: arity and binding");
        assert_eq!(row.colour[3], 255, "{name}: an opaque colour");
    }
    // The built-in families' arrows tell them apart.
    for (i, a) in TABLE.iter().enumerate() {
        for b in &TABLE[i + 1..] {
            assert_ne!(a.colour, b.colour, "{} and {}", a.name, b.name);
        }
    }
}

#[test]
fn every_row_says_what_its_formula_reads_and_stores() {
    let mut random = SplitMix64::new(43);
    let (soft, stiff) = (
        Material::parse("E=1e5,nu=0.2").unwrap(),
        Material::parse("E=3e6,nu=0.45").unwrap(),
    );
    for (families, family) in every_family() {
        let row = families.row(family);
        let name = &row.name;
        let constraint = families.constraint(family);
        let (mut reads, mut depends) = (false, false);
        for _ in 0..20 {
            let centre = random.in_cube(2.0);
            let p = points(&mut random, row.arity, centre);
            let (a, b) = (
                points(&mut random, row.arity, centre),
                points(&mut random, row.arity, centre),
            );
            let (ea, eb) = (
                constraint.evaluate(&p, 0.3, &a),
                constraint.evaluate(&p, 0.3, &b),
            );
            reads |= ea.value.to_bits() != eb.value.to_bits() || ea.gradients != eb.gradients;
            let (ra, rb) = (
                constraint.rest_value(&a, &soft),
                constraint.rest_value(&a, &stiff),
            );
            depends |= ra.to_bits() != rb.to_bits();
            for material in [&soft, &stiff] {
                assert_eq!(
                    constraint.store(&a, material).len(),
                    row.stored_len,
                    "{name}: what it stores"
                );
            }
        }
        assert_eq!(reads, row.reads_rest_shape, "{name}: reads the rest shape");
        if depends {
            assert!(
                row.rest_uses_material,
                "{name}: its rest value is the material's"
            );
        }
        if family.index() < TABLE.len() {
            assert_eq!(
                depends, row.rest_uses_material,
                "{name}: rest value and material"
            );
        }
    }
}

#[test]
fn every_pair_is_two_families_that_name_each_other_and_project_as_one() {
    let mut pairs = 0;
    for (families, family) in every_family() {
        let row = families.row(family);
        let Some(partner) = row.projected_with else {
            continue;
        };
        let other = families.row(partner);
        assert_eq!(
            other.projected_with,
            Some(family),
            "{}: both ways",
            row.name
        );
        assert_eq!(row.binding, other.binding, "{}: one binding", row.name);
        assert_eq!(row.group, other.group, "{}: one group", row.name);
        // Active together, they are one projection of two values, led by the first.
        let active = families.per_family(|f| f == family || f == partner);
        let unit = families.unit_of(family, &active);
        assert_eq!(unit.lead, family.min(partner));
        assert_eq!(unit.partner, Some(family.max(partner)));
        assert_eq!(families.units(&active).collect::<Vec<_>>(), [unit]);
        struct Values;
        impl VisitProjected for Values {
            type Output = usize;
            fn visit<const N: usize, const K: usize, P>(self, _: [Family; K], _: &P) -> usize
            where
                P: tetlab_core::constraints::Projected<N, K>,
            {
                K
            }
        }
        assert_eq!(families.visit_unit(unit, Values), 2, "{}", row.name);
        // Alone, each is a projection of its own.
        let alone: PerFamily<bool> = families.per_family(|f| f == family);
        let lone = Unit {
            lead: family,
            partner: None,
        };
        assert_eq!(families.unit_of(family, &alone), lone);
        assert_eq!(families.visit_unit(lone, Values), 1);
        pairs += 1;
    }
    assert!(
        pairs >= 4,
        "the neo-Hookean pair and a file's pair, both ways: {pairs}"
    );
}
