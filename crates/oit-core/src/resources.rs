//! The resource layer under the methods: shader modules, bind-group layouts and pipelines
//! built once per device from hashable descriptors (`PipelineCache`, held by the
//! `GpuContext`), storage buffers bound as one group that are reallocated only when their
//! sizes change (`StorageGroup`), and atomic counters with their readback (`Counter`). The
//! pass helpers on `FrameCtx` (method/mod.rs) bind the shared groups themselves, so a method
//! names only what is its own. A frame only looks pipelines up; it never builds one twice.

use std::collections::HashMap;
use std::sync::Mutex;

use crate::context::GpuContext;
use crate::error::Result;
use crate::pipeline;
use crate::shader::{self, Const};
use crate::targets::{read_buffer, storage_buffer, COLOR_FORMAT};

/// A shader file with its compile-time constants (besides the shared ones).
#[derive(Clone, Debug, PartialEq, Eq, Hash)]
pub struct ShaderKey {
    pub path: &'static str,
    consts: Vec<ConstKey>,
}

/// A `Const` by value bits, so that it can be hashed.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
enum ConstKey {
    U32(&'static str, u32),
    F32(&'static str, u32),
}

impl ShaderKey {
    pub fn new(path: &'static str, consts: &[Const]) -> Self {
        let consts = consts
            .iter()
            .map(|c| match *c {
                Const::U32(n, v) => ConstKey::U32(n, v),
                Const::F32(n, v) => ConstKey::F32(n, v.to_bits()),
            })
            .collect();
        Self { path, consts }
    }

    fn consts(&self) -> Vec<Const> {
        self.consts
            .iter()
            .map(|c| match *c {
                ConstKey::U32(n, v) => Const::U32(n, v),
                ConstKey::F32(n, bits) => Const::F32(n, f32::from_bits(bits)),
            })
            .collect()
    }
}

/// A bind-group layout by its shape.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Layout {
    /// Group 0: the scene's vertex-pulling buffers and the frame uniform (upload.rs).
    Scene,
    /// Group 1: the opaque depth and base color (targets.rs).
    Targets,
    /// Group 1 of a coverage-mask frame: per-sample opaque layers.
    SampleTargets,
    /// `n` read-write storage buffers at bindings 0..n.
    Storage(u32),
    /// Unfilterable float textures at these bindings (accumulation targets a resolve reads).
    Textures(&'static [u32]),
}

impl Layout {
    fn create(self, device: &wgpu::Device) -> wgpu::BindGroupLayout {
        let entries: Vec<wgpu::BindGroupLayoutEntry> = match self {
            Layout::Scene => return crate::upload::scene_layout(device),
            Layout::Targets => return crate::targets::targets_layout(device),
            Layout::SampleTargets => return crate::targets::samples_layout(device),
            Layout::Storage(n) => (0..n).map(pipeline::storage_entry).collect(),
            Layout::Textures(bindings) => bindings.iter().map(|&b| pipeline::float_texture_entry(b)).collect(),
        };
        device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor { label: Some("oit group"), entries: &entries })
    }
}

/// What a render pipeline draws.
#[derive(Clone, Debug, PartialEq, Eq, Hash)]
pub enum Draw {
    /// Scene triangles by vertex pulling (`vs_main`), at `samples` samples a pixel.
    Geometry { depth: Option<wgpu::DepthStencilState>, samples: u32 },
    /// One full-screen triangle (`vs_fullscreen`).
    Fullscreen,
}

/// Everything a render pipeline is made of; equal descriptors share one pipeline.
#[derive(Clone, Debug, PartialEq, Eq, Hash)]
pub struct RenderDesc {
    pub shader: ShaderKey,
    pub entry: &'static str,
    pub groups: Vec<Layout>,
    pub draw: Draw,
    pub targets: Vec<Option<wgpu::ColorTargetState>>,
}

/// Everything a compute pipeline is made of.
#[derive(Clone, Debug, PartialEq, Eq, Hash)]
pub struct ComputeDesc {
    pub shader: ShaderKey,
    pub entry: &'static str,
    pub groups: Vec<Layout>,
}

/// Modules, layouts and pipelines of one device, each built at its first use.
#[derive(Default)]
pub struct PipelineCache {
    modules: Mutex<HashMap<ShaderKey, wgpu::ShaderModule>>,
    layouts: Mutex<HashMap<Layout, wgpu::BindGroupLayout>>,
    render: Mutex<HashMap<RenderDesc, wgpu::RenderPipeline>>,
    compute: Mutex<HashMap<ComputeDesc, wgpu::ComputePipeline>>,
}

fn lock<T>(m: &Mutex<T>) -> std::sync::MutexGuard<'_, T> {
    m.lock().unwrap_or_else(|p| p.into_inner())
}

impl PipelineCache {
    pub fn layout(&self, device: &wgpu::Device, layout: Layout) -> wgpu::BindGroupLayout {
        lock(&self.layouts).entry(layout).or_insert_with(|| layout.create(device)).clone()
    }

    fn module(&self, device: &wgpu::Device, key: &ShaderKey) -> wgpu::ShaderModule {
        lock(&self.modules).entry(key.clone()).or_insert_with(|| shader::module(device, key.path, &key.consts())).clone()
    }

    fn pipeline_layout(&self, device: &wgpu::Device, groups: &[Layout]) -> wgpu::PipelineLayout {
        let layouts: Vec<wgpu::BindGroupLayout> = groups.iter().map(|g| self.layout(device, *g)).collect();
        pipeline::layout(device, &layouts.iter().collect::<Vec<_>>())
    }

    pub fn render(&self, device: &wgpu::Device, desc: &RenderDesc) -> wgpu::RenderPipeline {
        if let Some(p) = lock(&self.render).get(desc) {
            return p.clone();
        }
        let module = self.module(device, &desc.shader);
        let layout = self.pipeline_layout(device, &desc.groups);
        let built = match &desc.draw {
            Draw::Geometry { depth, samples } => {
                pipeline::geometry_samples(device, desc.entry, &module, &layout, desc.entry, &desc.targets, depth.clone(), *samples)
            }
            Draw::Fullscreen => pipeline::fullscreen_targets(device, desc.entry, &module, &layout, desc.entry, &desc.targets),
        };
        lock(&self.render).entry(desc.clone()).or_insert(built).clone()
    }

    pub fn compute(&self, device: &wgpu::Device, desc: &ComputeDesc) -> wgpu::ComputePipeline {
        if let Some(p) = lock(&self.compute).get(desc) {
            return p.clone();
        }
        let module = self.module(device, &desc.shader);
        let layout = self.pipeline_layout(device, &desc.groups);
        let built = pipeline::compute(device, &layout, &module, desc.entry);
        lock(&self.compute).entry(desc.clone()).or_insert(built).clone()
    }

    /// Pipelines built so far (render and compute), for tests of reuse.
    pub fn pipelines(&self) -> usize {
        lock(&self.render).len() + lock(&self.compute).len()
    }
}

/// The color targets of a full-screen resolve: the RGBA32F output, and the R32F error bound
/// when the method writes one.
pub fn resolve_targets(bound: bool) -> Vec<Option<wgpu::ColorTargetState>> {
    let mut t = vec![Some(COLOR_FORMAT.into())];
    if bound {
        t.push(Some(crate::targets::BOUND_FORMAT.into()));
    }
    t
}

/// A mappable copy of a storage buffer, for what the CPU reads back.
pub struct Readback {
    buffer: wgpu::Buffer,
}

impl Readback {
    pub fn new(gpu: &GpuContext, label: &str, bytes: u64) -> Self {
        let buffer = gpu.device.create_buffer(&wgpu::BufferDescriptor {
            label: Some(label),
            size: bytes,
            usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        Self { buffer }
    }

    /// Records the copy of `source`'s first bytes that `read` maps.
    pub fn copy(&self, enc: &mut wgpu::CommandEncoder, source: &wgpu::Buffer) {
        enc.copy_buffer_to_buffer(source, 0, &self.buffer, 0, self.buffer.size());
    }

    /// The bytes of the last submitted `copy` (waits for it).
    pub fn read(&self, gpu: &GpuContext) -> Result<Vec<u8>> {
        read_buffer(gpu, &self.buffer, self.buffer.size())
    }
}

/// A u32 atomic counter in a storage buffer, with the readback that reads it.
pub struct Counter {
    pub buffer: wgpu::Buffer,
    readback: Readback,
}

impl Counter {
    pub fn new(gpu: &GpuContext, label: &str) -> Self {
        Self { buffer: storage_buffer(&gpu.device, label, 4, wgpu::BufferUsages::COPY_SRC), readback: Readback::new(gpu, label, 4) }
    }

    pub fn clear(&self, enc: &mut wgpu::CommandEncoder) {
        enc.clear_buffer(&self.buffer, 0, None);
    }

    /// Records the copy that `read` maps, after the passes that count.
    pub fn copy(&self, enc: &mut wgpu::CommandEncoder) {
        self.readback.copy(enc, &self.buffer);
    }

    /// The count copied by the last submitted `copy` (waits for it).
    pub fn read(&self, gpu: &GpuContext) -> Result<u64> {
        let raw = self.readback.read(gpu)?;
        Ok(u32::from_le_bytes(raw[..4].try_into().expect("4 bytes")) as u64)
    }
}

/// Storage buffers bound together as one group (bindings 0..n in order, then the counters'),
/// reallocated only when their sizes change.
pub struct StorageGroup {
    sizes: Vec<u64>,
    pub buffers: Vec<wgpu::Buffer>,
    pub group: wgpu::BindGroup,
}

impl StorageGroup {
    /// The group in `slot`, made anew when `buffers` ((label, bytes) per binding) differ in size
    /// from what it holds; `counters` follow them at the next bindings.
    pub fn ensure<'s>(
        slot: &'s mut Option<StorageGroup>,
        gpu: &GpuContext,
        buffers: &[(&str, u64)],
        counters: &[&Counter],
    ) -> &'s StorageGroup {
        let sizes: Vec<u64> = buffers.iter().map(|(_, b)| *b).collect();
        if slot.as_ref().is_none_or(|g| g.sizes != sizes) {
            *slot = None; // free the old buffers first
            let d = &gpu.device;
            let made: Vec<wgpu::Buffer> =
                buffers.iter().map(|(label, bytes)| storage_buffer(d, label, *bytes, wgpu::BufferUsages::COPY_SRC)).collect();
            let all: Vec<&wgpu::Buffer> = made.iter().chain(counters.iter().map(|c| &c.buffer)).collect();
            let layout = gpu.cache.layout(d, Layout::Storage(all.len() as u32));
            let entries: Vec<wgpu::BindGroupEntry> =
                all.iter().enumerate().map(|(i, b)| wgpu::BindGroupEntry { binding: i as u32, resource: b.as_entire_binding() }).collect();
            let group =
                d.create_bind_group(&wgpu::BindGroupDescriptor { label: buffers.first().map(|b| b.0), layout: &layout, entries: &entries });
            *slot = Some(StorageGroup { sizes, buffers: made, group });
        }
        slot.as_ref().expect("made above")
    }

    /// The layout a pipeline over this group binds at group 2.
    pub fn layout(&self) -> Layout {
        Layout::Storage(self.group_len())
    }

    fn group_len(&self) -> u32 {
        self.buffers.len() as u32
    }

    /// Records zeroing every buffer of the group (not the counters).
    pub fn clear(&self, enc: &mut wgpu::CommandEncoder) {
        for b in &self.buffers {
            enc.clear_buffer(b, 0, None);
        }
    }

    pub fn bytes(&self) -> u64 {
        self.sizes.iter().sum()
    }
}
