// Random numbers and sampling warps for the path tracer.
// A per-path PCG stream (PCG hash of Jarzynski & Olano 2020, "Hash Functions for GPU
// Rendering") seeded from (seed, frame, pixel, sample), so any sample of any frame is
// reproducible alone.

const PI: f32 = 3.14159265358979;
const TWO_PI: f32 = 6.28318530717959;
const INV_PI: f32 = 0.318309886183791;

fn pcg_hash(v: u32) -> u32 {
    let state = v * 747796405u + 2891336453u;
    let word = ((state >> ((state >> 28u) + 4u)) ^ state) * 277803737u;
    return (word >> 22u) ^ word;
}

// Strong 32-bit avalanche (Wellons' "lowbias32") to combine the seed inputs: chained PCG hashes
// of small consecutive integers (seeds 3, 4, 5, ...) left visible correlations between seeds.
fn hash_mix(v: u32) -> u32 {
    var x = v;
    x ^= x >> 16u;
    x *= 0x7feb352du;
    x ^= x >> 15u;
    x *= 0x846ca68bu;
    x ^= x >> 16u;
    return x;
}

fn rng_seed(seed: vec2u, frame: u32, pixel: u32, sample: u32) -> u32 {
    var h = hash_mix(seed.x ^ hash_mix(seed.y ^ 0x9e3779b9u));
    h = hash_mix(h ^ hash_mix(frame + 0x632be5abu));
    h = hash_mix(h ^ hash_mix(pixel + 0x85ebca6bu));
    return pcg_hash(h ^ hash_mix(sample + 0xc2b2ae35u));
}

// Uniform in [0, 1): 24 high bits of the next PCG output.
fn rng_next(state: ptr<function, u32>) -> f32 {
    *state = *state * 747796405u + 2891336453u;
    let s = *state;
    let word = ((s >> ((s >> 28u) + 4u)) ^ s) * 277803737u;
    return f32(((word >> 22u) ^ word) >> 8u) * (1.0 / 16777216.0);
}

fn rng_next2(state: ptr<function, u32>) -> vec2f {
    let a = rng_next(state);
    let b = rng_next(state);
    return vec2f(a, b);
}

// Orthonormal basis around a unit normal (Duff et al. 2017).
fn basis_tangent(n: vec3f) -> vec3f {
    let s = select(-1.0, 1.0, n.z >= 0.0);
    let a = -1.0 / (s + n.z);
    let b = n.x * n.y * a;
    return vec3f(1.0 + s * n.x * n.x * a, s * b, -s * n.x);
}

fn basis_bitangent(n: vec3f) -> vec3f {
    let s = select(-1.0, 1.0, n.z >= 0.0);
    let a = -1.0 / (s + n.z);
    let b = n.x * n.y * a;
    return vec3f(b, s + n.y * n.y * a, -n.y);
}

fn to_world(local: vec3f, n: vec3f) -> vec3f {
    return local.x * basis_tangent(n) + local.y * basis_bitangent(n) + local.z * n;
}

// Cosine-weighted hemisphere around +z; pdf = cos / pi.
fn sample_cosine_hemisphere(u: vec2f) -> vec3f {
    let r = sqrt(u.x);
    let phi = TWO_PI * u.y;
    return vec3f(r * cos(phi), r * sin(phi), sqrt(max(0.0, 1.0 - u.x)));
}

// Uniform on the unit sphere; pdf = 1 / (4 pi).
fn sample_uniform_sphere(u: vec2f) -> vec3f {
    let z = 1.0 - 2.0 * u.x;
    let r = sqrt(max(0.0, 1.0 - z * z));
    let phi = TWO_PI * u.y;
    return vec3f(r * cos(phi), r * sin(phi), z);
}

// Uniform in the cone of directions within acos(cos_max) of +z; pdf = 1 / (2 pi (1 - cos_max)).
fn sample_uniform_cone(u: vec2f, cos_max: f32) -> vec3f {
    let z = 1.0 - u.x * (1.0 - cos_max);
    let r = sqrt(max(0.0, 1.0 - z * z));
    let phi = TWO_PI * u.y;
    return vec3f(r * cos(phi), r * sin(phi), z);
}

// Uniform barycentrics on a triangle (square-root warp).
fn sample_triangle(u: vec2f) -> vec2f {
    let s = sqrt(u.x);
    return vec2f(1.0 - s, u.y * s);
}

// Veach's power heuristic (beta = 2) for one sample from each of two strategies.
fn power_heuristic(pdf_a: f32, pdf_b: f32) -> f32 {
    let a2 = pdf_a * pdf_a;
    let b2 = pdf_b * pdf_b;
    if a2 + b2 <= 0.0 {
        return 0.0;
    }
    return a2 / (a2 + b2);
}

fn luminance(c: vec3f) -> f32 {
    return dot(c, vec3f(0.2126, 0.7152, 0.0722));
}

fn max_component(c: vec3f) -> f32 {
    return max(c.x, max(c.y, c.z));
}
