//! Per-pixel linked lists in a global node pool (Yang et al. 2010), shared by the methods
//! that capture every fragment (abuffer, adaptive): one capture pass, one full-screen
//! resolve. The pool follows the scene: it grows to the counted fragments and the frame is
//! rendered again when the atomic counter says the pool overflowed (docs/methods.md).

use super::{FrameCtx, Limits, MethodReport};
use crate::context::GpuContext;
use crate::error::{OitError, Result};
use crate::gpu_types::Alloc;
use crate::pipeline;
use crate::shader::{self, Const};
use crate::targets::{read_buffer, storage_buffer};

/// Storage bindings the pool is split across (shaders/common/pool.wgsl).
pub const POOL_BINDINGS: u64 = 4;
/// Fragments sorted per sweep of a resolve (shaders/abuffer.wgsl, adaptive.wgsl).
pub const BATCH: u32 = 32;

const ALLOC_BYTES: u64 = std::mem::size_of::<Alloc>() as u64;

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
    state_words: u64,
    /// Per-triangle data of the allocation pass (binding 7).
    prims: wgpu::Buffer,
    prim_bytes: u64,
    triangles: u64,
    pub layout: wgpu::BindGroupLayout,
    pub group: Option<wgpu::BindGroup>,
}

impl NodePool {
    pub fn new(gpu: &GpuContext, limits: &Limits, node_bytes: u64, state_words: u64, prim_bytes: u64) -> Self {
        let d = &gpu.device;
        let layout = d.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("node pool"),
            entries: &(0..4 + POOL_BINDINGS as u32).map(pipeline::storage_entry).collect::<Vec<_>>(),
        });
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
            prims: storage_buffer(d, "per-triangle data", 4, wgpu::BufferUsages::empty()),
            prim_bytes,
            triangles: 0,
            layout,
            group: None,
        }
    }

    pub fn consts(&self) -> [Const; 1] {
        [Const::U32("NODES_PER_BINDING", self.nodes_per_binding as u32)]
    }

    pub fn max_nodes(&self) -> u64 {
        self.nodes_per_binding * POOL_BINDINGS
    }

    pub fn bytes(&self) -> u64 {
        self.capacity * self.node_bytes + self.pixels * (4 + 4 * self.state_words) + self.triangles * self.prim_bytes + ALLOC_BYTES
    }

    /// Makes room for `nodes` nodes, `pixels` heads and `triangles` per-triangle records,
    /// reallocating only when needed.
    pub fn reserve(&mut self, gpu: &GpuContext, nodes: u64, pixels: u64, triangles: u64) -> Result<()> {
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
            self.state = storage_buffer(d, "sweep state", pixels * 4 * self.state_words, wgpu::BufferUsages::empty());
            self.pixels = pixels;
            changed = true;
        }
        let triangles = if self.prim_bytes == 0 { 0 } else { triangles };
        if triangles != self.triangles {
            if triangles * self.prim_bytes > gpu.max_binding_bytes() {
                return Err(OitError::OutOfMemory(format!(
                    "{triangles} transparent triangles need {} bytes of per-triangle data, past the adapter's \
                     {}-byte storage binding limit: split the scene",
                    triangles * self.prim_bytes,
                    gpu.max_binding_bytes()
                )));
            }
            self.prims = storage_buffer(d, "per-triangle data", triangles * self.prim_bytes, wgpu::BufferUsages::empty());
            self.triangles = triangles;
            changed = true;
        }
        // Grow to what was counted; shrink when less than a quarter is used.
        if nodes > self.capacity || nodes < self.capacity / 4 {
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
            let mut entries = vec![
                wgpu::BindGroupEntry { binding: 0, resource: self.heads.as_entire_binding() },
                wgpu::BindGroupEntry { binding: 1, resource: self.alloc.as_entire_binding() },
            ];
            entries.extend(self.pools.iter().enumerate().map(|(i, b)| wgpu::BindGroupEntry {
                binding: 2 + i as u32,
                resource: b.as_entire_binding(),
            }));
            entries.push(wgpu::BindGroupEntry { binding: 2 + POOL_BINDINGS as u32, resource: self.state.as_entire_binding() });
            entries.push(wgpu::BindGroupEntry { binding: 3 + POOL_BINDINGS as u32, resource: self.prims.as_entire_binding() });
            self.group = Some(d.create_bind_group(&wgpu::BindGroupDescriptor { label: Some("node pool"), layout: &self.layout, entries: &entries }));
        }
        Ok(())
    }

    /// Records the per-frame reset: empty lists and a zero counter with the capacity.
    pub fn clear(&self, gpu: &GpuContext, enc: &mut wgpu::CommandEncoder) {
        enc.clear_buffer(&self.heads, 0, None);
        enc.clear_buffer(&self.state, 0, None);
        let alloc = Alloc { count: 0, capacity: self.capacity.min(u32::MAX as u64) as u32, escaped: 0, pad: 0 };
        gpu.queue.write_buffer(&self.alloc, 0, bytemuck::bytes_of(&alloc));
    }

    pub fn copy_count(&self, enc: &mut wgpu::CommandEncoder) {
        enc.copy_buffer_to_buffer(&self.alloc, 0, &self.alloc_readback, 0, ALLOC_BYTES);
    }

    /// The allocator after the last capture: nodes asked for (may exceed the capacity) and
    /// fragments that escaped their allocation.
    pub fn read_alloc(&self, gpu: &GpuContext) -> Result<Alloc> {
        let raw = read_buffer(gpu, &self.alloc_readback, ALLOC_BYTES)?;
        Ok(bytemuck::pod_read_unaligned::<Alloc>(&raw))
    }
}

/// A capture-then-resolve method over a node pool.
pub(crate) struct ListMethod {
    shader: &'static str,
    consts: Vec<Const>,
    pool: NodePool,
    /// Whether the resolve runs `cs_sweep` dispatches before the full-screen pass.
    sweeps: bool,
    /// Whether a `cs_allocate` pass over the triangles runs before capture.
    allocate: bool,
    pipelines: Option<Pipelines>,
}

struct Pipelines {
    allocate: Option<wgpu::ComputePipeline>,
    capture: wgpu::RenderPipeline,
    sweep: Option<wgpu::ComputePipeline>,
    resolve: wgpu::RenderPipeline,
}

/// The storage layout of a list method.
pub(crate) struct ListLayout {
    pub shader: &'static str,
    /// Bytes of one node.
    pub node_bytes: u64,
    /// Per-pixel words carried between resolve sweeps; 0 for a single-pass resolve.
    pub state_words: u64,
    /// Bytes per triangle filled by a `cs_allocate` pass before capture; 0 for none.
    pub prim_bytes: u64,
}

/// Loop iterations llvmpipe allows one shader invocation (all loops together); past them
/// it silently ends the loops. Methods whose per-pixel work grows with the depth complexity
/// check their estimate against it on that adapter.
pub const LLVMPIPE_LOOP_LIMIT: u64 = 65_535;

/// Whether `gpu` is llvmpipe (lavapipe), which has [`LLVMPIPE_LOOP_LIMIT`].
pub fn loop_limited(gpu: &GpuContext) -> bool {
    gpu.info.name.contains("llvmpipe")
}

impl ListMethod {
    pub fn new(gpu: &GpuContext, limits: &Limits, layout: ListLayout) -> Self {
        Self {
            shader: layout.shader,
            consts: Vec::new(),
            pool: NodePool::new(gpu, limits, layout.node_bytes, layout.state_words, layout.prim_bytes),
            sweeps: layout.state_words > 0,
            allocate: layout.prim_bytes > 0,
            pipelines: None,
        }
    }

    /// Sets the shader constants (besides the pool's); pipelines are rebuilt when they change.
    pub fn set_consts(&mut self, consts: Vec<Const>) {
        if consts.iter().map(|c| format!("{c:?}")).ne(self.consts.iter().map(|c| format!("{c:?}"))) {
            self.consts = consts;
            self.pipelines = None;
        }
    }

    fn build(&mut self, cx: &FrameCtx<'_>) {
        let d = &cx.gpu.device;
        let mut consts = self.pool.consts().to_vec();
        consts.push(Const::U32("BATCH", BATCH));
        consts.extend(self.consts.iter().copied());
        let module = shader::module(d, self.shader, &consts);
        let layout = pipeline::layout(d, &[cx.scene_layout, cx.targets_layout, &self.pool.layout]);
        let capture = pipeline::geometry(d, "list capture", &module, &layout, "fs_capture", &[], pipeline::depth_test_only());
        let resolve = pipeline::fullscreen(d, "list resolve", &module, &layout, "fs_resolve");
        let compute = |entry: &str| {
            d.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
                label: Some(entry),
                layout: Some(&layout),
                module: &module,
                entry_point: Some(entry),
                compilation_options: Default::default(),
                cache: None,
            })
        };
        let sweep = self.sweeps.then(|| compute("cs_sweep"));
        let allocate = self.allocate.then(|| compute("cs_allocate"));
        self.pipelines = Some(Pipelines { allocate, capture, sweep, resolve });
    }

    pub fn render(&mut self, cx: &mut FrameCtx<'_>) -> Result<MethodReport> {
        if self.pipelines.is_none() {
            self.build(cx);
        }
        let t = cx.targets;
        let pixels = t.width as u64 * t.height as u64;
        let initial = if self.pool.capacity == 0 { pixels.min(self.pool.max_nodes()) } else { self.pool.capacity };
        // A list of n fragments takes floor(n / BATCH) + 1 sweeps (the last one finds it empty).
        let sweeps = cx.max_depth_complexity / BATCH + 1;
        let triangles = cx.scene.transparent.triangles as u64;
        self.pool.reserve(cx.gpu, initial, pixels, triangles)?;
        let mut regrown = 0.0;
        loop {
            cx.timer.reset();
            let p = self.pipelines.as_ref().expect("built above");
            let group = self.pool.group.as_ref().expect("reserved above");
            let mut enc = cx.gpu.device.create_command_encoder(&Default::default());
            self.pool.clear(cx.gpu, &mut enc);
            if let (Some(allocate), true) = (&p.allocate, triangles > 0) {
                let mut pass = enc.begin_compute_pass(&wgpu::ComputePassDescriptor {
                    label: Some("list allocate"),
                    timestamp_writes: cx.timer.compute_pass("allocate"),
                });
                pass.set_pipeline(allocate);
                pass.set_bind_group(0, &cx.scene.transparent.group, &[]);
                pass.set_bind_group(1, &t.group, &[]);
                pass.set_bind_group(2, group, &[]);
                let groups = (triangles as u32).div_ceil(64);
                pass.dispatch_workgroups(groups.min(65535), groups.div_ceil(65535), 1);
            }
            {
                let mut pass = pipeline::capture_pass(&mut enc, "list capture", &t.depth, cx.timer.render_pass("capture"));
                pass.set_pipeline(&p.capture);
                pass.set_bind_group(1, &t.group, &[]);
                pass.set_bind_group(2, group, &[]);
                cx.scene.transparent.draw_all(&mut pass);
            }
            self.pool.copy_count(&mut enc);
            if let Some(sweep) = &p.sweep {
                let mut pass = enc.begin_compute_pass(&wgpu::ComputePassDescriptor {
                    label: Some("list sweeps"),
                    timestamp_writes: cx.timer.compute_pass("sweeps"),
                });
                pass.set_pipeline(sweep);
                pass.set_bind_group(0, &cx.scene.transparent.group, &[]);
                pass.set_bind_group(1, &t.group, &[]);
                pass.set_bind_group(2, group, &[]);
                for _ in 0..sweeps {
                    pass.dispatch_workgroups(t.width.div_ceil(8), t.height.div_ceil(8), 1);
                }
            }
            {
                let mut pass = pipeline::resolve_pass(&mut enc, "list resolve", &t.out, cx.timer.render_pass("resolve"));
                pass.set_pipeline(&p.resolve);
                pass.set_bind_group(0, &cx.scene.transparent.group, &[]);
                pass.set_bind_group(1, &t.group, &[]);
                pass.set_bind_group(2, group, &[]);
                pass.draw(0..3, 0..1);
            }
            cx.gpu.queue.submit([enc.finish()]);
            let alloc = self.pool.read_alloc(cx.gpu)?;
            if alloc.escaped > 0 {
                return Err(OitError::Device(format!(
                    "{} fragments fell outside their triangle's allocation (a bound that should be conservative \
                     was not); please report this with the scene",
                    alloc.escaped
                )));
            }
            let count = alloc.count as u64;
            if count <= self.pool.capacity {
                let memory = self.pool.bytes();
                let p = self.pipelines.as_ref().expect("built above");
                // Shrink for the next frame when this one used little of the pool.
                if count < self.pool.capacity / 4 {
                    self.pool.reserve(cx.gpu, count, pixels, triangles)?;
                }
                let extra = vec![
                    ("pool_regrown", regrown),
                    ("resolve_sweeps", if p.sweep.is_some() { sweeps as f64 } else { 1.0 }),
                    ("pool_nodes", count as f64),
                ];
                return Ok(MethodReport { memory_bytes: memory, overflow_fragments: 0, extra });
            }
            self.pool.reserve(cx.gpu, count, pixels, triangles)?;
            regrown += 1.0;
        }
    }
}
