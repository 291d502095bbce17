//! Regression suites (`flicker suite run|bless SUITE.ron`): cases played over seeds, gates on
//! their metrics judged against absolute limits or a blessed per-adapter baseline with Welch's
//! one-sided t-test; results as Markdown, JUnit XML and the exit code.

pub mod baseline;
pub mod gate;
pub mod junit;
pub mod markdown;
pub mod measured;
pub mod measurement;
pub mod metric;
pub mod run;
pub mod spec;
pub mod student_t;
pub mod welch;
pub mod window;

pub use run::{SuiteOptions, SuiteOutcome, bless, run};
pub use spec::Suite;
