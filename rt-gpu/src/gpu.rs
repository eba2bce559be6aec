//! The adapter and its device.

use crate::GpuError;

/// A GPU adapter and the device and queue opened on it.
#[derive(Debug)]
pub struct Gpu {
    pub(crate) device: wgpu::Device,
    pub(crate) queue: wgpu::Queue,
    info: wgpu::AdapterInfo,
}

impl Gpu {
    /// The first adapter of the Vulkan, Metal or DX12 drivers installed
    /// (high-performance first), or, where `RT_GPU_ADAPTER` is set, the
    /// first whose name contains it (e.g. `llvmpipe` for Mesa's software
    /// Vulkan).
    ///
    /// # Errors
    /// [`GpuError::NoAdapter`] where there is none, [`GpuError::Device`]
    /// where the adapter refuses a device.
    pub fn new() -> Result<Self, GpuError> {
        let instance = wgpu::Instance::new(wgpu::InstanceDescriptor {
            backends: wgpu::Backends::VULKAN | wgpu::Backends::METAL | wgpu::Backends::DX12,
            ..wgpu::InstanceDescriptor::new_without_display_handle()
        });
        let adapter = match std::env::var("RT_GPU_ADAPTER") {
            Ok(name) => {
                let all = pollster::block_on(instance.enumerate_adapters(wgpu::Backends::all()));
                all.into_iter().find(|a| a.get_info().name.contains(&name))
            }
            Err(_) => pollster::block_on(instance.request_adapter(&wgpu::RequestAdapterOptions {
                power_preference: wgpu::PowerPreference::HighPerformance,
                ..Default::default()
            }))
            .ok(),
        }
        .ok_or(GpuError::NoAdapter)?;
        let info = adapter.get_info();
        let (device, queue) = pollster::block_on(adapter.request_device(&wgpu::DeviceDescriptor {
            label: Some("rt-gpu"),
            required_limits: adapter.limits(),
            ..Default::default()
        }))
        .map_err(|e| GpuError::Device(e.to_string()))?;
        Ok(Self { device, queue, info })
    }

    /// The adapter's name (`"llvmpipe (LLVM 15.0.6, 256 bits)"`,
    /// `"NVIDIA H100 80GB HBM3"`).
    #[must_use]
    pub fn name(&self) -> &str {
        &self.info.name
    }

    /// Whether the adapter is a CPU (Mesa's lavapipe, WARP): its rates
    /// are no GPU figures.
    #[must_use]
    pub fn is_software(&self) -> bool {
        self.info.device_type == wgpu::DeviceType::Cpu
    }
}

/// Switches off Mesa's Vulkan device-select layer on a machine with no
/// desktop session (no `XDG_RUNTIME_DIR`): the layer looks for the
/// session's default GPU by connecting to Wayland and prints `error:
/// XDG_RUNTIME_DIR is invalid` at every adapter query; without a session
/// there is no default to find ([`Gpu::new`] picks the adapter itself).
/// Sets `NODEVICE_SELECT=1` unless the user set it.
///
/// # Safety
/// It sets an environment variable of the process: call it before any
/// other thread starts (first thing in `main`).
pub unsafe fn quiet_without_session() {
    if std::env::var_os("XDG_RUNTIME_DIR").is_none()
        && std::env::var_os("NODEVICE_SELECT").is_none()
    {
        // SAFETY: the caller runs this before any other thread.
        unsafe { std::env::set_var("NODEVICE_SELECT", "1") };
    }
}
