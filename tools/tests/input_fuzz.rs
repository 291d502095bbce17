//! Byte mutations of every binary or generated input a run reads: a glTF scene (its JSON, its
//! embedded buffers and texture, and the same scene as a .glb), the EXR and PNG frames that
//! `flicker measure` reads, and the manifest.json and frames.csv that `flicker run --resume`
//! reads. Whatever the bytes, the reader returns a valid result or an error that names the file
//! (and the line, column, part or frame where the format has one); it never panics.
//! PROPTEST_CASES sets the cases per input (default 300).

use std::path::{Path, PathBuf};

use proptest::prelude::*;
use proptest::sample::Index;
use proptest::test_runner::{Config, TestRunner};

/// A fixed seed, so that CI runs the same cases each time; PROPTEST_RNG_SEED explores others.
fn rng_seed() -> proptest::test_runner::RngSeed {
    match std::env::var("PROPTEST_RNG_SEED").ok().and_then(|v| v.parse().ok()) {
        Some(seed) => proptest::test_runner::RngSeed::Fixed(seed),
        None => proptest::test_runner::RngSeed::Fixed(0x1f_0c4e),
    }
}

/// Byte strings that the readers treat specially: JSON and CSV syntax, numbers at the edge of
/// their type, glTF's keys and enums.
const TOKENS: &[&[u8]] = &[
    b"NaN",
    b"-1",
    b"0",
    b"1e39",
    b"-1e39",
    b"4294967295",
    b"4294967296",
    b"18446744073709551616",
    b"null",
    b"true",
    b"[]",
    b"{}",
    b"\"",
    b",",
    b":",
    b"\n",
    b"\\u0000",
    b"\xff\xfe",
    b"\"count\": 4294967295",
    b"\"byteOffset\": 1000000",
    b"\"byteLength\": 0",
    b"\"bufferView\": 99",
    b"\"componentType\": 5125",
    b"\"mode\": 4",
    b"\"status\": \"failed\"",
    b"\"frames\": 100000",
    b"pt,99999",
];

/// A little-endian u32 that headers and buffers treat specially (sizes, NaN, infinity).
const WORDS: &[u32] =
    &[0, 1, 0x7fff_ffff, 0xffff_ffff, 0x7fc0_0000, 0x7f80_0000, 0xff80_0000, 65536];

#[derive(Clone, Debug)]
enum Mutation {
    Flip(Index, u8),
    Delete(Index, usize),
    Insert(Index, usize),
    Duplicate(Index, usize),
    Word(Index, usize),
    Truncate(Index),
}

fn mutation() -> impl Strategy<Value = Mutation> {
    prop_oneof![
        4 => (any::<Index>(), any::<u8>()).prop_map(|(at, b)| Mutation::Flip(at, b)),
        1 => (any::<Index>(), 1..32usize).prop_map(|(at, n)| Mutation::Delete(at, n)),
        2 => (any::<Index>(), 0..TOKENS.len()).prop_map(|(at, t)| Mutation::Insert(at, t)),
        1 => (any::<Index>(), 1..64usize).prop_map(|(at, n)| Mutation::Duplicate(at, n)),
        3 => (any::<Index>(), 0..WORDS.len()).prop_map(|(at, w)| Mutation::Word(at, w)),
        1 => any::<Index>().prop_map(Mutation::Truncate),
    ]
}

/// `bytes` with `mutations` applied; positions fall in `region` (a byte range of `bytes`, e.g. a
/// GLB's binary chunk) when it is given, anywhere otherwise.
fn apply(bytes: &[u8], mutations: &[Mutation], region: Option<(usize, usize)>) -> Vec<u8> {
    let mut b = bytes.to_vec();
    for m in mutations {
        let (lo, hi) = region.unwrap_or((0, b.len()));
        let (lo, hi) = (lo.min(b.len()), hi.min(b.len()));
        if hi <= lo {
            continue;
        }
        let at = |i: &Index| lo + i.index(hi - lo);
        match m {
            Mutation::Flip(i, v) => {
                let s = at(i);
                b[s] = *v;
            }
            Mutation::Delete(i, n) => {
                let s = at(i);
                b.drain(s..(s + n).min(b.len()));
            }
            Mutation::Insert(i, t) => {
                let s = at(i);
                b.splice(s..s, TOKENS[*t].iter().copied());
            }
            Mutation::Duplicate(i, n) => {
                let s = at(i);
                let piece = b[s..(s + n).min(b.len())].to_vec();
                b.splice(s..s, piece);
            }
            Mutation::Word(i, w) => {
                let s = at(i);
                for (k, byte) in WORDS[*w].to_le_bytes().into_iter().enumerate() {
                    if let Some(x) = b.get_mut(s + k) {
                        *x = byte;
                    }
                }
            }
            Mutation::Truncate(i) => b.truncate(at(i)),
        }
    }
    b
}

fn cases() -> u32 {
    std::env::var("PROPTEST_CASES").ok().and_then(|v| v.parse().ok()).unwrap_or(300)
}

fn scratch(name: &str) -> tempfile::TempDir {
    tempfile::Builder::new().prefix(&format!("flicker-input-fuzz-{name}-")).tempdir().unwrap()
}

/// Writes each mutation of `original` to `target` and runs `read`, which returns the error's
/// text, `Ok` when the mutated input is still valid. Every error must contain `names` (the
/// file, and what locates the fault where the format has it, checked by `located`).
fn fuzz(
    original: &[u8],
    region: Option<(usize, usize)>,
    target: &Path,
    read: impl Fn() -> Result<(), String>,
    located: impl Fn(&str) -> bool,
) {
    let config = Config {
        cases: cases(),
        failure_persistence: None,
        rng_seed: rng_seed(),
        ..Config::default()
    };
    let (valid, errors) = (std::cell::Cell::new(0u32), std::cell::Cell::new(0u32));
    let name = target.display().to_string();
    TestRunner::new(config)
        .run(&prop::collection::vec(mutation(), 1..5), |mutations| {
            std::fs::write(target, apply(original, &mutations, region)).unwrap();
            match read() {
                Ok(()) => valid.set(valid.get() + 1),
                Err(e) => {
                    errors.set(errors.get() + 1);
                    prop_assert!(e.contains(&name), "the error does not name {name}: {e}");
                    prop_assert!(located(&e), "the error does not locate the fault: {e}");
                }
            }
            Ok(())
        })
        .unwrap_or_else(|e| panic!("{e}"));
    // The mutations reach both outcomes (a fuzzer whose every input fails tests one branch).
    let (valid, errors) = (valid.get(), errors.get());
    eprintln!("{name}: {valid} valid, {errors} errors");
    assert!(errors > 0 && valid > 0, "{name}: {valid} valid, {errors} errors");
}

fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("..")
}

/// What an imported scene promises the renderer: finite numbers, indices in range, meshes a
/// BVH is built over.
fn check_template(t: &sim::template::WorldTemplate) -> Result<(), String> {
    for (i, mesh) in t.meshes.iter().enumerate() {
        let finite = mesh.positions.iter().all(|p| p.is_finite())
            && mesh.normals.iter().all(|n| n.is_finite())
            && mesh.uvs.iter().all(|u| u.is_finite());
        assert!(finite, "mesh {i} has a non-finite vertex");
        render::bvh::Blas::build(i, mesh).map_err(|e| format!("imported, then: {e}"))?;
    }
    for node in &t.nodes {
        let tr = &node.transform;
        let finite = tr.translation.is_finite() && tr.rotation.is_finite() && tr.scale.is_finite();
        assert!(finite, "node '{}' has a non-finite transform", node.name);
    }
    for m in &t.materials.materials {
        let numbers = [m.base_color.is_finite(), m.emission.is_finite(), m.roughness.is_finite()];
        assert!(numbers.iter().all(|&b| b) && m.metallic.is_finite(), "{m:?}");
    }
    Ok(())
}

#[test]
fn gltf_scenes() {
    let tmp = scratch("gltf");
    let dir = tmp.path().to_path_buf();
    let original = std::fs::read(root().join("scenarios/assets/test_scene.gltf")).unwrap();
    let import = |path: &Path| -> Result<(), String> {
        let t = sim::gltf_import::import(path).map_err(|e| e.to_string())?;
        check_template(&t).map_err(|e| format!("{}: {e}", path.display()))
    };
    // The JSON structure (before the first data URI), then the whole file with the base64
    // buffer and texture it embeds.
    let gltf = dir.join("scene.gltf");
    let structure = original.windows(5).position(|w| w == b"data:").unwrap();
    fuzz(&original, Some((0, structure)), &gltf, || import(&gltf), |_| true);
    fuzz(&original, None, &gltf, || import(&gltf), |_| true);

    // The same scene as a .glb: the binary chunk's bytes, then the header and the JSON.
    std::fs::write(&gltf, &original).unwrap();
    let (doc, buffers, _) = gltf::import(&gltf).unwrap();
    let mut json = doc.into_json();
    json.buffers[0].uri = None;
    let bin = buffers[0].0.clone();
    json.buffers[0].byte_length = (bin.len() as u64).into();
    json.images.clear();
    json.textures.clear();
    for m in &mut json.materials {
        m.pbr_metallic_roughness.base_color_texture = None;
    }
    let json_bytes = serde_json::to_vec(&json).unwrap();
    let glb = gltf::Glb {
        header: gltf::binary::Header { magic: *b"glTF", version: 2, length: 0 },
        json: std::borrow::Cow::Owned(json_bytes),
        bin: Some(std::borrow::Cow::Owned(bin.clone())),
    }
    .to_vec()
    .unwrap();
    let path = dir.join("scene.glb");
    std::fs::write(&path, &glb).unwrap();
    import(&path).expect("the unmutated .glb imports");
    let bin_at = glb.len() - bin.len();
    fuzz(&glb, Some((bin_at, glb.len())), &path, || import(&path), |_| true);
    fuzz(&glb, Some((0, bin_at)), &path, || import(&path), |_| true);
}

/// An 8x8 frame with a gradient (SMAPE and FLIP see something).
fn frame(seed: f32) -> Vec<[f32; 4]> {
    (0..64).map(|i| [i as f32 / 64.0 * seed, 0.5, (64 - i) as f32 / 64.0, 1.0]).collect()
}

#[test]
fn frames_that_measure_reads() {
    use frame::output::{write_exr, write_png};
    let tmp = scratch("measure");
    let dir = tmp.path().to_path_buf();
    for kind in ["exr", "png"] {
        let (reference, test) = (dir.join(format!("ref_{kind}")), dir.join(format!("test_{kind}")));
        for (folder, seed) in [(&reference, 1.0), (&test, 0.9)] {
            for f in 0..2 {
                let file = folder.join(format!("{f:04}.{kind}"));
                let rgba = frame(seed + f as f32 * 0.05);
                match kind {
                    "exr" => write_exr(&file, 8, 8, &rgba).unwrap(),
                    _ => write_png(&file, 8, 8, &rgba, 1.0).unwrap(),
                }
            }
        }
        let opts = tools::measure::MeasureOptions {
            reference,
            tests: vec![("test".into(), test.clone())],
            motion: Vec::new(),
            timings: Vec::new(),
            fps: 30.0,
            events: Vec::new(),
            labels: Vec::new(),
            out: dir.join("out"),
            cvvdp: Default::default(),
            smape_epsilon: 0.01,
        };
        let target = test.join(format!("0001.{kind}"));
        let original = std::fs::read(&target).unwrap();
        let read =
            || tools::measure::Measured::read(&opts).map(|_| ()).map_err(|e| format!("{e:#}"));
        read().expect("the unmutated frames are measured");
        fuzz(&original, None, &target, read, |e| e.contains("frame 1"));
    }
}

/// "FILE:LINE" or "FILE:LINE:COLUMN" somewhere in `e`, for the file named `name`.
fn has_line(e: &str, name: &str) -> bool {
    e.split(name).skip(1).any(|rest| {
        rest.strip_prefix(':')
            .and_then(|r| r.split(|c: char| !c.is_ascii_digit()).next())
            .is_some_and(|n| !n.is_empty())
    })
}

#[test]
fn what_resume_reads() {
    use frame::frame_record::{FrameRecord, to_csv};
    let tmp = scratch("resume");
    let dir = tmp.path().to_path_buf();
    let scenario = dir.join("tiny.ron");
    std::fs::write(
        &scenario,
        "Scenario(scene: Builtin(\"cornell_box\"), resolution: (8, 8), frames: 3,\n  reference: (spp: 1, frames: List([])),\n  methods: [PathTracing(spp: 1), Taa()])",
    )
    .unwrap();
    let run = dir.join("run");
    let overrides = playback::scenario::Overrides { out: Some(run.clone()), ..Default::default() };
    let spec = playback::scenario::RunSpec::load(&scenario, &overrides).unwrap();
    // The manifest as a run writes it, stopped after frame 1.
    let gpu = render::gpu::Gpu::new().unwrap();
    let mut manifest = playback::manifest::build(&spec, &scenario, &gpu, &overrides).unwrap();
    drop(gpu);
    playback::manifest::set_status(&mut manifest, playback::manifest::Status::Interrupted, Some(1));
    let manifest = serde_json::to_string_pretty(&manifest).unwrap();
    let rows: Vec<FrameRecord> = (0..2)
        .flat_map(|frame| {
            ["pt_1spp", "taa_1spp"].map(|method| FrameRecord {
                method: method.into(),
                frame,
                cpu_ms: 1.5,
                passes: vec![("trace".into(), Some(0.25))],
                smape: Some(0.125),
                ..Default::default()
            })
        })
        .collect();
    let csv = to_csv(&rows);
    std::fs::create_dir_all(&run).unwrap();
    let (manifest_file, csv_file) = (run.join("manifest.json"), run.join("frames.csv"));
    std::fs::write(&manifest_file, &manifest).unwrap();
    std::fs::write(&csv_file, &csv).unwrap();
    // A run folder read is one that resumes within the run: at most its frames are on disk.
    let read = || {
        let stored = playback::resume::read(&run).map_err(|e| format!("{e:#}"))?;
        assert!(stored.from <= stored.spec.scenario.frames, "resumes at frame {}", stored.from);
        Ok(())
    };
    let stored = playback::resume::read(&run).expect("the unmutated run folder reads");
    assert_eq!(stored.from, 2);

    // A JSON syntax error has a line and column; a field's error names the field.
    let name = manifest_file.display().to_string();
    let json_located = |e: &str| !e.contains("not valid JSON") || has_line(e, &name);
    fuzz(manifest.as_bytes(), None, &manifest_file, read, json_located);
    std::fs::write(&manifest_file, &manifest).unwrap();
    // A cell's error has the line (the reader reads the frame column of the last row).
    let name = csv_file.display().to_string();
    fuzz(csv.as_bytes(), None, &csv_file, read, |e| has_line(e, &name) || e.contains("header"));
}
