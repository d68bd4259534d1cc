"""Memory formulas of the bounded methods, as docs/methods.md states them; the tests check
`frame.stats["memory_bytes"]` against these. Unbounded methods (abuffer, adaptive) size
their node pool to the frame's fragments and have no formula in W and H alone."""

from __future__ import annotations

# Words per pixel of hybrid's accumulators: core RGB (3), tail sums as 64-bit pairs (8),
# tail count, transmittance behind the core, nearest evicted key, two error-bound sums, and
# the tail colors' smallest and largest channel.
HYBRID_ACCUM_WORDS = 18


def memory_bytes(method: str, width: int, height: int, **params) -> int | None:
    """GPU bytes `method` allocates for a width x height frame, or None when unbounded (auto:
    when it rendered hybrid, pass its `slots` = stats["auto_slots"])."""
    pixels = width * height
    if method in ("hybrid", "ktab"):
        k = int(params.get("k", 8))
        return pixels * (2 * k + HYBRID_ACCUM_WORDS) * 4 + 4  # k-TAB, visibility, accumulators, counter
    if method == "auto" and "slots" in params:
        # hybrid with each pixel's own slots (2 words a slot), the accumulators, the slot
        # offsets (pixels + 1 words) and the counter; the estimate pass's 5 words a pixel
        slots = int(params["slots"])
        return 2 * slots * 4 + pixels * HYBRID_ACCUM_WORDS * 4 + (pixels + 1) * 4 + 4 + pixels * 20
    if method == "hybrid64":
        return pixels * (8 * int(params.get("k", 8)) + 9 * 4) + 4  # 64-bit k-TAB, tail sums, counter
    if method in ("wavg", "wsum", "wboit"):
        return pixels * (16 + 4)  # RGBA32F accumulation and an R32F count or revealage
    if method in ("unsorted", "sorted", "additive", "filter"):
        return 0  # blends into the shared output target
    if method in ("depth_peeling", "dual_depth_peeling"):
        return pixels * (4 * 8 + 2 * 16 + 9 * 4) + 4  # four 64-bit keys, two layers, accumulators
    if method == "bucket_peeling":
        return pixels * (8 + int(params.get("buckets", 32)) * (8 + 16)) + 4  # bounds; key and color a bucket
    if method == "stochastic":
        return pixels * (4 * int(params.get("samples", 8)) + 16 + 4)  # sample depths, two float targets
    if method == "screen_door":
        return pixels * 4  # its own depth buffer
    return None
