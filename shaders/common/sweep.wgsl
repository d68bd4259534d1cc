// The exact resolve shared by the fragment-storing methods (abuffer, sbuffer, pall,
// compact_abuffer): each pixel's list is sorted once, in place, in O(n log n), then
// composited front to back; a full-screen pass adds the opaque scene or background.
//   - A pixel of at most RUN fragments (most pixels) loads them into a local array, sorts it
//     (insertion within blocks of BLOCK, then local merges) and composites it: one walk of
//     its list.
//   - A deeper pixel sorts its list in runs of RUN (each run sorted locally and relinked),
//     then merges the runs bottom-up by relinking the nodes' `next` fields (no scratch
//     memory), then walks the sorted list to composite it.
//   - Each phase runs over a list of the pixels with work in it (cs_active, cs_sort), by
//     indirect dispatch.
// The work is a per-pixel state machine that stops after STEP_BUDGET steps and resumes in the
// next dispatch, so any depth completes; the host dispatches enough sweeps for the deepest
// pixel (oit_core::method::lists::resolve_steps mirrors the counts below). A step is one
// iteration of llvmpipe's loop limiter, which ends an invocation's loops after 65,535 in all
// and counts every `switch` as one (SPIR-V to NIR makes a switch a loop): each pool access
// is one (common/nodes.wgsl). Where the work pauses does not change the result: the sorted
// order is unique and the composite runs in that order.
// The including shader defines
//   fn list_head(px: u32) -> u32             the link (node index + 1) of the first node, 0: none
//   fn walk(link: u32, px: u32) -> Walked    a node's fragment and link, from one load
//   fn frag_mask(f: Frag) -> u32             the pixel's samples it covers (bit s: sample s)
//   fn frag_shaded(f: Frag, px: u32) -> Frag the fragment as composited (compact_abuffer shades
//                                            it here, once; the others as stored:
//                                            common/stored_color.wgsl)
//   fn tie_key(f: Frag) -> u32               what orders fragments of equal depth and color
//                                            before their links (0: nothing)
// and declares the `state` storage binding; common/nodes.wgsl gives load_next/store_next.
// docs/methods.md ("abuffer").

// Per-pixel state (STATE_WORDS words), then per sample of the pixel (PIXEL_SAMPLES, from the
// targets include: 1, or the coverage-mask sample count) its accumulated color and
// transmittance.
const STATE_WORDS: u32 = 12u + 4u * PIXEL_SAMPLES;
const S_PHASE: u32 = 0u; // phase | sub-phase << 4 | MULTI (this pass wrote more than one run)
const S_WIDTH: u32 = 1u; // run length of the merge pass
const S_SRC: u32 = 2u;   // next node this pass has not reached; the composite's cursor
const S_TAIL: u32 = 3u;  // last node of this pass's output (0: none yet)
const S_A: u32 = 4u;     // the pair being merged: its first run's next node and count left,
const S_NA: u32 = 5u;
const S_B: u32 = 6u;     // the second run's,
const S_NB: u32 = 7u;
const S_REST: u32 = 8u;  // and the node after the pair
const SAMPLE_STATE: u32 = 12u;

const FRESH: u32 = 0u; // the cleared state: no pass has reached the pixel (fs_resolve: the base)
const RUNS: u32 = 1u;
const MERGE: u32 = 2u;
const COMPOSITE: u32 = 3u;
const DONE: u32 = 4u;
const SPLIT_A: u32 = 0u;
const SPLIT_B: u32 = 1u;
const MERGING: u32 = 2u;
const MULTI: u32 = 0x100u;
// Steps per node loaded into a run, per node relinked, per merge step and per fragment
// composited from the list: the SWEEP_* constants (oit_core::consts, where they are explained;
// oit_core::method::lists::StepCosts plans the dispatches from the same ones), plus FRAG_STEPS
// (injected), what turning a node into a fragment adds, and SHADE_STEPS (injected), what
// frag_shaded adds to a composited fragment (compact_abuffer shades it there).
const LOAD_STEPS: u32 = SWEEP_LOAD_STEPS + FRAG_STEPS;
const LINK_STEPS: u32 = SWEEP_LINK_STEPS;
const MERGE_STEPS: u32 = SWEEP_MERGE_STEPS + 2u * FRAG_STEPS;
const COMPOSITE_STEPS: u32 = SWEEP_COMPOSITE_STEPS + PIXEL_SAMPLES + FRAG_STEPS + SHADE_STEPS;

// `id`: the node's link, or where runs are KEYED anything unique in the pixel the includer
// reads back (compact_abuffer: the triangle).
struct Frag {
    depth: f32,
    color: vec4<f32>,
    id: u32,
}

struct Walked {
    frag: Frag,
    next: u32,
}

// Strict total order: depth, then color, then the includer's tie key, then node link.
// Fragments equal in all but their links are interchangeable (the same composited color), so
// the composite does not depend on submission order.
fn frag_less(a: Frag, b: Frag) -> bool {
    if a.depth != b.depth { return a.depth < b.depth; }
    if a.color.r != b.color.r { return a.color.r < b.color.r; }
    if a.color.g != b.color.g { return a.color.g < b.color.g; }
    if a.color.b != b.color.b { return a.color.b < b.color.b; }
    if a.color.a != b.color.a { return a.color.a < b.color.a; }
    let ka = tie_key(a);
    let kb = tie_key(b);
    if ka != kb { return ka < kb; }
    return a.id < b.id;
}

// Front-to-back compositing per sample of the pixel.
struct Acc {
    color: array<vec3<f32>, PIXEL_SAMPLES>,
    trans: array<f32, PIXEL_SAMPLES>,
}

fn acc_empty() -> Acc {
    var c: Acc;
    for (var k = 0u; k < PIXEL_SAMPLES; k++) {
        c.trans[k] = 1.0;
    }
    return c;
}

// Composites one fragment into every sample it covers; true when all samples are opaque.
fn composite(c: ptr<function, Acc>, f: Frag) -> bool {
    let mask = frag_mask(f);
    var opaque = true;
    for (var k = 0u; k < PIXEL_SAMPLES; k++) {
        if (mask & (1u << k)) != 0u {
            (*c).color[k] += (*c).trans[k] * f.color.a * f.color.rgb;
            (*c).trans[k] *= 1.0 - f.color.a;
        }
        opaque = opaque && (*c).trans[k] == 0.0;
    }
    return opaque;
}

fn load_acc(px: u32) -> Acc {
    var c: Acc;
    for (var k = 0u; k < PIXEL_SAMPLES; k++) {
        let w = px * STATE_WORDS + SAMPLE_STATE + 4u * k;
        c.color[k] = vec3<f32>(bitcast<f32>(state[w]), bitcast<f32>(state[w + 1u]), bitcast<f32>(state[w + 2u]));
        c.trans[k] = bitcast<f32>(state[w + 3u]);
    }
    return c;
}

fn save_acc(px: u32, c: Acc) {
    for (var k = 0u; k < PIXEL_SAMPLES; k++) {
        let w = px * STATE_WORDS + SAMPLE_STATE + 4u * k;
        state[w] = bitcast<u32>(c.color[k].r);
        state[w + 1u] = bitcast<u32>(c.color[k].g);
        state[w + 2u] = bitcast<u32>(c.color[k].b);
        state[w + 3u] = bitcast<u32>(c.trans[k]);
    }
}

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
// Entries sorted by insertion before the merges.
const BLOCK: u32 = 8u;

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

// A deep pixel's progress between dispatches, in registers.
struct Sweep {
    px: u32,
    phase: u32,
    sub: u32,
    multi: bool,
    width: u32,
    src: u32,
    tail: u32,
    a: u32,
    na: u32,
    b: u32,
    nb: u32,
    rest: u32,
    // The merge's current fragments of runs a and b (bits 1 and 2 of `have`: loaded); kept
    // in registers within a dispatch only.
    fa: Frag,
    fb: Frag,
    have: u32,
}

// Appends node `link` to the pass's output.
fn append(s: ptr<function, Sweep>, link: u32) {
    if (*s).tail == 0u {
        atomicStore(&heads[(*s).px], link);
    } else {
        store_next((*s).tail - 1u, link);
    }
    (*s).tail = link;
}

// Ends a pass over the list: the next pass merges runs twice as long, or, when this one
// wrote a single run, the list is sorted and the composite starts.
fn end_pass(s: ptr<function, Sweep>) {
    store_next((*s).tail - 1u, 0u);
    let head = atomicLoad(&heads[(*s).px]);
    if (*s).multi {
        (*s).width = select(RUN, 2u * (*s).width, (*s).phase == MERGE);
        (*s).phase = MERGE;
    } else {
        (*s).phase = COMPOSITE;
    }
    (*s).src = head;
    (*s).tail = 0u;
    (*s).multi = false;
    (*s).sub = SPLIT_A;
    (*s).a = head;
    (*s).b = head;
    (*s).na = 0u;
}

// Relinks a sorted run onto the pass's output; after the list's last run, the merges start.
fn link_run(s: ptr<function, Sweep>, run: ptr<function, Run>, steps: ptr<function, u32>) {
    for (var i = 0u; i < (*run).n; i++) {
        append(s, entry_link((*run).entries[i]));
    }
    *steps += LINK_STEPS * (*run).n;
    (*s).src = (*run).next;
    (*s).phase = RUNS;
    if (*run).next == 0u {
        (*s).multi = true; // at least two runs: a list of one is composited by cs_sort
        end_pass(s);
    }
}

// One step of a merge pass: a node walked while splitting off the pair, or one node merged.
fn merge_step(s: ptr<function, Sweep>) {
    switch (*s).sub {
        case SPLIT_A: {
            if (*s).na < (*s).width && (*s).b != 0u {
                (*s).b = load_next((*s).b - 1u);
                (*s).na++;
            } else {
                (*s).sub = SPLIT_B;
                (*s).rest = (*s).b;
                (*s).nb = 0u;
            }
        }
        case SPLIT_B: {
            if (*s).nb < (*s).width && (*s).rest != 0u {
                (*s).rest = load_next((*s).rest - 1u);
                (*s).nb++;
            } else {
                (*s).sub = MERGING;
                (*s).multi = (*s).multi || (*s).rest != 0u || (*s).tail != 0u;
            }
        }
        default: {
            var take_a = (*s).nb == 0u;
            if (*s).na > 0u && (*s).nb > 0u {
                if ((*s).have & 1u) == 0u {
                    (*s).fa = walk((*s).a, (*s).px).frag;
                }
                if ((*s).have & 2u) == 0u {
                    (*s).fb = walk((*s).b, (*s).px).frag;
                }
                (*s).have = 3u;
                take_a = !frag_less((*s).fb, (*s).fa);
            }
            var link: u32;
            if take_a {
                link = (*s).a;
                (*s).a = load_next(link - 1u);
                (*s).na--;
                (*s).have &= 2u;
            } else {
                link = (*s).b;
                (*s).b = load_next(link - 1u);
                (*s).nb--;
                (*s).have &= 1u;
            }
            append(s, link);
            if (*s).na == 0u && (*s).nb == 0u {
                (*s).src = (*s).rest;
                (*s).sub = SPLIT_A;
                (*s).a = (*s).rest;
                (*s).b = (*s).rest;
                (*s).na = 0u;
                if (*s).rest == 0u {
                    end_pass(s);
                }
            }
        }
    }
}

fn load_sweep(px: u32) -> Sweep {
    let at = px * STATE_WORDS;
    var s: Sweep;
    s.px = px;
    let phase = state[at + S_PHASE];
    s.phase = phase & 0xfu;
    s.sub = (phase >> 4u) & 0xfu;
    s.multi = (phase & MULTI) != 0u;
    s.width = state[at + S_WIDTH];
    s.src = state[at + S_SRC];
    s.tail = state[at + S_TAIL];
    s.a = state[at + S_A];
    s.na = state[at + S_NA];
    s.b = state[at + S_B];
    s.nb = state[at + S_NB];
    s.rest = state[at + S_REST];
    return s;
}

fn save_sweep(s: Sweep) {
    let at = s.px * STATE_WORDS;
    state[at + S_PHASE] = s.phase | (s.sub << 4u) | select(0u, MULTI, s.multi);
    if s.phase != DONE {
        state[at + S_WIDTH] = s.width;
        state[at + S_SRC] = s.src;
        state[at + S_TAIL] = s.tail;
        state[at + S_A] = s.a;
        state[at + S_NA] = s.na;
        state[at + S_B] = s.b;
        state[at + S_NB] = s.nb;
        state[at + S_REST] = s.rest;
    }
}

// Two lists of pixel indices after the per-pixel state, so that each phase runs over the pixels
// that have work in it, not the frame (llvmpipe runs a shader's code for every SIMD group, lanes
// that have returned included): the pixels with fragments, which cs_active lists for cs_sort,
// and the deep pixels, which cs_sort lists for the later phases.
fn active_list_at() -> u32 {
    return frame.tile_size.x * frame.tile_size.y * STATE_WORDS;
}

fn deep_list_at() -> u32 {
    return frame.tile_size.x * frame.tile_size.y * (STATE_WORDS + 1u);
}

// Workgroups of LIST_GROUP invocations for the phases over a list: at most 65,535 in x, then
// rows of them.
const LIST_GROUP: u32 = 64u;

// The i-th pixel of the list at `at` of `count` pixels, dispatched with the workgroups from
// `groups` (OUTSIDE past its end).
fn listed_pixel(gid: vec3<u32>, groups: u32, count: u32, at: u32) -> u32 {
    let i = gid.y * alloc.groups[groups] * LIST_GROUP + gid.x;
    if i >= count {
        return OUTSIDE;
    }
    return state[at + i];
}

@compute @workgroup_size(8, 8)
fn cs_active(@builtin(global_invocation_id) gid: vec3<u32>) {
    let px = compute_pixel(gid);
    if px == OUTSIDE || list_head(px) == 0u {
        return;
    }
    state[active_list_at() + atomicAdd(&alloc.listed, 1u)] = px;
}

// An empty list gets no workgroups at all (x = y = 0).
fn set_groups(at: u32, count: u32) {
    let groups = (count + LIST_GROUP - 1u) / LIST_GROUP;
    let x = min(groups, 65535u);
    alloc.groups[at] = x;
    alloc.groups[at + 1u] = select(0u, (groups + x - 1u) / max(x, 1u), x > 0u);
    alloc.groups[at + 2u] = 1u;
}

// The workgroups of the dispatches over the two lists, from their lengths.
@compute @workgroup_size(1)
fn cs_groups() {
    set_groups(0u, atomicLoad(&alloc.listed));
    set_groups(3u, atomicLoad(&alloc.deep));
}

// The first dispatch: every pixel with fragments sorts its first run. A list of one run (most
// pixels) is composited and done; a longer one keeps the run, relinked, goes on to cs_runs and
// joins the deep list. A pixel without fragments keeps its cleared state: fs_resolve gives it
// the opaque scene or background.
@compute @workgroup_size(LIST_GROUP)
fn cs_sort(@builtin(global_invocation_id) gid: vec3<u32>) {
    let px = listed_pixel(gid, 0u, atomicLoad(&alloc.listed), active_list_at());
    if px == OUTSIDE {
        return;
    }
    var run: Run;
    var steps = 0u;
    load_run(list_head(px), px, &run, &steps);
    var c = acc_empty();
    if run.next == 0u {
        for (var i = 0u; i < run.n; i++) {
            if composite(&c, frag_shaded(entry_frag(run.entries[i], px), px)) {
                break;
            }
        }
        state[px * STATE_WORDS + S_PHASE] = DONE;
    } else {
        var s: Sweep;
        s.px = px;
        link_run(&s, &run, &steps);
        save_sweep(s);
        state[deep_list_at() + atomicAdd(&alloc.deep, 1u)] = px;
    }
    save_acc(px, c);
}

// The deeper pixels, one phase an entry point so that each dispatch runs one tight loop:
// their further runs, then their merge passes, then their composite, STEP_BUDGET steps a
// dispatch. The host dispatches each enough times for the deepest pixel
// (oit_core::method::lists::resolve_dispatches), over the deep list; a pixel in another phase
// returns at once.
fn resume(gid: vec3<u32>, phase: u32) -> u32 {
    let px = listed_pixel(gid, 3u, atomicLoad(&alloc.deep), deep_list_at());
    if px == OUTSIDE || (state[px * STATE_WORDS + S_PHASE] & 0xfu) != phase {
        return OUTSIDE;
    }
    return px;
}

@compute @workgroup_size(LIST_GROUP)
fn cs_runs(@builtin(global_invocation_id) gid: vec3<u32>) {
    let px = resume(gid, RUNS);
    if px == OUTSIDE {
        return;
    }
    var s = load_sweep(px);
    var steps = 0u;
    while s.phase == RUNS && steps < STEP_BUDGET {
        var run: Run;
        load_run(s.src, px, &run, &steps);
        link_run(&s, &run, &steps);
    }
    save_sweep(s);
}

@compute @workgroup_size(LIST_GROUP)
fn cs_merge(@builtin(global_invocation_id) gid: vec3<u32>) {
    let px = resume(gid, MERGE);
    if px == OUTSIDE {
        return;
    }
    var s = load_sweep(px);
    var steps = 0u;
    while s.phase == MERGE && steps < STEP_BUDGET {
        merge_step(&s);
        steps += MERGE_STEPS;
    }
    save_sweep(s);
}

@compute @workgroup_size(LIST_GROUP)
fn cs_composite(@builtin(global_invocation_id) gid: vec3<u32>) {
    let px = resume(gid, COMPOSITE);
    if px == OUTSIDE {
        return;
    }
    var c = load_acc(px);
    var link = state[px * STATE_WORDS + S_SRC];
    var steps = 0u;
    var done = false;
    while !done && steps < STEP_BUDGET {
        if link == 0u {
            done = true;
        } else {
            let w = walk(link, px);
            done = composite(&c, frag_shaded(w.frag, px));
            link = w.next;
        }
        steps += COMPOSITE_STEPS;
    }
    state[px * STATE_WORDS + S_SRC] = link;
    if done {
        state[px * STATE_WORDS + S_PHASE] = DONE;
    }
    save_acc(px, c);
}

// The pixel: the mean over its samples of the composite over that sample's opaque scene or
// background (one sample without coverage masks).
@fragment
fn fs_resolve(@builtin(position) pos: vec4<f32>) -> @location(0) vec4<f32> {
    let at = pixel_index(pos) * STATE_WORDS;
    let started = (state[at + S_PHASE] & 0xfu) == DONE;
    var sum = vec4<f32>(0.0);
    for (var k = 0u; k < PIXEL_SAMPLES; k++) {
        let base = base_at_sample(pos, k);
        if !started {
            sum += base;
            continue;
        }
        let w = at + SAMPLE_STATE + 4u * k;
        let accum = vec3<f32>(bitcast<f32>(state[w]), bitcast<f32>(state[w + 1u]), bitcast<f32>(state[w + 2u]));
        let trans = bitcast<f32>(state[w + 3u]);
        sum += vec4<f32>(accum + trans * base.rgb, 1.0 - trans * (1.0 - base.a));
    }
    return sum / f32(PIXEL_SAMPLES);
}
