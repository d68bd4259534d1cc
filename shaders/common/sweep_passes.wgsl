// The sorted resolve's dispatches (common/sweep.wgsl): cs_active lists the pixels with
// fragments, cs_groups sizes the dispatches over the lists, cs_sort sorts each pixel's first run
// (and, without a loop limit, finishes every pixel), then cs_runs, cs_merge and cs_composite
// resume the deep pixels, STEP_BUDGET steps a dispatch.

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
//!if BUDGETED
        save_sweep(s);
        state[deep_list_at() + atomicAdd(&alloc.deep, 1u)] = px;
//!else
        // No loop limit: the pixel's further runs, its merges and its composite, here.
        sweep_runs(&s);
        sweep_merge(&s);
        var link = s.src;
        sweep_composite(&link, px, &c);
        state[px * STATE_WORDS + S_PHASE] = DONE;
//!endif
    }
    save_acc(px, c);
}

// The deeper pixels, one phase an entry point so that each dispatch runs one tight loop:
// their further runs, then their merge passes, then their composite, STEP_BUDGET steps a
// dispatch. The host dispatches each enough times for the deepest pixel
// (oit_core::method::resolve_plan::resolve_dispatches), over the deep list; a pixel in another phase
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
    sweep_runs(&s);
    save_sweep(s);
}

@compute @workgroup_size(LIST_GROUP)
fn cs_merge(@builtin(global_invocation_id) gid: vec3<u32>) {
    let px = resume(gid, MERGE);
    if px == OUTSIDE {
        return;
    }
    var s = load_sweep(px);
    sweep_merge(&s);
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
    let done = sweep_composite(&link, px, &c);
    state[px * STATE_WORDS + S_SRC] = link;
    if done {
        state[px * STATE_WORDS + S_PHASE] = DONE;
    }
    save_acc(px, c);
}

// Whether a deep pixel's work goes on after `steps` steps in this invocation: below STEP_BUDGET
// where the adapter has a loop limit (BUDGETED), always where it has none (the plain strategy,
// which finishes every pixel in cs_sort).
fn within_budget(steps: u32) -> bool {
//!if BUDGETED
    return steps < STEP_BUDGET;
//!else
    return true;
//!endif
}

// A deep pixel's phases, each until it ends or the budget is spent: its further runs, sorted
// and relinked; its merge passes; its composite from `*link`, the list's node the composite has
// reached (true when the pixel is done: the list ended, or every sample is opaque).
fn sweep_runs(s: ptr<function, Sweep>) {
    var steps = 0u;
    while (*s).phase == RUNS && within_budget(steps) {
        var run: Run;
        load_run((*s).src, (*s).px, &run, &steps);
        link_run(s, &run, &steps);
    }
}

fn sweep_merge(s: ptr<function, Sweep>) {
    var steps = 0u;
    while (*s).phase == MERGE && within_budget(steps) {
        merge_step(s);
        steps += MERGE_STEPS;
    }
}

fn sweep_composite(link: ptr<function, u32>, px: u32, c: ptr<function, Acc>) -> bool {
    var steps = 0u;
    var done = false;
    while !done && within_budget(steps) {
        if *link == 0u {
            done = true;
        } else {
            let w = walk(*link, px);
            done = composite(c, frag_shaded(w.frag, px));
            *link = w.next;
        }
        steps += COMPOSITE_STEPS;
    }
    return done;
}
