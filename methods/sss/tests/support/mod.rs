//! Support shared by this crate's tests and examples, not part of the library: the random-walk
//! reference (`random_walk`), the path-traced ground truth of a flat plane built on it
//! (`ground_truth`), the synthetic dynamic scenes (`synthetic`) and Table 7.3's measures
//! (`evaluation`). A test or example uses only some of it.
#![allow(dead_code)]

pub mod evaluation;
pub mod ground_truth;
pub mod random_walk;
pub mod synthetic;
