//! One device for the renderer and the GPU engine: the window's (or the page's) wgpu device is
//! asked for with the adapter's own limits ([`wgpu_options`]), not WebGPU's defaults, so that a
//! large body's buffers fit it, and handed to the engine once the workbench starts
//! ([`share_with_the_engine`]). In a page this is the only way the engine gets a GPU: a browser
//! gives WebGPU to the page's renderer, and a page cannot wait for a second adapter.

use eframe::egui_wgpu::{self, WgpuConfiguration, WgpuSetup, wgpu};
use std::sync::Arc;

/// eframe's wgpu set-up with one change: a device on a GPU backend (Vulkan, Metal, DX12,
/// WebGPU) takes the adapter's limits, which the engine needs (a 1M-tet block's particles take
/// more than WebGPU's default 128 MiB binding); a GL device keeps egui's WebGL2 limits.
pub fn wgpu_options() -> WgpuConfiguration {
    let WgpuSetup::CreateNew(mut setup) = WgpuSetup::without_display_handle() else {
        return WgpuConfiguration::default();
    };
    let egui_descriptor = Arc::clone(&setup.device_descriptor);
    setup.device_descriptor = Arc::new(move |adapter: &wgpu::Adapter| {
        let mut descriptor = egui_descriptor(adapter);
        if adapter.get_info().backend != wgpu::Backend::Gl {
            descriptor.required_limits = adapter.limits();
        }
        descriptor
    });
    WgpuConfiguration {
        wgpu_setup: WgpuSetup::CreateNew(setup),
        ..WgpuConfiguration::default()
    }
}

/// Hands the renderer's device to the GPU engine ([`tetlab_core::simulation::gpu::adopt`]),
/// where it is not GL's and the process has no GPU yet; returns the line the console shows:
/// where the GPU engine runs, or why it does not.
pub fn share_with_the_engine(render_state: &egui_wgpu::RenderState) -> String {
    use tetlab_core::simulation::gpu;
    let adopted = gpu::adopt(
        &render_state.adapter,
        &render_state.device,
        &render_state.queue,
    );
    match gpu::gpu() {
        Ok(gpu) if adopted => format!(
            "tetlab: the GPU engine runs on the renderer's device ({})",
            gpu.describe()
        ),
        Ok(gpu) => format!("tetlab: the GPU engine runs on {}", gpu.describe()),
        Err(why) => format!("tetlab: no GPU engine: {why}"),
    }
}
