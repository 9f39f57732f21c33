//! What a reader asks of the fast engine: its numbering, its colours and their order, its
//! positions and velocities in the scene's numbering, how far each family is from holding, its
//! soundness, its memory, and the timings `tetlab bench` reports.

use super::{Batches, FamilyBatches, FastSimulation, POSITION_LIMIT, Team, Timings, share_timers};
use crate::constraints::{Constraint, Family, PerFamily, SubstepStart, Visit};
use crate::input::limits::SOUND_LIMIT;
use crate::simulation::Resolved;
use crate::simulation::divergence::Divergence;
use crate::simulation::projection::SkipCounts;
use glam::{DVec3, Vec3A};

impl FastSimulation {
    /// The scene's number of each particle, in the fast engine's (Morton) order.
    pub fn original(&self) -> &[u32] {
        &self.original
    }

    /// The order `family`'s colours are projected in, in each segment of its layout: colour
    /// numbers, below [`FamilyBatches::colour_count`].
    pub fn colour_order(&self, family: Family) -> Vec<usize> {
        let colours = self.batches(family).colour_count();
        let order = &self.colour_orders[family];
        (0..colours)
            .map(|k| order.get(k).map_or(k, |&c| c as usize))
            .collect()
    }

    /// The threads the projections run on.
    pub fn threads(&self) -> usize {
        self.team.as_ref().map_or(1, Team::threads)
    }

    /// The constraints of `family`, coloured and in batches (empty when it is not active).
    pub fn batches(&self, family: Family) -> FamilyBatches<'_> {
        FamilyBatches {
            layout: self.layouts.of(&self.families, family),
            batches: &self.sets[family],
        }
    }

    /// How far `threads` threads would keep to their own particles on `family`'s colours:
    /// (lines from another thread, lines) over one sweep ([`super::Layout::lines_from_other_threads`]).
    pub fn lines_from_other_threads(&self, family: Family, threads: usize) -> (usize, usize) {
        self.layouts
            .of(&self.families, family)
            .lines_from_other_threads(&self.colour_orders[family], threads)
    }

    /// Per active family, how far its constraints are from holding now: √(mean (C / rest)²) (a
    /// rest value of zero counts as one).
    pub fn relative_error(&self) -> PerFamily<Option<f64>> {
        struct RelativeError<'a> {
            batches: FamilyBatches<'a>,
            positions: &'a [Vec3A],
            rest_positions: &'a [Vec3A],
        }
        impl Visit for RelativeError<'_> {
            type Output = f64;
            fn visit<const N: usize, C: Constraint<N>>(self, _: Family, c: &C) -> f64 {
                let mut sum = 0.0;
                for (particles, rest, stored) in self.batches.constraints_storing() {
                    let at = |positions: &[Vec3A]| -> [Vec3A; N] {
                        std::array::from_fn(|k| positions[particles[k] as usize])
                    };
                    let p = at(self.positions);
                    let value = c
                        .evaluate_stored(
                            &p,
                            rest,
                            &at(self.rest_positions),
                            &stored,
                            SubstepStart::at_rest(&p),
                        )
                        .value;
                    let scale = if rest == 0.0 { 1.0 } else { rest.abs() };
                    sum += (f64::from(value) / f64::from(scale)).powi(2);
                }
                (sum / self.batches.len().max(1) as f64).sqrt()
            }
        }
        let active = self.resolved.active;
        self.families.per_family(|family| {
            active[family].then(|| {
                self.families.visit(
                    family,
                    RelativeError {
                        batches: self.batches(family),
                        positions: &self.positions,
                        rest_positions: &self.rest_positions,
                    },
                )
            })
        })
    }

    /// The settings in force, resolved against the table.
    pub fn resolved(&self) -> &Resolved {
        &self.resolved
    }

    /// Positions in the scene's particle numbering.
    pub fn positions(&self) -> Vec<DVec3> {
        let mut positions = self.in_scene_order(&self.positions);
        for (new, &old) in self.original.iter().enumerate() {
            positions[old as usize] += self.origin + self.residuals[new].as_dvec3();
        }
        positions
    }

    /// Velocities in the scene's particle numbering.
    pub fn velocities(&self) -> Vec<DVec3> {
        self.in_scene_order(&self.velocities)
    }

    fn in_scene_order(&self, values: &[Vec3A]) -> Vec<DVec3> {
        let mut out = vec![DVec3::ZERO; values.len()];
        for (v, &i) in values.iter().zip(&self.original) {
            out[i as usize] = v.as_dvec3();
        }
        out
    }

    /// Ok while every f32 coordinate (measured from the engine's origin, which follows the
    /// body) is finite and below [`POSITION_LIMIT`] in size, every position below
    /// [`SOUND_LIMIT`], and every velocity component below that too; otherwise
    /// the first that is not (particles in the scene's numbering).
    pub fn check(&self) -> Result<(), Divergence> {
        let f64s = |v: &Vec3A| v.as_dvec3().to_array();
        let original = |i: usize| self.original[i] as usize;
        Divergence::find(
            self.frame,
            (POSITION_LIMIT, SOUND_LIMIT),
            self.positions.iter().map(f64s),
            self.velocities.iter().map(f64s),
            original,
        )?;
        let global = |v: &Vec3A| (self.origin + v.as_dvec3()).to_array();
        Divergence::find(
            self.frame,
            (SOUND_LIMIT, SOUND_LIMIT),
            self.positions.iter().map(global),
            std::iter::empty(),
            original,
        )
    }

    /// Whether [`FastSimulation::check`] finds nothing.
    pub fn is_sound(&self) -> bool {
        self.check().is_ok()
    }

    /// Frames stepped.
    pub fn frame(&self) -> u64 {
        self.frame
    }

    /// The tets in the scene.
    pub fn tet_count(&self) -> usize {
        self.tets
    }

    /// Constraint projections one frame makes with the current settings.
    pub fn projections_per_frame(&self) -> u64 {
        (self.resolved.settings)
            .projections_per_frame(self.families.per_family(|f| self.batches(f).len()))
    }

    /// The bytes of memory the solver's arrays take.
    pub fn heap_bytes(&self) -> usize {
        (self.positions.capacity()
            + self.previous.capacity()
            + self.residuals.capacity()
            + self.previous_residuals.capacity()
            + self.velocities.capacity()
            + self.rest_positions.capacity())
            * size_of::<Vec3A>()
            + self.inverse_masses.capacity() * size_of::<f32>()
            + (self.original.capacity() + self.renumber.capacity()) * size_of::<u32>()
            + (self.layouts.all())
                .map(|layout| layout.heap_bytes())
                .sum::<usize>()
            + self
                .sets
                .every_place()
                .map(Batches::heap_bytes)
                .sum::<usize>()
            + (self.corrections.predicted.capacity()
                + self.corrections.last.capacity()
                + self.corrections.frame.capacity())
                * size_of::<Vec3A>()
            + self.jacobi.as_ref().map_or(0, |j| {
                j.sums.capacity() * size_of::<Vec3A>()
                    + j.factors.every_place().map(Vec::capacity).sum::<usize>() * size_of::<f32>()
            })
    }

    /// Time and projections per family since the last [`FastSimulation::reset_timings`].
    pub fn timings(&self) -> Timings {
        self.timings
    }

    /// The projections skipped for a counted reason (∇C undefined, or a step beyond
    /// [`crate::simulation::projection::DEFAULT_REACH`]) since the last call, per family; the
    /// count starts again.
    pub(super) fn take_skipped(&mut self) -> PerFamily<SkipCounts> {
        std::mem::take(&mut self.skipped)
    }

    /// Starts the timings afresh.
    pub fn reset_timings(&mut self) {
        self.timings = Timings::default();
        share_timers::reset();
    }

    /// With the feature `share-timers`, the mean time of a colour large enough to share and of
    /// each thread's share of one, since [`FastSimulation::reset_timings`] (process-wide: one
    /// simulation at a time); `None` without it.
    pub fn share_timings(&self) -> Option<String> {
        share_timers::report()
    }
}
