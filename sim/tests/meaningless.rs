//! Values that parse but make a run meaningless are refused at file:line:column with what was
//! expected: property tests generate such values for each field, and their sensible neighbours
//! load. The scene-level refusals (nothing emits, zero-extent geometry) use a one-triangle glTF.

use std::path::{Path, PathBuf};

use proptest::prelude::*;
use sim::{Scenario, Simulation};

/// A fixed seed, so that CI runs the same cases each time; PROPTEST_RNG_SEED explores others.
fn rng_seed() -> proptest::test_runner::RngSeed {
    match std::env::var("PROPTEST_RNG_SEED").ok().and_then(|v| v.parse().ok()) {
        Some(seed) => proptest::test_runner::RngSeed::Fixed(seed),
        None => proptest::test_runner::RngSeed::Fixed(0x3e_a41e),
    }
}

const HEAD: &str = "Scenario(scene: Builtin(\"cornell_box\"), resolution: (16, 8),";

/// A scenario whose line 3 is `field` (with `frames` and `warmup_frames` on line 2).
fn scenario(frames: u32, warmup: u32, field: &str) -> String {
    format!(
        "{HEAD}\n  frames: {frames}, warmup_frames: {warmup}, methods: [PathTracing(spp: 1)],\n  {field},\n)\n"
    )
}

fn load(text: &str) -> Result<Scenario, String> {
    Scenario::from_ron(text, Path::new("dir/s.ron")).map_err(|e| e.to_string())
}

/// The scenario is refused at line 3, at the column of `at` (the first occurrence on the line
/// after `after`), with a message that says what was expected and contains `says`.
fn refused(text: &str, after: &str, at: &str, says: &str) -> Result<(), TestCaseError> {
    let err = match load(text) {
        Ok(_) => return Err(TestCaseError::fail(format!("loaded:\n{text}"))),
        Err(e) => e,
    };
    let line = text.lines().nth(2).unwrap();
    let from = line.find(after).unwrap_or(0);
    let column = from + line[from..].find(at).expect("marker on line 3") + 1;
    let place = format!("dir/s.ron:3:{column}: ");
    prop_assert!(err.starts_with(&place), "expected {place}: {err}\n{text}");
    prop_assert!(err.contains("expected") && err.contains(says), "{err}");
    Ok(())
}

fn loads(text: &str) -> Result<(), TestCaseError> {
    prop_assert!(load(text).is_ok(), "{:?}\n{text}", load(text).err());
    Ok(())
}

/// A vertical field of view that sees nothing: 0 or less, 180 or more.
fn bad_fov() -> impl Strategy<Value = f32> {
    prop_oneof![Just(0.0f32), -1000.0f32..=0.0, 180.0f32..1.0e4, Just(180.0f32)]
}

fn vec3(range: std::ops::Range<f32>) -> impl Strategy<Value = (f32, f32, f32)> {
    (range.clone(), range.clone(), range)
}

fn nonzero_vec3() -> impl Strategy<Value = (f32, f32, f32)> {
    vec3(-10.0..10.0).prop_filter("non-zero", |(x, y, z)| x * x + y * y + z * z > 1e-2)
}

fn v(t: (f32, f32, f32)) -> String {
    format!("({:?}, {:?}, {:?})", t.0, t.1, t.2)
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 64, rng_seed: rng_seed(), ..ProptestConfig::default() })]

    #[test]
    fn degenerate_views_are_refused(fov in bad_fov(), good in 1.0f32..179.0,
                                   p in vec3(-5.0..5.0), up in nonzero_vec3(), k in 0.1f32..10.0,
                                   sign in prop_oneof![Just(1.0f32), Just(-1.0)]) {
        let camera = |fov: f32| format!(
            "camera: (position: (0, 1, 3), target: (0, 1, 0), vfov_degrees: {fov:?})");
        refused(&scenario(4, 0, &camera(fov)), "camera", "vfov_degrees", "field of view")?;
        loads(&scenario(4, 0, &camera(good)))?;
        // Looking along the up vector, either way.
        let target = (p.0 + sign * k * up.0, p.1 + sign * k * up.1, p.2 + sign * k * up.2);
        let along = format!("camera: (position: {}, target: {}, up: {})", v(p), v(target), v(up));
        refused(&scenario(4, 0, &along), "camera", "up:", "up vector")?;
        // The target on the camera.
        let onto = format!("camera: (position: {}, target: {})", v(p), v(p));
        refused(&scenario(4, 0, &onto), "camera", "target", "target away")?;
        // A camera path key with either problem, at its key.
        let path = format!(
            "animations: [CameraPath(keys: [(frame: 0, position: (0, 1, 3), target: (0, 1, 0)), (frame: 5, position: (0, 1, 3), target: (0, 1, 0), vfov_degrees: {fov:?})])]");
        refused(&scenario(4, 0, &path), "frame: 5", "frame", "field of view")?;
        let up_y = format!(
            "animations: [CameraPath(keys: [(frame: 0, position: {}, target: {})])]",
            v(p), v((p.0, p.1 + sign * k, p.2)));
        refused(&scenario(4, 0, &up_y), "keys", "frame", "up vector")?;
    }

    #[test]
    fn events_outside_the_run_are_refused(frames in 1u32..30, warmup in 0u32..30,
                                          past in 0u32..1000) {
        let total = frames + warmup;
        let event = |f: u32| format!("events: [(frame: 0, action: Toggle(entity: \"ceiling_light\")), (frame: {f}, action: Toggle(entity: \"ceiling_light\"))]");
        // The second event's frame: entries are found in file order.
        refused(&scenario(frames, warmup, &event(total + past)), "), (", "frame", "never happens")?;
        loads(&scenario(frames, warmup, &event(total - 1)))?;
        let once = |f: u32| format!("animations: [RotateOnce(entity: \"tall_box\", axis: (0, 1, 0), degrees: 30, frame: {f})]");
        refused(&scenario(frames, warmup, &once(total + past)), "RotateOnce", "frame", "never happens")?;
        loads(&scenario(frames, warmup, &once(total - 1)))?;
    }

    #[test]
    fn references_that_are_never_rendered_are_refused(frames in 1u32..30, past in 0u32..100,
                                                      n in 1u32..10) {
        let reference = |spp: u32, which: &str| format!("reference: (spp: {spp}, frames: {which})");
        refused(&scenario(frames, 0, &reference(0, &format!("Every({n})"))), "reference", "spp", "spp")?;
        refused(&scenario(frames, 0, &reference(4, "Every(0)")), "reference", "frames", "Every(n)")?;
        // An empty list asks for no reference, as None does.
        loads(&scenario(frames, 0, &reference(4, "List([])")))?;
        let list = format!("List([0, {}])", frames + past);
        refused(&scenario(frames, 0, &reference(4, &list)), "reference", "frames", "outside")?;
        loads(&scenario(frames, 0, &reference(4, &format!("List([0, {}])", frames - 1))))?;
        loads(&scenario(frames, 0, &reference(0, "None")))?;
    }

    #[test]
    fn zero_extents_and_dead_waveforms_are_refused(axis in 0usize..3, s in 0.1f32..4.0,
                                                   f in -10.0f32..=0.0, pr in prop_oneof![-1.0f32..=0.0, 1.0001f32..5.0]) {
        let mut scale = [s, s, s];
        scale[axis] = 0.0;
        let keys = |scale: [f32; 3]| format!(
            "animations: [Keyframes(entity: \"tall_box\", keys: [(frame: 0), (frame: 9, scale: ({:?}, {:?}, {:?}))])]",
            scale[0], scale[1], scale[2]);
        refused(&scenario(4, 0, &keys(scale)), "frame: 9", "frame", "zero extent")?;
        loads(&scenario(4, 0, &keys([s, s, s])))?;
        let axis0 = "animations: [Keyframes(entity: \"tall_box\", keys: [(frame: 2, rotation: (axis: (0, 0, 0), degrees: 30))])]";
        refused(&scenario(4, 0, axis0), "keys", "frame", "non-zero axis")?;
        let sine = format!("animations: [Flash(entity: \"ceiling_light\", waveform: Sine(frequency: {f:?}))]");
        refused(&scenario(4, 0, &sine), "Sine", "frequency", "frequency > 0")?;
        let strobe = format!("animations: [Flash(entity: \"ceiling_light\", waveform: Strobe(probability: {pr:?}))]");
        refused(&scenario(4, 0, &strobe), "Strobe", "probability", "probability")?;
        refused(&scenario(4, 0, "animations: [Boids(prototype: \"tall_box\", count: 0)]"), "Boids", "count", "at least 1")?;
    }

    #[test]
    fn meaningless_numbers_are_refused(eps in -1.0f32..=0.0, c in -5.0f32..-0.001,
                                       r in prop_oneof![-3.0f32..-0.001, 1.001f32..3.0]) {
        refused(&scenario(4, 0, "max_depth: 0"), "", "max_depth", "at least 1")?;
        refused(&scenario(4, 0, &format!("smape_epsilon: {eps:?}")), "", "smape_epsilon", "positive")?;
        refused(&scenario(4, 0, &format!("environment: (0.1, {c:?}, 0.1)")), "", "environment", ">= 0")?;
        let set = |field: &str| format!("events: [(frame: 1, action: SetMaterial(material: \"white\", {field}))]");
        refused(&scenario(4, 0, &set(&format!("roughness: {r:?}"))), "SetMaterial", "roughness", "0 to 1")?;
        refused(&scenario(4, 0, &set(&format!("metallic: {r:?}"))), "SetMaterial", "metallic", "0 to 1")?;
        refused(&scenario(4, 0, &set(&format!("emission: (1, {c:?}, 1)"))), "SetMaterial", "emission", ">= 0")?;
        loads(&scenario(4, 0, &set("roughness: 0.5, metallic: 1, emission: (0, 0, 0)")))?;
        let regions = "regions: [(name: \"a\", x: 0, y: 0, w: 4, h: 4), (name: \"a\", x: 4, y: 0, w: 4, h: 4)]";
        refused(&scenario(4, 0, regions), "", "\"a\"", "distinct names")?;
    }
}

/// A glTF file of one triangle (`positions`), one material (`emissive` or black) and no light.
fn triangle_gltf(dir: &Path, positions: [[f32; 3]; 3], emissive: bool) -> PathBuf {
    let mut bin: Vec<u8> = positions.iter().flatten().flat_map(|f| f.to_le_bytes()).collect();
    bin.extend([0u16, 1, 2, 0].iter().flat_map(|i| i.to_le_bytes()));
    std::fs::write(dir.join("tri.bin"), &bin).unwrap();
    let min: Vec<f32> =
        (0..3).map(|k| positions.iter().map(|p| p[k]).fold(f32::MAX, f32::min)).collect();
    let max: Vec<f32> =
        (0..3).map(|k| positions.iter().map(|p| p[k]).fold(f32::MIN, f32::max)).collect();
    let emission = if emissive { "[1, 1, 1]" } else { "[0, 0, 0]" };
    let gltf = format!(
        r#"{{"asset": {{"version": "2.0"}}, "scene": 0, "scenes": [{{"nodes": [0]}}],
 "nodes": [{{"mesh": 0, "name": "tri"}}],
 "meshes": [{{"name": "tri", "primitives": [{{"attributes": {{"POSITION": 0}}, "indices": 1, "material": 0}}]}}],
 "materials": [{{"name": "m", "emissiveFactor": {emission}}}],
 "buffers": [{{"uri": "tri.bin", "byteLength": {}}}],
 "bufferViews": [{{"buffer": 0, "byteOffset": 0, "byteLength": 36}}, {{"buffer": 0, "byteOffset": 36, "byteLength": 6}}],
 "accessors": [{{"bufferView": 0, "componentType": 5126, "count": 3, "type": "VEC3", "min": {min:?}, "max": {max:?}}},
               {{"bufferView": 1, "componentType": 5123, "count": 3, "type": "SCALAR"}}]}}"#,
        bin.len()
    );
    let path = dir.join("tri.gltf");
    std::fs::write(&path, gltf).unwrap();
    path
}

fn simulate(dir: &Path, extra: &str) -> Result<(), String> {
    let text = format!(
        "Scenario(scene: Gltf(\"tri.gltf\"), resolution: (8, 8), frames: 2,\n  methods: [PathTracing(spp: 1)],\n  camera: (position: (0.3, 0.3, 3), target: (0.3, 0.3, 0)),{extra}\n)\n"
    );
    let path = dir.join("s.ron");
    std::fs::write(&path, &text).unwrap();
    let scenario = Scenario::load(&path).map_err(|e| e.to_string())?;
    Simulation::new(&scenario).map(|_| ()).map_err(|e| e.to_string())
}

#[test]
fn scenes_that_emit_nothing_or_have_no_extent_are_refused() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path().to_path_buf();
    let tri = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]];
    // No light, no emission, no environment: every frame black.
    triangle_gltf(&dir, tri, false);
    let err = simulate(&dir, "").unwrap_err();
    assert!(
        err.starts_with(&format!(
            "{}:1:10: nothing in the scene emits",
            dir.join("s.ron").display()
        )),
        "{err}"
    );
    assert!(err.contains("expected a light"), "{err}");
    // Written as a black environment: the error points at it.
    let err = simulate(&dir, "\n  environment: (0, 0, 0),").unwrap_err();
    assert!(err.contains("s.ron:4:3: nothing in the scene emits"), "{err}");
    // Any one emitter makes the run meaningful: the environment, the material, a later event.
    simulate(&dir, "\n  environment: (0.1, 0.1, 0.1),").unwrap();
    simulate(
        &dir,
        "\n  events: [(frame: 1, action: SetMaterial(material: \"m\", emission: (1, 1, 1)))],",
    )
    .unwrap();
    triangle_gltf(&dir, tri, true);
    simulate(&dir, "").unwrap();
    // A triangle whose corners lie on one line: no surface at all.
    triangle_gltf(&dir, [[0.0, 0.0, 0.0], [1.0, 1.0, 0.0], [2.0, 2.0, 0.0]], true);
    let err = simulate(&dir, "").unwrap_err();
    assert!(err.contains("s.ron:1:10: mesh 'tri#0' has no triangle of positive area"), "{err}");
}
