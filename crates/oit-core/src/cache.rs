//! Shader modules, bind-group layouts and pipelines built once per device from hashable
//! descriptors (`PipelineCache`, held by the `GpuContext`). A frame only looks pipelines up; it
//! never builds one twice. The pass helpers on `FrameCtx` (method/frame.rs) use it, and bind the
//! shared groups themselves, so that a method names only what is its own.

use std::collections::HashMap;
use std::sync::Mutex;

use crate::bindings::{self, BOUND_FORMAT, COLOR_FORMAT};
use crate::pipeline;
use crate::shader::{self, Const};

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

    /// The same shader with `extra` constants after its own (a scene variant's, for instance).
    pub fn with(&self, extra: &[Const]) -> Self {
        let mut key = self.clone();
        key.consts.extend(Self::new(self.path, extra).consts);
        key
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
            Layout::Scene => return bindings::scene_layout(device),
            Layout::Targets => return bindings::targets_layout(device),
            Layout::SampleTargets => return bindings::samples_layout(device),
            Layout::Storage(n) => (0..n).map(bindings::storage_entry).collect(),
            Layout::Textures(at) => at.iter().map(|&b| bindings::float_texture_entry(b)).collect(),
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
        t.push(Some(BOUND_FORMAT.into()));
    }
    t
}
