// Inference in the register form (src/gpu/lane.rs): two queries per invocation (this workgroup's
// query lid and lid + WG_SIZE), no barrier, each staged weight loaded once for both. The
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
    let qa = wid.x * 2u * WG_SIZE + lid;
    let qb = qa + WG_SIZE;
    let mode = call.mode;
    if qa >= call.n {
        return;
    }
    // A second query past the end computes the last query again and writes nothing.
    let has_b = qb < call.n;
    let qb_read = select(call.n - 1u, qb, has_b);
    if mode == 4u {
        write_answer(qa, queries[qa].position.xyz, mode, vec3<f32>(0.0), vec3<f32>(0.0));
        if has_b {
            write_answer(qb, queries[qb].position.xyz, mode, vec3<f32>(0.0), vec3<f32>(0.0));
        }
        return;
    }
    let pr = predictors(mode);
    let a = queries[qa];
    let b = queries[qb_read];
    let xa = lane_inputs(normalize_to_bounds(hyper, a.position.xyz), a.direction.xyz, pr.first_net, pr.both);
    let xb = lane_inputs(normalize_to_bounds(hyper, b.position.xyz), b.direction.xyz, pr.first_net, pr.both);
    let f1 = lane_net(pr.first_net * LANE_W_VEC4, xa.a, xb.a);
    var f2a = vec3<f32>(0.0);
    var f2b = vec3<f32>(0.0);
    if pr.both {
        let f2 = lane_net(0u, xa.b, xb.b);
        f2a = f2.a.xyz;
        f2b = f2.b.xyz;
    }
    write_predictions(qa, a.position.xyz, mode, pr, f1.a.xyz, f2a);
    if has_b {
        write_predictions(qb, b.position.xyz, mode, pr, f1.b.xyz, f2b);
    }
}
