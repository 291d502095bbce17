// Inference in the register form (src/gpu/lane.rs): LANE_QUERIES queries per invocation (this
// workgroup's queries lid, lid + WG_SIZE, ..), no barrier, each staged weight loaded once for
// all of them. The hash-grid corners of a query are found once and both predictors' tables are
// read from them; the predictors' MLPs read their weights from the uniform buffer
// lane_stage.wgsl filled. Then answer.wgsl.

import package::nirc::config::{WG_SIZE};
import package::nirc::bindings::{call, queries};
import package::nirc::lane_queries::{LANE_QUERIES, lane_infer};
import package::nirc::answer::{predictors, write_answer};

@compute @workgroup_size(64)
fn main(@builtin(workgroup_id) wid: vec3<u32>, @builtin(local_invocation_index) lid: u32) {
    let q0 = wid.x * LANE_QUERIES * WG_SIZE + lid;
    let mode = call.mode;
    if q0 >= call.n {
        return;
    }
    if mode == 4u {
        for (var j = 0u; j < LANE_QUERIES; j++) {
            let qi = q0 + j * WG_SIZE;
            if qi < call.n {
                write_answer(qi, queries[qi].position.xyz, mode, vec3<f32>(0.0), vec3<f32>(0.0));
            }
        }
        return;
    }
    lane_infer(q0, predictors(mode), mode);
}
