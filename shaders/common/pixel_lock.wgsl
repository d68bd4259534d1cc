// Per-pixel critical sections from a storage-buffer atomic word a pixel (adaptive, mlab;
// docs/methods.md, "Critical sections"). The including shader defines `struct Incoming` (what
// a fragment brings) and `fn critical(px: u32, count: u32, f: Incoming) -> u32`, which runs
// while the fragment holds pixel px, reads and writes the pixel's entries with atomics, and
// returns their new count.

// locks[px]: bit 0 is set while a fragment holds pixel px; bits 1.. count its entries.
@group(2) @binding(1) var<storage, read_write> locks: array<atomic<u32>>;
// lock_stats[0]: fragments that gave up after LOCK_TRIES attempts (never entered);
// lock_stats[1]: fragments that found their pixel held at least once.
@group(2) @binding(2) var<storage, read_write> lock_stats: array<atomic<u32>, 2>;

// The entries pixel px holds (after the pass that writes them).
fn entries(px: u32) -> u32 {
    return atomicLoad(&locks[px]) >> 1u;
}

// Runs `critical` for fragment f holding pixel px. A fragment takes the lock by setting bit 0
// with one atomicOr: the one that finds it clear holds the pixel (and reads its count from the
// same word); one that finds it set changed nothing. The lane that takes the lock runs its
// critical section and releases the lock within the same iteration, so lanes of one SIMD group
// waiting on the same pixel cannot starve the holder; after LOCK_TRIES attempts a fragment
// gives up and is counted.
fn with_pixel_lock(px: u32, f: Incoming) {
    var done = false;
    var waited = false;
    for (var tries = 0u; tries < LOCK_TRIES; tries++) {
        let word = atomicOr(&locks[px], 1u);
        if (word & 1u) == 0u {
            let count = critical(px, word >> 1u, f);
            atomicStore(&locks[px], count << 1u);
            done = true;
        }
        if done {
            break;
        }
        waited = true;
    }
    if !done {
        atomicAdd(&lock_stats[0], 1u);
    }
    if waited {
        atomicAdd(&lock_stats[1], 1u);
    }
}
