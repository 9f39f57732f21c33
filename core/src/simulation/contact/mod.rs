//! Contact between bodies, and between parts of one body: the pairs of a surface particle and a
//! surface triangle that may meet within a frame, found once a frame ([`ContactFinder`] over a
//! [`ContactSurface`]), and projected at the end of every sweep by each active family that binds
//! to contacts ([`crate::constraints::Binding::Contacts`]: the built-in `contact`, whose formula
//! is the height constraint's, or a constraint file's), as an inequality C ≥ 0 with friction.
//!
//! What is the same as for the other families: the formula is the family's
//! [`crate::constraints::Constraint`], the rule is the family's (its compliance, XPBD or PBD),
//! and both CPU engines run the one pass (`project`), each in its own precision.
//! What differs: the pairs change every frame; a pair is projected only while C < 0 and its
//! particle is over the triangle; its rest value is the thickness ([`ContactSettings`]);
//! friction follows each projection.

mod broad_phase;
pub(crate) mod contact_settings;
pub(crate) mod describe;
pub(crate) mod project;
pub(crate) mod surface;

pub use broad_phase::{ContactFinder, Reach};
pub use contact_settings::ContactSettings;
pub use describe::ContactState;
pub use surface::ContactSurface;

use crate::constraints::{Binding, Families, Family, MAX_FAMILIES};
use crate::simulation::Resolved;
use arrayvec::ArrayVec;
use std::sync::Arc;

/// What a frame's sweeps project of contact: the pairs found at its start, the active families
/// that bind to contacts, the thickness and the friction.
#[derive(Clone, Debug)]
pub struct ContactPlan {
    /// The pairs, [particle, a, b, c] in the scene's numbering.
    pub found: Arc<Vec<[u32; 4]>>,
    /// The active families that bind to contacts, in the table's order.
    pub families: ArrayVec<Family, MAX_FAMILIES>,
    /// The order of the pairs that the settings' order seed asks for (`None`: as found).
    pub order: Option<Vec<u32>>,
    /// The contact settings.
    pub settings: ContactSettings,
}

impl ContactPlan {
    /// How many pairs the frame's arrays keep room for: half what the pairs found hold room for
    /// (they keep room for twice the most found yet, and for at least twice as many as the
    /// surface has particles, since how many pairs a frame finds changes with the bodies'
    /// speeds: [`keep_room`]).
    pub fn room(&self) -> usize {
        (self.found.capacity() / 2).max(self.found.len())
    }

    /// The plan of a frame under `resolved` with the pairs `found`: `None` when no active family
    /// binds to contacts.
    pub fn new(
        families: &Families,
        resolved: &Resolved,
        found: &Arc<Vec<[u32; 4]>>,
    ) -> Option<ContactPlan> {
        let contact: ArrayVec<Family, MAX_FAMILIES> =
            contact_families(families, &resolved.active).collect();
        if contact.is_empty() {
            return None;
        }
        let settings = resolved.settings;
        let order = settings.projection_order(contact[0], found.len());
        Some(ContactPlan {
            found: Arc::clone(found),
            families: contact,
            order,
            settings: settings.contact,
        })
    }
}

/// The built-in contact's C = h − d of `pair` ([particle, a, b, c]) at `positions`, with the
/// thickness d, where its particle is over its triangle and the triangle has an area; `None`
/// otherwise: what the metrics and the start of a scene read of a pair.
///
/// ```
/// use glam::DVec3;
/// use tetlab_core::simulation::contact::over_and_closing;
/// let positions = [DVec3::new(0.2, 0.005, 0.2), DVec3::ZERO, DVec3::Z, DVec3::X];
/// let c = over_and_closing(&positions, [0, 1, 2, 3], 0.01).unwrap();
/// assert!((c + 0.005).abs() < 1e-15, "5 mm into a 1 cm layer");
/// let beside = [DVec3::new(2.0, 0.005, 0.2), DVec3::ZERO, DVec3::Z, DVec3::X];
/// assert_eq!(over_and_closing(&beside, [0, 1, 2, 3], 0.01), None);
/// ```
pub fn over_and_closing(positions: &[glam::DVec3], pair: [u32; 4], thickness: f64) -> Option<f64> {
    let p = pair.map(|i| positions[i as usize]);
    project::over_triangle(p[0], [p[1], p[2], p[3]])?;
    let e = crate::constraints::contact::evaluate(&p, thickness);
    (!e.degenerate).then_some(e.value)
}

/// The families among `active` that bind to contacts.
pub fn contact_families<'a>(
    families: &'a Families,
    active: &'a crate::constraints::PerFamily<bool>,
) -> impl Iterator<Item = Family> + 'a {
    families
        .all()
        .filter(move |&f| active[f] && families.binding(f) == Binding::Contacts)
}

/// One pass of every family of `contact` over the pairs `found` (in the engine's numbering), on
/// an engine's arrays in its precision: the positions, where the particles were at the
/// substep's start, the inverse masses; `lambdas` holds each family's multipliers in turn
/// (`found.len()` each); `rules` are the families' rules. Adds each family's skipped
/// projections to `skipped`. With `only` = (family, pair), that one pair of that one family is
/// projected (step-by-step mode), as the pass would project it.
pub(crate) fn project_pairs<V: crate::numbers::vector::Vector3>(
    families: &Families,
    rules: &crate::constraints::PerFamily<crate::simulation::projection::Rule<f64>>,
    contact: &ContactPlan,
    (found, only): (&[[u32; 4]], Option<(Family, usize)>),
    (positions, previous, inverse_masses): (&mut [V], &mut [V], &[V::Real]),
    lambdas: &mut [V::Real],
    skipped: &mut crate::constraints::PerFamily<crate::simulation::projection::SkipCounts>,
) where
    V::Real: crate::numbers::vector::Real<Mask = bool> + PartialOrd,
{
    use crate::numbers::vector::Real;
    let n = found.len();
    let settings = contact.settings;
    for (k, &family) in contact.families.iter().enumerate() {
        if only.is_some_and(|(f, _)| f != family) {
            continue;
        }
        let pass = project::ContactPass {
            found,
            order: contact.order.as_deref(),
            positions: &mut *positions,
            previous: &mut *previous,
            inverse_masses,
            lambdas: &mut lambdas[k * n..(k + 1) * n],
            thickness: V::Real::from_f64(settings.thickness),
            rule: rules[family].to(),
            friction: [
                V::Real::from_f64(settings.static_friction),
                V::Real::from_f64(settings.kinetic_friction),
            ],
            only: only.map(|(_, c)| c),
        };
        let counted = families.visit(family, pass);
        skipped[family] = skipped[family] + counted;
    }
}

/// Makes room in `array` for twice `len` items (twice the most a frame has needed), so that
/// the frames after allocate nothing while their count of pairs stays under that. Pairs come
/// and go every frame: an array grown only to each new largest count would allocate at each.
///
/// ```
/// # use tetlab_core::simulation::contact::keep_room;
/// let mut pairs: Vec<[u32; 4]> = Vec::new();
/// keep_room(&mut pairs, 10);
/// let room = pairs.capacity();
/// assert!(room >= 20);
/// keep_room(&mut pairs, 10);
/// assert_eq!(pairs.capacity(), room, "room already made is kept, not made again");
/// ```
pub fn keep_room<T>(array: &mut Vec<T>, len: usize) {
    let room = 2 * len;
    if array.capacity() < room {
        array.reserve_exact(room - array.len());
    }
}

/// The unit tests' scene of contact: a cube of `resolution` cells on the ground and another
/// placed `at` (x, y, z) from where the mesh puts it, on `settings` with edges, volume and
/// contact switched on, run for `frames` frames.
#[cfg(test)]
pub(crate) fn cube_on_cube(
    resolution: u32,
    at: [f64; 3],
    settings: super::Settings,
    frames: usize,
) -> super::Simulation {
    let [x, y, z] = at;
    let text = format!(
        "[[body]]\nmesh = \"cube\"\nresolution = {resolution}\n\
         [[body]]\nmesh = \"cube\"\nresolution = {resolution}\ntranslate = [{x}, {y}, {z}]\n"
    );
    let scene = crate::scene::Scene::parse_file(std::path::Path::new("t.toml"), &text).unwrap();
    let mut simulation = super::Simulation::new(&scene, settings);
    let active = (simulation.families().parse_list("edges,volume,contact")).unwrap();
    simulation.set_settings(super::Settings { active, ..settings });
    for _ in 0..frames {
        simulation.step();
    }
    simulation
}
