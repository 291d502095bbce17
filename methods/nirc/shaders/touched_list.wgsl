// The list of grid quads a training step touched, in ascending order (sparse grid updates,
// `optimizer.sparse_grid`): a stream compaction of the step's bitmask (one bit per grid quad,
// set by sparse_mark in the training pass; generated in src/gpu/shaders.rs), so that the passes
// over the list (adam_sparse.wgsl) read and write the parameters in memory order. The list and
// its length depend on the set bits only, never on the threads' order.
//   count_blocks  per block of BLOCK_WORDS words: its set bits
//   scan_blocks   one workgroup: each block's first slot in the list (exclusive prefix sum over
//                 the blocks), the list's length and the dispatch size of the passes over it
//   emit_list     per block: a prefix sum of its threads' counts in workgroup memory, then each
//                 thread writes the quads of its words in order
// (The mask is cleared before the next step's training pass, src/gpu/mod.rs clear_step.)

import package::nirc::config::{WG_SIZE};

// Grid quads the step touched (relative to the grid's first quad), ascending.
@group(0) @binding(13) var<storage, read_write> touched: array<u32>;
// The list's length.
@group(0) @binding(14) var<storage, read_write> touched_len: u32;
// One bit per grid quad: touched this step (bit i % 32 of word i / 32).
@group(0) @binding(15) var<storage, read> touched_bits: array<u32>;
// The indirect dispatch of the passes over the list: (workgroups, 1, 1).
@group(0) @binding(17) var<storage, read_write> list_dispatch: array<u32, 4>;
// Per block: its set bits (count_blocks).
@group(0) @binding(18) var<storage, read_write> block_counts: array<u32>;
// Per block: its first slot in the list (scan_blocks; apart from the counts, so that each pass
// can be rerun alone, as the bench times them).
@group(0) @binding(19) var<storage, read_write> block_offsets: array<u32>;

// Consecutive words per thread, so that a thread's quads go to consecutive slots.
const WORDS_PER_THREAD: u32 = 4u;
const BLOCK_WORDS: u32 = WG_SIZE * WORDS_PER_THREAD;
// Grid quads per invocation of the passes over the list (adam_sparse.wgsl).
const LIST_QUADS_PER_INVOCATION: u32 = 4u;

// WG_SIZE words of workgroup memory (256 bytes at 64 threads).
var<workgroup> partial: array<u32, WG_SIZE>;

fn word_count() -> u32 {
    return arrayLength(&touched_bits);
}

fn block_count() -> u32 {
    return (word_count() + BLOCK_WORDS - 1u) / BLOCK_WORDS;
}

// The set bits of the words from `first` on that belong to one thread.
fn thread_bits(first: u32) -> u32 {
    var n = 0u;
    for (var k = 0u; k < WORDS_PER_THREAD; k++) {
        if first + k < word_count() {
            n += countOneBits(touched_bits[first + k]);
        }
    }
    return n;
}

// The inclusive prefix sum of the workgroup's values at thread t (Hillis and Steele's scan in
// workgroup memory); `partial` holds all of them on return.
fn scan_workgroup(t: u32, v: u32) -> u32 {
    partial[t] = v;
    workgroupBarrier();
    for (var d = 1u; d < WG_SIZE; d *= 2u) {
        var add = 0u;
        if t >= d {
            add = partial[t - d];
        }
        workgroupBarrier();
        partial[t] += add;
        workgroupBarrier();
    }
    return partial[t];
}

@compute @workgroup_size(WG_SIZE)
fn count_blocks(@builtin(workgroup_id) wid: vec3<u32>, @builtin(local_invocation_index) t: u32) {
    let total = scan_workgroup(t, thread_bits(BLOCK_WORDS * wid.x + WORDS_PER_THREAD * t));
    if t == WG_SIZE - 1u {
        block_counts[wid.x] = total;
    }
}

@compute @workgroup_size(WG_SIZE)
fn scan_blocks(@builtin(local_invocation_index) t: u32) {
    let blocks = block_count();
    var carry = 0u;
    for (var base = 0u; base < blocks; base += WG_SIZE) {
        let i = base + t;
        var count = 0u;
        if i < blocks {
            count = block_counts[i];
        }
        let inclusive = scan_workgroup(t, count);
        if i < blocks {
            block_offsets[i] = carry + inclusive - count;
        }
        carry += partial[WG_SIZE - 1u];
        // Every thread has read the total before the next round overwrites it.
        workgroupBarrier();
    }
    if t == 0u {
        touched_len = carry;
        let groups = (carry + WG_SIZE * LIST_QUADS_PER_INVOCATION - 1u) / (WG_SIZE * LIST_QUADS_PER_INVOCATION);
        list_dispatch[0] = min(groups, 65535u);
        list_dispatch[1] = 1u;
        list_dispatch[2] = 1u;
    }
}

@compute @workgroup_size(WG_SIZE)
fn emit_list(@builtin(workgroup_id) wid: vec3<u32>, @builtin(local_invocation_index) t: u32) {
    let first = BLOCK_WORDS * wid.x + WORDS_PER_THREAD * t;
    let n = thread_bits(first);
    var slot = block_offsets[wid.x] + scan_workgroup(t, n) - n;
    for (var k = 0u; k < WORDS_PER_THREAD; k++) {
        let w = first + k;
        if w < word_count() {
            var bits = touched_bits[w];
            while bits != 0u {
                touched[slot] = 32u * w + firstTrailingBit(bits);
                slot += 1u;
                bits &= bits - 1u;
            }
        }
    }
}
