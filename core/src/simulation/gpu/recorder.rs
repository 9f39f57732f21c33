//! A frame of the GPU engine recorded as the substep every engine shares
//! ([`crate::simulation::substep::frame`]): each stage of [`Substeps`] records its dispatches
//! into one compute pass ([`Recorder`]), so that every substep of a frame is one submission and
//! nothing is read back inside it. Only the order of the stages is the skeleton's; what each
//! stage computes is a kernel of [`super::kernels`].

use super::kernels::{Shape, WORKGROUP};
use super::resident::{ENTRY, Resident, entry};
use crate::constraints::Unit;
use crate::simulation::substep::{Plan, Substeps};
use glam::DVec3;

/// The dispatches a frame records, and how many.
pub(super) struct Recorder<'a> {
    pub resident: &'a Resident,
    pub pass: wgpu::ComputePass<'a>,
    pub shape: Shape,
    pub dispatches: u64,
}

impl Recorder<'_> {
    /// Records `pipeline` on `count` threads with dispatch entry `entry`.
    fn dispatch(&mut self, pipeline: &'static str, shaped: bool, entry: u32, count: u32) {
        let shape = if shaped { self.shape } else { Shape::NONE };
        let kernel = self.resident.kernel(pipeline, shape);
        self.run(kernel, entry, count);
    }

    fn run(&mut self, kernel: &wgpu::ComputePipeline, entry: u32, count: u32) {
        if count == 0 {
            return;
        }
        let offset = u64::from(entry) * ENTRY;
        self.pass.set_pipeline(kernel);
        self.pass
            .set_bind_group(0, &self.resident.bind_group, &[offset as u32]);
        let groups = count.div_ceil(WORKGROUP);
        let x = groups.min(65_535);
        self.pass.dispatch_workgroups(x, groups.div_ceil(x), 1);
        self.dispatches += 1;
    }

    fn particles(&self) -> u32 {
        self.resident.memory.particles()
    }
}

impl Substeps for Recorder<'_> {
    fn predict(&mut self, _: &Plan) {
        self.dispatch("predict", true, entry::PARTICLES, self.particles());
    }

    /// The target is in the frame's uniform and the particle in the grab's dispatch entry.
    fn hold(&mut self, _: usize, _: DVec3) {
        self.dispatch("hold", false, entry::GRAB, 1);
    }

    fn keep_predicted(&mut self) {
        self.dispatch("keep predicted", false, entry::PARTICLES, self.particles());
    }

    fn reset_multipliers(&mut self, _: &Plan) {
        let lambdas = &self.resident.memory.lambdas;
        self.dispatch("zero", false, entry::LAMBDAS, lambdas.end - lambdas.start);
    }

    fn project(&mut self, unit: Unit, _: &Plan) {
        let resident = self.resident;
        let Some(k) = (resident.memory.sweeps.iter()).position(|(u, _)| *u == unit) else {
            return;
        };
        let first = resident.sweep_entries[k];
        for (j, dispatch) in resident.memory.sweeps[k].1.iter().enumerate() {
            self.run(&resident.units[k], first + j as u32, dispatch.count);
        }
    }

    /// Never called: a frame with contact runs on the CPU (`super::GpuEngine`).
    fn contacts(&mut self, _: &Plan) {}

    /// The particle is in the grab's dispatch entry; the target and α̃ in the frame's uniform.
    fn soft_grab(&mut self, _: usize, _: DVec3, _: f64, _: f64) {
        self.dispatch("soft grab", false, entry::GRAB, 1);
    }

    fn ground_and_plane(&mut self, plan: &Plan) {
        if plan.motion.ground.is_some() || plan.motion.plane_strain {
            self.dispatch("ground and plane", true, entry::PARTICLES, self.particles());
        }
    }

    fn keep_corrections(&mut self) {
        self.dispatch(
            "keep corrections",
            false,
            entry::PARTICLES,
            self.particles(),
        );
    }

    fn update_velocities(&mut self, _: &Plan) {
        self.dispatch(
            "update velocities",
            true,
            entry::PARTICLES,
            self.particles(),
        );
    }
}
