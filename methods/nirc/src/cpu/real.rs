//! The scalar the CPU reference computes in: f32 (the GPU's precision, used for GPU-vs-CPU
//! tests) or f64 (for finite-difference gradient checks).

use std::ops::{Add, AddAssign, Div, Mul, Neg, Sub};

pub trait Real:
    Copy
    + PartialOrd
    + Add<Output = Self>
    + Sub<Output = Self>
    + Mul<Output = Self>
    + Div<Output = Self>
    + Neg<Output = Self>
    + AddAssign
    + std::fmt::Debug
{
    fn from_f32(x: f32) -> Self;
    fn to_f64(self) -> f64;
    fn zero() -> Self {
        Self::from_f32(0.0)
    }
}

impl Real for f32 {
    fn from_f32(x: f32) -> Self {
        x
    }
    fn to_f64(self) -> f64 {
        self as f64
    }
}

impl Real for f64 {
    fn from_f32(x: f32) -> Self {
        x as f64
    }
    fn to_f64(self) -> f64 {
        self
    }
}
