// Reading an order-independent fixed-point sum (see fixed_sum.wgsl) back as f32.

// The sum as f32: sign and magnitude, then hi * 2^16 + mid * 2^-16 + lo * 2^-48.
fn fixed_to_f32(w0_in: u32, w1_in: u32, w2_in: u32) -> f32 {
    var w0 = w0_in;
    var w1 = w1_in;
    var w2 = w2_in;
    let negative = (w2 >> 31u) == 1u;
    if negative {
        w0 = ~w0;
        w1 = ~w1;
        w2 = ~w2;
        w0 = w0 + 1u;
        if w0 == 0u {
            w1 = w1 + 1u;
            if w1 == 0u {
                w2 = w2 + 1u;
            }
        }
    }
    let v = f32(w2) * 65536.0 + f32(w1) * (1.0 / 65536.0) + f32(w0) * 3.5527136788005009e-15;
    return select(v, -v, negative);
}
