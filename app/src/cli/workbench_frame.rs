//! `tetlab bench --workbench`: what one frame of the workbench costs on the CPU, without a window.
//! The workbench's own code runs: a frame of the simulation (the step, then the metrics the
//! readouts and plots show), then what the 3D view draws ([`geometry::update`], into the buffers
//! it keeps between frames), then the upload: the bytes of every buffer that changed, copied as
//! `wgpu::Queue::write_buffer` copies them into its staging memory. Rasterising (the GPU's work,
//! or the software Vulkan driver's on a machine without one) is not part of the figure.

use super::UsageError;
use crate::gui::geometry::{self, SceneCache, ViewGeometry, ViewOptions};
use crate::gui::workbench::Workbench;
use serde::Serialize;
use std::io::Write;
use std::time::{Duration, Instant};
use tetlab_core::scene::Scene;
use tetlab_core::simulation::Settings;

/// The time of each part of a frame, summed over the frames timed.
#[derive(Clone, Copy, Debug, Default, Serialize)]
pub struct FrameCost {
    /// The simulation's step and the metrics measured after it.
    pub simulation_ms: f64,
    /// What the view draws, brought up to date.
    pub draw_ms: f64,
    /// The bytes uploaded, copied.
    pub upload_ms: f64,
    /// Bytes uploaded per frame.
    pub upload_bytes: f64,
    /// Vertices the view holds.
    pub vertices: usize,
    /// Frames per second the CPU side holds: 1000 / (simulation + draw + upload).
    pub frames_per_second: f64,
}

/// Times `frames` frames of the workbench on `scene` with `settings` (after `warmup` frames),
/// with the display options a user gets for the scene's size.
pub fn measure(
    scene: Scene,
    settings: Settings,
    families: tetlab_core::constraints::Families,
    threads: usize,
    frames: u64,
    warmup: u64,
) -> Result<FrameCost, UsageError> {
    let mut bench = Workbench::new(scene, settings);
    bench.simulation.set_families(families);
    bench.simulation.set_threads(threads);
    bench.set_playing(true);
    let cache = SceneCache::new(&bench.scene.mesh);
    let options = ViewOptions::for_size(bench.simulation.tets().len());
    let mut view = ViewGeometry::default();
    let mut staging: Vec<u8> = Vec::new();
    let mut uploaded_version = None;
    let (mut simulation, mut draw, mut upload) = (Duration::ZERO, Duration::ZERO, Duration::ZERO);
    let mut bytes = 0usize;
    for frame in 0..warmup + frames {
        let started = Instant::now();
        bench.step_frame();
        if let Some(divergence) = bench.diverged.take() {
            return Err(UsageError(divergence.to_string()));
        }
        let stepped = Instant::now();
        geometry::update(&mut view, &bench, &cache, &options, None);
        let drawn = Instant::now();
        // What the renderer does when the view's geometry is not the version it holds.
        let mut uploaded = 0;
        if uploaded_version != Some(view.version()) {
            for buffer in view.buffers() {
                staging.clear();
                staging.extend_from_slice(buffer);
                uploaded += buffer.len();
            }
            std::hint::black_box(&staging);
            uploaded_version = Some(view.version());
        }
        let done = Instant::now();
        if frame >= warmup {
            simulation += stepped - started;
            draw += drawn - stepped;
            upload += done - drawn;
            bytes += uploaded;
        }
    }
    let per_frame = |d: Duration| d.as_secs_f64() * 1e3 / frames as f64;
    let total = per_frame(simulation + draw + upload);
    Ok(FrameCost {
        simulation_ms: per_frame(simulation),
        draw_ms: per_frame(draw),
        upload_ms: per_frame(upload),
        upload_bytes: bytes as f64 / frames as f64,
        vertices: view.vertices(),
        frames_per_second: 1e3 / total.max(1e-9),
    })
}

/// Prints one frame's cost, and with `json` the same as one object.
pub fn write(
    out: &mut impl Write,
    scene: &str,
    tets: usize,
    engine: &str,
    cost: &FrameCost,
    json: bool,
) -> std::io::Result<()> {
    writeln!(
        out,
        "workbench frame, {scene} ({tets} tets), engine {engine}"
    )?;
    writeln!(
        out,
        "simulation             {:.3} ms (the step and its metrics)",
        cost.simulation_ms
    )?;
    writeln!(
        out,
        "what to draw           {:.3} ms ({} vertices held)",
        cost.draw_ms, cost.vertices
    )?;
    writeln!(
        out,
        "upload                 {:.3} ms ({:.0} bytes a frame)",
        cost.upload_ms, cost.upload_bytes
    )?;
    writeln!(
        out,
        "frames per second      {:.1} on the CPU side (drawing and upload {:.0} % of the step)",
        cost.frames_per_second,
        100.0 * (cost.draw_ms + cost.upload_ms) / cost.simulation_ms.max(1e-9)
    )?;
    if json {
        writeln!(
            out,
            "{}",
            serde_json::to_string(cost).expect("a cost serialises")
        )?;
    }
    Ok(())
}
