//! The passes of a frame before the method's: the strands and particles turned to face the eye,
//! the frame uniform, and the opaque pass (with the census after it, census.rs).

use std::time::Instant;

use super::execute::Job;
use super::Renderer;
use crate::antialias;
use crate::bindings::COLOR_FORMAT;
use crate::cache::{Draw, EXPAND_GAUSSIANS, EXPAND_PARTICLES, EXPAND_STRANDS, OPAQUE};
use crate::context::GpuContext;
use crate::error::Result;
use crate::gpu_types::{FrameUniform, GpuLight};
use crate::pipeline;
use crate::scene::Camera;
use crate::shader::SceneVariant;
use crate::shading::{Lighting, MAX_LIGHTS};
use crate::tiles::Tile;
use crate::upload::GpuScene;

/// The opaque pass's pipeline for `variant`: straight color, writes depth.
fn opaque_pipeline(gpu: &GpuContext, variant: SceneVariant) -> wgpu::RenderPipeline {
    let desc =
        OPAQUE.render(&variant.consts(), Draw::Geometry { depth: pipeline::depth_write(), samples: 1 }, vec![Some(COLOR_FORMAT.into())]);
    gpu.cache.render(&gpu.device, &desc)
}

impl Renderer {
    /// Builds the strand and particle corners under `camera` (shaders/expand.wgsl), once a
    /// frame before any pass draws them; nothing where the scene has none, or where the corners
    /// in `expanded` were built for this scene under the same matrices (a still camera, or
    /// another method of `oit compare` on the same view: no pass "expand" then).
    /// Its time is the frame's pass "expand": the wall time of its submission, waited for, and
    /// not timestamps, because on lavapipe a compute pass's timestamp queries make the draws
    /// after it up to twice as slow (docs/results.md, "Strands against triangle ribbons").
    pub(super) fn expand_primitives(&mut self, camera: &Camera, bg: [f32; 3]) -> Result<Option<Vec<(&'static str, f64)>>> {
        let (w, h) = (self.width, self.height);
        let Some((_, scene)) = self.scene.as_ref().filter(|(_, s)| s.primitives) else { return Ok(None) };
        // The corners depend on the uploaded scene and on the two matrices the uniform carries;
        // a scene that changes is uploaded again (GpuScene::new, which forgets the view).
        let view = expansion_view(camera, (w, h));
        if scene.expanded_view.get() == Some(view) {
            return Ok(None);
        }
        self.set_uniform(camera, scene, bg, Tile::frame(w, h));
        let consts = self.variant(scene).consts();
        // Compiled for the kinds the scene has (the cache keeps them).
        let pipeline = |kind: u32| {
            let spec = match kind {
                crate::primitive::PRIM_STRANDS => &EXPAND_STRANDS,
                crate::primitive::PRIM_GAUSSIANS => &EXPAND_GAUSSIANS,
                _ => &EXPAND_PARTICLES,
            };
            self.gpu.cache.compute(&self.gpu.device, &spec.compute_desc(&consts))
        };
        let mut enc = self.gpu.device.create_command_encoder(&Default::default());
        {
            let mut pass = enc.begin_compute_pass(&wgpu::ComputePassDescriptor { label: Some("expand"), timestamp_writes: None });
            scene.transparent.expand(&mut pass, pipeline);
            scene.opaque.expand(&mut pass, pipeline);
        }
        scene.expanded_view.set(Some(view));
        if !self.timer.enabled() {
            self.gpu.queue.submit([enc.finish()]);
            return Ok(None);
        }
        let start = Instant::now();
        self.gpu.queue.submit([enc.finish()]);
        self.gpu.wait()?;
        Ok(Some(vec![("expand", start.elapsed().as_secs_f64() * 1e3)]))
    }

    /// Writes the frame uniform for `camera` and the screen tile `tile`.
    pub(super) fn set_uniform(&self, camera: &Camera, scene: &GpuScene, bg: [f32; 3], tile: Tile) {
        let lighting = Lighting::new(&self.lights.0, self.lights.1, camera.view_direction());
        let mut lights = [GpuLight::default(); MAX_LIGHTS as usize];
        for (g, (l, radiance)) in lights.iter_mut().zip(&lighting.lights) {
            g.to_light = l.as_vec3().extend(0.0).to_array();
            g.radiance = radiance.as_vec3().extend(0.0).to_array();
        }
        let a = lighting.ambient.as_vec3();
        let uniform = FrameUniform {
            view_proj: camera.matrix_f32().to_cols_array_2d(),
            background: [bg[0], bg[1], bg[2], 0.0],
            size: [self.width, self.height],
            triangle_count: scene.transparent.triangles,
            seed: 0,
            tile_origin: [tile.x - tile.origin.0, tile.y - tile.origin.1],
            tile_size: [tile.width, tile.height],
            target_origin: [tile.origin.0, tile.origin.1],
            pad: [0; 2],
            inv_view_proj: camera.view_proj.inverse().as_mat4().to_cols_array_2d(),
            ambient: [a.x, a.y, a.z, 0.0],
            lights,
        };
        self.gpu.queue.write_buffer(&self.shared.uniform, 0, bytemuck::bytes_of(&uniform));
    }

    /// Opaque geometry into a base color and depth target over `tile` (under the current
    /// uniform), over the background or, in a frame into a caller's texture with its depth, over
    /// the caller's picture and depth.
    fn opaque_pass(&self, enc: &mut wgpu::CommandEncoder, tile: Tile, color: &wgpu::TextureView, depth: &wgpu::TextureView, bg: [f32; 3]) {
        let (_, scene) = self.scene.as_ref().expect("uploaded by the caller");
        let over = self.into.as_ref().and_then(|i| i.depth.as_ref().map(|d| (&i.color, d)));
        let (color_load, depth_load) = match over {
            Some((picture, caller_depth)) => {
                let t = self.targets.as_ref().expect("made by ensure_targets");
                enc.copy_texture_to_texture(caller_depth.as_image_copy(), t.depth_texture.as_image_copy(), caller_depth.size());
                self.blit(enc, &picture.create_view(&Default::default()), &t.base_texture, wgpu::ColorWrites::ALL, false);
                (wgpu::LoadOp::Load, wgpu::LoadOp::Load)
            }
            None => {
                (wgpu::LoadOp::Clear(wgpu::Color { r: bg[0] as f64, g: bg[1] as f64, b: bg[2] as f64, a: 0.0 }), wgpu::LoadOp::Clear(1.0))
            }
        };
        let mut pass = enc.begin_render_pass(&wgpu::RenderPassDescriptor {
            label: Some("opaque"),
            color_attachments: &[Some(wgpu::RenderPassColorAttachment {
                view: color,
                depth_slice: None,
                resolve_target: None,
                ops: wgpu::Operations { load: color_load, store: wgpu::StoreOp::Store },
            })],
            depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment {
                view: depth,
                depth_ops: Some(wgpu::Operations { load: depth_load, store: wgpu::StoreOp::Store }),
                stencil_ops: None,
            }),
            timestamp_writes: None,
            occlusion_query_set: None,
            multiview_mask: None,
        });
        tile.scissor(&mut pass);
        pass.set_pipeline(&opaque_pipeline(&self.gpu, self.variant(scene)));
        scene.opaque.draw_all(&mut pass);
    }

    /// The opaque pass of `tile` under the job's camera (for a coverage-mask frame, one per
    /// sample position into the sample targets), then with `census` the untimed fragment
    /// census, copied to its readback.
    pub(super) fn draw_opaque(&self, tile: Tile, job: &Job<'_>, census: bool) {
        let (camera, bg) = (job.camera, job.background);
        let t = self.targets.as_ref().expect("made by ensure_targets");
        let (_, scene) = self.scene.as_ref().expect("uploaded by the caller");
        let cov = self.coverage.as_ref().filter(|_| job.coverage);
        if let Some(c) = cov {
            let offsets = antialias::sample_offsets(c.targets.samples).expect("a supported sample count");
            for (s, offset) in offsets.iter().enumerate() {
                self.set_uniform(&camera.jittered(*offset, self.width, self.height), scene, bg, tile);
                let mut enc = self.gpu.device.create_command_encoder(&Default::default());
                self.opaque_pass(&mut enc, tile, &c.targets.base_layers[s], &c.targets.depth_layers[s], bg);
                self.gpu.queue.submit([enc.finish()]);
            }
        }
        self.set_uniform(camera, scene, bg, tile);
        let mut enc = self.gpu.device.create_command_encoder(&Default::default());
        if cov.is_none() {
            self.opaque_pass(&mut enc, tile, &t.base, &t.depth, bg);
        }
        if census {
            self.record_census(&mut enc, tile, job.coverage);
        }
        self.gpu.queue.submit([enc.finish()]);
    }
}

/// What the expansion reads of the camera, as the frame uniform carries it: the view-projection
/// and its inverse, float32 bits (their equality is the corners').
fn expansion_view(camera: &Camera, size: (u32, u32)) -> [u32; 34] {
    let mut bits = [0u32; 34];
    // Splats' footprints depend on the frame's size too (their low-pass is in pixels).
    (bits[32], bits[33]) = size;
    let a = camera.matrix_f32().to_cols_array();
    let b = camera.view_proj.inverse().as_mat4().to_cols_array();
    for (o, v) in bits.iter_mut().zip(a.iter().chain(&b)) {
        *o = v.to_bits();
    }
    bits
}
