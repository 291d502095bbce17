// Order-independent sums of f32 (CPU mirror: src/fixed_sum.rs). A value is converted exactly to
// a 96-bit two's-complement integer with 48 fractional bits and added word by word with
// atomicAdd, carrying by hand: integer addition is associative, so the total does not depend on
// the order the threads run in. The pass's bindings (package::nirc::bindings) declare
// `accum: array<atomic<u32>>` (lo, mid, hi).

import package::nirc::bindings::{accum};
import package::nirc::bindings_common::{is_finite};

// |x| >= 2^32 is refused; 2^15 such values cannot overflow the 96 bits.
const FIXED_MAX_EXPONENT: u32 = 158u;

// Adds x to the accumulator whose lo word is accum[base]. False if x is not finite or too large.
fn fixed_add(base: u32, x: f32) -> bool {
    let bits = bitcast<u32>(x);
    let e = (bits >> 23u) & 0xffu;
    if e == 0xffu || e > FIXED_MAX_EXPONENT {
        return false;
    }
    if e == 0u {
        return true; // zero or subnormal: below 2^-48
    }
    // x = m * 2^(e - 150); fixed = x * 2^48 = m * 2^(e - 102).
    var m = (bits & 0x7fffffu) | 0x800000u;
    var shift = i32(e) - 102;
    if shift < 0 {
        if shift <= -24 {
            return true;
        }
        m = m >> u32(-shift); // truncation toward zero of the magnitude
        shift = 0;
    }
    let q = u32(shift) / 32u;
    let r = u32(shift) % 32u;
    let low = m << r;
    let high = select(m >> (32u - r), 0u, r == 0u);
    // Word q gets low, word q + 1 high; selects rather than an indexed array (lavapipe keeps a
    // dynamically indexed private array in memory).
    var w0 = select(0u, low, q == 0u);
    var w1 = select(select(0u, high, q == 0u), low, q == 1u);
    var w2 = select(select(0u, high, q == 1u), low, q == 2u);
    if (bits >> 31u) == 1u {
        // Two's complement negation of the 96 bits.
        w0 = ~w0 + 1u;
        w1 = ~w1 + select(0u, 1u, w0 == 0u);
        w2 = ~w2 + select(0u, 1u, w0 == 0u && w1 == 0u);
    }
    fixed_add_words(base, w0, w1, w2);
    return true;
}

fn fixed_add_words(base: u32, w0: u32, w1: u32, w2: u32) {
    // Adding zero to a word is skipped (on lavapipe each atomic is a loop over the active
    // lanes). Most addends of the upper words are zero: a small value has no middle or high
    // bits, and a small negative one's all-ones upper words plus the carry wrap to zero.
    let old0 = atomicAdd(&accum[base], w0);
    let carry0 = select(0u, 1u, old0 + w0 < old0);
    let w1c = w1 + carry0;
    // w1 = 0xffffffff plus a carry wraps to 0: the carry moves on to the top word.
    let carry_through = select(0u, 1u, w1c < w1);
    var carry1 = 0u;
    if w1c != 0u {
        let old1 = atomicAdd(&accum[base + 1u], w1c);
        carry1 = select(0u, 1u, old1 + w1c < old1);
    }
    let w2c = w2 + carry1 + carry_through;
    if w2c != 0u {
        atomicAdd(&accum[base + 2u], w2c);
    }
}

// Adds x clamped to ±(2^32 - 2^8) (statistics: a firefly must not void a step).
fn fixed_add_clamped(base: u32, x: f32) -> bool {
    if !is_finite(x) {
        return false;
    }
    return fixed_add(base, clamp(x, -4294967040.0, 4294967040.0));
}
