// The sorted resolve's deep pixels (common/sweep.wgsl): a list longer than one run is sorted in
// runs relinked in place, then the runs are merged bottom-up by relinking the nodes' `next`
// fields (no scratch memory), a step at a time, so that the work can pause between dispatches.

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

