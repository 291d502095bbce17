// The jackknife transmittance estimate (Eq. 4, media::jackknife): K = cos(|X0 − X1|/2) exp(−(X0 + X1)/2).

fn jackknife(x0: f32, x1: f32) -> f32 {
    return cos(0.5 * abs(x0 - x1)) * exp(-0.5 * (x0 + x1));
}
