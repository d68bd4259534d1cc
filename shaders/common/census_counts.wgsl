// The census's counts buffer, a fragment count a pixel (oit_core::cache::CENSUS_ATOMIC and
// CENSUS_SAMPLES: group 2 of one binding).
@group(2) @binding(0) var<storage, read_write> counts: array<atomic<u32>>;
