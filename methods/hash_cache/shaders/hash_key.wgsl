// Voxel keys of the world-space hash cache: level of detail from the pixel footprint at the
// point's camera distance (and its incidence angle), voxel jitter in the tangent plane, the
// normal's major axis, and two hashes of the voxel (home slot, checksum).
// Mirrored bit for bit by src/key.rs.

import package::pt_sampling::{basis_bitangent, basis_tangent, hash_mix, pcg_hash};
import package::hash_cache_bindings::{hc};

const HC_EMPTY: u32 = 0u;
const HC_NONE: u32 = 0xffffffffu;
const HC_LEVEL_BIAS: i32 = 64;
const HC_MIN_COSINE: f32 = 0.25;

struct VoxelKey {
    home: u32,
    checksum: u32,
}

// Index 0..5 of the normal's dominant axis and sign (+x, -x, +y, -y, +z, -z).
fn hc_normal_axis(n: vec3f) -> u32 {
    let a = abs(n);
    if a.x >= a.y && a.x >= a.z {
        return select(1u, 0u, n.x >= 0.0);
    }
    if a.y >= a.z {
        return select(3u, 2u, n.y >= 0.0);
    }
    return select(5u, 4u, n.z >= 0.0);
}

// Voxel size exponent: the largest power of two <= lod_scale x pixel footprint at `distance`
// (sub-pixel voxels at lod_scale 1, the paper's choice), widened at grazing incidence
// (1 / max(|cos|, HC_MIN_COSINE)) when normal_lod is on.
fn hc_level(distance: f32, cos_incidence: f32) -> i32 {
    var footprint = distance * hc.pixel_angle * hc.lod_scale;
    if hc.normal_lod != 0u {
        footprint /= max(abs(cos_incidence), HC_MIN_COSINE);
    }
    return clamp(i32(floor(log2(max(footprint, 1.0e-30)))), -HC_LEVEL_BIAS, HC_LEVEL_BIAS - 1);
}

fn hc_key(p: vec3f, n: vec3f, level: i32, jitter: vec2f) -> VoxelKey {
    let size = exp2(f32(level));
    var q = p;
    if hc.jitter != 0u {
        q += size * ((jitter.x - 0.5) * basis_tangent(n) + (jitter.y - 0.5) * basis_bitangent(n));
    }
    let cell = vec3i(floor(q / size));
    let tag = u32(level + HC_LEVEL_BIAS) | (hc_normal_axis(n) << 8u);
    var h = hash_mix(u32(cell.x) ^ 0x68e31da4u);
    h = hash_mix(h ^ u32(cell.y));
    h = hash_mix(h ^ u32(cell.z));
    h = hash_mix(h ^ tag);
    var c = pcg_hash(u32(cell.x) + pcg_hash(u32(cell.y) + pcg_hash(u32(cell.z) + pcg_hash(tag))));
    if c == HC_EMPTY {
        c = 1u;
    }
    return VoxelKey(h % hc.capacity, c);
}
