//! Per-size frame resources shared by every method: the opaque color with coverage
//! (`base`), the opaque depth, the output image, census counts, and their readbacks.

use crate::bindings::{BOUND_FORMAT, COLOR_FORMAT, COUNT_FORMAT, DEPTH_FORMAT};
use crate::context::GpuContext;
use crate::tiles::Tile;

/// Bytes per row of a texture readback, padded to wgpu's 256-byte copy alignment.
pub fn padded_row(width: u32, bytes_per_pixel: u32) -> u32 {
    let a = wgpu::COPY_BYTES_PER_ROW_ALIGNMENT;
    (width * bytes_per_pixel).div_ceil(a) * a
}

pub struct Targets {
    pub width: u32,
    pub height: u32,
    pub base: wgpu::TextureView,
    pub depth: wgpu::TextureView,
    pub depth_texture: wgpu::Texture,
    pub out_texture: wgpu::Texture,
    pub out: wgpu::TextureView,
    pub base_texture: wgpu::Texture,
    pub bound_texture: wgpu::Texture,
    pub bound: wgpu::TextureView,
    pub bound_readback: wgpu::Buffer,
    /// Group 1 of storage-writing and resolve passes: opaque depth and base color.
    pub group: wgpu::BindGroup,
    pub counts: wgpu::Buffer,
    pub counts_group: wgpu::BindGroup,
    /// The census as an R32Float target that fragments add 1 to (`census.wgsl`'s fs_count).
    pub count_texture: wgpu::Texture,
    pub count: wgpu::TextureView,
    pub image_readback: wgpu::Buffer,
    pub counts_readback: wgpu::Buffer,
}

pub fn texture(
    device: &wgpu::Device,
    label: &str,
    w: u32,
    h: u32,
    format: wgpu::TextureFormat,
    usage: wgpu::TextureUsages,
) -> wgpu::Texture {
    device.create_texture(&wgpu::TextureDescriptor {
        label: Some(label),
        size: wgpu::Extent3d { width: w, height: h, depth_or_array_layers: 1 },
        mip_level_count: 1,
        sample_count: 1,
        dimension: wgpu::TextureDimension::D2,
        format,
        usage,
        view_formats: &[],
    })
}

fn opaque_group(
    device: &wgpu::Device,
    label: &str,
    layout: &wgpu::BindGroupLayout,
    depth: &wgpu::TextureView,
    base: &wgpu::TextureView,
) -> wgpu::BindGroup {
    device.create_bind_group(&wgpu::BindGroupDescriptor {
        label: Some(label),
        layout,
        entries: &[
            wgpu::BindGroupEntry { binding: 0, resource: wgpu::BindingResource::TextureView(depth) },
            wgpu::BindGroupEntry { binding: 1, resource: wgpu::BindingResource::TextureView(base) },
        ],
    })
}

impl Targets {
    pub fn new(gpu: &GpuContext, width: u32, height: u32, layout: &wgpu::BindGroupLayout) -> Self {
        let d = &gpu.device;
        use wgpu::TextureUsages as U;
        let base_texture = texture(d, "base", width, height, COLOR_FORMAT, U::RENDER_ATTACHMENT | U::TEXTURE_BINDING | U::COPY_SRC);
        let depth_texture =
            texture(d, "depth", width, height, DEPTH_FORMAT, U::RENDER_ATTACHMENT | U::TEXTURE_BINDING | U::COPY_SRC | U::COPY_DST);
        let out_texture =
            texture(d, "out", width, height, COLOR_FORMAT, U::RENDER_ATTACHMENT | U::TEXTURE_BINDING | U::COPY_SRC | U::COPY_DST);
        let bound_texture = texture(d, "error bound", width, height, BOUND_FORMAT, U::RENDER_ATTACHMENT | U::COPY_SRC | U::COPY_DST);
        let bound = bound_texture.create_view(&Default::default());
        let base = base_texture.create_view(&Default::default());
        let depth = depth_texture.create_view(&Default::default());
        let out = out_texture.create_view(&Default::default());
        let group = opaque_group(d, "targets", layout, &depth, &base);
        let pixels = width as u64 * height as u64;
        let counts = storage_buffer(d, "census counts", pixels * 4, wgpu::BufferUsages::COPY_SRC);
        let count_texture = texture(d, "census count", width, height, COUNT_FORMAT, U::RENDER_ATTACHMENT | U::COPY_SRC);
        let count = count_texture.create_view(&Default::default());
        let counts_group =
            crate::cache::bind_named(d, &gpu.cache, crate::cache::COUNTS, "census", &[("counts", counts.as_entire_binding())]);
        let readback = |label, size| {
            d.create_buffer(&wgpu::BufferDescriptor {
                label: Some(label),
                size,
                usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
                mapped_at_creation: false,
            })
        };
        let image_readback = readback("image readback", padded_row(width, 16) as u64 * height as u64);
        let counts_readback = readback("counts readback", padded_row(width, 4) as u64 * height as u64);
        let bound_readback = readback("bound readback", padded_row(width, 4) as u64 * height as u64);
        Self {
            width,
            height,
            base,
            depth,
            depth_texture,
            out_texture,
            out,
            base_texture,
            bound_texture,
            bound,
            bound_readback,
            group,
            counts,
            counts_group,
            count_texture,
            count,
            image_readback,
            counts_readback,
        }
    }

    /// Bytes of the frame's own targets (base, depth, out, census counts as a buffer and as a
    /// target, error bound) and their readbacks, not counted per method.
    pub fn bytes(&self) -> u64 {
        Self::bytes_for(self.width, self.height)
    }

    /// What `Targets::new` allocates at `width` x `height`.
    pub fn bytes_for(width: u32, height: u32) -> u64 {
        let readbacks = height as u64 * (padded_row(width, 16) + 2 * padded_row(width, 4)) as u64;
        width as u64 * height as u64 * (16 + 4 + 16 + 4 + 4 + 4) + readbacks
    }
}

/// A zero-initialised storage buffer (never smaller than 16 bytes).
pub fn storage_buffer(device: &wgpu::Device, label: &str, size: u64, extra: wgpu::BufferUsages) -> wgpu::Buffer {
    device.create_buffer(&wgpu::BufferDescriptor {
        label: Some(label),
        size: size.max(16).next_multiple_of(4),
        usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_DST | extra,
        mapped_at_creation: false,
    })
}

/// Maps `buffer` (MAP_READ), waits, and returns a copy of its first `size` bytes. The
/// buffer is unmapped on every path, so a failed frame leaves it usable for the next.
pub fn read_buffer(gpu: &GpuContext, buffer: &wgpu::Buffer, size: u64) -> crate::error::Result<Vec<u8>> {
    Ok(read_buffers(gpu, &[(buffer, size)])?.pop().expect("one buffer read"))
}

/// The first bytes of each readback buffer (`(buffer, bytes)`), mapped together after one wait
/// for the GPU: what a tile leaves to read is read at once.
pub fn read_buffers(gpu: &GpuContext, buffers: &[(&wgpu::Buffer, u64)]) -> crate::error::Result<Vec<Vec<u8>>> {
    use crate::error::OitError;
    let receivers: Vec<_> = buffers
        .iter()
        .map(|(buffer, size)| {
            let (tx, rx) = std::sync::mpsc::channel();
            buffer.slice(..*size).map_async(wgpu::MapMode::Read, move |r| {
                let _ = tx.send(r);
            });
            rx
        })
        .collect();
    let waited = gpu.wait();
    let mut out = Vec::with_capacity(buffers.len());
    let mut failed = None;
    for ((buffer, size), rx) in buffers.iter().zip(receivers) {
        // Another thread polling the same device may be the one running the callback: wait for it.
        match rx.recv_timeout(std::time::Duration::from_secs(30)) {
            Ok(Ok(())) => {
                let slice = buffer.slice(..*size);
                let view = slice.get_mapped_range().map(|v| v.to_vec());
                buffer.unmap();
                match view {
                    Ok(v) => out.push(v),
                    Err(e) => failed = failed.or(Some(OitError::Device(format!("reading a mapped buffer failed: {e:?}")))),
                }
            }
            Ok(Err(e)) => failed = failed.or(Some(OitError::Device(format!("mapping a readback buffer failed: {e}")))),
            Err(_) => failed = failed.or(Some(OitError::Device("a readback buffer was not mapped after the GPU finished".into()))),
        }
    }
    waited?;
    match failed {
        Some(e) => Err(e),
        None => Ok(out),
    }
}

/// The pixels of `tile` of a texture, row-major within the tile, as f32.
pub fn read_region(
    gpu: &GpuContext,
    texture: &wgpu::Texture,
    readback: &wgpu::Buffer,
    bytes_per_pixel: u32,
    tile: Tile,
) -> crate::error::Result<Vec<f32>> {
    let mut enc = gpu.device.create_command_encoder(&Default::default());
    let region = Region::copy(&mut enc, texture, readback, bytes_per_pixel, tile);
    gpu.queue.submit([enc.finish()]);
    let raw = read_buffer(gpu, readback, region.bytes())?;
    Ok(region.unpack(&raw))
}

/// A tile of a texture copied into a readback buffer in rows padded for the copy.
#[derive(Clone, Copy)]
pub struct Region {
    row: u32,
    bytes_per_pixel: u32,
    tile: Tile,
}

impl Region {
    /// Records the copy of `tile` of `texture` into `readback`.
    pub fn copy(
        enc: &mut wgpu::CommandEncoder,
        texture: &wgpu::Texture,
        readback: &wgpu::Buffer,
        bytes_per_pixel: u32,
        tile: Tile,
    ) -> Self {
        let row = padded_row(tile.width, bytes_per_pixel);
        enc.copy_texture_to_buffer(
            wgpu::TexelCopyTextureInfo {
                texture,
                mip_level: 0,
                origin: wgpu::Origin3d { x: tile.x, y: tile.y, z: 0 },
                aspect: wgpu::TextureAspect::All,
            },
            wgpu::TexelCopyBufferInfo {
                buffer: readback,
                layout: wgpu::TexelCopyBufferLayout { offset: 0, bytes_per_row: Some(row), rows_per_image: None },
            },
            wgpu::Extent3d { width: tile.width, height: tile.height, depth_or_array_layers: 1 },
        );
        Self { row, bytes_per_pixel, tile }
    }

    /// Bytes of the readback the copy fills.
    pub fn bytes(&self) -> u64 {
        self.row as u64 * self.tile.height as u64
    }

    /// The tile's pixels, row-major, as f32, from the readback's bytes.
    pub fn unpack(&self, raw: &[u8]) -> Vec<f32> {
        let (row, line) = (self.row as usize, (self.tile.width * self.bytes_per_pixel) as usize);
        let mut out = Vec::with_capacity(line / 4 * self.tile.height as usize);
        for r in 0..self.tile.height as usize {
            out.extend(bytemuck::pod_collect_to_vec::<u8, f32>(&raw[r * row..r * row + line]));
        }
        out
    }
}

/// The targets of a coverage-mask frame at `samples` samples a pixel: per sample position the
/// opaque base color and depth (one layer each, rendered with the camera moved onto it), and
/// the multisampled depth attachment transparent geometry is rasterized against (never
/// written: it only gives the pass its sample count).
pub struct SampleTargets {
    pub samples: u32,
    pub base_layers: Vec<wgpu::TextureView>,
    pub depth_layers: Vec<wgpu::TextureView>,
    pub group: wgpu::BindGroup,
    pub raster_depth: wgpu::TextureView,
    pixels: u64,
}

impl SampleTargets {
    pub fn new(gpu: &GpuContext, width: u32, height: u32, samples: u32, layout: &wgpu::BindGroupLayout) -> Self {
        let d = &gpu.device;
        use wgpu::TextureUsages as U;
        let array = |label, format| {
            d.create_texture(&wgpu::TextureDescriptor {
                label: Some(label),
                size: wgpu::Extent3d { width, height, depth_or_array_layers: samples },
                mip_level_count: 1,
                sample_count: 1,
                dimension: wgpu::TextureDimension::D2,
                format,
                usage: U::RENDER_ATTACHMENT | U::TEXTURE_BINDING,
                view_formats: &[],
            })
        };
        let base = array("sample base colors", COLOR_FORMAT);
        let depth = array("sample opaque depths", DEPTH_FORMAT);
        let layers = |t: &wgpu::Texture| -> Vec<wgpu::TextureView> {
            (0..samples)
                .map(|s| {
                    t.create_view(&wgpu::TextureViewDescriptor {
                        dimension: Some(wgpu::TextureViewDimension::D2),
                        base_array_layer: s,
                        array_layer_count: Some(1),
                        ..Default::default()
                    })
                })
                .collect()
        };
        let whole = |t: &wgpu::Texture| {
            t.create_view(&wgpu::TextureViewDescriptor { dimension: Some(wgpu::TextureViewDimension::D2Array), ..Default::default() })
        };
        let (base_all, depth_all) = (whole(&base), whole(&depth));
        let group = opaque_group(d, "sample targets", layout, &depth_all, &base_all);
        let raster = d.create_texture(&wgpu::TextureDescriptor {
            label: Some("multisampled raster depth"),
            size: wgpu::Extent3d { width, height, depth_or_array_layers: 1 },
            mip_level_count: 1,
            sample_count: samples,
            dimension: wgpu::TextureDimension::D2,
            format: DEPTH_FORMAT,
            usage: U::RENDER_ATTACHMENT,
            view_formats: &[],
        });
        Self {
            samples,
            base_layers: layers(&base),
            depth_layers: layers(&depth),
            group,
            raster_depth: raster.create_view(&Default::default()),
            pixels: width as u64 * height as u64,
        }
    }

    /// Bytes: base color and depth per sample, and the multisampled raster depth.
    pub fn bytes(&self) -> u64 {
        self.pixels * self.samples as u64 * (16 + 4 + 4)
    }

    /// What `SampleTargets::new` allocates at `width` x `height` and `samples`.
    pub fn bytes_for(width: u32, height: u32, samples: u32) -> u64 {
        width as u64 * height as u64 * samples as u64 * (16 + 4 + 4)
    }
}
