// Step counters (CPU mirror: `Counters` in src/cpu/optimizer.rs). `flag` is raised by any pass
// of a training step that meets a non-finite value; finish_step.wgsl commits or rolls back.
struct CountersAtomic {
    step: u32,
    rejected_steps: u32,
    grid_updates: u32,
    flag: atomic<u32>,
    beta1_pow: f32,
    beta2_pow: f32,
    alpha_pow: f32,
    pad: u32,
}

struct Counters {
    step: u32,
    rejected_steps: u32,
    grid_updates: u32,
    flag: u32,
    beta1_pow: f32,
    beta2_pow: f32,
    alpha_pow: f32,
    pad: u32,
}
