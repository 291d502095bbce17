//! Parameter sweeps (`flicker sweep plan|job|local|merge|run`): a grid or a list over method
//! parameters, crossed with cases (scenario + overrides, as suite cases) and their seeds. `plan`
//! writes a deterministic job list (one job = one case, one parameter point, one seed, one run
//! folder) and the files of the executors (GNU parallel job file, Slurm array script); each job
//! runs alone (`flicker sweep job DIR --index I`) so a failed one can be rerun; `merge` gathers
//! the finished jobs into summary.json, a speed-vs-accuracy chart with the Pareto front and a
//! report.

pub mod job;
pub mod local;
pub mod merge;
pub mod param;
pub mod plan;
pub mod spec;

pub use job::run_job;
pub use local::run_local;
pub use merge::merge;
pub use plan::{Plan, plan};
pub use spec::Sweep;
