// Inference, one invocation per query (the fallback for networks the tiled pass does not
// take, see infer_tile.wgsl): evaluates the predictors the mode needs, then answer.wgsl.

import package::nirc::bindings::{call, queries};
import package::nirc::answer::{write_answer};
import package::nirc::mlp::{encode_input, mlp_forward};

@compute @workgroup_size(64)
fn main(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(local_invocation_index) lid: u32) {
    let qi = gid.x;
    let in_range = qi < call.n;
    let q = queries[min(qi, call.n - 1u)];
    let pos = q.position.xyz;
    let dir = q.direction.xyz;
    let mode = call.mode;

    var f_ema = vec3<f32>(0.0);
    var f_cur = vec3<f32>(0.0);
    if mode != 1u && mode != 4u {
        if in_range {
            encode_input(1u, pos, dir);
            f_ema = mlp_forward(1u);
        }
    }
    if mode != 0u && mode != 4u {
        if in_range {
            encode_input(0u, pos, dir);
            f_cur = mlp_forward(0u);
        }
    }
    if in_range {
        write_answer(qi, pos, mode, f_ema, f_cur);
    }
}
