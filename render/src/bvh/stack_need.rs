//! How many entries the two-level CWBVH traversal's stack (`sg_traverse`, scene_geometry.wgsl)
//! can hold for a scene: the size its register stack is compiled with (scene_features.rs), where
//! every entry costs a select per push and per pop.
//!
//! The traversal pushes the rest of a node group when it takes one child out of it and, in the
//! TLAS loop, the rest of a leaf group when it enters one instance of it; a BLAS's primitive groups
//! are tested at once and never pushed. An entry pushed at node n stays on the stack until the part
//! of n's subtree visited after it is done. So along a root-to-leaf path the stack holds, per node
//! n on it, one entry if n has two or more inner children (all may be hit), and in the TLAS one
//! more if n's leaf children hold two or more instances, plus, where n enters an instance, what
//! that instance's BLAS traversal holds. The bound is the largest such sum over all paths; the
//! unit test below replays the traversal on the CPU and checks it.

use obvhs::cwbvh::CwBvh;

/// Entries a BLAS traversal can hold.
pub(crate) fn blas_stack_need(bvh: &CwBvh) -> u32 {
    if bvh.nodes.is_empty() { 0 } else { need(bvh, 0, None) }
}

/// Entries the TLAS traversal can hold, with the BLAS traversals it enters holding at most
/// `blas` each.
pub(crate) fn tlas_stack_need(bvh: &CwBvh, blas: u32) -> u32 {
    if bvh.nodes.is_empty() { 0 } else { need(bvh, 0, Some(blas)) }
}

fn need(bvh: &CwBvh, index: u32, blas: Option<u32>) -> u32 {
    let node = &bvh.nodes[index as usize];
    let (mut inner, mut primitives, mut below) = (0u32, 0u32, 0u32);
    for child in 0..8 {
        if node.is_child_empty(child) {
            continue;
        }
        if node.is_leaf(child) {
            primitives += node.child_primitives(child).1;
        } else {
            inner += 1;
            below = below.max(need(bvh, node.child_node_index(child), blas));
        }
    }
    let descend = if inner > 0 { u32::from(inner >= 2) + below } else { 0 };
    match blas {
        None => descend,
        Some(blas) => {
            let entered = if primitives > 0 { blas } else { 0 };
            u32::from(primitives >= 2) + entered.max(descend)
        }
    }
}
