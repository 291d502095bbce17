//! The wgpu device every pass runs on: adapter choice, limits read from the adapter, features.

use std::fmt;

/// Workgroup memory we allow a shader to declare. wgpu does not validate this on every backend
/// (lavapipe accepts more), so passes check their own usage against the smaller of this and the
/// adapter's limit.
pub const WORKGROUP_MEMORY_BUDGET: u32 = 32 * 1024;

#[derive(Debug, thiserror::Error)]
pub enum GpuError {
    #[error(
        "no GPU adapter found (on a machine without a GPU install Mesa's lavapipe: `apt-get install mesa-vulkan-drivers libvulkan1`): {0}"
    )]
    NoAdapter(String),
    #[error("the adapter '{adapter}' refused the device: {reason}")]
    Device { adapter: String, reason: String },
    #[error("{what} is {requested}, over this adapter's limit of {limit} ({adapter})")]
    OverLimit { what: String, requested: u64, limit: u64, adapter: String },
    /// An out-of-memory or validation error of the device (crate::gpu_fault).
    #[error("{pass} at {size}: {message}")]
    Fault { pass: String, size: String, message: String },
}

/// Loop iterations one shader invocation may run in total on Mesa's llvmpipe (lavapipe):
/// `LP_MAX_TGSI_LOOP_ITERATIONS`. Past it every loop of the invocation ends silently, so a
/// long invocation returns wrong results without an error.
pub const LLVMPIPE_LOOP_ITERATIONS: u64 = 65_535;

/// What the adapter is, for manifests and reference-cache keys.
#[derive(Clone, Debug, serde::Serialize, serde::Deserialize, PartialEq, Eq)]
pub struct AdapterSummary {
    pub name: String,
    pub backend: String,
    pub driver: String,
    pub driver_info: String,
    pub device_type: String,
}

impl fmt::Display for AdapterSummary {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{} ({}, {} {})", self.name, self.backend, self.driver, self.driver_info)
    }
}

pub struct Gpu {
    pub device: wgpu::Device,
    pub queue: wgpu::Queue,
    pub adapter: wgpu::Adapter,
    pub summary: AdapterSummary,
    /// Limits granted to the device: the adapter's own, not the WebGPU defaults.
    pub limits: wgpu::Limits,
    pub features: wgpu::Features,
}

impl Gpu {
    /// Opens the default adapter (set `WGPU_ADAPTER_NAME` or `WGPU_BACKEND` to choose another).
    pub fn new() -> Result<Self, GpuError> {
        pollster::block_on(Self::new_async(|adapter| adapter.clone()))
    }

    /// As [`Gpu::new`] with a device that grants `limits(adapter's)` (lower limits make a
    /// device that cannot hold what a scene needs: the fault tests).
    pub fn with_device_limits(
        limits: impl FnOnce(&wgpu::Limits) -> wgpu::Limits,
    ) -> Result<Self, GpuError> {
        pollster::block_on(Self::new_async(limits))
    }

    async fn new_async(
        device_limits: impl FnOnce(&wgpu::Limits) -> wgpu::Limits,
    ) -> Result<Self, GpuError> {
        let instance =
            wgpu::Instance::new(wgpu::InstanceDescriptor::new_without_display_handle_from_env());
        let adapter = match wgpu::util::initialize_adapter_from_env(&instance, None).await {
            Ok(adapter) => adapter,
            Err(_) => instance
                .request_adapter(&wgpu::RequestAdapterOptions {
                    power_preference: wgpu::PowerPreference::HighPerformance,
                    force_fallback_adapter: false,
                    compatible_surface: None,
                    ..Default::default()
                })
                .await
                .map_err(|e| GpuError::NoAdapter(e.to_string()))?,
        };
        let info = adapter.get_info();
        let summary = AdapterSummary {
            name: info.name.clone(),
            backend: format!("{:?}", info.backend),
            driver: info.driver.clone(),
            driver_info: info.driver_info.clone(),
            device_type: format!("{:?}", info.device_type),
        };
        // Timestamps are optional: passes report no GPU time where the adapter has none.
        let wanted =
            wgpu::Features::TIMESTAMP_QUERY | wgpu::Features::TIMESTAMP_QUERY_INSIDE_ENCODERS;
        let features = adapter.features() & wanted;
        let limits = device_limits(&adapter.limits());
        let (device, queue) = adapter
            .request_device(&wgpu::DeviceDescriptor {
                label: Some("flicker"),
                required_features: features,
                required_limits: limits.clone(),
                experimental_features: wgpu::ExperimentalFeatures::disabled(),
                memory_hints: wgpu::MemoryHints::Performance,
                trace: wgpu::Trace::Off,
            })
            .await
            .map_err(|e| GpuError::Device {
                adapter: summary.name.clone(),
                reason: e.to_string(),
            })?;
        Ok(Self { device, queue, adapter, summary, limits, features })
    }

    pub fn has_timestamps(&self) -> bool {
        self.features.contains(wgpu::Features::TIMESTAMP_QUERY)
    }

    /// Workgroup memory a shader may use: the adapter's limit, capped at 32 KiB.
    pub fn workgroup_memory_budget(&self) -> u32 {
        self.limits.max_compute_workgroup_storage_size.min(WORKGROUP_MEMORY_BUDGET)
    }

    /// Refuses an image size the adapter cannot hold as a 2D texture or as a storage buffer of
    /// `bytes_per_pixel` per pixel.
    pub fn check_resolution(
        &self,
        width: u32,
        height: u32,
        bytes_per_pixel: u64,
    ) -> Result<(), GpuError> {
        let max_dim = self.limits.max_texture_dimension_2d;
        for (what, v) in [("image width", width), ("image height", height)] {
            if v > max_dim {
                return Err(self.over(what, v as u64, max_dim as u64));
            }
            if v == 0 {
                return Err(GpuError::OverLimit {
                    what: what.into(),
                    requested: 0,
                    limit: max_dim as u64,
                    adapter: format!("{} must be at least 1", what),
                });
            }
        }
        self.check_buffer_size("per-pixel buffer", width as u64 * height as u64 * bytes_per_pixel)
    }

    /// Refuses a storage buffer larger than the adapter binds.
    pub fn check_buffer_size(&self, what: &str, bytes: u64) -> Result<(), GpuError> {
        let limit = self.limits.max_storage_buffer_binding_size.min(self.limits.max_buffer_size);
        if bytes > limit {
            return Err(self.over(&format!("{what} size in bytes"), bytes, limit));
        }
        Ok(())
    }

    /// Refuses a uniform binding larger than the adapter binds.
    pub fn check_uniform_size(&self, what: &str, bytes: u64) -> Result<(), GpuError> {
        let limit = self.limits.max_uniform_buffer_binding_size;
        if bytes > limit {
            return Err(self.over(&format!("{what} size in bytes"), bytes, limit));
        }
        Ok(())
    }

    /// Refuses a compute pass whose workgroup memory exceeds the budget.
    pub fn check_workgroup_memory(&self, pass: &str, bytes: u32) -> Result<(), GpuError> {
        let limit = self.workgroup_memory_budget();
        if bytes > limit {
            return Err(self.over(
                &format!("workgroup memory of pass '{pass}'"),
                bytes as u64,
                limit as u64,
            ));
        }
        Ok(())
    }

    /// The total loop iterations one invocation may run before the driver cuts it short, where
    /// known (llvmpipe); `None` on drivers without such a cap.
    pub fn loop_iteration_limit(&self) -> Option<u64> {
        let is_llvmpipe = |s: &str| s.to_ascii_lowercase().contains("llvmpipe");
        (is_llvmpipe(&self.summary.name) || is_llvmpipe(&self.summary.driver))
            .then_some(LLVMPIPE_LOOP_ITERATIONS)
    }

    /// Refuses a pass whose invocations would run more loop iterations than the driver allows.
    pub fn check_loop_iterations(&self, pass: &str, iterations: u64) -> Result<(), GpuError> {
        match self.loop_iteration_limit() {
            Some(limit) if iterations > limit => Err(self.over(
                &format!("loop iterations per invocation of pass '{pass}'"),
                iterations,
                limit,
            )),
            _ => Ok(()),
        }
    }

    /// A buffer holding `contents`: every pass makes its buffers from bytes through here.
    pub fn buffer_init(
        &self,
        label: &str,
        contents: &[u8],
        usage: wgpu::BufferUsages,
    ) -> wgpu::Buffer {
        use wgpu::util::DeviceExt;
        self.device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some(label),
            contents,
            usage,
        })
    }

    /// [`Gpu::buffer_init`] after refusing `contents` larger than the adapter binds (an error
    /// naming `label`).
    pub fn checked_buffer_init(
        &self,
        label: &str,
        contents: &[u8],
        usage: wgpu::BufferUsages,
    ) -> Result<wgpu::Buffer, GpuError> {
        self.check_buffer_size(label, contents.len() as u64)?;
        Ok(self.buffer_init(label, contents, usage))
    }

    /// Records commands into a new encoder labelled `label` and submits them (nothing is
    /// submitted when `record` fails): every one-off submission goes through here.
    pub fn submit<T, E>(
        &self,
        label: &str,
        record: impl FnOnce(&mut wgpu::CommandEncoder) -> Result<T, E>,
    ) -> Result<T, E> {
        let mut encoder = self
            .device
            .create_command_encoder(&wgpu::CommandEncoderDescriptor { label: Some(label) });
        let out = record(&mut encoder)?;
        self.queue.submit([encoder.finish()]);
        Ok(out)
    }

    fn over(&self, what: &str, requested: u64, limit: u64) -> GpuError {
        GpuError::OverLimit {
            what: what.into(),
            requested,
            limit,
            adapter: self.summary.name.clone(),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn opens_an_adapter_and_checks_limits() {
        let gpu = Gpu::new().expect("a wgpu adapter (lavapipe on CI)");
        assert!(gpu.limits.max_texture_dimension_2d >= 2048);
        assert!(gpu.check_resolution(64, 36, 16).is_ok());
        let too_wide = gpu.limits.max_texture_dimension_2d + 1;
        let err = gpu.check_resolution(too_wide, 4, 16).unwrap_err().to_string();
        assert!(err.contains("image width") && err.contains(&too_wide.to_string()), "{err}");
        assert!(gpu.check_workgroup_memory("x", 40 * 1024).is_err());
        assert!(gpu.check_workgroup_memory("x", 16 * 1024).is_ok());
    }
}
