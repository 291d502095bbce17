//! The structs NIRC shares with its shaders (render::gpu_struct!) have one layout on both sides,
//! as naga lays the WGSL out: every field at the same offset, the same size.

use nirc::cpu::optimizer::{Counters, counters_atomic_wgsl};
use nirc::gpu::{Call, Hyper};
use nirc::integrator::CacheParams;
use nirc::{CacheQuery, ReliabilitySample, TrainingRecord};
use render::gpu_struct::{GpuStruct, layout_mismatches};

#[test]
fn nirc_structs_have_one_layout() {
    for (name, found) in [
        ("Hyper", layout_mismatches::<Hyper>("")),
        ("Call", layout_mismatches::<Call>("")),
        ("TrainingRecord", layout_mismatches::<TrainingRecord>("")),
        ("CacheQuery", layout_mismatches::<CacheQuery>("")),
        ("ReliabilitySample", layout_mismatches::<ReliabilitySample>("")),
        ("Counters", layout_mismatches::<Counters>("")),
        ("CacheParams", layout_mismatches::<CacheParams>("")),
    ] {
        assert!(found.is_empty(), "{name}: {found:?}");
    }
    // The atomic view differs only in its name and the flag's type (same size and alignment).
    let atomic = counters_atomic_wgsl();
    assert_eq!(
        atomic.replace("CountersAtomic", "Counters").replace("atomic<u32>", "u32"),
        Counters::WGSL
    );
    assert!(atomic.contains("flag: atomic<u32>"), "{atomic}");
}
