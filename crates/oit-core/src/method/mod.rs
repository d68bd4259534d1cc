//! The method trait, the registry of names, and parameter validation.
//! Adding a method: one file here, its WGSL, one line in `REGISTRY`, and its tests.

mod abuffer;
mod adaptive;
mod auto;
mod blend;
mod bucket_peeling;
mod compact_abuffer;
pub mod hybrid;
mod hybrid64;
pub(crate) mod lists;
mod mlab;
mod pall;
pub mod peel;
mod sbuffer;
mod screen_door;
mod stochastic;
pub mod weighted;
mod info;

pub use info::*;

use crate::context::GpuContext;
use crate::error::{invalid, Result};
use crate::scene::Camera;
use crate::targets::{SampleTargets, Targets};
use crate::timer::PassTimer;
use crate::upload::GpuScene;

const REGISTRY: &[MethodInfo] = &[
    abuffer::INFO,
    blend::UNSORTED,
    blend::SORTED,
    blend::ADDITIVE,
    blend::FILTER,
    hybrid::HYBRID,
    hybrid::KTAB,
    hybrid64::INFO,
    weighted::WAVG,
    weighted::WSUM,
    weighted::WBOIT,
    adaptive::INFO,
    pall::INFO,
    compact_abuffer::INFO,
    sbuffer::INFO,
    peel::DEPTH_PEELING,
    peel::DUAL_DEPTH_PEELING,
    screen_door::INFO,
    stochastic::INFO,
    mlab::INFO,
    bucket_peeling::INFO,
    auto::INFO,
];

pub fn methods() -> &'static [MethodInfo] {
    REGISTRY
}

pub fn lookup(name: &str) -> Result<&'static MethodInfo> {
    REGISTRY.iter().find(|m| m.name == name).ok_or_else(|| {
        let names: Vec<&str> = REGISTRY.iter().map(|m| m.name).collect();
        invalid!("unknown method '{name}'{}; valid methods: {}", did_you_mean(name, names.iter().copied()), names.join(", "))
    })
}

/// GPU bytes `name` allocates for a `width` x `height` frame with `params` (the formula of its
/// `MethodInfo::memory`): None when that grows with the scene, or for auto without `slots`.
pub fn memory_bytes(name: &str, width: u32, height: u32, params: &[(String, ParamValue)], slots: Option<u64>) -> Result<Option<u64>> {
    let info = lookup(name)?;
    if slots.is_some() && !matches!(info.memory, Memory::Slots { .. }) {
        return Err(invalid!("'{name}' has no per-pixel slots; `slots` is for methods that choose them per frame (auto)"));
    }
    let params = info.resolve_params(params)?;
    Ok(info.memory_bytes(width as u64 * height as u64, &params, slots))
}

/// Limits a method sizes its buffers by: the adapter's, or lower ones a caller asks for
/// (tests use a small binding limit to exercise buffer splitting on small scenes).
#[derive(Clone, Copy, Debug)]
pub struct Limits {
    pub max_binding_bytes: u64,
}

/// Everything a method needs to record one frame. The opaque pass and the census have run;
/// the method writes its final image into `targets.out`.
pub(crate) struct FrameCtx<'a> {
    pub gpu: &'a GpuContext,
    pub scene: &'a GpuScene,
    pub camera: &'a Camera,
    pub targets: &'a Targets,
    pub targets_layout: &'a wgpu::BindGroupLayout,
    pub scene_layout: &'a wgpu::BindGroupLayout,
    pub timer: &'a mut PassTimer,
    pub params: &'a Params,
    /// Transparent fragments per pixel (row-major), from this frame's census.
    pub depth_complexity: &'a [u32],
    /// Largest transparent fragment count of a pixel, from this frame's census.
    pub max_depth_complexity: u32,
    /// Transparent fragments of the frame, from the census.
    pub fragments: u64,
    /// The frame uniform (`gpu_types::FrameUniform`), for methods that set its `seed`.
    pub frame_uniform: &'a wgpu::Buffer,
    /// Limits to size buffers by (the adapter's, or lower ones the caller asked for).
    pub limits: Limits,
    /// A coverage-mask frame's per-sample targets (only methods that take coverage masks
    /// see one); `targets_layout` is then their layout.
    pub coverage: Option<&'a SampleTargets>,
}

impl<'a> FrameCtx<'a> {
    /// Group 1 of storage-writing and resolve passes: the frame's targets, or the per-sample
    /// ones of a coverage-mask frame.
    pub fn targets_group(&self) -> &'a wgpu::BindGroup {
        self.coverage.map_or(&self.targets.group, |c| &c.group)
    }

    /// The depth attachment geometry passes draw against (read-only).
    pub fn raster_depth(&self) -> &'a wgpu::TextureView {
        self.coverage.map_or(&self.targets.depth, |c| &c.raster_depth)
    }
}

impl FrameCtx<'_> {
    /// The same frame for another method's parameters (methods that delegate, e.g. auto).
    pub fn with_params<'b>(&'b mut self, params: &'b Params) -> FrameCtx<'b> {
        FrameCtx {
            gpu: self.gpu,
            scene: self.scene,
            camera: self.camera,
            targets: self.targets,
            targets_layout: self.targets_layout,
            scene_layout: self.scene_layout,
            timer: &mut *self.timer,
            params,
            depth_complexity: self.depth_complexity,
            max_depth_complexity: self.max_depth_complexity,
            fragments: self.fragments,
            frame_uniform: self.frame_uniform,
            limits: self.limits,
            coverage: self.coverage,
        }
    }

    /// Refuses a frame whose per-pixel buffer of `bytes_per_pixel` would pass one storage
    /// binding, naming the largest frame that fits.
    pub fn check_per_pixel(&self, what: &str, bytes_per_pixel: u64) -> Result<()> {
        check_per_pixel(self.limits.max_binding_bytes, self.targets.width, self.targets.height, what, bytes_per_pixel)
    }
}

/// See [`FrameCtx::check_per_pixel`].
pub(crate) fn check_per_pixel(limit: u64, width: u32, height: u32, what: &str, bytes_per_pixel: u64) -> Result<()> {
    let pixels = width as u64 * height as u64;
    if pixels * bytes_per_pixel <= limit {
        return Ok(());
    }
    let fits = limit / bytes_per_pixel.max(1);
    let side = (fits as f64).sqrt() as u64;
    Err(crate::error::OitError::OutOfMemory(format!(
        "{what} needs {} bytes at {width} x {height}, past the {limit}-byte storage binding limit: render at most \
         {fits} pixels (e.g. {side} x {side})",
        pixels * bytes_per_pixel
    )))
}

/// What a method reports about its frame, beyond what the renderer measures.
#[derive(Debug, Default)]
pub struct MethodReport {
    /// GPU memory the method itself allocated (buffers kept for this frame).
    pub memory_bytes: u64,
    /// Fragments a bounded structure could not hold.
    pub overflow_fragments: u64,
    /// Method-specific numbers (e.g. how often the node pool grew).
    pub extra: Vec<(&'static str, f64)>,
    /// Whether the method wrote a per-pixel error bound into `targets.bound`.
    pub error_bound: bool,
}

pub(crate) trait Method: Send {
    fn render(&mut self, cx: &mut FrameCtx<'_>) -> Result<MethodReport>;
}
