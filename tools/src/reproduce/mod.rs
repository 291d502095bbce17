//! `flicker reproduce PAPER|all`: each seed paper's headline claims (`claims/PAPER.ron`), played
//! over seeds through the suite machinery, each judged reproduced / not reproduced /
//! inconclusive against its smallest effect that matters (or not comparable, with the reason),
//! written as reproduce.md and reproduce.html beside the paper's numbers.

pub mod alone;
pub mod by_window;
pub mod case_methods;
pub mod claims;
pub mod computation;
pub mod distributed;
pub mod effect;
pub mod events;
pub mod folder_statistic;
pub mod frame_columns;
pub mod frames_csv;
pub mod judge;
pub mod log_ratio;
pub mod pass_ms;
pub mod report;
pub mod run;
pub mod table;
pub mod verdict;

pub use claims::{Claim, Claims, Comparison, Scale};
pub use effect::Effect;
pub use judge::judge;
pub use run::{ClaimOutcome, ReproduceOptions, ReproduceOutcome, reproduce};
pub use verdict::{Judged, Verdict};
