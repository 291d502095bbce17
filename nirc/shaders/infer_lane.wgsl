// Inference in the register form (src/gpu/lane.rs): one query per invocation, no barrier. The
// hash-grid corners of a query are found once and both predictors' tables are read from them;
// the predictors' MLPs read their weights from the uniform buffer lane_stage.wgsl filled. Then
// answer.wgsl.

import package::nirc::config::{WG_SIZE};
import package::nirc::bindings::{call, hyper, queries};
import package::nirc::bindings_common::{normalize_to_bounds};
import package::nirc::lane::{LANE_W_VEC4, lane_inputs, lane_net};
import package::nirc::answer::{predictors, write_answer, write_predictions};

@compute @workgroup_size(64)
fn main(@builtin(workgroup_id) wid: vec3<u32>, @builtin(local_invocation_index) lid: u32) {
    let qi = wid.x * WG_SIZE + lid;
    let mode = call.mode;
    if qi >= call.n {
        return;
    }
    if mode == 4u {
        write_answer(qi, queries[qi].position.xyz, mode, vec3<f32>(0.0), vec3<f32>(0.0));
        return;
    }
    let pr = predictors(mode);
    let q = queries[qi];
    let x = lane_inputs(normalize_to_bounds(hyper, q.position.xyz), q.direction.xyz, pr.first_net, pr.both);
    let f1 = lane_net(pr.first_net * LANE_W_VEC4, x.a).xyz;
    var f2 = vec3<f32>(0.0);
    if pr.both {
        f2 = lane_net(0u, x.b).xyz;
    }
    write_predictions(qi, q.position.xyz, mode, pr, f1, f2);
}
