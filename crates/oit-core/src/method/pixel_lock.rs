//! The pixel-locked methods' shared layer (`adaptive`, adaptive.rs, and `mlab`, mlab.rs, as the
//! seeds design them): a fixed number of entries a pixel, updated by each fragment inside its
//! pixel's critical section (shaders/common/pixel_lock.wgsl), so that memory does not grow with
//! the fragments. This file keeps their storage (the entries, the lock words and the two lock
//! counts) and reports the counts. The list versions they replace are `adaptive_lists` and
//! `mlab_lists`.

use super::frame::{FrameCtx, MethodReport};
use crate::cache::Layout;
use crate::error::Result;
use crate::resources::{Readback, StorageGroup};

/// Group 2 of a pixel-locked method: its entries (by the name its shader gives them), the lock
/// words, and the two lock counts.
macro_rules! locked_layout {
    ($entries:literal) => {
        crate::cache::Layout::Storage(&[$entries, "locks", "lock_stats"])
    };
}
pub(super) use locked_layout;

/// Bytes of a pixel's lock word (with its entry count), and of the two lock counts.
pub(super) const LOCK_BYTES: u64 = 4;
pub(super) const LOCK_STATS_BYTES: u64 = 8;

/// A pixel-locked method's storage, kept from frame to frame.
#[derive(Default)]
pub(super) struct PixelLocks {
    buffers: Option<StorageGroup>,
    lock_stats: Option<Readback>,
}

impl PixelLocks {
    /// Checks that `n` entries of `entry_bytes` a pixel fit (`what` names them for the error),
    /// makes the entries, lock words and counts of the group `own` (`locked_layout!`) for this
    /// frame, and records the reset of the locks and counts: the group at binding 2 and the
    /// frame's encoder.
    pub fn begin(
        &mut self,
        cx: &FrameCtx<'_>,
        own: Layout,
        what: &str,
        (entry_bytes, n): (u64, u32),
    ) -> Result<(&wgpu::BindGroup, wgpu::CommandEncoder)> {
        cx.check_per_pixel(what, entry_bytes * n as u64)?;
        let pixels = cx.pixels();
        let Layout::Storage([entries, ..]) = own else { unreachable!("locked_layout! names the entries first") };
        let sizes = [(*entries, pixels * entry_bytes * n as u64), ("locks", pixels * LOCK_BYTES), ("lock_stats", LOCK_STATS_BYTES)];
        let b = StorageGroup::ensure(&mut self.buffers, cx.gpu, own, &sizes, &[]);
        self.lock_stats.get_or_insert_with(|| Readback::new(cx.gpu, "lock counts", LOCK_STATS_BYTES));
        let mut enc = cx.encoder();
        enc.clear_buffer(&b.buffers[1], 0, None);
        enc.clear_buffer(&b.buffers[2], 0, None);
        Ok((&b.group, enc))
    }

    /// Copies the lock counts after the passes `enc` recorded, submits, and reports the frame
    /// with `memory` bytes: a fragment that gave up on its pixel's lock is one the structure did
    /// not take.
    pub fn finish(&mut self, cx: &FrameCtx<'_>, mut enc: wgpu::CommandEncoder, memory: u64) -> Result<MethodReport> {
        let (b, readback) = (self.buffers.as_ref().expect("begun"), self.lock_stats.as_ref().expect("begun"));
        readback.copy(&mut enc, &b.buffers[2]);
        cx.submit(enc);
        let raw = readback.read(cx.gpu)?;
        let count = |i: usize| u32::from_le_bytes(raw[4 * i..4 * i + 4].try_into().expect("4 bytes")) as u64;
        let (failures, waits) = (count(0), count(1));
        Ok(MethodReport {
            memory_bytes: memory,
            overflow_fragments: failures,
            extra: vec![("lock_failures", failures as f64), ("lock_waits", waits as f64)],
            ..Default::default()
        })
    }
}
