//! Device creation, buffer helpers and readback.

#[derive(Debug, thiserror::Error)]
pub enum GpuError {
    #[error("no GPU adapter found ({0}). On Debian/Ubuntu without a GPU install Mesa's software Vulkan: sudo apt-get install mesa-vulkan-drivers libvulkan1")]
    NoAdapter(String),
    #[error("could not open the GPU device: {0}")]
    Device(String),
    #[error("{0}")]
    Invalid(String),
    #[error("GPU error: {0}")]
    Validation(String),
    #[error("the GPU device was lost ({0})")]
    DeviceLost(String),
}

/// Pipeline constants of a technique's analysis variant of its evaluation (`view.wgsl`).
pub const COUNTING: &[(&str, f64)] = &[("COUNT_SAMPLES", 1.0)];

pub struct Gpu {
    pub device: wgpu::Device,
    pub queue: wgpu::Queue,
    pub info: wgpu::AdapterInfo,
    pub limits: wgpu::Limits,
    /// Stage times come from GPU timestamps (else wall clock with a device wait); see `timing`.
    pub gpu_timestamps: bool,
    /// The device's errors and shadowlab's refusals ([`Gpu::refuse`]), oldest first.
    errors: std::sync::Arc<std::sync::Mutex<Vec<GpuError>>>,
    /// Why the device was lost (a driver reset, a backgrounded browser tab, `destroy`), once it is.
    lost: std::sync::Arc<std::sync::Mutex<Option<String>>>,
    /// Queue submissions made through [`Gpu::submit`] (tests count a frame's submits).
    submits: std::sync::atomic::AtomicU64,
    /// The buffer counter and the upload / readback pools (alloc.rs).
    pub(crate) alloc: crate::alloc::Alloc,
}

impl Gpu {
    /// Opens the first high-performance adapter (any backend; lavapipe on GPU-less machines).
    #[cfg(not(target_arch = "wasm32"))]
    pub fn new() -> Result<Gpu, GpuError> {
        pollster::block_on(Gpu::open())
    }

    /// [`Gpu::new`] with the device descriptor edited by `edit` first (tests: the same adapter
    /// with a feature left out or a limit lowered).
    #[cfg(not(target_arch = "wasm32"))]
    pub fn new_with(edit: impl FnOnce(&mut wgpu::DeviceDescriptor<'static>)) -> Result<Gpu, GpuError> {
        pollster::block_on(Gpu::open_with(edit))
    }

    /// [`Gpu::new`] as a future (the browser's adapter: WebGPU's `requestAdapter`, awaited).
    pub async fn open() -> Result<Gpu, GpuError> {
        Gpu::open_with(|_| {}).await
    }

    async fn open_with(edit: impl FnOnce(&mut wgpu::DeviceDescriptor<'static>)) -> Result<Gpu, GpuError> {
        let instance = wgpu::Instance::new(wgpu::InstanceDescriptor::new_without_display_handle_from_env());
        let adapter = instance
            .request_adapter(&wgpu::RequestAdapterOptions {
                power_preference: wgpu::PowerPreference::HighPerformance,
                force_fallback_adapter: false,
                compatible_surface: None,
                apply_limit_buckets: false,
            })
            .await
            .map_err(|e| GpuError::NoAdapter(e.to_string()))?;
        let info = adapter.get_info();
        let mut desc = Gpu::device_descriptor(&adapter);
        edit(&mut desc);
        let (device, queue) = adapter.request_device(&desc).await.map_err(|e| GpuError::Device(e.to_string()))?;
        Gpu::from_device(device, queue, info)
    }

    /// What shadowlab asks of an adapter's device: all of its limits, timestamps where offered,
    /// and the optional features `sv` uses (the viewer opens its window's device with this too).
    pub fn device_descriptor(adapter: &wgpu::Adapter) -> wgpu::DeviceDescriptor<'static> {
        let ts = wgpu::Features::TIMESTAMP_QUERY | wgpu::Features::TIMESTAMP_QUERY_INSIDE_ENCODERS;
        let has_ts = adapter.features().contains(ts);
        wgpu::DeviceDescriptor {
            label: Some("shadowlab"),
            // sv: unclipped depth (infinite extrusion) and a float depth-stencil target; the
            // paraboloid maps: clip distances (warp/depth_clip.wgsl); each where offered
            required_features: (if has_ts { ts } else { wgpu::Features::empty() })
                | (adapter.features()
                    & (wgpu::Features::DEPTH_CLIP_CONTROL | wgpu::Features::DEPTH32FLOAT_STENCIL8 | wgpu::Features::CLIP_DISTANCES)),
            required_limits: adapter.limits(),
            experimental_features: wgpu::ExperimentalFeatures::disabled(),
            memory_hints: wgpu::MemoryHints::Performance,
            trace: wgpu::Trace::Off,
        }
    }

    /// Wraps a device the host application already opened (the library seam). shadowlab keeps
    /// no state outside this struct; it installs an uncaptured-error handler on the device so
    /// that [`Gpu::take_error`] can report validation errors. Stage timing uses GPU timestamps
    /// when the device was opened with `TIMESTAMP_QUERY | TIMESTAMP_QUERY_INSIDE_ENCODERS` and
    /// the adapter is not a CPU one (`SHADOWLAB_TIMER` overrides). What each technique needs
    /// beyond WebGPU's defaults is listed by `shadowlab techniques` (`TechniqueInfo::needs`).
    pub fn from_device(device: wgpu::Device, queue: wgpu::Queue, info: wgpu::AdapterInfo) -> Result<Gpu, GpuError> {
        let limits = device.limits();
        let ts = wgpu::Features::TIMESTAMP_QUERY | wgpu::Features::TIMESTAMP_QUERY_INSIDE_ENCODERS;
        let gpu_timestamps = device.features().contains(ts) && crate::timing::want_timestamps(&info)?;
        let errors = std::sync::Arc::new(std::sync::Mutex::new(Vec::new()));
        let sink = errors.clone();
        device
            .on_uncaptured_error(std::sync::Arc::new(move |e: wgpu::Error| sink.lock().unwrap().push(GpuError::Validation(e.to_string()))));
        let lost = std::sync::Arc::new(std::sync::Mutex::new(None));
        let why = lost.clone();
        device.set_device_lost_callback(move |reason, msg| {
            let reason = match reason {
                wgpu::DeviceLostReason::Destroyed => "destroyed",
                _ => "driver reset or unknown cause",
            };
            *why.lock().unwrap() = Some(if msg.is_empty() { reason.to_string() } else { format!("{reason}: {msg}") });
        });
        Ok(Gpu { device, queue, info, limits, gpu_timestamps, errors, lost, submits: Default::default(), alloc: Default::default() })
    }

    /// Submits one command buffer (every submit of shadowlab goes through here and is counted).
    pub fn submit(&self, cmd: wgpu::CommandBuffer) {
        self.submits.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
        self.queue.submit([cmd]);
    }

    /// Submits made through [`Gpu::submit`] so far.
    pub fn submit_count(&self) -> u64 {
        self.submits.load(std::sync::atomic::Ordering::Relaxed)
    }

    /// Records a refusal (a resource over the device's limits): [`Gpu::take_error`] returns it
    /// before any error the device raises because of it.
    pub fn refuse(&self, msg: String) {
        self.errors_push(GpuError::Invalid(msg));
    }

    pub(crate) fn errors_push(&self, e: GpuError) {
        self.errors.lock().unwrap().push(e);
    }

    /// Why the device was lost, once it is: nothing made on it works any more; a host makes a
    /// new [`Gpu`] (and `Lab`) or says so and stops.
    pub fn lost(&self) -> Option<String> {
        self.lost.lock().unwrap().clone()
    }

    /// Returns the device's loss, else the first refusal or GPU validation/out-of-memory error
    /// raised since the last call.
    pub fn take_error(&self) -> Result<(), GpuError> {
        if let Some(why) = self.lost() {
            self.errors.lock().unwrap().clear();
            return Err(GpuError::DeviceLost(why));
        }
        match self.errors.lock().unwrap().drain(..).next() {
            Some(e) => Err(e),
            None => Ok(()),
        }
    }

    /// "llvmpipe (Vulkan, Cpu)" and the like, for reports.
    pub fn adapter_summary(&self) -> String {
        format!("{} ({:?}, {:?})", self.info.name, self.info.backend, self.info.device_type)
    }

    /// Which timer the stage times come from, for every report that prints a time.
    pub fn timer_name(&self) -> &'static str {
        if self.gpu_timestamps {
            crate::timing::TIMESTAMP_TIMER
        } else {
            crate::timing::WALL_TIMER
        }
    }

    /// Which timer the per-stage times come from.
    pub fn stages_timer_name(&self) -> &'static str {
        if self.gpu_timestamps {
            crate::timing::TIMESTAMP_TIMER
        } else {
            crate::timing::PROFILE_TIMER
        }
    }

    /// Rejects output sizes of 0 or above the device's texture limit.
    pub fn check_size(&self, width: u32, height: u32, what: &str) -> Result<(), GpuError> {
        let max = self.limits.max_texture_dimension_2d;
        if width == 0 || height == 0 || width > max || height > max {
            return Err(GpuError::Invalid(format!("{what} {width}x{height} must be between 1 and {max} on this device")));
        }
        Ok(())
    }

    pub fn buffer_init(&self, label: &str, contents: &[u8], usage: wgpu::BufferUsages) -> wgpu::Buffer {
        // wgpu rejects empty buffers; keep one word so bindings stay valid.
        let contents = if contents.is_empty() { &[0u8; 4][..] } else { contents };
        self.buffer_desc_init(&wgpu::util::BufferInitDescriptor { label: Some(label), contents, usage })
    }

    pub fn storage(&self, label: &str, size: u64) -> wgpu::Buffer {
        self.buffer(&wgpu::BufferDescriptor {
            label: Some(label),
            size: size.max(4),
            usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        })
    }

    pub fn uniform<T: bytemuck::Pod>(&self, label: &str, value: &T) -> wgpu::Buffer {
        self.uniform_array(label, std::slice::from_ref(value))
    }

    /// A uniform buffer holding an array of `values`.
    pub fn uniform_array<T: bytemuck::Pod>(&self, label: &str, values: &[T]) -> wgpu::Buffer {
        // STORAGE: bound as read-only storage on lavapipe (crate::quirks)
        let usage = wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_DST;
        self.buffer_init(label, bytemuck::cast_slice(values), usage)
    }

    /// Whether the device clips by distances from the vertex stage (`CLIP_DISTANCES`): the
    /// paraboloid depth passes then need no fragment stage.
    pub fn clip_distances(&self) -> bool {
        self.device.features().contains(wgpu::Features::CLIP_DISTANCES)
    }

    /// Waits until the work submitted so far is done (in the browser: yields to the event loop
    /// under JSPI until it is, [`crate::web`]).
    pub fn wait(&self) {
        #[cfg(not(target_arch = "wasm32"))]
        let _ = self.device.poll(wgpu::PollType::wait_indefinitely());
        #[cfg(target_arch = "wasm32")]
        {
            let done = std::sync::Arc::new(std::sync::atomic::AtomicBool::new(false));
            let flag = done.clone();
            self.queue.on_submitted_work_done(move || flag.store(true, std::sync::atomic::Ordering::Release));
            crate::web::block_until(&done, || self.lost().is_some());
        }
    }

    /// Copies a buffer back to the CPU (blocking).
    pub fn read_buffer(&self, src: &wgpu::Buffer) -> Vec<u8> {
        self.read_buffer_range(src, 0, src.size())
    }

    /// Copies `size` bytes of a buffer from `offset` (both multiples of 4) back to the CPU.
    pub fn read_buffer_range(&self, src: &wgpu::Buffer, offset: u64, size: u64) -> Vec<u8> {
        let staging = self.readback(size);
        let mut enc = self.device.create_command_encoder(&Default::default());
        enc.copy_buffer_to_buffer(src, offset, &staging, 0, size);
        self.submit(enc.finish());
        let mut bytes = self.map_and_take(&staging, size as usize);
        self.give_readback(staging);
        bytes.truncate(size as usize);
        bytes
    }

    /// `count` values from byte `offset` of a buffer.
    pub fn read_buffer_at<T: bytemuck::Pod>(&self, src: &wgpu::Buffer, offset: u64, count: usize) -> Vec<T> {
        bytemuck::pod_collect_to_vec(&self.read_buffer_range(src, offset, (count * std::mem::size_of::<T>()) as u64))
    }

    /// Maps a `MAP_READ` buffer whose copy was already submitted, and reads `count` values.
    pub fn map_read_as<T: bytemuck::Pod>(&self, staging: &wgpu::Buffer, count: usize) -> Vec<T> {
        let bytes = self.map_and_take(staging, count * std::mem::size_of::<T>());
        bytemuck::pod_collect_to_vec(&bytes[..count * std::mem::size_of::<T>()])
    }

    pub fn read_buffer_as<T: bytemuck::Pod>(&self, src: &wgpu::Buffer, count: usize) -> Vec<T> {
        let bytes = self.read_buffer(src);
        bytemuck::pod_collect_to_vec(&bytes[..count * std::mem::size_of::<T>()])
    }

    /// Copies a 2D texture (mip 0) back to the CPU as tightly packed rows.
    pub fn read_texture(&self, tex: &wgpu::Texture, bytes_per_pixel: u32) -> Vec<u8> {
        self.read_texture_layer(tex, bytes_per_pixel, 0)
    }

    /// [`Gpu::read_texture`] of one layer of a 2D array texture.
    pub fn read_texture_layer(&self, tex: &wgpu::Texture, bytes_per_pixel: u32, layer: u32) -> Vec<u8> {
        let (w, h) = (tex.width(), tex.height());
        let row = w * bytes_per_pixel;
        let padded = row.div_ceil(wgpu::COPY_BYTES_PER_ROW_ALIGNMENT) * wgpu::COPY_BYTES_PER_ROW_ALIGNMENT;
        let staging = self.readback((padded * h) as u64);
        let mut enc = self.device.create_command_encoder(&Default::default());
        enc.copy_texture_to_buffer(
            wgpu::TexelCopyTextureInfo { origin: wgpu::Origin3d { x: 0, y: 0, z: layer }, ..tex.as_image_copy() },
            wgpu::TexelCopyBufferInfo {
                buffer: &staging,
                layout: wgpu::TexelCopyBufferLayout { offset: 0, bytes_per_row: Some(padded), rows_per_image: Some(h) },
            },
            wgpu::Extent3d { width: w, height: h, depth_or_array_layers: 1 },
        );
        self.submit(enc.finish());
        let data = self.map_and_take(&staging, (padded * h) as usize);
        self.give_readback(staging);
        let mut out = Vec::with_capacity((row * h) as usize);
        for y in 0..h as usize {
            out.extend_from_slice(&data[y * padded as usize..y * padded as usize + row as usize]);
        }
        out
    }

    /// The bytes of a mapped readback (at least `len`). When the map fails (a buffer refused
    /// over a limit, a lost device) `len` zero bytes, and the failure is reported by
    /// [`Gpu::take_error`], which every caller asks before using what it read.
    fn map_and_take(&self, staging: &wgpu::Buffer, len: usize) -> Vec<u8> {
        use std::sync::atomic::{AtomicBool, Ordering};
        use std::sync::{Arc, Mutex};
        let slice = staging.slice(..);
        let (done, result) = (Arc::new(AtomicBool::new(false)), Arc::new(Mutex::new(None)));
        let (flag, slot) = (done.clone(), result.clone());
        slice.map_async(wgpu::MapMode::Read, move |r| {
            *slot.lock().unwrap() = Some(r);
            flag.store(true, Ordering::Release);
        });
        // natively the device wait runs the callback; the browser runs it from its event loop
        #[cfg(not(target_arch = "wasm32"))]
        self.wait();
        #[cfg(target_arch = "wasm32")]
        crate::web::block_until(&done, || self.lost().is_some());
        let mapped = match result.lock().unwrap().take() {
            Some(r) => r.map_err(|e| e.to_string()),
            None => Err("the device was lost before the map completed".to_string()),
        };
        if let Err(e) = mapped {
            self.errors_push(GpuError::Validation(format!("reading back {len} bytes failed: {e}")));
            return vec![0; len];
        }
        let data = slice.get_mapped_range().expect("mapped range").to_vec();
        staging.unmap();
        if data.len() < len {
            // the stand-in of a readback refused over a limit (`Gpu::buffer`)
            self.errors_push(GpuError::Validation(format!("reading back {len} bytes from a buffer of {}", data.len())));
            return vec![0; len];
        }
        data
    }

    /// A WGSL module (uniform buffers declared as the adapter binds them, [`crate::quirks`]).
    pub fn shader(&self, label: &str, source: &str) -> wgpu::ShaderModule {
        let source = crate::quirks::wgsl(source, crate::quirks::uniforms_as_storage(&self.info));
        self.device.create_shader_module(wgpu::ShaderModuleDescriptor { label: Some(label), source: wgpu::ShaderSource::Wgsl(source) })
    }

    /// A compute pipeline with explicit bind group layouts.
    pub fn compute_pipeline(&self, label: &str, source: &str, entry: &str, layouts: &[&wgpu::BindGroupLayout]) -> wgpu::ComputePipeline {
        self.compute_pipeline_with(label, source, entry, layouts, &[])
    }

    /// [`Gpu::compute_pipeline`] with WGSL `override` constants set (e.g. `COUNT_SAMPLES` for a
    /// technique's analysis variant of its evaluation).
    pub fn compute_pipeline_with(
        &self,
        label: &str,
        source: &str,
        entry: &str,
        layouts: &[&wgpu::BindGroupLayout],
        constants: &[(&str, f64)],
    ) -> wgpu::ComputePipeline {
        let module = self.shader(label, source);
        let layout = self.pipeline_layout(label, layouts);
        self.device.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
            label: Some(label),
            layout: Some(&layout),
            module: &module,
            entry_point: Some(entry),
            compilation_options: wgpu::PipelineCompilationOptions { constants, ..Default::default() },
            cache: None,
        })
    }

    pub fn pipeline_layout(&self, label: &str, layouts: &[&wgpu::BindGroupLayout]) -> wgpu::PipelineLayout {
        let opt: Vec<Option<&wgpu::BindGroupLayout>> = layouts.iter().map(|l| Some(*l)).collect();
        self.device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some(label),
            bind_group_layouts: &opt,
            immediate_size: 0,
        })
    }

    /// Records one compute dispatch covering `w x h` threads in 8x8 groups.
    pub fn dispatch_2d(
        &self,
        enc: &mut wgpu::CommandEncoder,
        label: &str,
        pipeline: &wgpu::ComputePipeline,
        groups: &[&wgpu::BindGroup],
        w: u32,
        h: u32,
    ) {
        let mut pass = enc.begin_compute_pass(&wgpu::ComputePassDescriptor { label: Some(label), timestamp_writes: None });
        pass.set_pipeline(pipeline);
        for (i, g) in groups.iter().enumerate() {
            pass.set_bind_group(i as u32, *g, &[]);
        }
        self.dispatch(&mut pass, [w.div_ceil(8), h.div_ceil(8), 1]);
    }
}
