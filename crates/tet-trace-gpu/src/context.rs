//! Adapter and device set-up: the adapter's highest limits, timestamp queries
//! when available, and an optional artificial cap on buffer sizes (tests and
//! what-if runs for smaller GPUs).

use std::sync::OnceLock;

use crate::error::GpuError;

/// Environment variable that, when set to a non-empty value other than `0`,
/// tells the test helpers to treat "no adapter" as a failure instead of a
/// skip (CI sets it after installing lavapipe).
pub const REQUIRE_ADAPTER_ENV: &str = "TET_GPU_REQUIRED";

/// Options of [`GpuContext::with_options`].
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct GpuOptions {
    /// Caps `max_storage_buffer_binding_size` and `max_buffer_size` below the
    /// device's values (bytes); `None` keeps the device's. Tests use it to
    /// exercise splitting and the limit errors on any adapter.
    pub max_buffer_bytes: Option<u64>,
    /// Never use timestamp queries (wall time only).
    pub disable_timestamps: bool,
    /// Ask wgpu for its fallback (software) adapter.
    pub force_fallback_adapter: bool,
}

/// A wgpu device with the limits the kernels must respect.
#[derive(Debug)]
pub struct GpuContext {
    pub(crate) device: wgpu::Device,
    pub(crate) queue: wgpu::Queue,
    info: wgpu::AdapterInfo,
    /// Effective `max_storage_buffer_binding_size`.
    pub(crate) max_binding: u64,
    /// Effective `max_buffer_size`.
    pub(crate) max_buffer: u64,
    /// `max_compute_workgroups_per_dimension`.
    pub(crate) max_workgroups: u32,
    /// `max_storage_buffers_per_shader_stage`.
    pub(crate) max_storage_buffers: u32,
    pub(crate) timestamps: bool,
}

impl GpuContext {
    /// The default adapter with default options.
    pub fn new() -> Result<GpuContext, GpuError> {
        GpuContext::with_options(&GpuOptions::default())
    }

    /// Opens the first Vulkan adapter wgpu offers (high-performance
    /// preference), requesting its highest limits and, when supported, the
    /// timestamp-query feature. The instance and adapter are found once per
    /// process and shared by every context (each context has its own
    /// device and queue).
    pub fn with_options(opts: &GpuOptions) -> Result<GpuContext, GpuError> {
        let adapter = match shared_adapter(opts.force_fallback_adapter) {
            Ok(a) => a,
            Err(first) if !opts.force_fallback_adapter => {
                shared_adapter(true).map_err(|e| GpuError::NoAdapter {
                    reason: format!("{first}; fallback adapter: {e}"),
                })?
            }
            Err(e) => {
                return Err(GpuError::NoAdapter {
                    reason: e.to_string(),
                });
            }
        };
        let info = adapter.get_info();
        let timestamps = !opts.disable_timestamps
            && adapter.features().contains(wgpu::Features::TIMESTAMP_QUERY);
        let features = if timestamps {
            wgpu::Features::TIMESTAMP_QUERY
        } else {
            wgpu::Features::empty()
        };
        let (device, queue) = pollster::block_on(adapter.request_device(&wgpu::DeviceDescriptor {
            label: Some("tet-trace-gpu"),
            required_features: features,
            required_limits: adapter.limits(),
            ..Default::default()
        }))
        .map_err(|e| GpuError::Device {
            adapter: info.name.clone(),
            reason: e.to_string(),
        })?;
        let limits = device.limits();
        let cap = opts.max_buffer_bytes.unwrap_or(u64::MAX);
        Ok(GpuContext {
            max_binding: limits.max_storage_buffer_binding_size.min(cap),
            max_buffer: limits.max_buffer_size.min(cap),
            max_workgroups: limits.max_compute_workgroups_per_dimension.max(1),
            max_storage_buffers: limits.max_storage_buffers_per_shader_stage,
            device,
            queue,
            info,
            timestamps,
        })
    }

    /// The adapter's description (name, backend, device type, driver).
    pub fn adapter_info(&self) -> &wgpu::AdapterInfo {
        &self.info
    }

    /// One line naming the adapter, for reports: `"name (type, backend, driver)"`.
    pub fn device_name(&self) -> String {
        format!(
            "{} ({:?}, {:?}, {} {})",
            self.info.name,
            self.info.device_type,
            self.info.backend,
            self.info.driver,
            self.info.driver_info
        )
    }

    /// True on a CPU (software) adapter such as lavapipe.
    pub fn is_software(&self) -> bool {
        self.info.device_type == wgpu::DeviceType::Cpu
    }

    /// Whether dispatches are timed with timestamp queries.
    pub fn has_timestamps(&self) -> bool {
        self.timestamps
    }

    /// The largest storage binding the kernels may use (bytes).
    pub fn max_binding_bytes(&self) -> u64 {
        self.max_binding.min(self.max_buffer)
    }

    /// Checks one buffer size against both limits.
    pub(crate) fn check_size(&self, buffer: &'static str, bytes: u64) -> Result<(), GpuError> {
        if bytes > self.max_binding {
            return Err(GpuError::TooLarge {
                buffer,
                bytes,
                limit: "max_storage_buffer_binding_size",
                value: self.max_binding,
            });
        }
        if bytes > self.max_buffer {
            return Err(GpuError::TooLarge {
                buffer,
                bytes,
                limit: "max_buffer_size",
                value: self.max_buffer,
            });
        }
        Ok(())
    }
}

/// The process's wgpu instance and its two adapters (default and fallback),
/// each looked up on first use. Every adapter enumeration makes the Vulkan
/// loader's implicit layers probe the window systems: Mesa's device-select
/// layer connects to Wayland, and libwayland prints `error: XDG_RUNTIME_DIR
/// is invalid or not set in the environment.` where there is no Wayland
/// session (a headless machine, CI) although nothing failed. Enumerating
/// once per process keeps that to one line however many contexts a run
/// opens.
struct Shared {
    instance: wgpu::Instance,
    adapters: [OnceLock<Result<wgpu::Adapter, wgpu::RequestAdapterError>>; 2],
}

/// The adapter wgpu offers with `fallback` (see [`Shared`]).
fn shared_adapter(fallback: bool) -> Result<wgpu::Adapter, wgpu::RequestAdapterError> {
    static SHARED: OnceLock<Shared> = OnceLock::new();
    let shared = SHARED.get_or_init(|| {
        let mut desc = wgpu::InstanceDescriptor::new_without_display_handle_from_env();
        // Only the Vulkan backend is compiled in (lavapipe in CI).
        desc.backends = wgpu::Backends::VULKAN;
        Shared {
            instance: wgpu::Instance::new(desc),
            adapters: [OnceLock::new(), OnceLock::new()],
        }
    });
    shared.adapters[fallback as usize]
        .get_or_init(|| {
            pollster::block_on(
                shared
                    .instance
                    .request_adapter(&wgpu::RequestAdapterOptions {
                        power_preference: wgpu::PowerPreference::HighPerformance,
                        force_fallback_adapter: fallback,
                        compatible_surface: None,
                        ..Default::default()
                    }),
            )
        })
        .clone()
}
