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
    /// Group 0: the scene's vertex-pulling buffers and the frame uniform (upload/).
    Scene,
    /// Group 1: the opaque depth and base color (targets.rs).
    Targets,
    /// Group 1 of a coverage-mask frame: per-sample opaque layers.
    SampleTargets,
    /// Read-write storage buffers at bindings 0, 1, ..., by the names their WGSL declares
    /// (tests/bindings.rs checks each name against the shader's variable at that binding).
    Storage(&'static [&'static str]),
    /// Unfilterable float textures (accumulation targets a resolve reads), by WGSL name and
    /// binding.
    Textures(&'static [(&'static str, u32)]),
    /// The prefix sum's group (scan.rs): the data and block sums, read-write, and its uniform.
    Scan,
    /// Group 0 of the expansion of strands and particles (shaders/expand.wgsl): the scene's,
    /// with the expanded corners writable.
    Expand,
}

impl Layout {
    /// The entries of the layout: what `PipelineCache::layout` creates, and what
    /// tests/bindings.rs checks each shader's bindings against.
    pub fn entries(self) -> Vec<wgpu::BindGroupLayoutEntry> {
        match self {
            Layout::Scene => bindings::scene_entries(),
            Layout::Targets => bindings::opaque_entries(wgpu::TextureViewDimension::D2),
            Layout::SampleTargets => bindings::opaque_entries(wgpu::TextureViewDimension::D2Array),
            Layout::Storage(names) => (0..names.len() as u32).map(bindings::storage_entry).collect(),
            Layout::Textures(at) => at.iter().map(|&(_, b)| bindings::float_texture_entry(b)).collect(),
            Layout::Scan => bindings::scan_entries(),
            Layout::Expand => bindings::expand_entries(),
        }
    }

    /// The binding each of the layout's names is at; None for the shared layouts, which are
    /// bound by their owners (upload/, targets.rs, scan.rs).
    pub fn named(self) -> Option<Vec<(&'static str, u32)>> {
        match self {
            Layout::Storage(names) => Some(names.iter().zip(0..).map(|(&n, b)| (n, b)).collect()),
            Layout::Textures(at) => Some(at.to_vec()),
            _ => None,
        }
    }

    /// What the device's layout object depends on: the entries, not the names (layouts that
    /// differ only in names share one).
    fn shape(self) -> Shape {
        match self {
            Layout::Storage(names) => Shape::Storage(names.len() as u32),
            Layout::Textures(at) => Shape::Textures(at.iter().map(|&(_, b)| b).collect()),
            other => Shape::Shared(other),
        }
    }

    fn create(self, device: &wgpu::Device) -> wgpu::BindGroupLayout {
        let label = match self {
            Layout::Scene => "scene",
            Layout::Targets => "targets",
            Layout::SampleTargets => "sample targets",
            Layout::Scan => "scan",
            Layout::Expand => "expand",
            Layout::Storage(_) | Layout::Textures(_) => "oit group",
        };
        device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor { label: Some(label), entries: &self.entries() })
    }
}

/// A layout's key in the cache (`Layout::shape`).
#[derive(Clone, Debug, PartialEq, Eq, Hash)]
enum Shape {
    Storage(u32),
    Textures(Vec<u32>),
    Shared(Layout),
}

/// A bind group of `layout` over `resources` given by the names the layout declares, each
/// name once: the binding each resource lands at comes from the layout, never from the order
/// the caller lists them in.
pub fn bind_named(
    device: &wgpu::Device,
    cache: &PipelineCache,
    layout: Layout,
    label: &str,
    resources: &[(&str, wgpu::BindingResource<'_>)],
) -> wgpu::BindGroup {
    let named = layout.named().unwrap_or_else(|| panic!("{layout:?} is bound by its owner, not by name"));
    let mut entries = Vec::with_capacity(named.len());
    for &(name, binding) in &named {
        let mut given = resources.iter().filter(|(n, _)| *n == name);
        let (_, resource) = given.next().unwrap_or_else(|| panic!("{label}: no resource named '{name}' for {layout:?}"));
        assert!(given.next().is_none(), "{label}: '{name}' given twice for {layout:?}");
        entries.push(wgpu::BindGroupEntry { binding, resource: resource.clone() });
    }
    if let Some((extra, _)) = resources.iter().find(|(n, _)| !named.iter().any(|(d, _)| d == n)) {
        panic!("{label}: {layout:?} declares no binding named '{extra}'");
    }
    let layout = cache.layout(device, layout);
    device.create_bind_group(&wgpu::BindGroupDescriptor { label: Some(label), layout: &layout, entries: &entries })
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

/// The stages a pipeline runs, and so its entry points besides its own.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Stages {
    /// Scene triangles by vertex pulling (`vs_main`), then the fragment entry.
    Geometry,
    /// One full-screen triangle (`vs_fullscreen`), then the fragment entry.
    Fullscreen,
    /// The compute entry alone.
    Compute,
}

/// One pipeline as declared once: its shader file, entry point, stages, and the layout of each
/// bind group (0, 1, ...). Each method builds its pipelines from its table of these
/// (`MethodInfo::pipelines`; the renderer's are `ENGINE_PIPELINES`), and tests/bindings.rs
/// checks every entry against what its WGSL binds, by naga reflection.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct PipelineSpec {
    pub shader: &'static str,
    pub entry: &'static str,
    pub stages: Stages,
    pub groups: &'static [Layout],
}

impl PipelineSpec {
    /// A geometry pipeline of the fragment entry `entry`.
    pub const fn geometry(shader: &'static str, entry: &'static str, groups: &'static [Layout]) -> Self {
        Self { shader, entry, stages: Stages::Geometry, groups }
    }

    /// A full-screen pipeline of the fragment entry `entry`.
    pub const fn fullscreen(shader: &'static str, entry: &'static str, groups: &'static [Layout]) -> Self {
        Self { shader, entry, stages: Stages::Fullscreen, groups }
    }

    pub const fn compute(shader: &'static str, entry: &'static str, groups: &'static [Layout]) -> Self {
        Self { shader, entry, stages: Stages::Compute, groups }
    }

    /// The entry points the pipeline runs, with their stages.
    pub fn entry_points(&self) -> Vec<(&'static str, wgpu::ShaderStages)> {
        match self.stages {
            Stages::Geometry => vec![("vs_main", wgpu::ShaderStages::VERTEX), (self.entry, wgpu::ShaderStages::FRAGMENT)],
            Stages::Fullscreen => vec![("vs_fullscreen", wgpu::ShaderStages::VERTEX), (self.entry, wgpu::ShaderStages::FRAGMENT)],
            Stages::Compute => vec![(self.entry, wgpu::ShaderStages::COMPUTE)],
        }
    }

    /// The render pipeline of this spec with the shader constants `consts`.
    pub fn render(&self, consts: &[Const], draw: Draw, targets: Vec<Option<wgpu::ColorTargetState>>) -> RenderDesc {
        let stages = match draw {
            Draw::Geometry { .. } => Stages::Geometry,
            Draw::Fullscreen => Stages::Fullscreen,
        };
        assert_eq!(stages, self.stages, "{} {}: drawn as another kind of pipeline than declared", self.shader, self.entry);
        RenderDesc { shader: ShaderKey::new(self.shader, consts), entry: self.entry, groups: self.groups.to_vec(), draw, targets }
    }

    /// The compute pipeline of this spec with the shader constants `consts`.
    pub fn compute_desc(&self, consts: &[Const]) -> ComputeDesc {
        assert_eq!(self.stages, Stages::Compute, "{} {}: not declared a compute pipeline", self.shader, self.entry);
        ComputeDesc { shader: ShaderKey::new(self.shader, consts), entry: self.entry, groups: self.groups.to_vec() }
    }
}

/// The pipeline of `entry` in `table` (a method's declared pipelines).
pub fn spec(table: &'static [PipelineSpec], entry: &str) -> &'static PipelineSpec {
    table.iter().find(|p| p.entry == entry).unwrap_or_else(|| {
        let shader = table.first().map_or("an empty table", |p| p.shader);
        panic!("{shader}: no pipeline of entry {entry} is declared in its table")
    })
}

/// Modules, layouts and pipelines of one device, each built at its first use.
#[derive(Default)]
pub struct PipelineCache {
    modules: Mutex<HashMap<ShaderKey, wgpu::ShaderModule>>,
    layouts: Mutex<HashMap<Shape, wgpu::BindGroupLayout>>,
    render: Mutex<HashMap<RenderDesc, wgpu::RenderPipeline>>,
    compute: Mutex<HashMap<ComputeDesc, wgpu::ComputePipeline>>,
}

fn lock<T>(m: &Mutex<T>) -> std::sync::MutexGuard<'_, T> {
    m.lock().unwrap_or_else(|p| p.into_inner())
}

impl PipelineCache {
    pub fn layout(&self, device: &wgpu::Device, layout: Layout) -> wgpu::BindGroupLayout {
        lock(&self.layouts).entry(layout.shape()).or_insert_with(|| layout.create(device)).clone()
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
                pipeline::geometry_samples(device, &module, &layout, desc.entry, &desc.targets, depth.clone(), *samples)
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

/// The renderer's own pipelines (renderer/execute.rs, renderer/into.rs) and the prefix sum's
/// (scan.rs), listed in `ENGINE_PIPELINES`; the methods' are in their `MethodInfo::pipelines`.
pub const OPAQUE: PipelineSpec = PipelineSpec::geometry("opaque.wgsl", "fs_opaque", &[Layout::Scene]);
/// The census by blending into the count target.
pub const CENSUS_BLEND: PipelineSpec = PipelineSpec::geometry("census.wgsl", "fs_count", &[Layout::Scene]);
/// The census's counts buffer (shaders/common/census_counts.wgsl), group 2 of its atomic passes.
pub const COUNTS: Layout = Layout::Storage(&["counts"]);
/// The census with an atomic a fragment into the counts buffer.
pub const CENSUS_ATOMIC: PipelineSpec = PipelineSpec::geometry("census.wgsl", "fs_census", &[Layout::Scene, Layout::Targets, COUNTS]);
/// The census of a coverage-mask frame, at each sample's coverage.
pub const CENSUS_SAMPLES: PipelineSpec =
    PipelineSpec::geometry("census_samples.wgsl", "fs_census", &[Layout::Scene, Layout::SampleTargets, COUNTS]);
/// The blit's one group: the picture it copies.
pub const BLIT_SOURCE: &[Layout] = &[Layout::Textures(&[("source", 0)])];
pub const BLIT: PipelineSpec = PipelineSpec::fullscreen("blit.wgsl", "fs_blit", BLIT_SOURCE);
pub const BLIT_SRGB: PipelineSpec = PipelineSpec::fullscreen("blit.wgsl", "fs_blit_srgb", BLIT_SOURCE);
pub const SCAN_BLOCKS: PipelineSpec = PipelineSpec::compute("scan.wgsl", "cs_scan_blocks", &[Layout::Scan]);
pub const SCAN_ADD: PipelineSpec = PipelineSpec::compute("scan.wgsl", "cs_add_blocks", &[Layout::Scan]);
/// Strands and particles facing the eye, before a frame's geometry passes (upload/geometry.rs), an
/// entry point a kind.
pub const EXPAND_STRANDS: PipelineSpec = PipelineSpec::compute("expand.wgsl", "cs_expand_strands", &[Layout::Expand]);
pub const EXPAND_PARTICLES: PipelineSpec = PipelineSpec::compute("expand.wgsl", "cs_expand_particles", &[Layout::Expand]);
pub const EXPAND_GAUSSIANS: PipelineSpec = PipelineSpec::compute("expand.wgsl", "cs_expand_gaussians", &[Layout::Expand]);
pub const ENGINE_PIPELINES: &[PipelineSpec] = &[
    OPAQUE,
    CENSUS_BLEND,
    CENSUS_ATOMIC,
    CENSUS_SAMPLES,
    BLIT,
    BLIT_SRGB,
    SCAN_BLOCKS,
    SCAN_ADD,
    EXPAND_STRANDS,
    EXPAND_PARTICLES,
    EXPAND_GAUSSIANS,
];
