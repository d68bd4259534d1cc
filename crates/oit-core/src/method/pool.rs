//! The node pool of the list methods (lists.rs): per-pixel heads, the allocator, the nodes split
//! across POOL_BINDINGS storage bindings, the sorted resolve's per-pixel state and pixel lists,
//! what binding 7 holds, and the per-pixel counts of a capture that counts its fragments
//! (shaders/common/pool.wgsl mirrors its bindings).

use super::frame::Limits;
use crate::cache::{Layout, PipelineSpec};
use crate::context::GpuContext;
use crate::error::{OitError, Result};
use crate::gpu_types::Alloc;
use crate::shader::Const;
use crate::targets::{read_buffer, storage_buffer};

/// Storage bindings the pool is split across (shaders/common/pool.wgsl).
pub const POOL_BINDINGS: u64 = 4;
/// The pool's group: heads, allocator, the `POOL_BINDINGS` pool bindings, sweep state, binding
/// 7 by the name the method's shader gives it ("_" where no shader of the method reads it),
/// and the per-pixel counts a capture that counts its own fragments keeps (binding 8).
macro_rules! pool_layout {
    ($aux:literal) => {
        crate::cache::Layout::Storage(&["heads", "alloc", "pool0", "pool1", "pool2", "pool3", "state", $aux, "pixel_counts"])
    };
}
pub(crate) use pool_layout;

/// The pool's group of a method that keeps nothing at binding 7.
pub(crate) const POOL_LAYOUT: Layout = pool_layout!("_");
const _: () = assert!(matches!(POOL_LAYOUT, Layout::Storage(n) if n.len() as u64 == 5 + POOL_BINDINGS));

pub(super) const ALLOC_BYTES: u64 = std::mem::size_of::<Alloc>() as u64;
/// The indirect dispatch arguments (x, y, z workgroups) of the sorted resolve's first pass,
/// then of its deep phases.
pub(super) const LIST_ARGS_BYTES: u64 = 24;

/// What a list method's pool keeps at binding 7 (shaders/common/pool.wgsl), and so which
/// pass runs before its capture.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) enum PoolAux {
    None,
    /// Bytes per transparent triangle, filled by a `cs_allocate` pass before capture.
    PerTriangle(u64),
    /// W * H + 1 words: per-pixel counts scanned into range starts (sbuffer).
    PixelOffsets,
}

/// The storage layout of a list method.
pub(crate) struct ListLayout {
    /// The pipelines of its shader (list_pipelines.rs).
    pub pipelines: &'static [PipelineSpec],
    /// Bytes of one node.
    pub node_bytes: u64,
    /// Per-pixel words carried between resolve sweeps; 0 for a single-pass resolve.
    pub state_words: u64,
    /// Samples a pixel of the sorted resolve (common/sweep.wgsl); unused without sweeps.
    pub samples: u32,
    /// Whether turning a node into a fragment shades it (compact_abuffer): its loop
    /// iterations then count in the resolve's step budget.
    pub shades_at_resolve: bool,
    /// What binding 7 holds, and so which passes run before capture.
    pub aux: PoolAux,
    /// Whether the capture can count each pixel's fragments itself (its nodes are its
    /// fragments), so that a frame after the first needs no census (`ListMethod::counts_in_capture`).
    pub counts_in_capture: bool,
}

/// A linked-list node pool with its heads and allocator, shared by list-based methods.
pub(crate) struct NodePool {
    node_bytes: u64,
    pub nodes_per_binding: u64,
    pub capacity: u64,
    pixels: u64,
    pub heads: wgpu::Buffer,
    pub alloc: wgpu::Buffer,
    alloc_readback: wgpu::Buffer,
    pub pools: Vec<wgpu::Buffer>,
    /// Per-pixel state carried between resolve sweeps (binding 6).
    state: wgpu::Buffer,
    pub state_words: u64,
    /// The sorted resolve's indirect dispatch arguments, copied from the allocator.
    pub(super) list_args: wgpu::Buffer,
    /// Binding 7: per-triangle data of the allocation pass, or per-pixel offsets.
    pub aux: wgpu::Buffer,
    aux_kind: PoolAux,
    aux_len: u64,
    /// Binding 8: each pixel's fragments, where the capture counts them itself (`counting`),
    /// with its readback; a placeholder otherwise.
    counts: wgpu::Buffer,
    counts_readback: Option<wgpu::Buffer>,
    pub(super) counting: bool,
    /// The group's layout, by the names of the method's shader (its table's group 2).
    pub layout: Layout,
    pub group: Option<wgpu::BindGroup>,
}

impl NodePool {
    pub fn new(gpu: &GpuContext, limits: &Limits, layout: &ListLayout) -> Self {
        let (node_bytes, state_words, aux_kind, counting) = (layout.node_bytes, layout.state_words, layout.aux, layout.counts_in_capture);
        // The method's own names for the group (its table's group 2).
        let layout = layout.pipelines[0].groups[2];
        let d = &gpu.device;
        let alloc = storage_buffer(d, "alloc", ALLOC_BYTES, wgpu::BufferUsages::COPY_SRC);
        let alloc_readback = d.create_buffer(&wgpu::BufferDescriptor {
            label: Some("alloc readback"),
            size: ALLOC_BYTES,
            usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        Self {
            node_bytes,
            nodes_per_binding: (limits.max_binding_bytes / node_bytes).max(1).min(u32::MAX as u64 / POOL_BINDINGS),
            capacity: 0,
            pixels: 0,
            heads: storage_buffer(d, "heads", 4, wgpu::BufferUsages::empty()),
            alloc,
            alloc_readback,
            pools: Vec::new(),
            state: storage_buffer(d, "sweep state", 4, wgpu::BufferUsages::empty()),
            state_words,
            list_args: d.create_buffer(&wgpu::BufferDescriptor {
                label: Some("pixel list dispatch args"),
                size: LIST_ARGS_BYTES,
                usage: wgpu::BufferUsages::INDIRECT | wgpu::BufferUsages::COPY_DST,
                mapped_at_creation: false,
            }),
            aux: storage_buffer(d, "list aux", 4, wgpu::BufferUsages::empty()),
            aux_kind,
            aux_len: 0,
            counts: storage_buffer(d, "capture counts", 4, wgpu::BufferUsages::empty()),
            counts_readback: None,
            counting,
            layout,
            group: None,
        }
    }

    /// The pool's shape for its shaders: nodes a binding, and bindings in use (1 lets them
    /// skip the switch over bindings).
    pub fn consts(&self) -> [Const; 2] {
        let split = if self.capacity <= self.nodes_per_binding { 1 } else { POOL_BINDINGS as u32 };
        [Const::U32("NODES_PER_BINDING", self.nodes_per_binding as u32), Const::U32("POOL_SPLIT", split)]
    }

    pub fn max_nodes(&self) -> u64 {
        self.nodes_per_binding * POOL_BINDINGS
    }

    /// Words of the state buffer a pixel: its sweep state and, with one, its entries of the
    /// pixel lists (shaders/common/sweep.wgsl).
    pub fn state_len(&self) -> u64 {
        self.state_words + 2 * (self.state_words > 0) as u64
    }

    /// Bytes a pixel keeps: its head, sweep state and list entries, and its count where the
    /// capture counts.
    pub fn pixel_bytes(&self) -> u64 {
        4 * (1 + self.state_len() + self.counting as u64)
    }

    pub fn bytes(&self) -> u64 {
        self.capacity * self.node_bytes + self.pixels * self.pixel_bytes() + self.aux_len + ALLOC_BYTES + LIST_ARGS_BYTES
    }

    /// Makes room for `nodes` nodes, `pixels` heads and `triangles` per-triangle records,
    /// reallocating only when needed.
    /// With `exact`, the pool is made exactly `nodes` large (a tile of a budgeted frame);
    /// otherwise it keeps a larger capacity unless less than a quarter would be used.
    pub fn reserve(&mut self, gpu: &GpuContext, nodes: u64, pixels: u64, triangles: u64, exact: bool) -> Result<()> {
        if nodes > self.max_nodes() {
            return Err(OitError::OutOfMemory(format!(
                "the frame has {nodes} transparent fragments but the node pool holds at most {} on this adapter \
                 ({POOL_BINDINGS} bindings of {} bytes): render at a smaller size or with a bounded method (e.g. hybrid)",
                self.max_nodes(),
                self.nodes_per_binding * self.node_bytes
            )));
        }
        let d = &gpu.device;
        let mut changed = self.group.is_none();
        if pixels != self.pixels {
            self.heads = storage_buffer(d, "heads", pixels * 4, wgpu::BufferUsages::empty());
            self.state = storage_buffer(d, "sweep state", pixels * 4 * self.state_len(), wgpu::BufferUsages::empty());
            if self.counting {
                self.counts = storage_buffer(d, "capture counts", pixels * 4, wgpu::BufferUsages::COPY_SRC);
                self.counts_readback = Some(d.create_buffer(&wgpu::BufferDescriptor {
                    label: Some("capture counts readback"),
                    size: ALLOC_BYTES + pixels * 4,
                    usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
                    mapped_at_creation: false,
                }));
            }
            self.pixels = pixels;
            changed = true;
        }
        let aux_len = match self.aux_kind {
            PoolAux::None => 0,
            // At least one record: a binding must hold one element even without triangles.
            PoolAux::PerTriangle(bytes) => triangles.max(1) * bytes,
            PoolAux::PixelOffsets => (pixels + 1) * 4,
        };
        if aux_len != self.aux_len {
            if aux_len > gpu.max_binding_bytes() {
                return Err(OitError::OutOfMemory(format!(
                    "this frame needs a {aux_len}-byte buffer of per-triangle or per-pixel data, past the adapter's \
                     {}-byte storage binding limit: split the scene or render a smaller frame",
                    gpu.max_binding_bytes()
                )));
            }
            self.aux = storage_buffer(d, "list aux", aux_len, wgpu::BufferUsages::COPY_SRC);
            self.aux_len = aux_len;
            changed = true;
        }
        // Grow to what was counted; shrink when less than a quarter is used.
        if nodes > self.capacity || nodes < self.capacity / 4 || (exact && nodes.max(1) != self.capacity) {
            self.capacity = nodes.max(1);
            self.pools = (0..POOL_BINDINGS)
                .map(|b| {
                    let n = self.capacity.saturating_sub(b * self.nodes_per_binding).min(self.nodes_per_binding).max(1);
                    storage_buffer(d, "node pool", n * self.node_bytes, wgpu::BufferUsages::empty())
                })
                .collect();
            changed = true;
        }
        if changed {
            let Some(names) = self.layout.named() else { unreachable!("a storage layout") };
            // Heads, allocator, pools, state, binding 7, counts: in the layout's order.
            let buffers = [&self.heads, &self.alloc].into_iter().chain(&self.pools).chain([&self.state, &self.aux, &self.counts]);
            let entries: Vec<(&str, wgpu::BindingResource<'_>)> =
                names.iter().zip(buffers).map(|((name, _), b)| (*name, b.as_entire_binding())).collect();
            self.group = Some(crate::cache::bind_named(&gpu.device, &gpu.cache, self.layout, "node pool", &entries));
        }
        Ok(())
    }

    /// Records the per-frame reset: empty lists and a zero counter with the capacity.
    pub fn clear(&self, gpu: &GpuContext, enc: &mut wgpu::CommandEncoder) {
        enc.clear_buffer(&self.heads, 0, None);
        enc.clear_buffer(&self.state, 0, None);
        let alloc = Alloc { capacity: self.capacity.min(u32::MAX as u64) as u32, ..Default::default() };
        gpu.queue.write_buffer(&self.alloc, 0, bytemuck::bytes_of(&alloc));
    }

    pub fn copy_count(&self, enc: &mut wgpu::CommandEncoder) {
        enc.copy_buffer_to_buffer(&self.alloc, 0, &self.alloc_readback, 0, ALLOC_BYTES);
    }

    /// Records the zeroing of the capture's per-pixel counts.
    pub(super) fn clear_counts(&self, enc: &mut wgpu::CommandEncoder) {
        enc.clear_buffer(&self.counts, 0, None);
    }

    /// Records the copy of the allocator and the capture's per-pixel counts to one readback,
    /// so that the host waits once for both.
    pub(super) fn copy_counts(&self, enc: &mut wgpu::CommandEncoder) {
        let r = self.counts_readback.as_ref().expect("a counting pool has its readback once reserved");
        enc.copy_buffer_to_buffer(&self.alloc, 0, r, 0, ALLOC_BYTES);
        enc.copy_buffer_to_buffer(&self.counts, 0, r, ALLOC_BYTES, self.pixels * 4);
    }

    /// The allocator after the capture and the capture's per-pixel counts, row-major in the
    /// tile (after `copy_counts` ran).
    pub(super) fn read_counts(&self, gpu: &GpuContext) -> Result<(Alloc, Vec<u32>)> {
        let r = self.counts_readback.as_ref().expect("a counting pool has its readback once reserved");
        let raw = read_buffer(gpu, r, ALLOC_BYTES + self.pixels * 4)?;
        let (alloc, counts) = raw.split_at(ALLOC_BYTES as usize);
        Ok((bytemuck::pod_read_unaligned::<Alloc>(alloc), bytemuck::pod_collect_to_vec(counts)))
    }

    /// The allocator after the last capture: nodes asked for (may exceed the capacity) and
    /// fragments that escaped their allocation.
    pub fn read_alloc(&self, gpu: &GpuContext) -> Result<Alloc> {
        let raw = read_buffer(gpu, &self.alloc_readback, ALLOC_BYTES)?;
        Ok(bytemuck::pod_read_unaligned::<Alloc>(&raw))
    }
}
