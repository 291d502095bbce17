//! Storage and packing of the cache (twin of shaders/storage.wgsl), and the mask
//! invariants every frame must keep.
//!
//! Slot s of pixel p is element `s * pixels + p` (one layer per slot index). A slot is 32 bytes:
//! the packed first hit `[instance, primitive, bits(b1), bits(b2)]` and `[L_s.rgb, c_s]`.
//! Listing 1 of the paper packs 32-bit barycentrics and then ORs material bits over their top
//! byte, corrupting them; we keep full f32 barycentrics in a plain vec4<u32> and store no material
//! (it is the instance's). A background sample is `[NO_HIT, bits(dir.xyz)]`.
//! The mask holds occupancy in bits 0..N and visibility in bits N..2N.

use glam::{Vec2, Vec3};

use render::path_tracer::NO_HIT;

render::gpu_struct! {
    /// One cached sample: its hit (see the accessors) and rgb: accumulated radiance L_s, w:
    /// sample count c_s.
    #[derive(Default, PartialEq)]
    pub struct SscSlot {
        pub hit: [u32; 4] => "vec4u",
        pub radiance: [f32; 4] => "vec4f",
    }
}

/// The former name of [`SscSlot`].
pub type GpuSlot = SscSlot;

const _: () = assert!(size_of::<SscSlot>() == 32);

/// A decoded cached sample.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum CachedHit {
    Surface { instance: u32, primitive: u32, barycentrics: Vec2 },
    Background { direction: Vec3 },
}

impl SscSlot {
    pub fn decode(&self) -> CachedHit {
        let h = self.hit;
        if h[0] == NO_HIT {
            CachedHit::Background {
                direction: Vec3::new(
                    f32::from_bits(h[1]),
                    f32::from_bits(h[2]),
                    f32::from_bits(h[3]),
                ),
            }
        } else {
            CachedHit::Surface {
                instance: h[0],
                primitive: h[1],
                barycentrics: Vec2::new(f32::from_bits(h[2]), f32::from_bits(h[3])),
            }
        }
    }

    pub fn count(&self) -> f32 {
        self.radiance[3]
    }
}

pub fn occupancy(mask: u32, n: u32) -> u32 {
    mask & ((1u32 << n) - 1)
}

pub fn visibility(mask: u32, n: u32) -> u32 {
    (mask >> n) & ((1u32 << n) - 1)
}

/// The invariants of a final mask (after retrace): visible implies occupied, at least one visible
/// sample (every pixel is covered: background samples cover the sky), at most N samples, unused
/// bits zero, and occupied slots packed first (canonical compaction).
pub fn check_mask(mask: u32, n: u32) -> Result<(), String> {
    let (o, v) = (occupancy(mask, n), visibility(mask, n));
    if 2 * n < 32 && mask >> (2 * n) != 0 {
        return Err(format!("mask {mask:#010x}: bits above 2N = {} set", 2 * n));
    }
    if v & !o != 0 {
        return Err(format!("mask {mask:#010x}: visible but unoccupied slots {:#x}", v & !o));
    }
    if v == 0 {
        return Err(format!("mask {mask:#010x}: no visible sample"));
    }
    if o.count_ones() > n {
        return Err(format!("mask {mask:#010x}: more than N = {n} samples"));
    }
    if o & (o + 1) != 0 {
        return Err(format!("mask {mask:#010x}: occupied slots not packed first"));
    }
    Ok(())
}
