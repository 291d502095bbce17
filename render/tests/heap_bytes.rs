//! `render::memory::heap_bytes` counts what is held: a test binary of its own, with one test,
//! because the library's other unit tests allocate and free tens of MiB on their threads while
//! it reads (measured: 70 MiB between two readings), which no slack would tell from a fault.

#[test]
#[cfg(all(target_os = "linux", target_env = "gnu"))]
fn heap_bytes_count_a_live_allocation_and_drop_it_when_freed() {
    use render::memory::heap_bytes;
    const MIB: u64 = 1 << 20;
    // Glibc maps a 64 MiB block on its own (above its largest mmap threshold, 32 MiB), so it is
    // counted in `hblkhd`; leaving that out of heap_bytes fails this test.
    let before = heap_bytes().unwrap();
    let block = vec![1u8; (64 * MIB) as usize];
    let held = heap_bytes().unwrap();
    drop(std::hint::black_box(block));
    let after = heap_bytes().unwrap();
    assert!(held >= before + 63 * MIB, "holding 64 MiB: {before} -> {held} bytes");
    assert!(after + 63 * MIB <= held, "64 MiB freed: {held} -> {after} bytes");
}
