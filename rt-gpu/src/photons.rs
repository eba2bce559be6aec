//! A grid on the device, and photons traced through it
//! (`shaders/photons.wgsl`).

use bytemuck::{Pod, Zeroable};
use glam::DVec3;
use rt_volume::{Grid, GridField, IndexField as _, Interp};
use wgpu::util::DeviceExt as _;

use crate::{Gpu, GpuError};

/// A photon: where it starts and where it heads (any length but zero).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Photon {
    /// Its start, outside or inside the box.
    pub origin: DVec3,
    /// Its direction.
    pub direction: DVec3,
}

/// How a photon's trace ended.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ExitStatus {
    /// Its straight line misses the box: the exit is the photon itself.
    Missed,
    /// It left the box through a face.
    Left,
    /// It took [`TraceSettings::max_steps`] steps without leaving.
    OutOfSteps,
}

/// Where and how a photon left the box.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Exit {
    /// The exit point (on a face, for [`ExitStatus::Left`]).
    pub position: DVec3,
    /// Its unit direction there.
    pub direction: DVec3,
    /// `T − n₀·d`: the ray vector's change from its entry (`n₀` the index
    /// at the entry point, `d` the unit direction), as the shader
    /// accumulated it.
    pub deflection: DVec3,
    /// The index at the entry point (`1 +` the shader's f32 excess).
    pub n0: f64,
    /// `∫ n ds` from the photon's start: the ambient index times the
    /// distance to the entry point, then the path inside the box (as the
    /// CPU's trace counts it).
    pub optical_path: f64,
    /// How the trace ended.
    pub status: ExitStatus,
    /// Steps taken.
    pub steps: u32,
}

/// The scheme's settings: kick–drift–kick leapfrog at a fixed step.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TraceSettings {
    /// The step in the ray parameter `t` (`ds = n dt`).
    pub step: f64,
    /// The most steps a photon takes.
    pub max_steps: u32,
}

impl TraceSettings {
    /// The CPU's default for grids (`TraceParams::for_grid`): a step of the
    /// smallest spacing.
    #[must_use]
    pub fn for_grid(grid: &Grid) -> Self {
        Self { step: grid.spacing().min_element(), max_steps: 1_000_000 }
    }
}

/// The shader's `Params` (five `vec4`s).
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
struct Params {
    dims: [u32; 4],
    first: [f32; 4],
    inv_spacing: [f32; 4],
    hi: [f32; 4],
    counts: [u32; 4],
}

#[repr(C)]
#[derive(Clone, Copy, Pod, Zeroable)]
struct GpuPhoton {
    origin: [f32; 4],
    direction: [f32; 4],
}

#[repr(C)]
#[derive(Clone, Copy, Pod, Zeroable)]
struct GpuExit {
    position: [f32; 4],
    deflection: [f32; 4],
    status: [u32; 4],
}

/// Photons one dispatch traces: 65 535 workgroups of 64.
const BATCH: usize = 65_535 * 64;

/// A grid uploaded to a device, ready for photons.
#[derive(Debug)]
pub struct GridTracer<'g> {
    gpu: &'g Gpu,
    pipeline: wgpu::ComputePipeline,
    samples: wgpu::Buffer,
    params: Params,
    lo: DVec3,
    ambient: f64,
    /// Photons a dispatch takes: [`BATCH`], or fewer where the exits would
    /// not fit one storage buffer.
    batch: usize,
}

impl<'g> GridTracer<'g> {
    /// Uploads `field`'s grid (its `f32` samples, trilinear, edge samples
    /// with zero slope within half a cell of its faces, as on the CPU).
    ///
    /// # Errors
    /// [`GpuError::Unsupported`] for an interpolant other than trilinear,
    /// [`GpuError::NonFinite`] for a sample that is not finite,
    /// [`GpuError::TooLarge`] for a grid beyond the device's storage
    /// buffers.
    pub fn new(gpu: &'g Gpu, field: &GridField) -> Result<Self, GpuError> {
        if field.interp() != Interp::Trilinear {
            return Err(GpuError::Unsupported("only the trilinear interpolant runs on the GPU"));
        }
        let grid = field.grid();
        let data = grid.data();
        if let Some(index) = data.iter().position(|v| !v.is_finite()) {
            return Err(GpuError::NonFinite { what: "sample", index });
        }
        let bytes = core::mem::size_of_val(data) as u64;
        let limits = gpu.device.limits();
        let limit = limits.max_storage_buffer_binding_size.min(limits.max_buffer_size);
        if bytes > limit {
            return Err(GpuError::TooLarge { bytes, limit });
        }
        let bounds = grid.bounds();
        let (lo, hi) = (bounds.min, bounds.max);
        // The first sample's centre, relative to the box's lower corner.
        let first = grid.origin() - lo;
        let inv = grid.spacing().recip();
        let [nx, ny, nz] = grid.dims().map(|n| n as u32);
        let params = Params {
            dims: [nx, ny, nz, 0],
            first: [first.x as f32, first.y as f32, first.z as f32, 0.0],
            inv_spacing: [inv.x as f32, inv.y as f32, inv.z as f32, 0.0],
            hi: [(hi.x - lo.x) as f32, (hi.y - lo.y) as f32, (hi.z - lo.z) as f32, 0.0],
            counts: [0; 4],
        };
        let device = &gpu.device;
        let samples = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("rt-gpu samples"),
            contents: bytemuck::cast_slice(data),
            usage: wgpu::BufferUsages::STORAGE,
        });
        let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
            label: Some("rt-gpu photons"),
            source: wgpu::ShaderSource::Wgsl(include_str!("shaders/photons.wgsl").into()),
        });
        let pipeline = device.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
            label: Some("rt-gpu photons"),
            layout: None,
            module: &module,
            entry_point: Some("main"),
            compilation_options: Default::default(),
            cache: None,
        });
        let batch = usize::try_from(limit / core::mem::size_of::<GpuExit>() as u64)
            .unwrap_or(BATCH)
            .clamp(1, BATCH);
        Ok(Self { gpu, pipeline, samples, params, lo, ambient: field.ambient(), batch })
    }

    /// Traces `photons`, in batches the device dispatches at once.
    ///
    /// # Errors
    /// [`GpuError::BadSettings`], [`GpuError::NonFinite`] or
    /// [`GpuError::ZeroDirection`] for a photon (nothing is traced then),
    /// [`GpuError::Lost`] where the device fails.
    pub fn trace(
        &self,
        photons: &[Photon],
        settings: &TraceSettings,
    ) -> Result<Vec<Exit>, GpuError> {
        let step = settings.step as f32;
        if !(step.is_finite() && step > 0.0 && settings.max_steps > 0) {
            return Err(GpuError::BadSettings);
        }
        let mut input = Vec::with_capacity(photons.len());
        for (index, p) in photons.iter().enumerate() {
            let o = p.origin - self.lo;
            let d = p.direction.normalize_or_zero().as_vec3();
            if !o.is_finite() {
                return Err(GpuError::NonFinite { what: "origin", index });
            }
            if !p.direction.is_finite() {
                return Err(GpuError::NonFinite { what: "direction", index });
            }
            if d == glam::Vec3::ZERO {
                return Err(GpuError::ZeroDirection { index });
            }
            input.push(GpuPhoton {
                origin: [o.x as f32, o.y as f32, o.z as f32, 0.0],
                direction: [d.x, d.y, d.z, 0.0],
            });
        }
        let mut out = Vec::with_capacity(photons.len());
        for (chunk, given) in input.chunks(self.batch).zip(photons.chunks(self.batch)) {
            let exits = self.dispatch(chunk, step, settings.max_steps)?;
            out.extend(exits.iter().zip(given).map(|(e, p)| self.exit(e, p)));
        }
        Ok(out)
    }

    /// The exit record of `e` for photon `p`.
    fn exit(&self, e: &GpuExit, p: &Photon) -> Exit {
        let d = p.direction.normalize();
        let v = |a: [f32; 4]| DVec3::new(f64::from(a[0]), f64::from(a[1]), f64::from(a[2]));
        let n0 = 1.0 + f64::from(e.deflection[3]);
        let status = match e.status[0] {
            0 => ExitStatus::Missed,
            1 => ExitStatus::Left,
            _ => ExitStatus::OutOfSteps,
        };
        let deflection = v(e.deflection);
        let direction = match status {
            ExitStatus::Missed => d,
            _ => (n0 * d + deflection).normalize_or(d),
        };
        let position = v(e.position) + self.lo;
        // `∫ n ds` = ambient · (entry − o)·d + (exit − entry)·d + what the
        // shader summed beyond that straight line: the entry point cancels
        // but for the ambient's excess over 1.
        let near = f64::from(f32::from_bits(e.status[2]));
        let optical_path = match status {
            ExitStatus::Missed => 0.0,
            _ => {
                (self.ambient - 1.0) * near
                    + (position - p.origin).dot(d)
                    + f64::from(e.position[3])
            }
        };
        Exit { position, direction, deflection, n0, optical_path, status, steps: e.status[1] }
    }

    fn dispatch(
        &self,
        photons: &[GpuPhoton],
        step: f32,
        max_steps: u32,
    ) -> Result<Vec<GpuExit>, GpuError> {
        let device = &self.gpu.device;
        let mut params = self.params;
        params.first[3] = step;
        params.counts = [photons.len() as u32, max_steps, 0, 0];
        let uniform = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("rt-gpu params"),
            contents: bytemuck::bytes_of(&params),
            usage: wgpu::BufferUsages::UNIFORM,
        });
        let input = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("rt-gpu photons"),
            contents: bytemuck::cast_slice(photons),
            usage: wgpu::BufferUsages::STORAGE,
        });
        let size = (photons.len() * core::mem::size_of::<GpuExit>()) as u64;
        let exits = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("rt-gpu exits"),
            size,
            usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC,
            mapped_at_creation: false,
        });
        let readback = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("rt-gpu readback"),
            size,
            usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let bind = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("rt-gpu photons"),
            layout: &self.pipeline.get_bind_group_layout(0),
            entries: &[
                wgpu::BindGroupEntry { binding: 0, resource: uniform.as_entire_binding() },
                wgpu::BindGroupEntry { binding: 1, resource: self.samples.as_entire_binding() },
                wgpu::BindGroupEntry { binding: 2, resource: input.as_entire_binding() },
                wgpu::BindGroupEntry { binding: 3, resource: exits.as_entire_binding() },
            ],
        });
        let mut encoder =
            device.create_command_encoder(&wgpu::CommandEncoderDescriptor { label: None });
        {
            let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor::default());
            pass.set_pipeline(&self.pipeline);
            pass.set_bind_group(0, &bind, &[]);
            pass.dispatch_workgroups(photons.len().div_ceil(64) as u32, 1, 1);
        }
        encoder.copy_buffer_to_buffer(&exits, 0, &readback, 0, size);
        self.gpu.queue.submit([encoder.finish()]);
        let slice = readback.slice(..);
        let (tx, rx) = std::sync::mpsc::channel();
        slice.map_async(wgpu::MapMode::Read, move |r| {
            let _ = tx.send(r);
        });
        device
            .poll(wgpu::PollType::wait_indefinitely())
            .map_err(|e| GpuError::Lost(e.to_string()))?;
        rx.recv()
            .map_err(|e| GpuError::Lost(e.to_string()))?
            .map_err(|e| GpuError::Lost(e.to_string()))?;
        let view = slice.get_mapped_range().map_err(|e| GpuError::Lost(e.to_string()))?;
        let out = bytemuck::cast_slice::<u8, GpuExit>(&view).to_vec();
        drop(view);
        readback.unmap();
        Ok(out)
    }
}
