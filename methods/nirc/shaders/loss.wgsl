// Relative L2 loss (CPU mirror: src/cpu/loss.rs): mean over RGB of (f - y)^2 / (sg(f)^2 + ε),
// the denominators under stop-gradient, per channel or by luminance. Returns dL/df in .xyz and
// the loss in .w.

import package::nirc::bindings::{hyper};

fn relative_l2(f: vec3<f32>, y: vec3<f32>) -> vec4<f32> {
    var den: vec3<f32>;
    if hyper.loss_luminance == 1u {
        let l = 0.2126 * f.x + 0.7152 * f.y + 0.0722 * f.z;
        den = vec3<f32>(l * l + hyper.loss_epsilon);
    } else {
        den = f * f + vec3<f32>(hyper.loss_epsilon);
    }
    var loss = 0.0;
    var d_out = vec3<f32>(0.0);
    for (var c = 0u; c < 3u; c++) {
        let diff = f[c] - y[c];
        loss += diff * diff / den[c];
        d_out[c] = (2.0 / 3.0) * diff / den[c];
    }
    return vec4<f32>(d_out, loss / 3.0);
}
