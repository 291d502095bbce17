// Slope test of adaptive retracing (section 3.4, eqs. 1 and 2; twin of src/slope.rs).

// Eq. 1: expected spread of first-hit distances inside one pixel frustum on a locally flat
// surface, Δn = t_s |1 - cos θ / cos(θ - φ)|, θ the angle between the normal and the direction to
// the camera, φ the angle subtended by a pixel's diagonal.
fn ssc_slope(t: f32, cos_theta: f32, phi: f32) -> f32 {
    let c = clamp(cos_theta, 0.0, 1.0);
    let theta = acos(c);
    return t * abs(1.0 - c / cos(theta - phi));
}

// Eq. 2: the 3x3 neighbourhood is consistent with one flat surface when
// t_max < (1 + ε1)(t_min + 2 Δn).
fn ssc_consistent(t_min: f32, t_max: f32, slope: f32, epsilon1: f32) -> bool {
    return t_max < (1.0 + epsilon1) * (t_min + 2.0 * slope);
}

// Orders (depth, Δn) pairs for the closest sample of a pixel or a neighbourhood: nearer first,
// on a tie the smaller Δn (the stricter test), so the choice does not depend on slot order.
fn ssc_closer(a: vec2f, b: vec2f) -> bool {
    return a.x < b.x || (a.x == b.x && a.y < b.y);
}
