//! `cargo run --release -p metrics --example jod_time -- W H FRAMES [THREADS]`: milliseconds per
//! frame of ColorVideoVDP on a video of synthetic HDR pairs (fresh noise per frame), best of 3,
//! for comparing with `scripts/cvvdp_fixtures.py time W H FRAMES` (cvvdp on the CPU).

use std::time::Instant;

fn main() -> anyhow::Result<()> {
    let args: Vec<u32> = std::env::args().skip(1).map(|a| a.parse()).collect::<Result<_, _>>()?;
    let [w, h, n, rest @ ..] = args.as_slice() else {
        anyhow::bail!("usage: jod_time WIDTH HEIGHT FRAMES [THREADS]")
    };
    if let Some(&t) = rest.first() {
        rayon::ThreadPoolBuilder::new().num_threads(t as usize).build_global()?;
    }
    let pairs: Vec<_> =
        (0..*n).map(|f| metrics::synthetic::synthetic_hdr_pair(*w, *h, 7 + f)).collect();
    let reference: Vec<_> = pairs.iter().map(|p| p.0.clone()).collect();
    let test: Vec<_> = pairs.iter().map(|p| p.1.clone()).collect();
    let settings = metrics::CvvdpSettings::default();
    let mut best = f64::INFINITY;
    let mut jod = 0.0;
    for _ in 0..3 {
        let t = Instant::now();
        jod = metrics::jod(&reference, &test, 30.0, &settings, false)?.jod;
        best = best.min(t.elapsed().as_secs_f64());
    }
    println!(
        "{w}x{h}, {n} frames, {} threads: {:.1} ms per frame, JOD {jod:.4}",
        rayon::current_num_threads(),
        best * 1e3 / *n as f64
    );
    Ok(())
}
