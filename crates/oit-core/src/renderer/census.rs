//! The fragment census: each pixel's transparent fragments, counted in a geometry pass after
//! the opaque one, by blending or with atomics, in bands of rows that the frame's targets hold.

use super::execute::Job;
use super::{Renderer, COVERAGE_SAMPLES};
use crate::bindings::COUNT_FORMAT;
use crate::cache::{Draw, CENSUS_ATOMIC, CENSUS_BLEND, CENSUS_SAMPLES};
use crate::context::GpuContext;
use crate::error::Result;
use crate::passes;
use crate::pipeline;
use crate::shader::SceneVariant;
use crate::targets::{read_buffer, read_region};
use crate::tiles::Tile;
use crate::upload::GpuScene;

/// How the census counts: by blending into the count target where the adapter blends float32
/// (one pass, no atomics), else with an atomic a fragment into the counts buffer; a
/// coverage-mask frame counts with atomics at each sample's coverage.
#[derive(Clone, Copy, PartialEq)]
enum CensusKind {
    Blend,
    Atomic,
    Samples,
}

/// The census pipeline of `kind`. The census reads only positions: its variant is the unlit
/// one, or for a scene with a material table (`shaded`) the shaded one without lights, whose
/// vertex shader drops the back faces a material culls (common/scene.wgsl); instanced where the
/// scene is.
fn census_pipeline(gpu: &GpuContext, kind: CensusKind, scene: &GpuScene) -> wgpu::RenderPipeline {
    let variant = SceneVariant {
        shaded: scene.shaded,
        instanced: scene.instanced,
        primitives: scene.primitives,
        sets_only: scene.sets_only,
        ..Default::default()
    }
    .consts();
    let add = wgpu::BlendComponent {
        src_factor: wgpu::BlendFactor::One,
        dst_factor: wgpu::BlendFactor::One,
        operation: wgpu::BlendOperation::Add,
    };
    let desc = match kind {
        CensusKind::Blend => CENSUS_BLEND.render(
            &variant,
            Draw::Geometry { depth: pipeline::depth_test_only(), samples: 1 },
            vec![Some(wgpu::ColorTargetState {
                format: COUNT_FORMAT,
                blend: Some(wgpu::BlendState { color: add, alpha: add }),
                write_mask: wgpu::ColorWrites::RED,
            })],
        ),
        CensusKind::Atomic => CENSUS_ATOMIC.render(&variant, Draw::Geometry { depth: pipeline::depth_test_only(), samples: 1 }, vec![]),
        CensusKind::Samples => {
            CENSUS_SAMPLES.render(&variant, Draw::Geometry { depth: pipeline::raster_only(), samples: COVERAGE_SAMPLES }, vec![])
        }
    };
    gpu.cache.render(&gpu.device, &desc)
}

impl Renderer {
    /// Every pixel's transparent fragments (row-major), counted in bands of rows the targets
    /// hold, and the tile whose opaque pass the targets hold after it.
    pub(super) fn count_fragments(&mut self, job: &Job<'_>) -> Result<(Vec<u32>, Option<Tile>)> {
        let (w, h) = (self.width, self.height);
        let rows = self.census_rows(job.coverage)?;
        let mut counts = vec![0u32; w as usize * h as usize];
        let mut drawn = None;
        for y in (0..h).step_by(rows as usize) {
            let mut band = Tile { x: 0, y, width: w, height: rows.min(h - y), frame: (w, h), origin: (0, 0) };
            if rows < h {
                band = band.own_targets();
            }
            self.ensure_targets(w, rows, job.coverage)?;
            self.draw_opaque(band, job, true);
            let values = self.read_census(band, job.coverage)?;
            counts[(y * w) as usize..(y * w) as usize + values.len()].copy_from_slice(&values);
            drawn = Some(band);
        }
        Ok((counts, drawn))
    }

    /// Records the census of `tile` after its opaque pass, copied to its readback.
    pub(super) fn record_census(&self, enc: &mut wgpu::CommandEncoder, tile: Tile, coverage: bool) {
        let t = self.targets.as_ref().expect("made by ensure_targets");
        let (_, scene) = self.scene.as_ref().expect("uploaded by the caller");
        match self.census_kind(coverage) {
            CensusKind::Blend => {
                let count = wgpu::RenderPassColorAttachment {
                    view: &t.count,
                    depth_slice: None,
                    resolve_target: None,
                    ops: wgpu::Operations { load: wgpu::LoadOp::Clear(wgpu::Color::TRANSPARENT), store: wgpu::StoreOp::Store },
                };
                let mut pass = passes::capture_into(enc, "census", &t.depth, &[Some(count)], None);
                tile.scissor(&mut pass);
                pass.set_pipeline(&census_pipeline(&self.gpu, CensusKind::Blend, scene));
                scene.transparent.draw_all(&mut pass);
            }
            kind => {
                enc.clear_buffer(&t.counts, 0, None);
                let (group, depth) = match self.coverage.as_ref().filter(|_| coverage) {
                    Some(c) => (&c.targets.group, &c.targets.raster_depth),
                    None => (&t.group, &t.depth),
                };
                {
                    let mut pass = passes::capture_pass(enc, "census", depth, None);
                    tile.scissor(&mut pass);
                    pass.set_pipeline(&census_pipeline(&self.gpu, kind, scene));
                    pass.set_bind_group(1, group, &[]);
                    pass.set_bind_group(2, &t.counts_group, &[]);
                    scene.transparent.draw_all(&mut pass);
                }
                let bytes = (tile.pixels() * 4).min(t.counts.size()).min(t.counts_readback.size());
                enc.copy_buffer_to_buffer(&t.counts, 0, &t.counts_readback, 0, bytes);
            }
        }
    }

    /// How this frame's census counts (`CensusKind`).
    fn census_kind(&self, coverage: bool) -> CensusKind {
        match coverage {
            true => CensusKind::Samples,
            false if !self.atomic_census && self.gpu.device.features().contains(wgpu::Features::FLOAT32_BLENDABLE) => CensusKind::Blend,
            false => CensusKind::Atomic,
        }
    }

    /// The census's per-pixel counts of `tile`, row-major.
    fn read_census(&self, tile: Tile, coverage: bool) -> Result<Vec<u32>> {
        let t = self.targets.as_ref().expect("made by ensure_targets");
        Ok(match self.census_kind(coverage) {
            // Whole numbers below 2^24, exact in float32.
            CensusKind::Blend => {
                read_region(&self.gpu, &t.count_texture, &t.counts_readback, 4, tile.local())?.iter().map(|&c| c as u32).collect()
            }
            _ => bytemuck::pod_collect_to_vec(&read_buffer(&self.gpu, &t.counts_readback, tile.pixels() * 4)?),
        })
    }
}
