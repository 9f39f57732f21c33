//! Where the GPU engine keeps each number ([`Memory`]): four buffers, laid out from the fast
//! engine's arrays (the GPU projects the fast engine's layout: its particle numbering, colours,
//! batches, rest values and order), and the dispatches of one sweep.
//!
//! - `points` (`vec4<f32>` per particle), one [`Section`] of n after another: positions, their
//!   residuals, both at the start of the substep, velocities, rest positions, external forces,
//!   the ground's pushes, what was taken, the predicted positions and Δp;
//! - `numbers` (`f32`): the inverse masses; every multiplier (each active family's, then the
//!   compliant grab's), together, so one dispatch zeroes them; each layout's weights and sizes;
//!   each family's rest values, stored numbers and own α̃ (batch × 8 + lane, as the fast engine
//!   stores its lanes);
//! - `indices` (`u32`): each layout's particles, then the elements of each dispatch (its slots,
//!   batch × 8 + lane, padding left out);
//! - `counters`: per family, the projections skipped as degenerate and as too long.

use crate::constraints::{Families, Family, PerFamily, Unit};
use crate::simulation::fast::FastSimulation;
use crate::simulation::fast::batches::{Layout, group_index};
use glam::Vec3A;
use std::ops::Range;

/// A run of n `vec4<f32>` in `points`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum Section {
    /// x.
    Positions,
    /// r: what x's rounding left out.
    Residuals,
    /// x at the start of the substep.
    Previous,
    /// r at the start of the substep.
    PreviousResiduals,
    /// v.
    Velocities,
    /// The rest shape.
    Rest,
    /// External forces (zero: none).
    Forces,
    /// The ground's moves within the substep.
    Pushes,
    /// What the ground, damping and the cap took, this frame.
    Taken,
    /// The predicted positions, which Δp is measured from.
    Predicted,
    /// Δp of the last substep.
    LastCorrections,
    /// Δp summed over the frame.
    FrameCorrections,
}

/// How many sections `points` has.
pub(super) const SECTIONS: usize = 12;

/// Where a layout's arrays are: its particles in `indices`, its weights and sizes in `numbers`.
#[derive(Clone, Copy, Debug)]
pub(super) struct LayoutAt {
    pub particles: u32,
    pub weights: u32,
    pub size: u32,
}

/// Where a family's numbers are in `numbers`.
#[derive(Clone, Copy, Debug)]
pub(super) struct FamilyAt {
    pub rest: u32,
    pub lambda: u32,
    pub stored: u32,
    pub stored_len: usize,
    /// The own α̃ rows, where some element has a compliance of its own.
    pub own: Option<u32>,
}

/// One dispatch of a sweep: `count` threads on the slots from `first` in `indices`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) struct Dispatch {
    pub first: u32,
    pub count: u32,
}

/// The memory map of one build of the GPU engine (see the module).
#[derive(Debug)]
pub(super) struct Memory {
    particles: u32,
    layouts: Vec<LayoutAt>,
    layout_of: PerFamily<Option<usize>>,
    families: PerFamily<Option<FamilyAt>>,
    /// Every multiplier, the grab's last.
    pub lambdas: Range<u32>,
    /// The numbers and indices in all.
    pub numbers_len: usize,
    pub indices: Vec<u32>,
    /// The dispatches of each unit's sweep, in order: level by level, colour by colour, every
    /// group of a level in one dispatch (the groups share no particle).
    pub sweeps: Vec<(Unit, Vec<Dispatch>)>,
}

impl Memory {
    /// The map of `mirror`'s arrays, projecting `units`; also the `indices` buffer's content.
    pub(super) fn new(mirror: &FastSimulation, families: &Families, units: &[Unit]) -> Memory {
        let n = mirror.positions.len();
        let mut numbers = n;
        // The next `len` numbers.
        fn take_from(numbers: &mut usize, len: usize) -> u32 {
            let at = *numbers as u32;
            *numbers += len;
            at
        }
        macro_rules! take {
            ($len:expr) => {
                take_from(&mut numbers, $len)
            };
        }
        // The multipliers first, together.
        let active: Vec<Family> = units.iter().flat_map(|u| u.families()).collect();
        let lambda_start = numbers as u32;
        let mut lambda_at = PerFamily::<Option<u32>>::default();
        for &family in &active {
            let batches = mirror.sets[family].uploaded().0.len();
            lambda_at[family] = Some(take!(batches * 8));
        }
        let grab = take!(1);
        let lambdas = lambda_start..grab + 1;
        // The layouts, each once.
        let mut distinct: Vec<&Layout> = Vec::new();
        let mut layout_of = PerFamily::<Option<usize>>::default();
        for &family in &active {
            let layout = mirror.layouts.of(families, family);
            let k = match distinct.iter().position(|l| std::ptr::eq(*l, layout)) {
                Some(k) => k,
                None => {
                    distinct.push(layout);
                    distinct.len() - 1
                }
            };
            layout_of[family] = Some(k);
        }
        let mut indices: Vec<u32> = Vec::new();
        let mut layouts = Vec::new();
        for layout in &distinct {
            let (particles, weights, size) = layout.rows();
            let at = LayoutAt {
                particles: indices.len() as u32,
                weights: take!(weights.len() * 8),
                size: take!(size.len() * 8),
            };
            indices.extend(particles.iter().flatten());
            layouts.push(at);
        }
        let mut family_at = PerFamily::<Option<FamilyAt>>::default();
        for &family in &active {
            let (rest, stored, stored_len, own) = mirror.sets[family].uploaded();
            family_at[family] = Some(FamilyAt {
                rest: take!(rest.len() * 8),
                lambda: lambda_at[family].expect("every active family has its multipliers"),
                stored: take!(stored.len() * 8),
                stored_len,
                own: (!own.is_empty()).then(|| take!(own.len() * 8)),
            });
        }
        let mut sweeps = Vec::new();
        for &unit in units {
            let layout = mirror.layouts.of(families, unit.lead);
            let order = &mirror.colour_orders[unit.lead];
            let mut dispatches = Vec::new();
            for level in 0..layout.levels() {
                for k in 0..layout.colour_count() {
                    let first = indices.len() as u32;
                    for group in 0..layout.groups(level) {
                        let entry =
                            layout.entry(group_index(layout.regions(), level, group), k, order);
                        let start = entry.batches.start as u32 * 8;
                        indices.extend(start..start + entry.elements as u32);
                    }
                    let count = indices.len() as u32 - first;
                    if count > 0 {
                        dispatches.push(Dispatch { first, count });
                    }
                }
            }
            sweeps.push((unit, dispatches));
        }
        Memory {
            particles: n as u32,
            layouts,
            layout_of,
            families: family_at,
            lambdas,
            numbers_len: numbers,
            indices,
            sweeps,
        }
    }

    /// The particles.
    pub(super) fn particles(&self) -> u32 {
        self.particles
    }

    /// Where `section` starts in `points`.
    pub(super) fn section(&self, section: Section) -> u32 {
        section as u32 * self.particles
    }

    /// Where the layout `family` is projected on is.
    ///
    /// # Panics
    /// If `family` is not projected.
    pub(super) fn layout_of(&self, family: Family) -> LayoutAt {
        self.layouts[self.layout_of[family].expect("a projected family has its layout")]
    }

    /// Where `family`'s numbers are.
    ///
    /// # Panics
    /// If `family` is not projected.
    pub(super) fn family(&self, family: Family) -> FamilyAt {
        self.families[family].expect("a projected family has its numbers")
    }

    /// Where the compliant grab's multiplier is.
    pub(super) fn grab_lambda(&self) -> u32 {
        self.lambdas.end - 1
    }

    /// The `numbers` buffer's content from `mirror`: inverse masses, multipliers at 0, the
    /// layouts' weights and sizes, the families' rest values, stored numbers and own α̃.
    pub(super) fn numbers(&self, mirror: &FastSimulation, families: &Families) -> Vec<f32> {
        let mut numbers = vec![0.0f32; self.numbers_len];
        numbers[..mirror.inverse_masses.len()].copy_from_slice(&mirror.inverse_masses);
        let mut put = |at: u32, rows: &[crate::numbers::lanes::F32x8]| {
            for (k, row) in rows.iter().enumerate() {
                let at = at as usize + k * 8;
                numbers[at..at + 8].copy_from_slice(&row.to_array());
            }
        };
        for family in families.all() {
            let (Some(at), Some(k)) = (self.families[family], self.layout_of[family]) else {
                continue;
            };
            let layout = mirror.layouts.of(families, family);
            let (_, weights, size) = layout.rows();
            put(self.layouts[k].weights, weights);
            put(self.layouts[k].size, size);
            let (rest, stored, _, own) = mirror.sets[family].uploaded();
            put(at.rest, rest);
            put(at.stored, stored);
            if let Some(own_at) = at.own {
                put(own_at, own);
            }
        }
        numbers
    }

    /// The `points` buffer's content from `mirror` (sections in order; pushes, taken and the
    /// predicted positions zero).
    pub(super) fn points(&self, mirror: &FastSimulation) -> Vec<[f32; 4]> {
        let n = self.particles as usize;
        let mut points = Vec::with_capacity(SECTIONS * n);
        let zero = vec![Vec3A::ZERO; n];
        let or_zero = |v: &'_ Vec<Vec3A>| {
            if v.len() == n {
                v.clone()
            } else {
                zero.clone()
            }
        };
        let corrections = &mirror.corrections;
        for section in [
            &mirror.positions,
            &mirror.residuals,
            &mirror.previous,
            &mirror.previous_residuals,
            &mirror.velocities,
            &mirror.rest_positions,
            &or_zero(&mirror.forces),
            &zero,
            &zero,
            &zero,
            &or_zero(&corrections.last),
            &or_zero(&corrections.frame),
        ] {
            points.extend(section.iter().map(|v| [v.x, v.y, v.z, 0.0]));
        }
        points
    }
}
