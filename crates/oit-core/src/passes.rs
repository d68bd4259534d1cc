//! Render passes every method begins the same way: a geometry pass that only reads the opaque
//! depth, a pass that blends over the opaque scene, and full-screen resolves into the output
//! (and the error bound).

/// A geometry pass that only reads the opaque depth (bound as a texture at the same time).
pub fn capture_pass<'e>(
    enc: &'e mut wgpu::CommandEncoder,
    label: &str,
    depth: &'e wgpu::TextureView,
    timestamps: Option<wgpu::RenderPassTimestampWrites<'e>>,
) -> wgpu::RenderPass<'e> {
    capture_into(enc, label, depth, &[], timestamps)
}

/// A geometry pass that reads the opaque depth and blends into `colors`.
pub fn capture_into<'e>(
    enc: &'e mut wgpu::CommandEncoder,
    label: &str,
    depth: &'e wgpu::TextureView,
    colors: &[Option<wgpu::RenderPassColorAttachment<'e>>],
    timestamps: Option<wgpu::RenderPassTimestampWrites<'e>>,
) -> wgpu::RenderPass<'e> {
    enc.begin_render_pass(&wgpu::RenderPassDescriptor {
        label: Some(label),
        color_attachments: colors,
        depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment { view: depth, depth_ops: None, stencil_ops: None }),
        timestamp_writes: timestamps,
        occlusion_query_set: None,
        multiview_mask: None,
    })
}

/// A pass over `tile` that draws over the opaque scene: the base color is copied to the output
/// first, and the pass blends into it against `depth` (read-only with `depth_ops` None).
pub fn over_base_pass<'e>(
    enc: &'e mut wgpu::CommandEncoder,
    label: &str,
    targets: &'e crate::targets::Targets,
    depth: &'e wgpu::TextureView,
    depth_ops: Option<wgpu::Operations<f32>>,
    tile: crate::tiles::Tile,
    timestamps: Option<wgpu::RenderPassTimestampWrites<'e>>,
) -> wgpu::RenderPass<'e> {
    let out = &targets.out_texture;
    enc.copy_texture_to_texture(targets.base_texture.as_image_copy(), out.as_image_copy(), out.size());
    over_pass(enc, label, targets, depth, depth_ops, tile, timestamps)
}

/// `over_base_pass` without the copy: the pass blends into the output as an earlier pass left
/// it (a frame drawn in several passes).
pub fn over_pass<'e>(
    enc: &'e mut wgpu::CommandEncoder,
    label: &str,
    targets: &'e crate::targets::Targets,
    depth: &'e wgpu::TextureView,
    depth_ops: Option<wgpu::Operations<f32>>,
    tile: crate::tiles::Tile,
    timestamps: Option<wgpu::RenderPassTimestampWrites<'e>>,
) -> wgpu::RenderPass<'e> {
    let mut pass = enc.begin_render_pass(&wgpu::RenderPassDescriptor {
        label: Some(label),
        color_attachments: &[Some(wgpu::RenderPassColorAttachment {
            view: &targets.out,
            depth_slice: None,
            resolve_target: None,
            ops: wgpu::Operations { load: wgpu::LoadOp::Load, store: wgpu::StoreOp::Store },
        })],
        depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment { view: depth, depth_ops, stencil_ops: None }),
        timestamp_writes: timestamps,
        occlusion_query_set: None,
        multiview_mask: None,
    });
    tile.scissor(&mut pass);
    pass
}

/// A resolve's target, kept as it is: the pass writes every pixel of its tile, and the tiles
/// rendered before it stay.
fn kept(view: &wgpu::TextureView) -> Option<wgpu::RenderPassColorAttachment<'_>> {
    Some(wgpu::RenderPassColorAttachment {
        view,
        depth_slice: None,
        resolve_target: None,
        ops: wgpu::Operations { load: wgpu::LoadOp::Load, store: wgpu::StoreOp::Store },
    })
}

/// A pass that writes `target` over the tile it is scissored to (full-screen resolves).
pub fn resolve_pass<'e>(
    enc: &'e mut wgpu::CommandEncoder,
    label: &str,
    target: &'e wgpu::TextureView,
    timestamps: Option<wgpu::RenderPassTimestampWrites<'e>>,
) -> wgpu::RenderPass<'e> {
    resolve_targets(enc, label, &[kept(target)], timestamps)
}

/// A full-screen resolve that also writes the per-pixel error bound.
pub fn resolve_with_bound<'e>(
    enc: &'e mut wgpu::CommandEncoder,
    label: &str,
    targets: &'e crate::targets::Targets,
    timestamps: Option<wgpu::RenderPassTimestampWrites<'e>>,
) -> wgpu::RenderPass<'e> {
    resolve_targets(enc, label, &[kept(&targets.out), kept(&targets.bound)], timestamps)
}

fn resolve_targets<'e>(
    enc: &'e mut wgpu::CommandEncoder,
    label: &str,
    attachments: &[Option<wgpu::RenderPassColorAttachment<'e>>],
    timestamps: Option<wgpu::RenderPassTimestampWrites<'e>>,
) -> wgpu::RenderPass<'e> {
    enc.begin_render_pass(&wgpu::RenderPassDescriptor {
        label: Some(label),
        color_attachments: attachments,
        depth_stencil_attachment: None,
        timestamp_writes: timestamps,
        occlusion_query_set: None,
        multiview_mask: None,
    })
}
