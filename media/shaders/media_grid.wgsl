// A medium's voxel densities (nearest neighbour) and super-voxels (size³ voxels, 16 by default: min, max, mean,
// RMS of μ − μ_min), in texel space with the ray parameter t in world units (media::medium).
// Several media may be bound (`media`, their voxels and super-voxels concatenated): every
// function here reads the one `media_index` selects (select_medium), the first by default.

import package::media::types::{RaySegment};
import package::media::medium_bindings::{density, media, super_voxels};

// Relative floor of the variance-aware importance in non-empty super-voxels (IMPORTANCE_FLOOR).
const IMPORTANCE_FLOOR: f32 = 1e-3;
const BIG: f32 = 3.4e38;

// The medium the functions below read (private, so 0 unless a pass selects another).
var<private> media_index: u32;

fn select_medium(i: u32) {
    media_index = i;
}

// Super-voxels per axis of the selected medium.
fn media_dims() -> vec3u {
    return media[media_index].dims;
}

// Voxels per axis of the selected medium.
fn media_res() -> vec3u {
    return media[media_index].res;
}

// The selected medium's extinction in voxel v (no lookup counted: regular tracking's).
fn voxel_density(v: vec3u) -> f32 {
    let medium = media[media_index];
    return density[medium.density_offset + v.x + medium.res.x * (v.y + medium.res.y * v.z)];
}

// Voxels per super-voxel edge of the selected medium.
fn super_voxel_size() -> u32 {
    return media[media_index].super_voxel;
}

fn media_count() -> u32 {
    return media[0].count;
}

// High-resolution density lookups of this invocation (what the paper counts).
var<private> media_lookups: u32;

fn seg_at(s: RaySegment, t: f32) -> vec3f {
    return s.origin + s.dir * t;
}

// The part of the world ray (origin, unit dir) in [0, t_max] inside the box; t0 >= t1 on a miss.
fn medium_segment(origin: vec3f, dir: vec3f, t_max: f32) -> RaySegment {
    let medium = media[media_index];
    let voxel = (medium.box_max - medium.box_min) / vec3f(medium.res);
    let o = (origin - medium.box_min) / voxel;
    let d = dir / voxel;
    let inv = 1.0 / d;
    let a = -o * inv;
    let b = (vec3f(medium.res) - o) * inv;
    let lo = min(a, b);
    let hi = max(a, b);
    let t0 = max(max(max(lo.x, lo.y), lo.z), 0.0);
    let t1 = min(min(min(hi.x, hi.y), hi.z), t_max);
    return RaySegment(o, t0, d, t1);
}

fn super_voxel(c: vec3i) -> vec4f {
    let u = vec3u(c);
    let medium = media[media_index];
    return super_voxels[medium.super_voxel_offset + u.x + medium.dims.x * (u.y + medium.dims.y * u.z)];
}

// μ at t inside super-voxel `cell` (the voxel clamped into it, as media::Medium::mu).
fn mu_at(s: RaySegment, t: f32, cell: vec3i) -> f32 {
    media_lookups += 1u;
    let medium = media[media_index];
    let lo = vec3u(cell) * medium.super_voxel;
    let hi = min(lo + vec3u(medium.super_voxel - 1u), medium.res - vec3u(1u));
    let v = clamp(vec3u(max(floor(seg_at(s, t)), vec3f(0.0))), lo, hi);
    return density[medium.density_offset + v.x + medium.res.x * (v.y + medium.res.y * v.z)];
}

// μ at t anywhere on the segment (its super-voxel found from the point).
fn mu_point(s: RaySegment, t: f32) -> f32 {
    let cell = clamp(vec3i(floor(seg_at(s, t) / f32(super_voxel_size()))), vec3i(0), vec3i(media[media_index].dims) - vec3i(1));
    return mu_at(s, t, cell);
}

// (P, μ_min) of a super-voxel: Kettunen's mean (variance_aware false) or Eq. 5 with the floor.
fn importance(sv: vec4f, variance_aware: bool) -> vec2f {
    if !variance_aware {
        return vec2f(sv.z, 0.0);
    }
    let p = select(0.0, max(sv.w, IMPORTANCE_FLOOR * sv.y), sv.y > 0.0);
    return vec2f(p, sv.x);
}
