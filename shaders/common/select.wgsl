// Batched selection over a linked list: the BATCH smallest items greater than a threshold,
// kept in a max-heap so that each list node costs at most log2(BATCH) steps whatever the
// list's order (llvmpipe ends an invocation's loops after 65,535 iterations in all, so the
// worst case must stay linear). The including shader defines `struct Frag` and
// `fn frag_less(a: Frag, b: Frag) -> bool`, a strict total order.

fn heap_sift_down(heap: ptr<function, array<Frag, BATCH>>, start: u32, end: u32) {
    var i = start;
    loop {
        let l = 2u * i + 1u;
        if l >= end {
            break;
        }
        var c = l;
        if l + 1u < end && frag_less((*heap)[l], (*heap)[l + 1u]) {
            c = l + 1u;
        }
        if !frag_less((*heap)[i], (*heap)[c]) {
            break;
        }
        let t = (*heap)[i];
        (*heap)[i] = (*heap)[c];
        (*heap)[c] = t;
        i = c;
    }
}

// Offers `f` to a heap holding the n smallest items seen so far; returns the new n.
fn heap_offer(heap: ptr<function, array<Frag, BATCH>>, n: u32, f: Frag) -> u32 {
    if n < BATCH {
        var i = n;
        (*heap)[i] = f;
        while i > 0u {
            let p = (i - 1u) / 2u;
            if !frag_less((*heap)[p], (*heap)[i]) {
                break;
            }
            let t = (*heap)[p];
            (*heap)[p] = (*heap)[i];
            (*heap)[i] = t;
            i = p;
        }
        return n + 1u;
    }
    if frag_less(f, (*heap)[0]) {
        (*heap)[0] = f;
        heap_sift_down(heap, 0u, n);
    }
    return n;
}

// Sorts the heap's n items ascending, in place.
fn heap_sort(heap: ptr<function, array<Frag, BATCH>>, n: u32) {
    var end = n;
    while end > 1u {
        end -= 1u;
        let t = (*heap)[0];
        (*heap)[0] = (*heap)[end];
        (*heap)[end] = t;
        heap_sift_down(heap, 0u, end);
    }
}
