//! What the tests of several crates share and no product code uses: the relation check over
//! seeds that the methods' end-to-end tests make (`relations`).

pub mod relations;
