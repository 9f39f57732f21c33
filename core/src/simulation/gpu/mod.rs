//! The GPU engine ([`GpuEngine`]): the fast engine's model on a GPU, in WGSL compute shaders on
//! wgpu. The same f32 numbers as the fast engine (each position with the residual its rounding
//! left out, every correction added compensated), the same particle numbering, the same colours
//! in the same order ([`crate::simulation::fast`]'s layout, uploaded as it is), and the same
//! code: every kernel is the CPU engines' Rust run on traced numbers
//! ([`crate::numbers::traced`]), a family's formula (a built-in one or a constraint file's tape),
//! the projection rule and the integration, turned into WGSL when the engine is built, and
//! checked by naga before a driver sees it (`kernels`).
//!
//! A frame is one submission: its substeps are the skeleton every engine shares
//! ([`crate::simulation::substep::frame`]), each stage recorded as dispatches (`recorder`); one
//! dispatch projects one colour of a family (every group of a level at once, since groups share
//! no particle), one thread per element. After the frame the positions, velocities, Δp, what
//! the ground, damping and the cap took and the skip counts are read back once, into a fast
//! engine kept beside it as the CPU's copy (the mirror), which writes the simulation's state
//! as the fast engine does.
//!
//! What runs on the CPU instead, in the mirror, one frame at a time, with
//! [`Engine::describe`] saying so: a frame with contact (its pairs are found and projected on
//! the CPU for now), and every frame when no GPU can be had or a kernel does not compile.

mod device;
mod kernels;
mod memory;
mod recorder;
mod resident;

pub use device::{Gpu, adopt, gpu};

use crate::constraints::material::Material;
use crate::constraints::{Families, PerFamily, Unit};
use crate::simulation::engine::{Engine, Frame, Start};
use crate::simulation::fast::FastSimulation;
use crate::simulation::integrate::{Ending, Motion};
use crate::simulation::projection::{Rule, SkipCounts};
use crate::simulation::state::{Revision, State};
use crate::simulation::substep::{self, Plan};
use crate::simulation::{Divergence, Taken};
use glam::Vec3A;
use kernels::{Shape, slot};
use recorder::Recorder;
use resident::Resident;

/// What the GPU side was built for: when one of these changes, it is built again.
#[derive(Clone, Debug, PartialEq)]
struct BuiltFor {
    body: u64,
    active: PerFamily<bool>,
    material: Material,
    /// Each family's rule kind (XPBD, PBD, compliant PBD): it shapes the kernels.
    rules: PerFamily<u8>,
    order_seed: Option<u64>,
}

impl BuiltFor {
    fn of(frame: &Frame<'_>) -> BuiltFor {
        let resolved = frame.resolved;
        let h = resolved.substep_length();
        BuiltFor {
            body: frame.revision.body,
            active: resolved.active,
            material: resolved.settings.material,
            rules: frame
                .families
                .per_family(|f| rule_kind(resolved.rule(f, h))),
            order_seed: resolved.settings.order_seed,
        }
    }
}

fn rule_kind(rule: Rule<f64>) -> u8 {
    match rule {
        Rule::Xpbd { .. } => 0,
        Rule::Pbd { .. } => 1,
        Rule::CompliantPbd { .. } => 2,
    }
}

/// The GPU engine. See the module documentation.
pub struct GpuEngine {
    /// The CPU's copy: the layout the GPU projects, the state read back each frame, and the
    /// engine of the frames that run on the CPU.
    mirror: FastSimulation,
    families: Families,
    /// What is on the GPU, or why nothing is.
    resident: Result<Resident, String>,
    built_for: Option<BuiltFor>,
    /// The revision of the simulation's state the GPU holds (`None`: take it up again).
    synced: Option<u64>,
    /// The substep length the own α̃ on the GPU are for.
    own_h: f64,
    /// Whether the last frame ran on the CPU, and why.
    on_cpu: Option<&'static str>,
    /// Dispatches recorded by the last frame.
    dispatches: u64,
    /// The frame submitted whose results are on their way back.
    in_flight: Option<InFlight>,
    /// Whether [`Engine::step`] returns once a frame is submitted, without waiting for its
    /// results ([`GpuEngine::asynchronous`]).
    asynchronous: bool,
}

impl GpuEngine {
    /// The GPU engine for a simulation's body and state: laid out as the fast engine lays it
    /// out, uploaded to the process's GPU ([`gpu`]) on the first frame.
    pub fn new(start: Start<'_>) -> GpuEngine {
        let start = Start {
            threads: 1,
            ..start
        };
        GpuEngine {
            mirror: FastSimulation::new(start),
            families: start.families.clone(),
            resident: Err("not built yet".to_owned()),
            built_for: None,
            synced: None,
            own_h: f64::NAN,
            on_cpu: None,
            dispatches: 0,
            in_flight: None,
            asynchronous: cfg!(target_arch = "wasm32"),
        }
    }

    /// The GPU engine that never waits for the GPU: [`Engine::step`] submits a frame and
    /// returns, [`Engine::pending`] says the frame is under way, and a later `step` of the same
    /// frame takes its results once they arrived. The page's engine is this one (a browser
    /// hands a GPU's results over only between two of the page's frames); on the desktop it is
    /// for tests of that path, with the same results as [`GpuEngine::new`]'s.
    pub fn asynchronous(start: Start<'_>) -> GpuEngine {
        GpuEngine {
            asynchronous: true,
            ..GpuEngine::new(start)
        }
    }

    /// Whether frames run on the GPU: `Err` says why not.
    pub fn ready(&self) -> Result<(), &str> {
        self.resident.as_ref().map(|_| ()).map_err(String::as_str)
    }

    /// The bytes its buffers take on the GPU (0 where it has none).
    pub fn device_bytes(&self) -> u64 {
        self.resident.as_ref().map_or(0, Resident::device_bytes)
    }

    /// Dispatches the last frame recorded (0 for a frame that ran on the CPU).
    pub fn dispatches(&self) -> u64 {
        self.dispatches
    }

    /// Brings the mirror and the GPU up to `frame`: built again when what they were built for
    /// changed, the state taken up again after an edit.
    fn prepare(&mut self, frame: &Frame<'_>) {
        self.mirror.prepare(frame);
        let wanted = BuiltFor::of(frame);
        if self.built_for.as_ref() != Some(&wanted) {
            self.families = frame.families.clone();
            self.resident = gpu().and_then(|gpu| {
                let units: Vec<Unit> = frame.families.units(&frame.resolved.active).collect();
                let h = frame.resolved.substep_length();
                let rules = frame.families.per_family(|f| frame.resolved.rule(f, h));
                Resident::new(gpu, &self.mirror, &self.families, (&units, &rules))
            });
            self.built_for = Some(wanted);
            self.synced = Some(frame.revision.state);
            self.own_h = f64::NAN;
            return;
        }
        if self.synced != Some(frame.revision.state) {
            if let Ok(resident) = &self.resident {
                resident.upload(&self.mirror, &self.families);
            }
            self.synced = Some(frame.revision.state);
        }
    }

    /// A frame on the CPU, in the mirror (the fast engine), for `why`; the GPU takes the state
    /// up again before its next frame.
    fn on_the_cpu(&mut self, frame: Frame<'_>, why: &'static str) -> PerFamily<SkipCounts> {
        self.on_cpu = Some(why);
        self.dispatches = 0;
        self.synced = None;
        Engine::step(&mut self.mirror, frame)
    }
}

impl GpuEngine {
    /// One frame on the GPU: recorded and submitted, its results asked for.
    fn submit(&mut self, plan: &Plan, revision: Revision) -> Result<InFlight, String> {
        // The own α̃ follow h (the mirror works them out, the GPU takes them up).
        let mut own_changed = false;
        for family in self.families.all() {
            let set = &mut self.mirror.sets[family];
            if !set.uploaded().3.is_empty() && self.own_h != plan.h {
                set.set_substep(plan.h);
                own_changed = true;
            }
        }
        self.own_h = plan.h;
        let origin = self.mirror.origin;
        self.mirror.recentre();
        let shape = Shape {
            ground: plan.motion.ground.is_some(),
            plane_strain: plan.motion.plane_strain,
            forces: !self.mirror.forces.is_empty(),
            damped: plan.damping > 0.0,
            cap: plan.settling,
        };
        let resident = self.resident.as_mut().map_err(|e| e.clone())?;
        resident.prepare_kernels(shape)?;
        let resident = &*resident;
        if own_changed {
            resident.upload(&self.mirror, &self.families);
        } else if self.mirror.origin != origin {
            resident.upload_positions(&self.mirror);
        }
        write_uniforms(&self.mirror, &self.families, resident, plan);
        let device = &resident.gpu.device;
        let mut encoder = device.create_command_encoder(&wgpu::CommandEncoderDescriptor {
            label: Some("gpu engine frame"),
        });
        let memory = &resident.memory;
        let n = u64::from(memory.particles()) * 16;
        for section in [memory::Section::Taken, memory::Section::FrameCorrections] {
            let at = u64::from(memory.section(section)) * 16;
            encoder.clear_buffer(&resident.points, at, Some(n));
        }
        encoder.clear_buffer(&resident.counters, 0, None);
        let dispatches = {
            let pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
                label: Some("gpu engine frame"),
                timestamp_writes: None,
            });
            let mut recorder = Recorder {
                resident,
                pass,
                shape,
                dispatches: 0,
            };
            substep::frame(&mut recorder, plan);
            recorder.dispatches
        };
        resident.copy_back(&mut encoder);
        resident.gpu.queue.submit([encoder.finish()]);
        Ok(InFlight {
            reading: resident.request_read(),
            revision,
            dispatches,
        })
    }

    /// Takes the arrived results of `flight` into the mirror, and from there into the state.
    /// An error when the device failed the frame: the mirror still holds the state before it.
    fn finish(
        &mut self,
        flight: InFlight,
        state: &mut State,
    ) -> Result<PerFamily<SkipCounts>, String> {
        let counters = match &self.resident {
            Ok(resident) => resident.take(&mut self.mirror)?,
            Err(why) => return Err(why.clone()),
        };
        self.dispatches = flight.dispatches;
        self.on_cpu = None;
        self.mirror.frame += 1;
        let mut taken = Taken::default();
        taken.add_and_clear(&mut self.mirror.taken);
        state.taken.ground += taken.ground;
        state.taken.damping += taken.damping;
        state.taken.settling += taken.settling;
        let corrections = (&mut state.corrections[..], &mut state.frame_corrections[..]);
        self.mirror.store(
            &mut state.positions,
            &mut state.velocities,
            Some(corrections),
        );
        Ok(self.families.per_family(|f| SkipCounts {
            degenerate: u64::from(counters[2 * f.index()]),
            too_long: u64::from(counters[2 * f.index() + 1]),
        }))
    }

    /// A frame in flight whose results arrived, or `None` while they are on their way (the
    /// frame is still pending).
    fn landed(&mut self) -> Option<Result<InFlight, String>> {
        let flight = self.in_flight.as_ref()?;
        let arrived = match &self.resident {
            Ok(resident) => resident.arrived(&flight.reading, !self.asynchronous),
            Err(why) => Err(why.clone()),
        };
        match arrived {
            Ok(false) => None,
            Ok(true) => self.in_flight.take().map(Ok),
            Err(why) => {
                self.in_flight = None;
                Some(Err(why))
            }
        }
    }
}

/// A frame submitted whose results are on their way back.
struct InFlight {
    reading: resident::Reading,
    /// The revision of the state it started from: an edit since makes its results stale.
    revision: Revision,
    dispatches: u64,
}

impl Engine for GpuEngine {
    fn step(&mut self, mut frame: Frame<'_>) -> PerFamily<SkipCounts> {
        frame.threads = 1;
        let nothing = || frame.families.per_family(|_| SkipCounts::default());
        // A frame begun by an earlier call (a page's, which cannot wait for it) finishes here
        // once its results arrived, when the state was not edited since.
        match self.landed() {
            None if self.in_flight.is_some() => return nothing(),
            None => {}
            Some(Ok(flight)) if flight.revision == frame.revision => {
                match self.finish(flight, frame.state) {
                    Ok(skipped) => return skipped,
                    // The frame runs again, on the CPU (below).
                    Err(why) => self.resident = Err(why),
                }
            }
            Some(Ok(_)) => {
                if let Ok(resident) = &self.resident {
                    resident.discard();
                }
            }
            Some(Err(why)) => self.resident = Err(why),
        }
        self.prepare(&frame);
        let plan = Plan::of(&frame);
        if plan.contact.is_some() {
            return self.on_the_cpu(frame, "contact runs on the CPU");
        }
        if self.resident.is_err() {
            return self.on_the_cpu(frame, "no GPU");
        }
        let flight = match self.submit(&plan, frame.revision) {
            Ok(flight) => flight,
            Err(why) => {
                // A kernel that did not compile: the mirror still holds the state before the
                // frame, and steps it.
                self.resident = Err(why);
                return self.on_the_cpu(frame, "the GPU failed");
            }
        };
        self.in_flight = Some(flight);
        if self.asynchronous {
            return nothing();
        }
        // On the desktop the results are waited for: they have arrived, or the device failed.
        let finished = match self.landed() {
            Some(Ok(flight)) => self.finish(flight, frame.state),
            Some(Err(why)) => Err(why),
            None => Err("the GPU dropped the frame's results".to_owned()),
        };
        finished.unwrap_or_else(|why| {
            self.resident = Err(why);
            self.on_the_cpu(frame, "the GPU failed")
        })
    }

    fn pending(&self) -> bool {
        self.in_flight.is_some()
    }

    fn describe(&self) -> String {
        match (&self.resident, self.on_cpu) {
            (Ok(resident), None) => format!("gpu (f32, {})", resident.gpu.describe()),
            (Ok(_), Some(why)) => format!("gpu (f32; this frame on the CPU: {why})"),
            (Err(why), _) if self.built_for.is_none() => format!("gpu (f32; {why})"),
            (Err(why), _) => format!("gpu unavailable, frames on the CPU (f32): {why}"),
        }
    }

    fn check(&self) -> Result<(), Divergence> {
        self.mirror.check()
    }

    fn heap_bytes(&self) -> usize {
        self.mirror.heap_bytes()
    }

    fn as_any_mut(&mut self) -> &mut dyn std::any::Any {
        self
    }
}

/// The frame's numbers, written to the `frame` uniform, and the grabbed particle to its
/// dispatch entry.
fn write_uniforms(mirror: &FastSimulation, families: &Families, resident: &Resident, plan: &Plan) {
    let origin = mirror.origin;
    let mut motion = plan.motion;
    motion.ground = motion.ground.map(|ground| -(origin.y - ground));
    let moving = Motion::<Vec3A>::of(motion);
    let ending = Ending::<Vec3A>::of(plan.h, plan.damping, plan.settling, motion.gravity);
    let mut values = [[0.0f32; 4]; slot::LEN];
    values[slot::SPECIAL] = [f32::INFINITY, f32::NAN, 0.0, 0.0];
    values[slot::MOTION] = [moving.pull.y, moving.h, moving.floor.unwrap_or(0.0), 0.0];
    values[slot::ENDING] = [ending.h, ending.keep, ending.pull.y, 0.0];
    let grab = plan.rigid_grab.or(plan.soft_grab.map(|(p, t, _)| (p, t)));
    let grab_alpha = plan.soft_grab.map_or(0.0, |(_, _, compliance)| {
        (compliance / (plan.h * plan.h)) as f32
    });
    values[slot::REACH_AND_GRAB] = [plan.reach as f32, grab_alpha, 0.0, 0.0];
    if let Some((_, target)) = grab {
        let t = (target - origin).as_vec3a();
        values[slot::TARGET] = [t.x, t.y, t.z, 0.0];
    }
    for family in families.all() {
        let value = match plan.rules[family].to::<f32>() {
            Rule::Xpbd { alpha_tilde } | Rule::CompliantPbd { alpha_tilde } => alpha_tilde,
            Rule::Pbd { k } => k,
        };
        values[slot::RULES + family.index()][0] = value;
    }
    let queue = &resident.gpu.queue;
    queue.write_buffer(&resident.frame, 0, bytemuck::cast_slice(&values));
    let particle = grab.map_or(0, |(p, _)| mirror.renumber[p]);
    let entry = u64::from(resident::entry::GRAB) * resident::ENTRY;
    queue.write_buffer(
        &resident.dispatch,
        entry,
        bytemuck::cast_slice(&[0, 1, particle, 0]),
    );
}
