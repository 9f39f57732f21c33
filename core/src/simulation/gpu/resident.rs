//! What the GPU engine holds on the device ([`Resident`]): the four buffers of its memory map
//! ([`super::memory`]), the frame's and the dispatches' uniforms, the bind group every kernel
//! shares, the compiled kernels, and a buffer to read a frame's results back through.

use super::device::Gpu;
use super::kernels::{self, Shape, UnitKernel, slot};
use super::memory::{Memory, SECTIONS, Section};
use crate::constraints::{Families, PerFamily, Unit};
use crate::simulation::fast::FastSimulation;
use crate::simulation::projection::Rule;
use glam::Vec3A;
use std::collections::HashMap;
use std::sync::{Arc, Condvar, Mutex, PoisonError};

/// Bytes between two dispatches' entries in the dispatch uniform (WebGPU's largest minimum
/// uniform offset alignment).
pub(super) const ENTRY: u64 = 256;

/// The dispatch entries every frame uses: all particles, the grabbed particle, the multipliers.
pub(super) mod entry {
    /// One thread per particle.
    pub(crate) const PARTICLES: u32 = 0;
    /// One thread, on the grabbed particle.
    pub(crate) const GRAB: u32 = 1;
    /// One thread per multiplier.
    pub(crate) const LAMBDAS: u32 = 2;
    /// The sweeps' dispatches, from here on.
    pub(crate) const SWEEPS: u32 = 3;
}

/// The sections read back after a frame, in the order they lie in the read-back buffer.
pub(super) const READ_BACK: [Section; 6] = [
    Section::Positions,
    Section::Residuals,
    Section::Velocities,
    Section::Taken,
    Section::LastCorrections,
    Section::FrameCorrections,
];

/// The skip counters: two per family.
pub(super) const COUNTERS: usize = 2 * crate::constraints::MAX_FAMILIES;

/// The GPU engine's buffers, bind group and kernels for one build.
pub(super) struct Resident {
    pub gpu: Arc<Gpu>,
    pub memory: Memory,
    pub points: wgpu::Buffer,
    pub numbers: wgpu::Buffer,
    pub counters: wgpu::Buffer,
    pub frame: wgpu::Buffer,
    pub dispatch: wgpu::Buffer,
    pub read_back: wgpu::Buffer,
    pub bind_group: wgpu::BindGroup,
    layout: wgpu::PipelineLayout,
    /// Each unit's kernel, by the unit's place in `memory.sweeps`.
    pub units: Vec<wgpu::ComputePipeline>,
    /// The per-particle kernels, by name and shape.
    kernels: HashMap<(&'static str, Shape), wgpu::ComputePipeline>,
    /// The first dispatch entry of each unit's sweep.
    pub sweep_entries: Vec<u32>,
}

/// A frame's results on their way back: set when the read-back buffer is mapped, or could not be.
#[derive(Default)]
pub(super) struct Reading(Arc<(Mutex<Landing>, Condvar)>);

/// What the map's callback said: nothing yet, mapped, or why not.
type Landing = Option<Result<(), String>>;

/// A storage or uniform binding of the layout.
fn binding(index: u32, ty: wgpu::BufferBindingType) -> wgpu::BindGroupLayoutEntry {
    wgpu::BindGroupLayoutEntry {
        binding: index,
        visibility: wgpu::ShaderStages::COMPUTE,
        ty: wgpu::BindingType::Buffer {
            ty,
            has_dynamic_offset: index == 5,
            min_binding_size: None,
        },
        count: None,
    }
}

impl Resident {
    /// Lays `mirror` out on `gpu` for `units` under `rules`, uploads it and compiles each unit's
    /// kernel. The error says which kernel did not compile (naga's message).
    pub(super) fn new(
        gpu: Arc<Gpu>,
        mirror: &FastSimulation,
        families: &Families,
        (units, rules): (&[Unit], &PerFamily<Rule<f64>>),
    ) -> Result<Resident, String> {
        let memory = Memory::new(mirror, families, units);
        let device = &gpu.device;
        let storage = |label: &str, bytes: u64, extra: wgpu::BufferUsages| {
            device.create_buffer(&wgpu::BufferDescriptor {
                label: Some(label),
                size: bytes.max(16),
                usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_DST | extra,
                mapped_at_creation: false,
            })
        };
        let n = u64::from(memory.particles());
        // A device shared with a window's renderer may allow less than the adapter could.
        let limits = device.limits();
        let allowed = limits
            .max_storage_buffer_binding_size
            .min(limits.max_buffer_size);
        let largest = (SECTIONS as u64 * n * 16)
            .max(memory.numbers_len as u64 * 4)
            .max(memory.indices.len() as u64 * 4);
        if largest > allowed {
            return Err(format!(
                "the body needs {:.0} MiB in one GPU buffer, and this device allows {:.0} MiB",
                largest as f64 / 1048576.0,
                allowed as f64 / 1048576.0
            ));
        }
        let copy_src = wgpu::BufferUsages::COPY_SRC;
        let points = storage("points", SECTIONS as u64 * n * 16, copy_src);
        let numbers = storage("numbers", memory.numbers_len as u64 * 4, copy_src);
        let indices = storage("indices", memory.indices.len() as u64 * 4, copy_src);
        let counters = storage("counters", COUNTERS as u64 * 4, copy_src);
        gpu.queue
            .write_buffer(&indices, 0, bytemuck::cast_slice(&memory.indices));
        let uniform = |label: &str, bytes: u64| {
            device.create_buffer(&wgpu::BufferDescriptor {
                label: Some(label),
                size: bytes,
                usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
                mapped_at_creation: false,
            })
        };
        let frame = uniform("frame", slot::LEN as u64 * 16);
        let sweeps: usize = memory.sweeps.iter().map(|(_, d)| d.len()).sum();
        let entries = u64::from(entry::SWEEPS) + sweeps as u64;
        let dispatch = uniform("dispatch", entries * ENTRY);
        let read_back = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("read back"),
            size: (READ_BACK.len() as u64 * n * 16 + COUNTERS as u64 * 4).max(16),
            usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let storage_rw = wgpu::BufferBindingType::Storage { read_only: false };
        let bind_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("gpu engine"),
            entries: &[
                binding(0, storage_rw),
                binding(1, storage_rw),
                binding(2, wgpu::BufferBindingType::Storage { read_only: true }),
                binding(3, storage_rw),
                binding(4, wgpu::BufferBindingType::Uniform),
                binding(5, wgpu::BufferBindingType::Uniform),
            ],
        });
        fn whole(index: u32, buffer: &wgpu::Buffer) -> wgpu::BindGroupEntry<'_> {
            wgpu::BindGroupEntry {
                binding: index,
                resource: buffer.as_entire_binding(),
            }
        }
        let bind_group = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("gpu engine"),
            layout: &bind_layout,
            entries: &[
                whole(0, &points),
                whole(1, &numbers),
                whole(2, &indices),
                whole(3, &counters),
                whole(4, &frame),
                wgpu::BindGroupEntry {
                    binding: 5,
                    resource: wgpu::BindingResource::Buffer(wgpu::BufferBinding {
                        buffer: &dispatch,
                        offset: 0,
                        size: wgpu::BufferSize::new(16),
                    }),
                },
            ],
        });
        let layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("gpu engine"),
            bind_group_layouts: &[Some(&bind_layout)],
            immediate_size: 0,
        });
        // The dispatch entries: the fixed three, then every sweep's.
        let mut table = vec![0u8; (entries * ENTRY) as usize];
        let mut put = |entry: u64, words: [u32; 4]| {
            let at = (entry * ENTRY) as usize;
            table[at..at + 16].copy_from_slice(bytemuck::cast_slice(&words));
        };
        put(u64::from(entry::PARTICLES), [0, memory.particles(), 0, 0]);
        let lambdas = &memory.lambdas;
        put(
            u64::from(entry::LAMBDAS),
            [lambdas.start, lambdas.end - lambdas.start, 0, 0],
        );
        let mut next = u64::from(entry::SWEEPS);
        let mut sweep_entries = Vec::new();
        for (_, dispatches) in &memory.sweeps {
            sweep_entries.push(next as u32);
            for d in dispatches {
                put(next, [d.first, d.count, 0, 0]);
                next += 1;
            }
        }
        gpu.queue.write_buffer(&dispatch, 0, &table);
        let mut resident = Resident {
            gpu,
            memory,
            points,
            numbers,
            counters,
            frame,
            dispatch,
            read_back,
            bind_group,
            layout,
            units: Vec::new(),
            kernels: HashMap::new(),
            sweep_entries,
        };
        let unit_kernel = UnitKernel {
            memory: &resident.memory,
            rules,
        };
        let sources: Vec<(Unit, String)> = (resident.memory.sweeps.iter())
            .map(|&(unit, _)| (unit, unit_kernel.source(families, unit)))
            .collect();
        for (unit, source) in sources {
            let name = families.name(unit.lead);
            let pipeline = resident
                .compile(&source)
                .map_err(|e| format!("the GPU kernel of '{name}' does not compile: {e}"))?;
            resident.units.push(pipeline);
        }
        resident.upload(mirror, families);
        Ok(resident)
    }

    /// Compiles `source` (checked by naga first, so that a fault is an error, not a driver's).
    fn compile(&self, source: &str) -> Result<wgpu::ComputePipeline, String> {
        kernels::validate(source)?;
        let device = &self.gpu.device;
        let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
            label: Some("gpu engine"),
            source: wgpu::ShaderSource::Wgsl(source.into()),
        });
        Ok(
            device.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
                label: Some("gpu engine"),
                layout: Some(&self.layout),
                module: &module,
                entry_point: Some("main"),
                compilation_options: wgpu::PipelineCompilationOptions::default(),
                cache: None,
            }),
        )
    }

    /// Compiles the kernels of `shape` that are not yet: the per-particle stages, whose code
    /// the ground, plane strain, forces, damping and the cap shape, and (under
    /// [`Shape::NONE`]) those whose code nothing shapes.
    pub(super) fn prepare_kernels(&mut self, shape: Shape) -> Result<(), String> {
        type Make = fn(&Memory, Shape) -> String;
        let shaped: [(&'static str, Make); 3] = [
            ("predict", kernels::predict),
            ("ground and plane", kernels::ground_and_plane),
            ("update velocities", kernels::update_velocities),
        ];
        let fixed: [(&'static str, Make); 5] = [
            ("keep predicted", |m, _| kernels::keep_predicted(m)),
            ("keep corrections", |m, _| kernels::keep_corrections(m)),
            ("hold", |m, _| kernels::hold(m)),
            ("soft grab", |m, _| kernels::soft_grab(m)),
            ("zero", |_, _| kernels::zero_numbers()),
        ];
        let wanted = (shaped.into_iter().map(|(name, make)| (name, make, shape))).chain(
            fixed
                .into_iter()
                .map(|(name, make)| (name, make, Shape::NONE)),
        );
        for (name, make, shape) in wanted {
            let key = (name, shape);
            if self.kernels.contains_key(&key) {
                continue;
            }
            let source = make(&self.memory, shape);
            let pipeline = self
                .compile(&source)
                .map_err(|e| format!("the GPU kernel '{name}' does not compile: {e}"))?;
            self.kernels.insert(key, pipeline);
        }
        Ok(())
    }

    /// The compiled per-particle kernel `name` of `shape` ([`Resident::prepare_kernels`]).
    ///
    /// # Panics
    /// If it was not prepared.
    pub(super) fn kernel(&self, name: &'static str, shape: Shape) -> &wgpu::ComputePipeline {
        &self.kernels[&(name, shape)]
    }

    /// Uploads `mirror`'s particles and numbers: after a build, an edit of the state, or a frame
    /// the CPU stepped.
    pub(super) fn upload(&self, mirror: &FastSimulation, families: &Families) {
        let queue = &self.gpu.queue;
        let points = self.memory.points(mirror);
        queue.write_buffer(&self.points, 0, bytemuck::cast_slice(&points));
        let numbers = self.memory.numbers(mirror, families);
        queue.write_buffer(&self.numbers, 0, bytemuck::cast_slice(&numbers));
    }

    /// Uploads the positions and their values at the start of the substep (after the origin
    /// moved).
    pub(super) fn upload_positions(&self, mirror: &FastSimulation) {
        let queue = &self.gpu.queue;
        for (section, values) in [
            (Section::Positions, &mirror.positions),
            (Section::Previous, &mirror.previous),
        ] {
            let rows: Vec<[f32; 4]> = values.iter().map(|v| [v.x, v.y, v.z, 0.0]).collect();
            let at = u64::from(self.memory.section(section)) * 16;
            queue.write_buffer(&self.points, at, bytemuck::cast_slice(&rows));
        }
    }

    /// Records the copies of what a frame gives back into the read-back buffer.
    pub(super) fn copy_back(&self, encoder: &mut wgpu::CommandEncoder) {
        let n = u64::from(self.memory.particles()) * 16;
        for (k, &section) in READ_BACK.iter().enumerate() {
            let from = u64::from(self.memory.section(section)) * 16;
            encoder.copy_buffer_to_buffer(&self.points, from, &self.read_back, k as u64 * n, n);
        }
        let at = READ_BACK.len() as u64 * n;
        encoder.copy_buffer_to_buffer(&self.counters, 0, &self.read_back, at, COUNTERS as u64 * 4);
    }

    /// Asks for the read-back buffer once the frame submitted last is done with it: the
    /// results' way back, which [`Resident::arrived`] watches.
    pub(super) fn request_read(&self) -> Reading {
        let reading = Reading::default();
        let arrived = Arc::clone(&reading.0);
        self.read_back
            .slice(..)
            .map_async(wgpu::MapMode::Read, move |result| {
                let (kept, landed) = &*arrived;
                let mut kept = kept.lock().unwrap_or_else(PoisonError::into_inner);
                *kept = Some(result.map_err(|e| e.to_string()));
                landed.notify_all();
            });
        reading
    }

    /// Whether the results of `reading` have arrived: waited for with `wait` (the desktop), or
    /// only looked at (a page, where the browser hands them over between two of its frames).
    /// An error when the device failed the frame.
    pub(super) fn arrived(&self, reading: &Reading, wait: bool) -> Result<bool, String> {
        let poll = if wait {
            wgpu::PollType::Wait {
                submission_index: None,
                timeout: None,
            }
        } else {
            wgpu::PollType::Poll
        };
        self.gpu
            .device
            .poll(poll)
            .map_err(|e| format!("the GPU did not finish the frame: {e}"))?;
        let (kept, landed) = &*reading.0;
        let mut kept = kept.lock().unwrap_or_else(PoisonError::into_inner);
        if wait {
            // The device is done with the frame; its callback may still be running on another
            // thread that polled the same device (tests share one), and wgpu always calls it.
            let minute = std::time::Duration::from_secs(60);
            kept = (landed.wait_timeout_while(kept, minute, |k| k.is_none()))
                .unwrap_or_else(PoisonError::into_inner)
                .0;
        }
        match &*kept {
            None if wait => Err("the GPU dropped the frame's results".to_owned()),
            None => Ok(false),
            Some(Err(e)) => {
                // The device's own error, where it reported one, says more than the map's.
                let reported = super::device::take_error().map(|error| format!(": {error}"));
                let reported = reported.unwrap_or_default();
                Err(format!(
                    "the frame's results could not be read ({e}){reported}"
                ))
            }
            Some(Ok(())) => Ok(true),
        }
    }

    /// Lets go of the results of a frame that arrived but is not wanted (the state was edited
    /// while it ran).
    pub(super) fn discard(&self) {
        self.read_back.unmap();
    }

    /// Reads the arrived results into `mirror`'s arrays; returns the skip counters.
    pub(super) fn take(&self, mirror: &mut FastSimulation) -> Result<[u32; COUNTERS], String> {
        let slice = self.read_back.slice(..);
        // An error the device reported during the frame leaves its results unread: the mirror
        // keeps the state before it.
        if let Some(error) = super::device::take_error() {
            self.read_back.unmap();
            return Err(error);
        }
        let n = self.memory.particles() as usize;
        let counters = {
            let bytes = slice
                .get_mapped_range()
                .map_err(|e| format!("the frame's results could not be read: {e}"))?;
            let rows: &[[f32; 4]] = bytemuck::cast_slice(&bytes[..READ_BACK.len() * n * 16]);
            let corrections = &mut mirror.corrections;
            if corrections.last.len() != n {
                corrections.last = vec![Vec3A::ZERO; n];
                corrections.frame = vec![Vec3A::ZERO; n];
            }
            for (k, section) in READ_BACK.iter().enumerate() {
                let to = match section {
                    Section::Positions => &mut mirror.positions,
                    Section::Residuals => &mut mirror.residuals,
                    Section::Velocities => &mut mirror.velocities,
                    Section::Taken => &mut mirror.taken,
                    Section::LastCorrections => &mut mirror.corrections.last,
                    _ => &mut mirror.corrections.frame,
                };
                for (v, row) in to.iter_mut().zip(&rows[k * n..(k + 1) * n]) {
                    *v = Vec3A::new(row[0], row[1], row[2]);
                }
            }
            let words: &[u32] = bytemuck::cast_slice(&bytes[READ_BACK.len() * n * 16..]);
            let mut counters = [0u32; COUNTERS];
            counters.copy_from_slice(&words[..COUNTERS]);
            counters
        };
        self.read_back.unmap();
        Ok(counters)
    }

    /// The bytes its buffers take on the device.
    pub(super) fn device_bytes(&self) -> u64 {
        [&self.points, &self.numbers, &self.counters, &self.read_back]
            .iter()
            .map(|b| b.size())
            .sum::<u64>()
            + self.memory.indices.len() as u64 * 4
    }
}
