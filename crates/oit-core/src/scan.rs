//! Exclusive prefix sum of a u32 storage buffer in place (shaders/scan.wgsl): 256-element
//! blocks scanned serially, one an invocation, their totals scanned recursively, then added
//! back.

use crate::cache::{SCAN_ADD, SCAN_BLOCKS};
use crate::context::GpuContext;
use crate::targets::storage_buffer;

const BLOCK: u64 = 256;
/// Blocks one workgroup of `cs_scan_blocks` scans.
const SCAN_GROUP: u64 = 64;
const MAX_GROUPS_X: u64 = 65_535;

struct Level {
    group: wgpu::BindGroup,
    /// Workgroups of the block scan (one invocation a block) and of the add (one a word),
    /// both laid out `add.0` wide as the shader's `groups_x` says.
    scan: (u32, u32),
    add: (u32, u32),
}

pub struct Scan {
    scan: wgpu::ComputePipeline,
    add: wgpu::ComputePipeline,
    levels: Vec<Level>,
    _buffers: Vec<wgpu::Buffer>,
    pub bytes: u64,
}

fn groups_for(n: u64) -> (u32, u32) {
    let blocks = n.div_ceil(BLOCK).max(1);
    let x = blocks.min(MAX_GROUPS_X);
    (x as u32, blocks.div_ceil(x) as u32)
}

impl Scan {
    /// A scan of the first `n` words of `data`.
    pub fn new(gpu: &GpuContext, data: &wgpu::Buffer, n: u64) -> Self {
        let d = &gpu.device;
        let layout = gpu.cache.layout(d, SCAN_BLOCKS.groups[0]);
        let (scan, add) = (gpu.cache.compute(d, &SCAN_BLOCKS.compute_desc(&[])), gpu.cache.compute(d, &SCAN_ADD.compute_desc(&[])));
        let mut buffers = Vec::new();
        let mut levels = Vec::new();
        let mut bytes = 0;
        let mut len = n;
        let mut current: Option<wgpu::Buffer> = None;
        loop {
            let blocks = len.div_ceil(BLOCK).max(1);
            let sums = storage_buffer(d, "scan sums", blocks * 4, wgpu::BufferUsages::empty());
            let groups = groups_for(len);
            let scan_groups = (groups.0.div_ceil(SCAN_GROUP as u32), groups.1);
            let params = d.create_buffer(&wgpu::BufferDescriptor {
                label: Some("scan params"),
                size: 16,
                usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
                mapped_at_creation: false,
            });
            gpu.queue.write_buffer(&params, 0, bytemuck::cast_slice(&[len as u32, groups.0, 0, 0]));
            let data_buf = current.as_ref().unwrap_or(data);
            let group = d.create_bind_group(&wgpu::BindGroupDescriptor {
                label: Some("scan level"),
                layout: &layout,
                entries: &[
                    wgpu::BindGroupEntry { binding: 0, resource: data_buf.as_entire_binding() },
                    wgpu::BindGroupEntry { binding: 1, resource: sums.as_entire_binding() },
                    wgpu::BindGroupEntry { binding: 2, resource: params.as_entire_binding() },
                ],
            });
            levels.push(Level { group, scan: scan_groups, add: groups });
            bytes += blocks * 4 + 16;
            buffers.push(params);
            if let Some(c) = current.take() {
                buffers.push(c);
            }
            if blocks == 1 {
                buffers.push(sums);
                break;
            }
            current = Some(sums);
            len = blocks;
        }
        Self { scan, add, levels, _buffers: buffers, bytes }
    }

    /// Records the scan: blocks of every level up, then totals added back down.
    pub fn record(&self, pass: &mut wgpu::ComputePass<'_>) {
        pass.set_pipeline(&self.scan);
        for l in &self.levels {
            pass.set_bind_group(0, &l.group, &[]);
            pass.dispatch_workgroups(l.scan.0, l.scan.1, 1);
        }
        pass.set_pipeline(&self.add);
        for l in self.levels.iter().rev().skip(1) {
            pass.set_bind_group(0, &l.group, &[]);
            pass.dispatch_workgroups(l.add.0, l.add.1, 1);
        }
    }
}
