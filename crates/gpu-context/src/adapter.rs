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
        let missing: Vec<Vec<&'static str>> = adapters.iter().map(missing_capabilities).collect();
        let unsupported = || GpuError::Unsupported {
            adapters: infos
                .iter()
                .zip(&missing)
                .filter(|(_, m)| !m.is_empty())
                .map(|(i, m)| format!("{} ({:?}) lacks {}", i.name, i.backend, m.join(", ")))
                .collect::<Vec<_>>()
                .join("; "),
        };
        let index = match wanted {
            Some((name, env)) => {
                let lower = name.to_lowercase();
                let index = infos
                    .iter()
                    .position(|i| i.name.to_lowercase().contains(&lower))
                    .ok_or_else(|| GpuError::AdapterNotFound {
                        wanted: name.clone(),
                        env,
                        available: list_names(&infos),
                    })?;
                if !missing[index].is_empty() {
                    return Err(unsupported());
                }
                index
            }
            None => {
                let kinds: Vec<_> = infos
                    .iter()
                    .zip(&missing)
                    .map(|(i, m)| (i.device_type, i.backend, m.is_empty()))
                    .collect();
                match best_adapter(&kinds, options.allow_software) {
                    Some(index) => index,
                    None if missing.iter().any(|m| !m.is_empty()) => return Err(unsupported()),
                    None => {
                        return Err(GpuError::NoAdapter {
                            backends: format!("{backends:?}"),
                            seen: list_names(&infos),
                        });
                    }
                }
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
        // Clip distances let the hemicube builder clip every tile of its atlas in one
        // instanced draw.
        let optional = (wgpu::Features::TEXTURE_ADAPTER_SPECIFIC_FORMAT_FEATURES
            | wgpu::Features::DEPTH32FLOAT_STENCIL8
            | wgpu::Features::FLOAT32_BLENDABLE
            | wgpu::Features::CLIP_DISTANCES)
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
        // wgpu's default for a validation error is a panic; record it instead, so that the next
        // read-back or wait returns it as `GpuError::Validation` (see `take_device_error`).
        device.on_uncaptured_error(std::sync::Arc::new(record_device_error));
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
            .map_err(|e| GpuError::Readback(e.to_string()))?;
        check_device_errors()
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

/// What an adapter lacks of what the workspace's GPU paths need, by name; empty when it can
/// run them all. The paths assume WebGPU: compute shaders, depth textures read with
/// `textureLoad` and copied to buffers (the depth visibility backend), read-only depth-stencil
/// (the shared frame) and 32-bit index draws; the shared frame renders into `Rgba32Float`.
/// Mesa's GL driver, for one, misses several of these and would fail inside wgpu.
fn missing_capabilities(adapter: &wgpu::Adapter) -> Vec<&'static str> {
    let mut missing: Vec<&'static str> = Vec::new();
    let downlevel = adapter.get_downlevel_capabilities();
    let lacking = wgpu::DownlevelFlags::compliant() - downlevel.flags;
    missing.extend(lacking.iter_names().map(|(name, _)| name));
    let float_target = adapter.get_texture_format_features(crate::COLOR_FORMAT);
    if !float_target
        .allowed_usages
        .contains(wgpu::TextureUsages::RENDER_ATTACHMENT)
    {
        missing.push("Rgba32Float render targets");
    }
    missing
}

/// Validation errors recorded by the devices this crate created, oldest first.
static DEVICE_ERRORS: std::sync::Mutex<Vec<String>> = std::sync::Mutex::new(Vec::new());

fn record_device_error(error: wgpu::Error) {
    log::error!("GPU validation error: {error}");
    let mut errors = DEVICE_ERRORS.lock().unwrap_or_else(|e| e.into_inner());
    // Bounded: one broken pipeline makes every later draw fail the same way.
    if errors.len() < 16 {
        errors.push(error.to_string());
    }
}

/// Take the validation errors that the devices created by [`GpuContext::new`] reported since
/// the last call (wgpu reports them asynchronously; without a handler it panics). `None` when
/// there were none. Read-backs and [`GpuContext::wait_idle`] call this and return
/// [`GpuError::Validation`]; code with its own read-back should do the same.
pub fn take_device_error() -> Option<String> {
    let mut errors = DEVICE_ERRORS.lock().unwrap_or_else(|e| e.into_inner());
    if errors.is_empty() {
        return None;
    }
    let joined = errors
        .iter()
        .map(|e| e.trim().replace('\n', " "))
        .collect::<Vec<_>>()
        .join("; ");
    errors.clear();
    Some(joined)
}

/// `Err(GpuError::Validation)` when a device reported an error since the last check.
pub(crate) fn check_device_errors() -> Result<(), GpuError> {
    take_device_error().map_or(Ok(()), |e| Err(GpuError::Validation(e)))
}

/// Rank adapters by (device type, backend): hardware before software, Vulkan/Metal/DX12
/// before GL; adapters lacking a needed capability (the `bool` is false) are never chosen.
/// Returns the index of the best one.
fn best_adapter(
    kinds: &[(wgpu::DeviceType, wgpu::Backend, bool)],
    allow_software: bool,
) -> Option<usize> {
    let rank = |(device_type, backend, capable): (wgpu::DeviceType, wgpu::Backend, bool)| {
        if !capable {
            return None;
        }
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
            (DeviceType::Cpu, Backend::Vulkan, true),
            (DeviceType::IntegratedGpu, Backend::Gl, true),
            (DeviceType::IntegratedGpu, Backend::Vulkan, true),
        ];
        assert_eq!(best_adapter(&kinds, true), Some(2));
        assert_eq!(best_adapter(&kinds[..1], true), Some(0));
        assert_eq!(best_adapter(&kinds[..1], false), None);
        assert_eq!(best_adapter(&[], true), None);
    }

    #[test]
    fn an_adapter_lacking_a_capability_is_never_chosen() {
        // Mesa's GL driver beside lavapipe: the capable software Vulkan adapter wins even
        // though GL ranks the same device type; alone, the incapable one gives None.
        let kinds = [
            (DeviceType::Cpu, Backend::Gl, false),
            (DeviceType::Cpu, Backend::Vulkan, true),
        ];
        assert_eq!(best_adapter(&kinds, true), Some(1));
        assert_eq!(best_adapter(&kinds[..1], true), None);
        let discrete_but_incapable = [
            (DeviceType::DiscreteGpu, Backend::Vulkan, false),
            (DeviceType::Cpu, Backend::Vulkan, true),
        ];
        assert_eq!(best_adapter(&discrete_but_incapable, true), Some(1));
    }
}
