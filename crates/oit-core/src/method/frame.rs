//! What a method renders with: the frame's context (`FrameCtx`: device, scene, camera, targets,
//! census, limits) with the helpers that look pipelines up and record passes, and what it
//! reports back (`MethodReport`); the `Method` trait.

use super::params::Params;
use crate::cache::{resolve_targets, Draw, Layout, PipelineSpec, RenderDesc};
use crate::context::GpuContext;
use crate::error::Result;
use crate::passes;
use crate::pipeline;
use crate::scene::Camera;
use crate::shader::{Const, SceneVariant};
use crate::targets::{SampleTargets, Targets};
use crate::tiles::Tile;
use crate::timer::PassTimer;
use crate::upload::GpuScene;

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
    pub timer: &'a mut PassTimer,
    pub params: &'a Params,
    /// The screen tile this render covers (the whole frame unless the renderer tiles): the
    /// method's per-pixel storage is for its pixels, and its passes are scissored to it.
    pub tile: Tile,
    /// Transparent fragments per pixel of the tile (row-major), from this frame's census.
    pub depth_complexity: &'a [u32],
    /// Largest transparent fragment count of a pixel of the tile, from the census.
    pub max_depth_complexity: u32,
    /// Largest of the whole frame: checks that refuse a frame do so at its first tile.
    pub frame_max_depth_complexity: u32,
    /// Transparent fragments of the tile, from the census.
    pub fragments: u64,
    /// The frame uniform (`gpu_types::FrameUniform`), for methods that set its `seed`.
    pub frame_uniform: &'a wgpu::Buffer,
    /// Limits to size buffers by (the adapter's, or lower ones the caller asked for).
    pub limits: Limits,
    /// What the memory budget leaves beside the frame's targets (None without a budget): a
    /// buffer that grows with the scene rather than the tile (`sorted`'s splat draws) is
    /// sized within it.
    pub memory_left: Option<u64>,
    /// A coverage-mask frame's per-sample targets (only methods that take coverage masks
    /// see one).
    pub coverage: Option<&'a SampleTargets>,
    /// What the scene's passes compile for (shading, light count, textures, and the extra
    /// light evaluations of `Renderer::set_shading_cost`): every pipeline a helper below looks
    /// up is specialized to it.
    pub variant: SceneVariant,
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

impl<'a> FrameCtx<'a> {
    pub fn pixels(&self) -> u64 {
        self.tile.pixels()
    }

    /// The layout of group 1 in this frame: the opaque targets, or their per-sample layers.
    fn targets_key(&self) -> Layout {
        if self.coverage.is_some() {
            Layout::SampleTargets
        } else {
            Layout::Targets
        }
    }

    /// Refuses a pipeline declared with other targets at group 1 than this frame binds.
    fn check_targets(&self, spec: &PipelineSpec) {
        assert_eq!(spec.groups[1], self.targets_key(), "{} {}: declared for other targets than this frame's", spec.shader, spec.entry);
    }

    /// `desc` compiled for this frame's scene variant, from the cache.
    fn render_pipeline(&self, mut desc: RenderDesc) -> wgpu::RenderPipeline {
        desc.shader = desc.shader.with(&self.variant.consts());
        self.gpu.cache.render(&self.gpu.device, &desc)
    }

    /// A geometry pipeline of `spec` (shader constants `consts`) that writes storage only,
    /// tested against the opaque depth; in a coverage-mask frame, multisampled.
    pub fn capture_pipeline(&self, spec: &PipelineSpec, consts: &[Const]) -> wgpu::RenderPipeline {
        let draw = match self.coverage {
            Some(c) => Draw::Geometry { depth: pipeline::raster_only(), samples: c.samples },
            None => Draw::Geometry { depth: pipeline::depth_test_only(), samples: 1 },
        };
        self.check_targets(spec);
        self.render_pipeline(spec.render(consts, draw, vec![]))
    }

    /// A geometry pipeline of `spec` with its color targets and depth state.
    pub fn draw_pipeline(
        &self,
        spec: &PipelineSpec,
        consts: &[Const],
        targets: Vec<Option<wgpu::ColorTargetState>>,
        depth: Option<wgpu::DepthStencilState>,
    ) -> wgpu::RenderPipeline {
        self.render_pipeline(spec.render(consts, Draw::Geometry { depth, samples: 1 }, targets))
    }

    /// A full-screen resolve of `spec` into the output (and the error bound, with `bound`); the
    /// method's groups are at 2, 3, ...
    pub fn resolve_pipeline(&self, spec: &PipelineSpec, consts: &[Const], bound: bool) -> wgpu::RenderPipeline {
        self.check_targets(spec);
        self.render_pipeline(spec.render(consts, Draw::Fullscreen, resolve_targets(bound)))
    }

    /// A full-screen resolve of `spec` that adds its color to the output (fixed-function
    /// additive blending) and writes the error bound.
    pub fn resolve_pipeline_adding(&self, spec: &PipelineSpec, consts: &[Const]) -> wgpu::RenderPipeline {
        self.check_targets(spec);
        let mut targets = resolve_targets(true);
        if let Some(Some(out)) = targets.first_mut() {
            out.blend = Some(wgpu::BlendState { color: pipeline::ADD, alpha: pipeline::ADD });
        }
        self.render_pipeline(spec.render(consts, Draw::Fullscreen, targets))
    }

    /// A compute pipeline of `spec` over the shared groups and the method's.
    pub fn compute_pipeline(&self, spec: &PipelineSpec, consts: &[Const]) -> wgpu::ComputePipeline {
        self.check_targets(spec);
        let mut desc = spec.compute_desc(consts);
        desc.shader = desc.shader.with(&self.variant.consts());
        self.gpu.cache.compute(&self.gpu.device, &desc)
    }

    /// A bind group of `layout` over `resources`, each given by its binding's name.
    pub fn group(&self, layout: Layout, resources: &[(&str, wgpu::BindingResource<'_>)]) -> wgpu::BindGroup {
        crate::cache::bind_named(&self.gpu.device, &self.gpu.cache, layout, "method group", resources)
    }

    /// Records a geometry pass of `pipeline` over the transparent geometry (timed as `label`),
    /// with the frame's targets at group 1 and `own` at group 2.
    pub fn capture(&mut self, enc: &mut wgpu::CommandEncoder, label: &'static str, pipeline: &wgpu::RenderPipeline, own: &wgpu::BindGroup) {
        self.capture_into(enc, label, pipeline, own, &[]);
    }

    /// Records a geometry pass like `capture` that also blends into `colors` (timed as `label`).
    pub fn capture_into(
        &mut self,
        enc: &mut wgpu::CommandEncoder,
        label: &'static str,
        pipeline: &wgpu::RenderPipeline,
        own: &wgpu::BindGroup,
        colors: &[Option<wgpu::RenderPassColorAttachment<'_>>],
    ) {
        let bound = self.bound();
        bound.capture(enc, label, colors, self.timer.render_pass(label), pipeline, own);
    }

    /// What every pass of this tile binds besides the method's own groups.
    fn bound(&self) -> TileBindings<'a> {
        TileBindings { scene: self.scene, targets: self.targets_group(), depth: self.raster_depth(), tile: self.tile }
    }

    /// [`FrameCtx::capture`] inside a span the caller times (per-layer passes).
    pub fn capture_untimed(
        &self,
        enc: &mut wgpu::CommandEncoder,
        label: &'static str,
        pipeline: &wgpu::RenderPipeline,
        own: &wgpu::BindGroup,
    ) {
        self.bound().capture(enc, label, &[], None, pipeline, own);
    }

    /// Binds the shared groups, `own` and `pipeline` to `pass` and dispatches one invocation
    /// per pixel (8 x 8 workgroups).
    pub fn bind_dispatch(&self, pass: &mut wgpu::ComputePass<'_>, pipeline: &wgpu::ComputePipeline, own: &wgpu::BindGroup) {
        self.bind_dispatch_with(pass, pipeline, own, Dispatch::Pixels);
    }

    /// Records a dispatch of `pipeline` with the shared groups and `own` bound, of the
    /// workgroups `dispatch` says.
    pub fn bind_dispatch_with(
        &self,
        pass: &mut wgpu::ComputePass<'_>,
        pipeline: &wgpu::ComputePipeline,
        own: &wgpu::BindGroup,
        dispatch: Dispatch<'_>,
    ) {
        self.bound().dispatch(pass, pipeline, own, dispatch);
    }

    /// Records a full-screen pass of `pipeline` into the output (and the error bound, with
    /// `bound`), with the shared groups and `own` bound.
    pub fn resolve(
        &mut self,
        enc: &mut wgpu::CommandEncoder,
        label: &'static str,
        pipeline: &wgpu::RenderPipeline,
        own: &wgpu::BindGroup,
        bound: bool,
    ) {
        self.resolve_groups(enc, label, pipeline, &[own], bound);
    }

    /// A full-screen pass like `resolve`, with the method's groups `own` at 2, 3, ...
    pub fn resolve_groups(
        &mut self,
        enc: &mut wgpu::CommandEncoder,
        label: &'static str,
        pipeline: &wgpu::RenderPipeline,
        own: &[&wgpu::BindGroup],
        bound: bool,
    ) {
        let (t, targets, scene, tile) = (self.targets, self.targets_group(), self.scene, self.tile);
        let timestamps = self.timer.render_pass(label);
        let mut pass = if bound {
            passes::resolve_with_bound(enc, label, t, timestamps)
        } else {
            passes::resolve_pass(enc, label, &t.out, timestamps)
        };
        tile.scissor(&mut pass);
        pass.set_pipeline(pipeline);
        pass.set_bind_group(0, scene.transparent.group(), &[]);
        pass.set_bind_group(1, targets, &[]);
        for (i, g) in own.iter().enumerate() {
            pass.set_bind_group(2 + i as u32, *g, &[]);
        }
        pass.draw(0..3, 0..1);
    }

    /// Records a compute pass of `pipeline`, one invocation per pixel (8 x 8 workgroups).
    pub fn dispatch(
        &mut self,
        enc: &mut wgpu::CommandEncoder,
        label: &'static str,
        pipeline: &wgpu::ComputePipeline,
        own: &wgpu::BindGroup,
    ) {
        self.dispatch_with(enc, label, pipeline, own, Dispatch::Pixels);
    }

    /// Records a compute pass of `pipeline`, timed as `label`, of the workgroups `dispatch` says.
    pub fn dispatch_with(
        &mut self,
        enc: &mut wgpu::CommandEncoder,
        label: &'static str,
        pipeline: &wgpu::ComputePipeline,
        own: &wgpu::BindGroup,
        dispatch: Dispatch<'_>,
    ) {
        let bound = self.bound();
        let timestamp_writes = self.timer.compute_pass(label);
        let mut pass = enc.begin_compute_pass(&wgpu::ComputePassDescriptor { label: Some(label), timestamp_writes });
        bound.dispatch(&mut pass, pipeline, own, dispatch);
    }

    pub fn encoder(&self) -> wgpu::CommandEncoder {
        self.gpu.device.create_command_encoder(&Default::default())
    }

    pub fn submit(&self, enc: wgpu::CommandEncoder) {
        self.gpu.queue.submit([enc.finish()]);
    }
}

/// What every pass of a tile binds besides the method's own groups: the scene (group 0), the
/// frame's targets (group 1), the depth its geometry passes test against, and the tile they are
/// scissored or dispatched to.
#[derive(Clone, Copy)]
struct TileBindings<'a> {
    scene: &'a GpuScene,
    targets: &'a wgpu::BindGroup,
    depth: &'a wgpu::TextureView,
    tile: Tile,
}

impl TileBindings<'_> {
    /// Records a geometry pass of `pipeline` over the transparent geometry, blending into
    /// `colors`, with `own` at group 2.
    fn capture(
        self,
        enc: &mut wgpu::CommandEncoder,
        label: &str,
        colors: &[Option<wgpu::RenderPassColorAttachment<'_>>],
        timestamps: Option<wgpu::RenderPassTimestampWrites<'_>>,
        pipeline: &wgpu::RenderPipeline,
        own: &wgpu::BindGroup,
    ) {
        let mut pass = passes::capture_into(enc, label, self.depth, colors, timestamps);
        self.tile.scissor(&mut pass);
        pass.set_pipeline(pipeline);
        pass.set_bind_group(1, self.targets, &[]);
        pass.set_bind_group(2, own, &[]);
        self.scene.transparent.draw_all(&mut pass);
    }

    /// Records a dispatch of `pipeline` with the shared groups and `own` bound.
    fn dispatch(self, pass: &mut wgpu::ComputePass<'_>, pipeline: &wgpu::ComputePipeline, own: &wgpu::BindGroup, dispatch: Dispatch<'_>) {
        pass.set_pipeline(pipeline);
        pass.set_bind_group(0, self.scene.transparent.group(), &[]);
        pass.set_bind_group(1, self.targets, &[]);
        pass.set_bind_group(2, own, &[]);
        match dispatch {
            Dispatch::Pixels => pass.dispatch_workgroups(self.tile.width.div_ceil(8), self.tile.height.div_ceil(8), 1),
            Dispatch::One => pass.dispatch_workgroups(1, 1, 1),
            Dispatch::Indirect(args, offset) => pass.dispatch_workgroups_indirect(args, offset),
        }
    }
}

/// The workgroups of a compute dispatch.
pub enum Dispatch<'a> {
    /// An invocation a pixel of the tile, in workgroups of 8 × 8.
    Pixels,
    /// One workgroup.
    One,
    /// The three workgroup counts a buffer holds at an offset, written by an earlier pass.
    Indirect(&'a wgpu::Buffer, u64),
}

impl FrameCtx<'_> {
    /// The same frame for another method's parameters (methods that delegate, e.g. auto).
    pub fn with_params<'b>(&'b mut self, params: &'b Params) -> FrameCtx<'b> {
        FrameCtx {
            gpu: self.gpu,
            scene: self.scene,
            camera: self.camera,
            targets: self.targets,
            timer: &mut *self.timer,
            params,
            tile: self.tile,
            depth_complexity: self.depth_complexity,
            max_depth_complexity: self.max_depth_complexity,
            frame_max_depth_complexity: self.frame_max_depth_complexity,
            fragments: self.fragments,
            frame_uniform: self.frame_uniform,
            limits: self.limits,
            memory_left: self.memory_left,
            coverage: self.coverage,
            variant: self.variant,
        }
    }

    /// Refuses a tile whose per-pixel buffer of `bytes_per_pixel` would pass one storage
    /// binding, naming the largest that fits.
    pub fn check_per_pixel(&self, what: &str, bytes_per_pixel: u64) -> Result<()> {
        check_per_pixel(self.limits.max_binding_bytes, self.tile.width, self.tile.height, what, bytes_per_pixel)
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
    /// Each pixel's transparent fragments (row-major), where the method counted them in its own
    /// capture in place of the census (`Method::counts_in_capture`).
    pub counts: Option<Vec<u32>>,
    /// Counts the method's passes leave for the executor to read with the tile's pixels (one
    /// wait for both): each adds to `overflow_fragments`, and to `extra` where named.
    pub tallies: Vec<Tally>,
}

/// A u32 count in a readback buffer, copied there by the method's last submission.
#[derive(Debug)]
pub struct Tally {
    pub readback: wgpu::Buffer,
    /// The extra stat it is also reported as.
    pub extra: Option<&'static str>,
}

/// What became of a tile a method was asked to render: the executor (renderer/execute.rs)
/// acts on each.
#[derive(Debug)]
pub(crate) enum Outcome {
    /// The tile is in the frame's targets.
    Done(MethodReport),
    /// Nothing usable was rendered: the method's storage proved too small and has grown to
    /// what the tile needs; the executor renders the tile again (the memory budget is held to
    /// what the tile then reports, as for any tile).
    Grow,
    /// Nothing was rendered: the tile needs `factor` times the storage one binding holds (more
    /// nodes than the census planned for); the executor plans smaller tiles.
    Retile { factor: f64 },
    /// Nothing was rendered: a frame the method counted itself (`Method::counts_in_capture`)
    /// does not fit one pool; the executor runs the census and plans tiles from it.
    NeedCensus,
}

pub(crate) trait Method: Send {
    fn render(&mut self, cx: &mut FrameCtx<'_>) -> Result<Outcome>;

    /// Whether the next whole, one-sample frame can go without the census because the method
    /// counts each pixel's fragments in its own capture and reports them
    /// (`MethodReport::counts`). Only a method whose `MethodInfo::census` is set asks this.
    fn counts_in_capture(&self) -> bool {
        false
    }
}
