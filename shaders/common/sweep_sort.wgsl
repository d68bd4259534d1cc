// The sorted resolve's local sort (common/sweep.wgsl): a run of up to RUN of a pixel's
// fragments loaded into a local array and sorted in frag_less's order.

// A run of up to RUN fragments in a local array. Where KEYED (the node's fragment costs nothing
// beyond its load) an entry is a sort key, the fragment's depth bits and node link: 8 bytes,
// not the fragment's 24. Keys are sorted by (depth, link), then equal depths, which are rare,
// are put in frag_less's order from their nodes, loaded again; the composite loads each node
// once more. Methods whose nodes cost more than their load to turn into fragments
// (FRAG_STEPS > 0) keep whole fragments (KEYED = 0); compact_abuffer's cost an interpolation
// from the triangle's record (it shades only in frag_shaded, at composite).
//!if KEYED
//!if INT64
// One 64-bit word where the device has 64-bit integers (INT64): the depth's bits above the
// link, so that one integer comparison is the keys' order (a depth is in [0, 1], where the
// bits of a float order as the float; -0 is taken as +0) and each access to the run's array
// moves one word, not two: the sort pass took about a quarter less time on foliage (lavapipe).
alias Entry = u64;

fn entry(w: Walked, link: u32) -> Entry {
    let bits = bitcast<u32>(w.frag.depth);
    return (u64(select(bits, 0u, bits == 0x80000000u)) << 32u) | u64(link);
}

fn key_less(a: Entry, b: Entry) -> bool {
    return a < b;
}

fn entry_depth(e: Entry) -> f32 {
    return bitcast<f32>(u32(e >> 32u));
}

fn entry_link(e: Entry) -> u32 {
    return u32(e);
}
//!else
alias Entry = vec2<u32>;

fn entry(w: Walked, link: u32) -> Entry {
    return vec2<u32>(bitcast<u32>(w.frag.depth), link);
}

// The keys' own order: depth, then node link.
fn key_less(a: Entry, b: Entry) -> bool {
    let da = bitcast<f32>(a.x);
    let db = bitcast<f32>(b.x);
    return da < db || (da == db && a.y < b.y);
}

fn entry_depth(e: Entry) -> f32 {
    return bitcast<f32>(e.x);
}

fn entry_link(e: Entry) -> u32 {
    return e.y;
}
//!endif

fn same_depth(a: Entry, b: Entry) -> bool {
    return entry_depth(a) == entry_depth(b);
}

// frag_less's order: the keys', loading both nodes for equal depths. Counts each comparison in
// `steps` as one with the loads (a lane without the tie loads nothing, but llvmpipe's loop
// limiter cannot tell).
fn entry_less(a: Entry, b: Entry, px: u32, steps: ptr<function, u32>) -> bool {
    *steps += 2u * LOAD_STEPS;
    let da = entry_depth(a);
    let db = entry_depth(b);
    if da != db {
        return da < db;
    }
    return frag_less(walk(entry_link(a), px).frag, walk(entry_link(b), px).frag);
}

fn entry_frag(e: Entry, px: u32) -> Frag {
    return walk(entry_link(e), px).frag;
}
//!else
alias Entry = Frag;

fn entry(w: Walked, link: u32) -> Entry {
    return w.frag;
}

fn key_less(a: Entry, b: Entry) -> bool {
    return frag_less(a, b);
}

fn entry_less(a: Entry, b: Entry, px: u32, steps: ptr<function, u32>) -> bool {
    return frag_less(a, b);
}

fn entry_link(e: Entry) -> u32 {
    return e.id;
}

fn entry_frag(e: Entry, px: u32) -> Frag {
    return e;
}

fn same_depth(a: Entry, b: Entry) -> bool {
    return a.depth == b.depth;
}
//!endif

// The run's array has two halves, which the merges alternate between (one, where a run is one
// block); RUN is a power of two, at least BLOCK.
const RUN_SLOTS: u32 = select(2u * RUN, RUN, RUN == BLOCK);
// Entries sorted by insertion before the merges (oit_core::consts::SWEEP_BLOCK).
const BLOCK: u32 = SWEEP_BLOCK;

struct Run {
    entries: array<Entry, RUN_SLOTS>,
    n: u32,
    // The node after the run (0: the list ended).
    next: u32,
}

// Sorts entries lo..hi by insertion, in the keys' order or (`whole`) frag_less's; returns the
// steps taken.
fn insertion_sort(run: ptr<function, Run>, lo: u32, hi: u32, px: u32, whole: bool) -> u32 {
    var steps = 0u;
    for (var i = lo + 1u; i < hi; i++) {
        let e = (*run).entries[i];
        var j = i;
        while j > lo && before(e, (*run).entries[j - 1u], px, &steps, whole) {
            (*run).entries[j] = (*run).entries[j - 1u];
            j--;
        }
        (*run).entries[j] = e;
        steps += i - j + 1u;
    }
    return steps;
}

fn before(a: Entry, b: Entry, px: u32, steps: ptr<function, u32>, whole: bool) -> bool {
    if whole {
        return entry_less(a, b, px, steps);
    }
    return key_less(a, b);
}

// Sorts the first n entries in frag_less's order where a run is one block, by insertion;
// otherwise in the keys' order: blocks of BLOCK by insertion, then merged bottom-up from one
// half of the array into the other (O(n log n), where insertion alone takes O(n^2) on the deep
// pixels that set a SIMD group's pace), and order_ties finishes. Returns the steps taken.
// `tie` is set when two sorted entries are at one depth (in the keys' order, where frag_less
// still has to order them): found as the last merge level writes the entries, or, when one
// block holds the run, by a walk over it.
fn sort_keys(run: ptr<function, Run>, n: u32, px: u32, tie: ptr<function, bool>) -> u32 {
    if RUN == BLOCK {
        return insertion_sort(run, 0u, n, px, true);
    }
    var steps = 0u;
    for (var lo = 0u; lo < n; lo += BLOCK) {
        steps += 1u + insertion_sort(run, lo, min(lo + BLOCK, n), px, false);
    }
    // One block: the walk (no lane of a SIMD group whose runs are all longer enters it).
    var prev = (*run).entries[0];
    for (var k = 1u; k < select(0u, n, n <= BLOCK); k++) {
        let e = (*run).entries[k];
        *tie = *tie || same_depth(e, prev);
        prev = e;
    }
    steps += 1u + select(0u, n, n <= BLOCK);
    var src = 0u;
    for (var width = BLOCK; width < n; width *= 2u) {
        let dst = RUN - src;
        // The last level (one pair) leaves its own answer.
        *tie = false;
        for (var lo = 0u; lo < n; lo += 2u * width) {
            let mid = min(lo + width, n);
            let hi = min(lo + 2u * width, n);
            var a = lo;
            var b = mid;
            for (var k = lo; k < hi; k++) {
                let take_b = b < hi && (a >= mid || key_less((*run).entries[src + b], (*run).entries[src + a]));
                let e = (*run).entries[select(src + a, src + b, take_b)];
                *tie = *tie || (k > lo && same_depth(e, prev));
                prev = e;
                (*run).entries[dst + k] = e;
                a += select(1u, 0u, take_b);
                b += select(0u, 1u, take_b);
            }
            steps += 1u + hi - lo;
        }
        src = dst;
        steps += 1u;
    }
    if src != 0u {
        for (var k = 0u; k < n; k++) {
            (*run).entries[k] = (*run).entries[src + k];
        }
        steps += n;
    }
    return steps;
}

//!if KEYED
// Puts entries of equal depth, which sort_keys left in link order, in frag_less's order, by
// insertion: on entries sorted by depth, one comparison of keys an entry outside runs of equal
// depth. Nodes are loaded only for equal depths (the entry being placed once), so that lanes
// without ties load nothing. Returns the steps taken.
fn order_ties(run: ptr<function, Run>, n: u32, px: u32) -> u32 {
    var steps = 0u;
    for (var i = 1u; i < n; i++) {
        let e = (*run).entries[i];
        var fe: Frag;
        var loaded = false;
        var j = i;
        while j > 0u {
            let p = (*run).entries[j - 1u];
            if !same_depth(p, e) {
                break;
            }
            if !loaded {
                fe = walk(entry_link(e), px).frag;
                loaded = true;
            }
            if !frag_less(fe, walk(entry_link(p), px).frag) {
                break;
            }
            (*run).entries[j] = p;
            j--;
        }
        (*run).entries[j] = e;
        steps += LOAD_STEPS + (i - j + 1u) * (1u + LOAD_STEPS);
    }
    return steps;
}
//!endif

// Loads the run starting at `link` and sorts it; `steps` grows by the work done.
fn load_run(link: u32, px: u32, run: ptr<function, Run>, steps: ptr<function, u32>) {
    var n = 0u;
    var at = link;
    while at != 0u && n < RUN {
        let w = walk(at, px);
        (*run).entries[n] = entry(w, at);
        at = w.next;
        n++;
    }
    var tie = false;
    var sorting = sort_keys(run, n, px, &tie);
//!if KEYED
    // Only runs with equal depths (rare) walk their entries again: a SIMD group without one
    // leaves the loop at once, where its body (two node loads, frag_less) would otherwise run
    // masked for every entry.
    if RUN > BLOCK {
        sorting += order_ties(run, select(0u, n, tie), px);
    }
//!endif
    (*run).n = n;
    (*run).next = at;
    *steps += LOAD_STEPS * (n + 1u) + sorting;
}

