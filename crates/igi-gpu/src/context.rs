//! The wgpu instance, adapter choice and device: the one place that decides which GPU igi
//! runs on (a real GPU when there is one, Mesa's software Vulkan adapter otherwise).

use std::sync::{Arc, Mutex};

use crate::shader::ParamsBinding;

/// Errors of the GPU layer, each one line for the user.
#[derive(Clone, Debug, thiserror::Error)]
pub enum GpuError {
    #[error("no GPU adapter found: install a Vulkan driver (on Debian/Ubuntu the software one: `apt-get install mesa-vulkan-drivers`)")]
    NoAdapter,
    #[error("no adapter matches '{0}' (run `igi info` to list them)")]
    AdapterNotFound(String),
    #[error("could not open the GPU device on '{adapter}': {reason}")]
    RequestDevice { adapter: String, reason: String },
    #[error("GPU error: {0}")]
    Device(String),
    #[error("{0}")]
    Limit(String),
    /// Memory could not be allocated: `what` was being allocated (GPU memory for what,
    /// mostly), `bytes` large (where known); `hint` says what needs less.
    #[error("{}", out_of_memory_message(what, *bytes, hint))]
    OutOfMemory {
        what: String,
        bytes: Option<u64>,
        hint: &'static str,
    },
}

/// What a frame needs less memory with: the hint of most [`GpuError::OutOfMemory`]s.
pub const SMALLER_FRAME: &str = "a smaller image or fewer VPLs need less";

fn out_of_memory_message(what: &str, bytes: Option<u64>, hint: &str) -> String {
    let size = match bytes {
        Some(b) => format!(" ({} MiB)", b.div_ceil(1 << 20)),
        None => String::new(),
    };
    format!("out of memory: could not allocate {what}{size}; {hint}")
}

/// VPL range of one gathering dispatch on a software adapter (see
/// [`GpuContext::vpls_per_dispatch`]): 8 traversals stay well inside llvmpipe's budget
/// even for long shadow rays through the 277K-triangle conference room.
pub const SOFTWARE_VPLS_PER_DISPATCH: u32 = 8;

/// The most storage buffers one pipeline of igi binds (the direct pass's; a test counts
/// them in the shaders) where its parameter blocks are uniform buffers (GPUs). wgpu's GL
/// backend offers fewer on some drivers (llvmpipe: 16).
pub const STORAGE_BUFFERS_PER_STAGE: u32 = 21;

/// The most storage buffers one pipeline of igi binds with its parameter blocks bound as
/// `params` (software adapters bind them as storage buffers too).
pub fn storage_buffers_per_stage(params: ParamsBinding) -> u32 {
    match params {
        ParamsBinding::Uniform => STORAGE_BUFFERS_PER_STAGE,
        // The direct pass's two blocks: the frame's parameters and a VPL range.
        ParamsBinding::Storage => STORAGE_BUFFERS_PER_STAGE + 2,
    }
}

/// Why igi cannot run on `adapter`, or `None` where it can: said when the device is
/// opened, before a pipeline fails with a multi-line validation dump, and by `igi info`.
fn shortfall(adapter: &wgpu::Adapter) -> Option<String> {
    let allowed = adapter.limits().max_storage_buffers_per_shader_stage;
    let needed = storage_buffers_per_stage(ParamsBinding::for_type(adapter.get_info().device_type));
    (allowed < needed)
        .then(|| format!("allows {allowed} storage buffers per shader stage; igi needs {needed}"))
}

/// Which adapter to use: the best one, or one named by index or by part of its name.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub enum AdapterChoice {
    #[default]
    Best,
    /// Index in the list of `igi info`, or a case-insensitive part of the adapter name.
    Named(String),
}

impl AdapterChoice {
    pub fn from_option(s: Option<&str>) -> Self {
        match s {
            None => AdapterChoice::Best,
            Some(s) => AdapterChoice::Named(s.to_string()),
        }
    }
}

/// One line per adapter for `igi info`.
#[derive(Clone, Debug)]
pub struct AdapterSummary {
    pub index: usize,
    pub name: String,
    pub backend: String,
    pub device_type: String,
    pub driver: String,
    pub timestamps: bool,
    /// Why igi cannot run on it, if it cannot (too few storage buffers per stage).
    pub unusable: Option<String>,
}

/// The device in use, with what igi needs to know about it.
pub struct GpuContext {
    pub adapter: wgpu::Adapter,
    pub device: wgpu::Device,
    pub queue: wgpu::Queue,
    pub info: wgpu::AdapterInfo,
    /// Whether GPU timestamp queries (per-stage timings) are available.
    pub timestamps: bool,
    /// Whether the device has WGSL subgroup operations (`Features::SUBGROUP`).
    pub subgroups: bool,
    /// The first uncaptured error (validation, out of memory) seen on the device, if any.
    errors: Arc<Mutex<Option<GpuError>>>,
    /// Why the device was lost, if it was: reported before any error it causes.
    lost: Arc<Mutex<Option<GpuError>>>,
}

fn instance() -> wgpu::Instance {
    wgpu::Instance::new(wgpu::InstanceDescriptor::new_without_display_handle_from_env())
}

/// Rank adapters so that a real GPU beats a software one.
fn preference(info: &wgpu::AdapterInfo) -> u32 {
    use wgpu::DeviceType::*;
    let ty = match info.device_type {
        DiscreteGpu => 4,
        IntegratedGpu => 3,
        VirtualGpu => 2,
        Other => 1,
        Cpu => 0,
    };
    // Vulkan first: it is the backend igi is measured and tested on.
    let backend = u32::from(info.backend == wgpu::Backend::Vulkan);
    ty * 2 + backend
}

fn adapters() -> Vec<wgpu::Adapter> {
    adapters_of(&instance())
}

fn adapters_of(instance: &wgpu::Instance) -> Vec<wgpu::Adapter> {
    pollster::block_on(instance.enumerate_adapters(wgpu::Backends::all()))
        .into_iter()
        // A compute-only renderer needs compute shaders and storage buffers: GL ES without
        // them is of no use.
        .filter(|a| {
            a.get_downlevel_capabilities()
                .flags
                .contains(wgpu::DownlevelFlags::COMPUTE_SHADERS)
        })
        .collect()
}

/// The adapters wgpu sees, and the index of the one [`AdapterChoice::Best`] would pick.
pub fn list_adapters() -> (Vec<AdapterSummary>, Option<usize>) {
    let adapters = adapters();
    let list: Vec<AdapterSummary> = adapters
        .iter()
        .enumerate()
        .map(|(index, a)| {
            let info = a.get_info();
            AdapterSummary {
                index,
                name: info.name.clone(),
                backend: format!("{:?}", info.backend),
                device_type: format!("{:?}", info.device_type),
                driver: format!("{} {}", info.driver, info.driver_info)
                    .trim()
                    .to_string(),
                timestamps: a.features().contains(wgpu::Features::TIMESTAMP_QUERY),
                unusable: shortfall(a),
            }
        })
        .collect();
    let best = pick(&adapters, &AdapterChoice::Best).ok();
    (list, best)
}

fn pick(adapters: &[wgpu::Adapter], choice: &AdapterChoice) -> Result<usize, GpuError> {
    if adapters.is_empty() {
        return Err(GpuError::NoAdapter);
    }
    match choice {
        // An adapter igi can run on beats any it cannot.
        AdapterChoice::Best => Ok((0..adapters.len())
            .max_by_key(|&i| {
                let usable = shortfall(&adapters[i]).is_none();
                (usable, preference(&adapters[i].get_info()), usize::MAX - i)
            })
            .expect("non-empty")),
        AdapterChoice::Named(name) => {
            if let Ok(i) = name.parse::<usize>() {
                return if i < adapters.len() {
                    Ok(i)
                } else {
                    Err(GpuError::AdapterNotFound(name.clone()))
                };
            }
            let lower = name.to_lowercase();
            adapters
                .iter()
                .position(|a| a.get_info().name.to_lowercase().contains(&lower))
                .ok_or_else(|| GpuError::AdapterNotFound(name.clone()))
        }
    }
}

impl GpuContext {
    /// Open the device of the chosen adapter, with timestamp queries when it has them and
    /// the adapter's own limits (large scenes need its full storage-buffer size).
    pub fn new(choice: &AdapterChoice) -> Result<GpuContext, GpuError> {
        let mut adapters = adapters();
        let index = pick(&adapters, choice)?;
        Self::open(adapters.swap_remove(index))
    }

    /// [`GpuContext::new`] for a window: the adapter is chosen among those that can present
    /// to `target` (the viewer's window), and the surface comes with the context.
    /// `display` is the windowing system's connection (needed by GL, unused by Vulkan).
    pub fn for_window(
        choice: &AdapterChoice,
        target: impl Into<wgpu::SurfaceTarget<'static>>,
        display: Box<dyn wgpu::wgt::WgpuHasDisplayHandle>,
    ) -> Result<(GpuContext, wgpu::Surface<'static>), GpuError> {
        let instance = wgpu::Instance::new(
            wgpu::InstanceDescriptor::new_with_display_handle_from_env(display),
        );
        let surface = instance
            .create_surface(target)
            .map_err(|e| GpuError::Device(format!("cannot draw into the window: {e}")))?;
        let mut adapters: Vec<wgpu::Adapter> = adapters_of(&instance)
            .into_iter()
            .filter(|a| a.is_surface_supported(&surface))
            .collect();
        let index = pick(&adapters, choice)?;
        Ok((Self::open(adapters.swap_remove(index))?, surface))
    }

    fn open(adapter: wgpu::Adapter) -> Result<GpuContext, GpuError> {
        let info = adapter.get_info();
        if let Some(why) = shortfall(&adapter) {
            return Err(GpuError::Limit(format!(
                "adapter '{}' ({:?}) {why}: choose a Vulkan, Metal or DX12 adapter (igi info lists them)",
                info.name, info.backend
            )));
        }
        let timestamps = adapter.features().contains(wgpu::Features::TIMESTAMP_QUERY);
        let mut features = wgpu::Features::empty();
        if timestamps {
            features |= wgpu::Features::TIMESTAMP_QUERY;
            // Stage timestamps between the dispatches of one compute pass (passes::Recorder).
            if adapter
                .features()
                .contains(wgpu::Features::TIMESTAMP_QUERY_INSIDE_PASSES)
            {
                features |= wgpu::Features::TIMESTAMP_QUERY_INSIDE_PASSES;
            }
        }
        let subgroups = adapter.features().contains(wgpu::Features::SUBGROUP);
        if subgroups {
            features |= wgpu::Features::SUBGROUP;
        }
        let desc = wgpu::DeviceDescriptor {
            label: Some("igi"),
            required_features: features,
            required_limits: adapter.limits(),
            experimental_features: wgpu::ExperimentalFeatures::disabled(),
            memory_hints: wgpu::MemoryHints::Performance,
            trace: wgpu::Trace::Off,
        };
        let (device, queue) = pollster::block_on(adapter.request_device(&desc)).map_err(|e| {
            GpuError::RequestDevice {
                adapter: info.name.clone(),
                reason: e.to_string(),
            }
        })?;
        let errors: Arc<Mutex<Option<GpuError>>> = Arc::default();
        let sink = errors.clone();
        device.on_uncaptured_error(Arc::new(move |e: wgpu::Error| {
            let mut slot = sink.lock().unwrap_or_else(|p| p.into_inner());
            if slot.is_none() {
                *slot = Some(uncaptured(&e));
            }
        }));
        let lost: Arc<Mutex<Option<GpuError>>> = Arc::default();
        let sink = lost.clone();
        device.set_device_lost_callback(move |reason, message| {
            let mut slot = sink.lock().unwrap_or_else(|p| p.into_inner());
            if slot.is_none() {
                *slot = Some(lost_device(reason, &message));
            }
        });
        Ok(GpuContext {
            adapter,
            device,
            queue,
            info,
            timestamps,
            subgroups,
            errors,
            lost,
        })
    }

    /// Wait for the work of one submission (and all before it), then report the first
    /// device error seen, if any.
    pub fn wait_for(&self, submission: wgpu::SubmissionIndex) -> Result<(), GpuError> {
        self.device
            .poll(wgpu::PollType::Wait {
                submission_index: Some(submission),
                timeout: None,
            })
            .map_err(|e| GpuError::Device(e.to_string()))?;
        self.check()
    }

    /// Wait for all submitted work, then report the first device error seen, if any.
    pub fn finish(&self) -> Result<(), GpuError> {
        self.device
            .poll(wgpu::PollType::wait_indefinitely())
            .map_err(|e| GpuError::Device(e.to_string()))?;
        self.check()
    }

    /// The loss of the device, else the first uncaptured device error, if one happened.
    pub fn check(&self) -> Result<(), GpuError> {
        if let Some(e) = self.lost.lock().unwrap_or_else(|p| p.into_inner()).as_ref() {
            return Err(e.clone());
        }
        let slot = self.errors.lock().unwrap_or_else(|p| p.into_inner());
        match slot.as_ref() {
            Some(e) => Err(e.clone()),
            None => Ok(()),
        }
    }

    /// Create resources with `make`, catching the device's out-of-memory errors: if an
    /// allocation fails, what `make` made is dropped and the error is
    /// [`GpuError::OutOfMemory`] naming `what()` and `bytes`. Other errors stay uncaptured
    /// (see [`GpuContext::check`]).
    pub fn allocate<T>(
        &self,
        what: impl FnOnce() -> String,
        bytes: u64,
        hint: &'static str,
        make: impl FnOnce() -> T,
    ) -> Result<T, GpuError> {
        let scope = self.device.push_error_scope(wgpu::ErrorFilter::OutOfMemory);
        let made = make();
        // With wgpu-core the future is ready at once: the scope holds what was caught.
        match pollster::block_on(scope.pop()) {
            None => Ok(made),
            Some(_) => {
                drop(made);
                Err(GpuError::OutOfMemory {
                    what: format!("GPU memory for {}", what()),
                    bytes: Some(bytes),
                    hint,
                })
            }
        }
    }

    /// Whether the adapter is a software one (lavapipe / llvmpipe): what the passes'
    /// loop limits, the mirror lanes and the ray schedules depend on.
    pub fn is_software(&self) -> bool {
        self.info.device_type == wgpu::DeviceType::Cpu
    }

    /// VPLs one gathering dispatch may take. A software adapter (llvmpipe) ends a shader
    /// invocation after 65535 loop iterations in all, and each VPL is a BVH traversal of
    /// up to a few thousand iterations, so there the VPL list is split into ranges of
    /// this many; a GPU takes the whole list at once.
    pub fn vpls_per_dispatch(&self) -> u32 {
        if self.is_software() {
            SOFTWARE_VPLS_PER_DISPATCH
        } else {
            u32::MAX
        }
    }

    /// "NAME (BACKEND, TYPE, DRIVER)" for reports.
    pub fn describe(&self) -> String {
        format!(
            "{} ({:?}, {:?}, {} {})",
            self.info.name,
            self.info.backend,
            self.info.device_type,
            self.info.driver,
            self.info.driver_info
        )
    }

    /// Largest storage buffer one binding may hold on this device, in bytes.
    pub fn max_storage_binding(&self) -> u64 {
        self.device.limits().max_storage_buffer_binding_size
    }

    /// Read a storage buffer back to the CPU (through a staging copy).
    pub fn read_buffer<T: bytemuck::Pod>(&self, buffer: &wgpu::Buffer) -> Result<Vec<T>, GpuError> {
        let size = buffer.size();
        let staging = self.allocate(
            || "a staging buffer to read results back".to_string(),
            size,
            SMALLER_FRAME,
            || {
                self.device.create_buffer(&wgpu::BufferDescriptor {
                    label: Some("readback"),
                    size,
                    usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
                    mapped_at_creation: false,
                })
            },
        )?;
        let mut encoder = self
            .device
            .create_command_encoder(&wgpu::CommandEncoderDescriptor {
                label: Some("readback"),
            });
        encoder.copy_buffer_to_buffer(buffer, 0, &staging, 0, size);
        self.queue.submit([encoder.finish()]);
        let slice = staging.slice(..);
        let (tx, rx) = std::sync::mpsc::channel();
        slice.map_async(wgpu::MapMode::Read, move |r| {
            let _ = tx.send(r);
        });
        self.finish()?;
        let mapped = rx.recv().map_err(|e| GpuError::Device(e.to_string()))?;
        // A lost device fails the mapping too: say why.
        self.check()?;
        mapped.map_err(|e| GpuError::Device(e.to_string()))?;
        let data = slice
            .get_mapped_range()
            .map_err(|e| GpuError::Device(e.to_string()))?;
        // Host memory, which a software adapter shares with its buffers: a failed
        // allocation is reported like the device's own.
        let values = bytemuck::cast_slice::<u8, T>(&data);
        let mut out = Vec::new();
        out.try_reserve_exact(values.len())
            .map_err(|_| GpuError::OutOfMemory {
                what: "host memory for the results read back".to_string(),
                bytes: Some(size),
                hint: SMALLER_FRAME,
            })?;
        out.extend_from_slice(values);
        drop(data);
        staging.unmap();
        Ok(out)
    }
}

/// An error no scope caught, for [`GpuContext::check`]: out of memory as such, anything
/// else as a device error (its message on one line).
fn uncaptured(e: &wgpu::Error) -> GpuError {
    match e {
        wgpu::Error::OutOfMemory { source } => GpuError::OutOfMemory {
            what: format!("GPU memory ({})", error_chain(source.as_ref())),
            bytes: None,
            hint: SMALLER_FRAME,
        },
        e => GpuError::Device(one_line(&e.to_string())),
    }
}

/// The error of a lost device. wgpu loses the device when memory it cannot do without
/// (a staging buffer, say) fails to allocate: that loss is reported as out of memory.
fn lost_device(reason: wgpu::DeviceLostReason, message: &str) -> GpuError {
    let detail = one_line(message);
    if detail.to_lowercase().contains("out of memory") {
        return GpuError::OutOfMemory {
            what: format!("GPU memory and the device was lost ({detail})"),
            bytes: None,
            hint: SMALLER_FRAME,
        };
    }
    let detail = if detail.is_empty() {
        String::new()
    } else {
        format!(": {detail}")
    };
    GpuError::Device(format!("the GPU device was lost ({reason:?}){detail}"))
}

/// An error and its sources, on one line, separated by ": ".
fn error_chain(e: &(dyn std::error::Error + 'static)) -> String {
    let mut parts = vec![one_line(&e.to_string())];
    let mut source = e.source();
    while let Some(s) = source {
        parts.push(one_line(&s.to_string()));
        source = s.source();
    }
    parts.dedup();
    parts.join(": ")
}

fn one_line(s: &str) -> String {
    s.split_whitespace().collect::<Vec<_>>().join(" ")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn uncaught_out_of_memory_is_reported_as_such() {
        let e = uncaptured(&wgpu::Error::OutOfMemory {
            source: "Not enough memory left.".into(),
        })
        .to_string();
        assert_eq!(
            e,
            "out of memory: could not allocate GPU memory (Not enough memory left.); a smaller image or fewer VPLs need less"
        );
        let e = uncaptured(&wgpu::Error::Validation {
            source: "x".into(),
            description: "Buffer is\n invalid".into(),
        });
        assert_eq!(e.to_string(), "GPU error: Buffer is invalid");
    }

    #[test]
    fn a_device_lost_for_memory_says_out_of_memory() {
        let e = lost_device(wgpu::DeviceLostReason::Unknown, "Out of memory").to_string();
        assert!(e.starts_with("out of memory:") && e.contains("lost"), "{e}");
        let e = lost_device(wgpu::DeviceLostReason::Destroyed, "").to_string();
        assert_eq!(e, "GPU error: the GPU device was lost (Destroyed)");
    }

    #[test]
    fn out_of_memory_names_what_and_how_large() {
        let e = GpuError::OutOfMemory {
            what: "GPU memory for the 13 frame buffers of a 4096x4096 image".into(),
            bytes: Some(13 * 4096 * 4096 * 16),
            hint: SMALLER_FRAME,
        };
        assert_eq!(
            e.to_string(),
            "out of memory: could not allocate GPU memory for the 13 frame buffers of a 4096x4096 image (3328 MiB); a smaller image or fewer VPLs need less"
        );
    }
}
