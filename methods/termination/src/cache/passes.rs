//! The cache's passes: their names (frames.csv's columns), their order and the insertion's
//! rounds.

pub const TC_PROPAGATE_PASS: &str = "tc_propagate";
pub const TC_FOLD_PASS: &str = "tc_fold";
pub const TC_TRACE_PASS: &str = "tc_trace";
pub const TC_STORE_PASS: &str = "tc_store";
/// The insertion of the frame's new keys: [`INSERT_ROUNDS`] claim and win dispatches and one
/// settle dispatch, timed as one pass.
pub const TC_INSERT_PASS: &str = "tc_insert";
/// Pass names, in the order of [`TcPass`].
pub(super) const PASSES: [&str; 5] =
    [TC_PROPAGATE_PASS, TC_FOLD_PASS, TC_TRACE_PASS, TC_INSERT_PASS, TC_STORE_PASS];
/// Entry points (indices of the pipelines): one per pass of [`PASSES`] but the insertion, whose
/// three follow.
pub(super) const ENTRY_POINTS: [&str; 7] = [
    TC_PROPAGATE_PASS,
    TC_FOLD_PASS,
    TC_TRACE_PASS,
    TC_STORE_PASS,
    "tc_insert_claim",
    "tc_insert_win",
    "tc_insert_settle",
];
/// Rounds of claim and win per frame: a request whose claim loses to another key's this many
/// times fails, as one whose probe window is full does (both counted in `insert_failures`).
/// A request loses a round only to another new key claiming the same empty slot in the same
/// frame, so rounds beyond a few settle nothing: at most the probe window's length are needed.
pub const INSERT_ROUNDS: u32 = 8;
/// Threads per workgroup of the insertion passes (`TC_INSERT_WORKGROUP`).
pub(super) const INSERT_WORKGROUP: u64 = 256;
/// Header words of `inserts` (indirect workgroups x, y, z; the request count).
pub(super) const INSERT_HEADER: [u32; 4] = [0, 1, 1, 0];

/// The cache's passes in frame order; each is timed under its name (frames.csv's column).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum TcPass {
    /// Per stored vertex: new estimates at the stored vertices.
    Propagate,
    /// Per record: the estimates folded into the record's moments.
    Fold,
    /// Per pixel: the image, the rule deciding at every vertex over the folded records.
    Trace,
    /// Per insertion request (a candidate vertex whose key has no slot): new keys get slots.
    Insert,
    /// Per record: the winning candidate becomes a stored vertex, for the next frame.
    Store,
}

impl TcPass {
    /// The passes before the image, in one submission.
    pub const UPDATE: [TcPass; 2] = [TcPass::Propagate, TcPass::Fold];
    /// The passes after the image, in one submission.
    pub const STORE: [TcPass; 2] = [TcPass::Insert, TcPass::Store];

    pub fn name(self) -> &'static str {
        PASSES[self as usize]
    }
}
