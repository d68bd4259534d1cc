//! GPU time per pass from timestamp queries (when the adapter offers them).

use crate::context::GpuContext;

const MAX_PASSES: u32 = 64;

pub struct PassTimer {
    queries: Option<(wgpu::QuerySet, wgpu::Buffer, wgpu::Buffer)>,
    labels: Vec<&'static str>,
    period_ns: f64,
}

impl PassTimer {
    pub fn new(gpu: &GpuContext) -> Self {
        let queries = gpu.has(wgpu::Features::TIMESTAMP_QUERY).then(|| {
            let set = gpu.device.create_query_set(&wgpu::QuerySetDescriptor {
                label: Some("pass timestamps"),
                ty: wgpu::QueryType::Timestamp,
                count: 2 * MAX_PASSES,
            });
            let size = 16 * MAX_PASSES as u64;
            let resolve = gpu.device.create_buffer(&wgpu::BufferDescriptor {
                label: Some("timestamp resolve"),
                size,
                usage: wgpu::BufferUsages::QUERY_RESOLVE | wgpu::BufferUsages::COPY_SRC,
                mapped_at_creation: false,
            });
            let readback = gpu.device.create_buffer(&wgpu::BufferDescriptor {
                label: Some("timestamp readback"),
                size,
                usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
                mapped_at_creation: false,
            });
            (set, resolve, readback)
        });
        Self { queries, labels: Vec::new(), period_ns: gpu.queue.get_timestamp_period() as f64 }
    }

    /// Whether passes are timed (the adapter offers timestamp queries).
    pub fn enabled(&self) -> bool {
        self.queries.is_some()
    }

    /// Forgets the passes recorded so far (a method that renders again starts over).
    pub fn reset(&mut self) {
        self.labels.clear();
    }

    /// Timestamp writes for the next pass, named `label`.
    pub fn render_pass(&mut self, label: &'static str) -> Option<wgpu::RenderPassTimestampWrites<'_>> {
        let i = self.slot(label)?;
        self.queries.as_ref().map(|(set, _, _)| wgpu::RenderPassTimestampWrites {
            query_set: set,
            beginning_of_pass_write_index: Some(2 * i),
            end_of_pass_write_index: Some(2 * i + 1),
        })
    }

    pub fn compute_pass(&mut self, label: &'static str) -> Option<wgpu::ComputePassTimestampWrites<'_>> {
        let i = self.slot(label)?;
        self.queries.as_ref().map(|(set, _, _)| wgpu::ComputePassTimestampWrites {
            query_set: set,
            beginning_of_pass_write_index: Some(2 * i),
            end_of_pass_write_index: Some(2 * i + 1),
        })
    }

    /// Opens a span that several passes share (e.g. the passes of a peeling loop): pass the
    /// slot to `span_compute` with `begin` on its first pass and `end` on its
    /// last; the span's time includes the gaps between its passes.
    pub fn span(&mut self, label: &'static str) -> Option<u32> {
        self.slot(label)
    }

    pub fn span_compute(&self, slot: Option<u32>, begin: bool, end: bool) -> Option<wgpu::ComputePassTimestampWrites<'_>> {
        let (set, _, _) = self.queries.as_ref()?;
        let i = slot?;
        (begin || end).then_some(wgpu::ComputePassTimestampWrites {
            query_set: set,
            beginning_of_pass_write_index: begin.then_some(2 * i),
            end_of_pass_write_index: end.then_some(2 * i + 1),
        })
    }

    /// `span_compute` for render passes.
    pub fn span_render(&self, slot: Option<u32>, begin: bool, end: bool) -> Option<wgpu::RenderPassTimestampWrites<'_>> {
        let (set, _, _) = self.queries.as_ref()?;
        let i = slot?;
        (begin || end).then_some(wgpu::RenderPassTimestampWrites {
            query_set: set,
            beginning_of_pass_write_index: begin.then_some(2 * i),
            end_of_pass_write_index: end.then_some(2 * i + 1),
        })
    }

    fn slot(&mut self, label: &'static str) -> Option<u32> {
        self.queries.as_ref()?;
        let i = self.labels.len() as u32;
        assert!(i < MAX_PASSES, "more than {MAX_PASSES} timed passes in one frame");
        self.labels.push(label);
        Some(i)
    }

    /// Reads every recorded pass's duration in milliseconds, in recording order.
    /// Records the copy of the recorded passes' timestamps into the readback: the buffer and
    /// bytes to read once submitted, or None where nothing is timed.
    pub fn record_read(&self, enc: &mut wgpu::CommandEncoder) -> Option<(wgpu::Buffer, u64)> {
        let (set, resolve, readback) = self.queries.as_ref()?;
        let n = self.labels.len() as u32;
        if n == 0 {
            return None;
        }
        enc.resolve_query_set(set, 0..2 * n, resolve, 0);
        enc.copy_buffer_to_buffer(resolve, 0, readback, 0, 16 * n as u64);
        Some((readback.clone(), 16 * n as u64))
    }

    /// Every recorded pass's duration in milliseconds, in recording order, from the bytes of a
    /// `record_read`.
    pub fn durations(&self, raw: &[u8]) -> Vec<(&'static str, f64)> {
        let ticks: Vec<u64> = bytemuck::pod_collect_to_vec(raw);
        self.labels
            .iter()
            .enumerate()
            .map(|(i, l)| (*l, ticks[2 * i + 1].saturating_sub(ticks[2 * i]) as f64 * self.period_ns * 1e-6))
            .collect()
    }
}
