// The jackknife transmittance estimate (Eq. 4, media::jackknife): K = cos(|X0 − X1|/2) exp(−(X0 + X1)/2).

fn jackknife(x0: f32, x1: f32) -> f32 {
    return cos(0.5 * abs(x0 - x1)) * exp(-0.5 * (x0 + x1));
}

// Eq. 3 from `count` >= 2 estimates x[0..count] (media::jackknife::jackknife_estimates): Eq. 4
// for 2, else exp(−X̄) 0F1(; (m−1)/2; −S²/4) by its series (S² the biased sample variance).
fn jackknife_estimates(x: array<f32, 9>, count: u32) -> f32 {
    if count == 2u {
        return jackknife(x[0], x[1]);
    }
    let m = f32(count);
    var mean = 0.0;
    for (var k = 0u; k < count; k++) {
        mean += x[k];
    }
    mean /= m;
    var s2 = 0.0;
    for (var k = 0u; k < count; k++) {
        s2 += (x[k] - mean) * (x[k] - mean);
    }
    s2 /= m;
    let a = 0.5 * (m - 1.0);
    let z = -0.25 * s2;
    var term = 1.0;
    var sum = 1.0;
    for (var j = 1u; j < 64u; j++) {
        let jf = f32(j);
        term *= z / (jf * (a + jf - 1.0));
        sum += term;
        if jf * (a + jf - 1.0) > -z && abs(term) <= 1e-8 * abs(sum) {
            break;
        }
    }
    return sum * exp(-mean);
}
