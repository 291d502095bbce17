// Indirect dispatch of the work lists: one thread writes the workgroup counts of the
// retrace list (after retrace_main filled it) or of the shade list (after select_main), so that
// retrace_list_main and shade_main launch one thread per entry instead of N · pixels threads
// that exit past the list's end. The host copies the three words into its indirect buffer.
// Mirrored on the CPU by SampleCache::list_dispatch (the direct dispatch's worst case).

import package::sample_cache_bindings::{ssc_work};
import package::sample_cache::storage::{SSC_LIST_WORKGROUP, SSC_MAX_GROUPS_X, SSC_RETRACE_ARGS, SSC_RETRACE_COUNT, SSC_SHADE_ARGS, SSC_SHADE_COUNT};

// Workgroups for `count` entries: x·y >= count / SSC_LIST_WORKGROUP, x within the limit.
fn write_list_args(count: u32, at: u32) {
    let groups = (count + SSC_LIST_WORKGROUP - 1u) / SSC_LIST_WORKGROUP;
    let x = min(groups, SSC_MAX_GROUPS_X);
    let y = select(0u, (groups + x - 1u) / max(x, 1u), x > 0u);
    atomicStore(&ssc_work[at], x);
    atomicStore(&ssc_work[at + 1u], y);
    atomicStore(&ssc_work[at + 2u], 1u);
}

@compute @workgroup_size(1, 1, 1)
fn retrace_args_main() {
    write_list_args(atomicLoad(&ssc_work[SSC_RETRACE_COUNT]), SSC_RETRACE_ARGS);
}

@compute @workgroup_size(1, 1, 1)
fn shade_args_main() {
    write_list_args(atomicLoad(&ssc_work[SSC_SHADE_COUNT]), SSC_SHADE_ARGS);
}
