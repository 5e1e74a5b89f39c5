//! Adapter selection: environment override, then hardware, then software.

use crate::GpuError;

/// Environment variable restricting backends (comma list: `vulkan`, `gl`, `metal`, `dx12`).
/// wgpu's own `WGPU_BACKEND` is honoured when this one is unset.
pub const BACKEND_ENV: &str = "CLOTH_VIS_BACKEND";
/// Environment variable choosing the adapter whose name contains its value (case-insensitive).
/// wgpu's own `WGPU_ADAPTER_NAME` is honoured when this one is unset.
pub const ADAPTER_ENV: &str = "CLOTH_VIS_ADAPTER";

/// How to choose an adapter and what to ask of the device.
#[derive(Clone, Debug)]
#[non_exhaustive]
pub struct GpuOptions {
    /// Backends to search; `None` means the environment's choice, else all that are built in.
    pub backends: Option<wgpu::Backends>,
    /// Substring of the adapter name to pick; `None` means the environment's choice, else the
    /// best hardware adapter, else a software one.
    pub adapter_name: Option<String>,
    /// Accept a CPU (software) adapter such as lavapipe when no hardware exists.
    pub allow_software: bool,
    /// Features the device must have (e.g. timestamp queries); the adapter must offer them.
    pub required_features: wgpu::Features,
}

impl Default for GpuOptions {
    fn default() -> Self {
        Self {
            backends: None,
            adapter_name: None,
            allow_software: true,
            required_features: wgpu::Features::empty(),
        }
    }
}

/// What was chosen, for run reports and log lines.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct AdapterSummary {
    /// Adapter name as the driver reports it (e.g. `llvmpipe (LLVM 15.0.6, 256 bits)`).
    pub name: String,
    /// Backend (`Vulkan`, `Gl`, …).
    pub backend: String,
    /// Device type (`DiscreteGpu`, `Cpu`, …).
    pub device_type: String,
    /// Driver name and version.
    pub driver: String,
    /// True for software rasterisers: timings there prove correctness only.
    pub is_software: bool,
}

impl std::fmt::Display for AdapterSummary {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{} ({}, {}", self.name, self.backend, self.device_type)?;
        if !self.driver.is_empty() {
            write!(f, ", {}", self.driver)?;
        }
        if self.is_software {
            write!(f, ", software")?;
        }
        write!(f, ")")
    }
}

/// An adapter with its device and queue.
#[derive(Debug)]
pub struct GpuContext {
    /// The wgpu instance (kept alive with the device).
    pub instance: wgpu::Instance,
    /// The chosen adapter.
    pub adapter: wgpu::Adapter,
    /// The logical device.
    pub device: wgpu::Device,
    /// Its queue.
    pub queue: wgpu::Queue,
    summary: AdapterSummary,
}

impl GpuContext {
    /// Pick an adapter as the crate docs describe and create a device with the adapter's own
    /// limits (headless tools want the largest textures the hardware allows).
    ///
    /// # Errors
    /// [`GpuError::NoAdapter`] when nothing usable exists (the message says what to install),
    /// [`GpuError::AdapterNotFound`] when a named adapter is missing,
    /// [`GpuError::RequestDevice`] when the adapter refuses the device.
    pub fn new(options: &GpuOptions) -> Result<Self, GpuError> {
        let requested = options
            .backends
            .or_else(|| env_nonempty(BACKEND_ENV).map(|s| wgpu::Backends::from_comma_list(&s)))
            .or_else(wgpu::Backends::from_env);
        // Without a request, probe the primary backends (Vulkan, Metal, DX12) first and GL only
        // when they offer nothing: probing GL on a headless machine logs EGL errors.
        let mut backends = requested.unwrap_or(wgpu::Backends::PRIMARY);
        let (mut instance, mut adapters) = enumerate(backends);
        if requested.is_none() && adapters.is_empty() {
            backends = wgpu::Backends::all();
            (instance, adapters) = enumerate(backends);
        }

        let wanted = options
            .adapter_name
            .clone()
            .map(|n| (n, "GpuOptions::adapter_name"));
        let wanted = wanted
            .or_else(|| env_nonempty(ADAPTER_ENV).map(|n| (n, ADAPTER_ENV)))
            .or_else(|| env_nonempty("WGPU_ADAPTER_NAME").map(|n| (n, "WGPU_ADAPTER_NAME")));
        let infos: Vec<wgpu::AdapterInfo> = adapters.iter().map(|a| a.get_info()).collect();
        let index = match wanted {
            Some((name, env)) => {
                let lower = name.to_lowercase();
                infos
                    .iter()
                    .position(|i| i.name.to_lowercase().contains(&lower))
                    .ok_or_else(|| GpuError::AdapterNotFound {
                        wanted: name.clone(),
                        env,
                        available: list_names(&infos),
                    })?
            }
            None => {
                let kinds: Vec<_> = infos.iter().map(|i| (i.device_type, i.backend)).collect();
                best_adapter(&kinds, options.allow_software).ok_or_else(|| GpuError::NoAdapter {
                    backends: format!("{backends:?}"),
                    seen: list_names(&infos),
                    env: BACKEND_ENV,
                })?
            }
        };
        let adapter = adapters.into_iter().nth(index).ok_or_else(|| {
            GpuError::Readback("adapter list changed during selection".to_owned())
        })?;
        let info = &infos[index];
        let summary = AdapterSummary {
            name: info.name.clone(),
            backend: format!("{:?}", info.backend),
            device_type: format!("{:?}", info.device_type),
            driver: format!("{} {}", info.driver, info.driver_info)
                .trim()
                .to_owned(),
            is_software: info.device_type == wgpu::DeviceType::Cpu,
        };
        // Optional features the renderer uses when the adapter has them: MSAA on Rgba32Float
        // (adapter-specific format features), a float depth with stencil, float32 blending.
        let optional = (wgpu::Features::TEXTURE_ADAPTER_SPECIFIC_FORMAT_FEATURES
            | wgpu::Features::DEPTH32FLOAT_STENCIL8
            | wgpu::Features::FLOAT32_BLENDABLE)
            & adapter.features();
        let (device, queue) = pollster::block_on(adapter.request_device(&wgpu::DeviceDescriptor {
            label: Some("cloth-vis device"),
            required_features: options.required_features | optional,
            required_limits: adapter.limits(),
            ..Default::default()
        }))
        .map_err(|source| GpuError::RequestDevice {
            adapter: summary.name.clone(),
            source,
        })?;
        log::info!("GPU adapter: {summary}");
        Ok(Self {
            instance,
            adapter,
            device,
            queue,
            summary,
        })
    }

    /// The chosen adapter, for reports.
    pub fn summary(&self) -> &AdapterSummary {
        &self.summary
    }

    /// Block until all submitted work has finished.
    ///
    /// # Errors
    /// [`GpuError::Readback`] when the device is lost or the wait fails.
    pub fn wait_idle(&self) -> Result<(), GpuError> {
        self.device
            .poll(wgpu::PollType::wait_indefinitely())
            .map(|_| ())
            .map_err(|e| GpuError::Readback(e.to_string()))
    }
}

fn enumerate(backends: wgpu::Backends) -> (wgpu::Instance, Vec<wgpu::Adapter>) {
    let mut desc = wgpu::InstanceDescriptor::new_without_display_handle();
    desc.backends = backends;
    let instance = wgpu::Instance::new(desc);
    let adapters = pollster::block_on(instance.enumerate_adapters(backends));
    (instance, adapters)
}

fn env_nonempty(name: &str) -> Option<String> {
    std::env::var(name).ok().filter(|s| !s.trim().is_empty())
}

fn list_names(infos: &[wgpu::AdapterInfo]) -> String {
    if infos.is_empty() {
        return "none".to_owned();
    }
    infos
        .iter()
        .map(|i| format!("{} ({:?}, {:?})", i.name, i.backend, i.device_type))
        .collect::<Vec<_>>()
        .join(", ")
}

/// Rank adapters by (device type, backend): hardware before software, Vulkan/Metal/DX12
/// before GL. Returns the index of the best one.
fn best_adapter(
    kinds: &[(wgpu::DeviceType, wgpu::Backend)],
    allow_software: bool,
) -> Option<usize> {
    let rank = |(device_type, backend): (wgpu::DeviceType, wgpu::Backend)| -> Option<u32> {
        let device = match device_type {
            wgpu::DeviceType::DiscreteGpu => 0,
            wgpu::DeviceType::IntegratedGpu => 1,
            wgpu::DeviceType::VirtualGpu => 2,
            wgpu::DeviceType::Other => 3,
            wgpu::DeviceType::Cpu if allow_software => 4,
            wgpu::DeviceType::Cpu => return None,
        };
        Some(device * 2 + u32::from(backend == wgpu::Backend::Gl))
    };
    kinds
        .iter()
        .enumerate()
        .filter_map(|(index, &kind)| rank(kind).map(|r| (r, index)))
        .min()
        .map(|(_, index)| index)
}

#[cfg(test)]
mod tests {
    use super::*;
    use wgpu::{Backend, DeviceType};

    #[test]
    fn hardware_is_preferred_over_software_and_vulkan_over_gl() {
        let kinds = [
            (DeviceType::Cpu, Backend::Vulkan),
            (DeviceType::IntegratedGpu, Backend::Gl),
            (DeviceType::IntegratedGpu, Backend::Vulkan),
        ];
        assert_eq!(best_adapter(&kinds, true), Some(2));
        assert_eq!(best_adapter(&kinds[..1], true), Some(0));
        assert_eq!(best_adapter(&kinds[..1], false), None);
        assert_eq!(best_adapter(&[], true), None);
    }
}
