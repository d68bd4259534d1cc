//! The texture atlas: every image of the scene's materials with its mips, packed into the
//! layers of one 2D array texture.

use crate::context::GpuContext;
use crate::error::{invalid, OitError, Result};
use crate::shading::Texture;

/// Places `rects` (image, level, width, height) in shelves, tallest first, in square layers of
/// `side`: (x, y, layer, width | height << 16) each, and the layers used.
fn shelves(rects: &[(usize, usize, u32, u32)], side: u32) -> (Vec<[u32; 4]>, u32) {
    let mut order: Vec<usize> = (0..rects.len()).collect();
    order.sort_by_key(|&k| std::cmp::Reverse((rects[k].3, rects[k].2)));
    let mut at = vec![[0u32; 4]; rects.len()];
    let (mut x, mut y, mut shelf, mut layer) = (0u32, 0u32, 0u32, 0u32);
    for k in order {
        let (_, _, w, h) = rects[k];
        if x + w > side {
            (x, y, shelf) = (0, y + shelf, 0);
        }
        if y + h > side {
            (x, y, shelf, layer) = (0, 0, 0, layer + 1);
        }
        at[k] = [x, y, layer, w | h << 16];
        x += w;
        shelf = shelf.max(h);
    }
    (at, layer + 1)
}

/// The scene's images with their mip chains, packed level by level into the layers of one
/// 8-bit RGBA 2D array texture (shelves of rectangles, tallest first), read as stored (sRGB
/// color decoded in the shader): 4 bytes a texel plus a third for the mips, and what packing
/// leaves.
pub struct Atlas {
    pub view: wgpu::TextureView,
    /// Bytes of the texture (0 for the placeholder of a scene without textures).
    pub bytes: u64,
}

impl Atlas {
    /// Packs and uploads `images`; returns the atlas and, an image, its levels' places.
    pub(super) fn new(gpu: &GpuContext, images: &[&Texture]) -> Result<(Self, Vec<Vec<[u32; 4]>>)> {
        let max_side = gpu.limits.max_texture_dimension_2d;
        let rects: Vec<(usize, usize, u32, u32)> = images
            .iter()
            .enumerate()
            .flat_map(|(i, t)| t.levels().iter().enumerate().map(move |(l, level)| (i, l, level.width, level.height)))
            .collect();
        if let Some(&(i, _, w, h)) = rects.iter().find(|r| r.2 > max_side || r.3 > max_side) {
            return Err(invalid!("texture {i} is {w} x {h}, past the adapter's largest texture side ({max_side}): downscale it"));
        }
        // The square side that packs into the fewest bytes: from the largest rectangle's power
        // of two up to the adapter's largest side (a few layers of the smallest side often
        // waste less than one large layer).
        let largest = rects.iter().map(|r| r.2.max(r.3)).max().unwrap_or(1).next_power_of_two().min(max_side);
        let sides = std::iter::successors(Some(largest), |&s| (s < max_side).then(|| (2 * s).min(max_side)));
        let max_layers = gpu.limits.max_texture_array_layers;
        let packings: Vec<(u32, Vec<[u32; 4]>, u32)> = sides
            .map(|side| {
                let (at, layers) = shelves(&rects, side);
                (side, at, layers)
            })
            .collect();
        let fewest = packings.iter().map(|p| p.2).min().unwrap_or(1);
        let Some((side, at, layers)) = packings
            .into_iter()
            .filter(|p| p.2 <= max_layers)
            .min_by_key(|&(side, _, layers)| (side as u64 * side as u64 * layers as u64, layers))
        else {
            return Err(OitError::OutOfMemory(format!(
                "the scene's textures need {fewest} layers of {max_side} x {max_side} texels, past the adapter's {max_layers}: \
                 use fewer or smaller textures"
            )));
        };
        let (size, layers) = if rects.is_empty() { (1, 1) } else { (side, layers) };
        let texture = gpu.device.create_texture(&wgpu::TextureDescriptor {
            label: Some("texture atlas"),
            size: wgpu::Extent3d { width: size, height: size, depth_or_array_layers: layers },
            mip_level_count: 1,
            sample_count: 1,
            dimension: wgpu::TextureDimension::D2,
            format: wgpu::TextureFormat::Rgba8Unorm,
            usage: wgpu::TextureUsages::TEXTURE_BINDING | wgpu::TextureUsages::COPY_DST,
            view_formats: &[],
        });
        let mut places: Vec<Vec<[u32; 4]>> = images.iter().map(|t| Vec::with_capacity(t.levels().len())).collect();
        for (&(i, l, w, h), &place) in rects.iter().zip(&at) {
            let [x, y, z, _] = place;
            gpu.queue.write_texture(
                wgpu::TexelCopyTextureInfo {
                    texture: &texture,
                    mip_level: 0,
                    origin: wgpu::Origin3d { x, y, z },
                    aspect: wgpu::TextureAspect::All,
                },
                bytemuck::cast_slice(&images[i].levels()[l].texels),
                wgpu::TexelCopyBufferLayout { offset: 0, bytes_per_row: Some(4 * w), rows_per_image: Some(h) },
                wgpu::Extent3d { width: w, height: h, depth_or_array_layers: 1 },
            );
            places[i].push(place);
        }
        let view = texture
            .create_view(&wgpu::TextureViewDescriptor { dimension: Some(wgpu::TextureViewDimension::D2Array), ..Default::default() });
        let bytes = if rects.is_empty() { 0 } else { 4 * side as u64 * side as u64 * layers as u64 };
        let atlas = Self { view, bytes };
        Ok((atlas, places))
    }
}
