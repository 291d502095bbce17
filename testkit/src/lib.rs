//! What the tests of several crates share and no product code uses: the relation check over
//! seeds that the methods' end-to-end tests make (`relations`), chi-square tests of sampling
//! routines (`chi2`), and small scenes on the GPU (`test_scenes`).

pub mod chi2;
pub mod relations;
pub mod test_scenes;
