//! The GPU the engine runs on ([`Gpu`]): one adapter and device per process, asked for once
//! ([`gpu`]), with what the front ends show of it: its name, its backend, and whether it is a
//! software rasteriser (lavapipe, SwiftShader, WARP), which runs the engine correctly but slowly.

use std::sync::{Arc, Mutex, OnceLock};

/// A device and its queue, with what the adapter says of itself.
pub struct Gpu {
    pub(super) device: wgpu::Device,
    pub(super) queue: wgpu::Queue,
    info: wgpu::AdapterInfo,
}

impl std::fmt::Debug for Gpu {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(&self.details())
    }
}

impl Gpu {
    /// What the front ends show of it, short enough for a readout: "NVIDIA H100 80GB HBM3",
    /// "llvmpipe, software" (the adapter's name up to its first parenthesis).
    pub fn describe(&self) -> String {
        let name = match self.info.name.split(" (").next().unwrap_or_default() {
            // A browser may keep the adapter's name to itself.
            "" if self.info.backend == wgpu::Backend::BrowserWebGpu => "WebGPU",
            "" => "unnamed adapter",
            name => name,
        };
        let software = if self.is_software() { ", software" } else { "" };
        format!("{name}{software}")
    }

    /// Its name in full, its backend and its driver, for a benchmark's report:
    /// "llvmpipe (LLVM 15.0.6, 256 bits), Vulkan, Mesa 22.3.6".
    pub fn details(&self) -> String {
        let info = &self.info;
        let driver = [info.driver.as_str(), info.driver_info.as_str()]
            .into_iter()
            .filter(|s| !s.is_empty())
            .collect::<Vec<_>>()
            .join(" ");
        let software = if self.is_software() { ", software" } else { "" };
        format!("{}, {:?}{software}, {driver}", info.name, info.backend)
    }

    /// Whether the adapter is a CPU that plays a GPU (lavapipe, SwiftShader, WARP): the engine
    /// runs there, for tests, but never by [`crate::simulation::EngineChoice::Auto`]'s choice.
    pub fn is_software(&self) -> bool {
        self.info.device_type == wgpu::DeviceType::Cpu
    }
}

/// The first error the device reported since [`take_error`] last took it.
static ERROR: Mutex<Option<String>> = Mutex::new(None);

/// The first error the device reported since the last call, if any.
pub(super) fn take_error() -> Option<String> {
    let mut kept = ERROR
        .lock()
        .unwrap_or_else(std::sync::PoisonError::into_inner);
    kept.take()
}

static GPU: OnceLock<Result<Arc<Gpu>, String>> = OnceLock::new();

/// The process's GPU: asked for on the first call (a high-performance adapter on any backend
/// `WGPU_BACKEND` allows, software ones included), the same one after. The error says why
/// there is none, in a line.
pub fn gpu() -> Result<Arc<Gpu>, String> {
    GPU.get_or_init(|| request().map(Arc::new)).clone()
}

#[cfg(not(target_arch = "wasm32"))]
fn request() -> Result<Gpu, String> {
    let instance =
        wgpu::Instance::new(wgpu::InstanceDescriptor::new_without_display_handle_from_env());
    let adapter = pollster::block_on(instance.request_adapter(&wgpu::RequestAdapterOptions {
        power_preference: wgpu::PowerPreference::HighPerformance,
        force_fallback_adapter: false,
        compatible_surface: None,
        ..Default::default()
    }))
    .map_err(|e| format!("no GPU adapter ({e}); a software one is Mesa's lavapipe: apt-get install mesa-vulkan-drivers"))?;
    let info = adapter.get_info();
    // The largest buffers and the most storage buffers the adapter allows: a 1M-tet block's
    // particles take more than WebGPU's default 128 MiB binding.
    let limits = adapter.limits();
    let (device, queue) = pollster::block_on(adapter.request_device(&wgpu::DeviceDescriptor {
        label: Some("tetlab gpu engine"),
        required_features: wgpu::Features::empty(),
        required_limits: limits,
        experimental_features: wgpu::ExperimentalFeatures::disabled(),
        memory_hints: wgpu::MemoryHints::Performance,
        trace: wgpu::Trace::Off,
    }))
    .map_err(|e| format!("the GPU adapter {} gave no device: {e}", info.name))?;
    keep_errors(&device);
    Ok(Gpu {
        device,
        queue,
        info,
    })
}

/// In a page the engine runs on the renderer's device where the browser gives it WebGPU
/// ([`adopt`]), and there is no other to ask for: a page cannot wait for an adapter.
#[cfg(target_arch = "wasm32")]
fn request() -> Result<Gpu, String> {
    Err("this browser gives the page no WebGPU; it draws with WebGL2".to_owned())
}

/// wgpu's default answer to an error is a panic: the engine keeps the error instead, and gives
/// its frames to the CPU ([`take_error`]).
fn keep_errors(device: &wgpu::Device) {
    device.on_uncaptured_error(Arc::new(|error| {
        let mut kept = ERROR
            .lock()
            .unwrap_or_else(std::sync::PoisonError::into_inner);
        kept.get_or_insert_with(|| error.to_string());
    }));
}

/// Makes a window's or a page's device (the one its renderer draws with) the process's GPU,
/// when none was asked for yet, so that the engine and the renderer share one device; returns
/// whether it did. A GL device is not taken (its compute shaders are not the engine's
/// target): [`gpu`] asks for a device of its own then, as it does without a window.
pub fn adopt(adapter: &wgpu::Adapter, device: &wgpu::Device, queue: &wgpu::Queue) -> bool {
    let info = adapter.get_info();
    if info.backend == wgpu::Backend::Gl || GPU.get().is_some() {
        return false;
    }
    keep_errors(device);
    let gpu = Gpu {
        device: device.clone(),
        queue: queue.clone(),
        info,
    };
    GPU.set(Ok(Arc::new(gpu))).is_ok()
}
