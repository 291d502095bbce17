//! Voxel keys of the hash cache on the CPU, bit for bit as methods/hash_cache/shaders/hash_key.wgsl:
//! level of detail, voxel jitter, normal axis, home slot and checksum.

use glam::{IVec3, Vec2, Vec3};

/// Checksum of an empty slot.
pub const EMPTY: u32 = 0;
/// "No slot" (a pixel without a cell, an unclaimed cell).
pub const NONE: u32 = u32::MAX;
pub const LEVEL_BIAS: i32 = 64;
/// Incidence cosine below which the normal-based LOD stops widening voxels.
pub const MIN_COSINE: f32 = 0.25;

/// The parts of the cache settings a key depends on.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct KeyParams {
    pub capacity: u32,
    /// 2 tan(vfov / 2) / height: pixel footprint per unit of distance.
    pub pixel_angle: f32,
    pub lod_scale: f32,
    pub normal_lod: bool,
    pub jitter: bool,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct VoxelKey {
    /// First slot of the probe sequence.
    pub home: u32,
    /// Second, independent hash stored in the slot; never [`EMPTY`].
    pub checksum: u32,
}

pub fn pcg_hash(v: u32) -> u32 {
    let state = v.wrapping_mul(747796405).wrapping_add(2891336453);
    let word = ((state >> ((state >> 28) + 4)) ^ state).wrapping_mul(277803737);
    (word >> 22) ^ word
}

pub fn hash_mix(v: u32) -> u32 {
    let mut x = v;
    x ^= x >> 16;
    x = x.wrapping_mul(0x7feb352d);
    x ^= x >> 15;
    x = x.wrapping_mul(0x846ca68b);
    x ^= x >> 16;
    x
}

/// The tangent frame of pt_sampling.wgsl (Duff et al. 2017).
pub fn basis_tangent(n: Vec3) -> Vec3 {
    let s = if n.z >= 0.0 { 1.0 } else { -1.0 };
    let a = -1.0 / (s + n.z);
    let b = n.x * n.y * a;
    Vec3::new(1.0 + s * n.x * n.x * a, s * b, -s * n.x)
}

pub fn basis_bitangent(n: Vec3) -> Vec3 {
    let s = if n.z >= 0.0 { 1.0 } else { -1.0 };
    let a = -1.0 / (s + n.z);
    let b = n.x * n.y * a;
    Vec3::new(b, s + n.y * n.y * a, -n.y)
}

/// 0..5 for +x, -x, +y, -y, +z, -z: the dominant axis of `n` and its sign.
pub fn normal_axis(n: Vec3) -> u32 {
    let a = n.abs();
    if a.x >= a.y && a.x >= a.z {
        return if n.x >= 0.0 { 0 } else { 1 };
    }
    if a.y >= a.z {
        return if n.y >= 0.0 { 2 } else { 3 };
    }
    if n.z >= 0.0 { 4 } else { 5 }
}

/// Voxel size exponent: the largest power of two not above lod_scale x the pixel footprint at
/// `distance`, divided by max(|cos|, MIN_COSINE) with the normal-based LOD. At lod_scale 1 a
/// voxel is smaller than a pixel (in (1/2, 1] footprints), as the paper chooses (§5).
pub fn level(p: &KeyParams, distance: f32, cos_incidence: f32) -> i32 {
    let mut footprint = distance * p.pixel_angle * p.lod_scale;
    if p.normal_lod {
        footprint /= cos_incidence.abs().max(MIN_COSINE);
    }
    (footprint.max(1.0e-30).log2().floor() as i32).clamp(-LEVEL_BIAS, LEVEL_BIAS - 1)
}

/// Integer voxel of point `x` (jittered in the tangent plane by `jitter` in [0, 1]^2).
pub fn voxel(p: &KeyParams, x: Vec3, n: Vec3, level: i32, jitter: Vec2) -> IVec3 {
    let size = (level as f32).exp2();
    let mut q = x;
    if p.jitter {
        q += size * ((jitter.x - 0.5) * basis_tangent(n) + (jitter.y - 0.5) * basis_bitangent(n));
    }
    (q / size).floor().as_ivec3()
}

pub fn key(p: &KeyParams, x: Vec3, n: Vec3, level: i32, jitter: Vec2) -> VoxelKey {
    let cell = voxel(p, x, n, level, jitter);
    let tag = (level + LEVEL_BIAS) as u32 | (normal_axis(n) << 8);
    let (cx, cy, cz) = (cell.x as u32, cell.y as u32, cell.z as u32);
    let mut h = hash_mix(cx ^ 0x68e31da4);
    h = hash_mix(h ^ cy);
    h = hash_mix(h ^ cz);
    h = hash_mix(h ^ tag);
    let mut c = pcg_hash(
        cx.wrapping_add(pcg_hash(cy.wrapping_add(pcg_hash(cz.wrapping_add(pcg_hash(tag)))))),
    );
    if c == EMPTY {
        c = 1;
    }
    VoxelKey { home: h % p.capacity, checksum: c }
}

/// WGSL `unpack2x16unorm`.
pub fn unpack2x16unorm(v: u32) -> Vec2 {
    Vec2::new((v & 0xffff) as f32 / 65535.0, (v >> 16) as f32 / 65535.0)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn params() -> KeyParams {
        KeyParams {
            capacity: 1 << 16,
            pixel_angle: 0.01,
            lod_scale: 1.0,
            normal_lod: true,
            jitter: false,
        }
    }

    #[test]
    fn level_grows_with_distance_and_grazing_incidence() {
        let p = params();
        // Footprint 0.01 at distance 1: 2^-7 = 0.0078 <= 0.01 < 2^-6 (sub-pixel voxels).
        assert_eq!(level(&p, 1.0, 1.0), -7);
        assert_eq!(level(&p, 2.0, 1.0), -6);
        assert_eq!(level(&p, 1.0, 0.5), -6);
        // Grazing angles stop widening at MIN_COSINE.
        assert_eq!(level(&p, 1.0, 0.01), level(&p, 1.0, MIN_COSINE));
        assert_eq!(level(&KeyParams { normal_lod: false, ..p }, 1.0, 0.01), -7);
        // Never larger than the footprint, never smaller than half of it.
        for d in [0.3f32, 1.0, 1.7, 5.0, 40.0] {
            let size = (level(&p, d, 1.0) as f32).exp2();
            assert!(size <= d * 0.01 && size > 0.5 * d * 0.01, "distance {d}: voxel {size}");
        }
    }

    #[test]
    fn points_of_one_voxel_share_a_key_and_neighbours_do_not() {
        let p = params();
        let n = Vec3::Y;
        let a = key(&p, Vec3::new(0.1, 0.0, 0.1), n, -3, Vec2::ZERO);
        assert_eq!(a, key(&p, Vec3::new(0.12, 0.01, 0.124), n, -3, Vec2::ZERO));
        assert_ne!(a, key(&p, Vec3::new(0.126, 0.0, 0.1), n, -3, Vec2::ZERO));
        // The same voxel at another level, or seen from below, is another cell.
        assert_ne!(a, key(&p, Vec3::new(0.1, 0.0, 0.1), n, -2, Vec2::ZERO));
        assert_ne!(a, key(&p, Vec3::new(0.1, 0.0, 0.1), -n, -3, Vec2::ZERO));
        assert!(a.home < p.capacity && a.checksum != EMPTY);
    }

    #[test]
    fn jitter_moves_lookups_by_at_most_one_voxel_in_the_tangent_plane() {
        let p = KeyParams { jitter: true, ..params() };
        let n = Vec3::new(0.3, 0.9, -0.2).normalize();
        let x = Vec3::new(0.37, 0.11, -0.52);
        let centre = voxel(&p, x, n, -3, Vec2::splat(0.5));
        for j in [Vec2::ZERO, Vec2::ONE, Vec2::new(0.0, 1.0)] {
            let v = voxel(&p, x, n, -3, j);
            assert!((v - centre).abs().max_element() <= 1, "{v} vs {centre}");
        }
    }
}
