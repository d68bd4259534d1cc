//! Storage the methods own: buffers bound together as one group that are reallocated only when
//! their sizes change (`StorageGroup`), atomic counters with their readback (`Counter`), and
//! readbacks (`Readback`). Pipelines and layouts come from the device's `cache::PipelineCache`.

use crate::cache::{bind_named, Layout};
use crate::context::GpuContext;
use crate::error::Result;
use crate::targets::{read_buffer, storage_buffer};

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

    /// Records the copy that the executor reads with the tile's pixels, after the passes that
    /// count: the tile's overflow, and the extra stat `extra` where given.
    pub fn tally(&self, enc: &mut wgpu::CommandEncoder, extra: Option<&'static str>) -> crate::method::Tally {
        self.copy(enc);
        crate::method::Tally { readback: self.readback.buffer.clone(), extra }
    }

    /// The count copied by the last submitted `copy` (waits for it).
    pub fn read(&self, gpu: &GpuContext) -> Result<u64> {
        let raw = self.readback.read(gpu)?;
        Ok(u32::from_le_bytes(raw[..4].try_into().expect("4 bytes")) as u64)
    }
}

/// Storage buffers bound together as one group of a `Layout::Storage` (the one the method's
/// pipeline table declares at group 2), each by its binding's name, reallocated only when
/// their sizes change.
pub struct StorageGroup {
    sizes: Vec<u64>,
    /// The buffers in the order `ensure` was given them.
    pub buffers: Vec<wgpu::Buffer>,
    pub group: wgpu::BindGroup,
}

impl StorageGroup {
    /// The group of `layout` in `slot`, made anew when `buffers` ((binding name, bytes) each)
    /// differ in size from what it holds; `counters` fill the bindings of their names.
    pub fn ensure<'s>(
        slot: &'s mut Option<StorageGroup>,
        gpu: &GpuContext,
        layout: Layout,
        buffers: &[(&'static str, u64)],
        counters: &[(&'static str, &Counter)],
    ) -> &'s StorageGroup {
        let sizes: Vec<u64> = buffers.iter().map(|(_, b)| *b).collect();
        if slot.as_ref().is_none_or(|g| g.sizes != sizes) {
            *slot = None; // free the old buffers first
            let d = &gpu.device;
            let made: Vec<wgpu::Buffer> =
                buffers.iter().map(|(name, bytes)| storage_buffer(d, name, *bytes, wgpu::BufferUsages::COPY_SRC)).collect();
            let named: Vec<(&str, wgpu::BindingResource<'_>)> = buffers
                .iter()
                .zip(&made)
                .map(|((name, _), b)| (*name, b.as_entire_binding()))
                .chain(counters.iter().map(|(name, c)| (*name, c.buffer.as_entire_binding())))
                .collect();
            let label = buffers.first().map_or("storage", |b| b.0);
            let group = bind_named(&gpu.device, &gpu.cache, layout, label, &named);
            *slot = Some(StorageGroup { sizes, buffers: made, group });
        }
        slot.as_ref().expect("made above")
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
