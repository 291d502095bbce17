//! glTF import: the shipped test asset, and errors that name the file and the part.

mod support;

use std::path::{Path, PathBuf};

use glam::Vec3;
use scene::Light;
use sim::gltf_import::import;

fn asset_path() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../scenarios/assets/test_scene.gltf")
}

fn temp_dir(tag: &str) -> tempfile::TempDir {
    tempfile::Builder::new().prefix(&format!("flicker-sim-{tag}-")).tempdir().unwrap()
}

/// The committed asset is exactly what the generator writes. FLICKER_REGENERATE=1 rewrites a
/// stale asset and still fails (the comparison is with the file as it was, never with what this
/// run wrote); the next run checks the new file.
#[test]
fn test_asset_is_generated_by_the_support_code() {
    let text = support::test_asset::gltf_text();
    let committed =
        std::fs::read_to_string(asset_path()).expect("scenarios/assets/test_scene.gltf exists");
    if committed != text && std::env::var_os("FLICKER_REGENERATE").is_some() {
        std::fs::write(asset_path(), &text).unwrap();
        panic!("test_scene.gltf was stale and is rewritten; run the tests again to check it");
    }
    assert!(committed == text, "test_scene.gltf is stale; run with FLICKER_REGENERATE=1");
}

#[test]
fn test_asset_imports_with_expected_counts() {
    use support::test_asset::*;
    let t = import(&asset_path()).unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(t.meshes.len(), MESHES);
    assert_eq!(t.materials.materials.len(), MATERIALS);
    assert_eq!(t.nodes.len(), NODES);
    assert_eq!(t.textures.len(), 1);
    let tex = &t.textures[0];
    assert_eq!((tex.width, tex.height, tex.rgba8.len()), (4, 4, 64));
    assert_eq!(&tex.rgba8[0..8], &[220, 30, 30, 255, 255, 255, 255, 255], "checker texels");

    let cube = t.meshes.iter().find(|m| m.name.starts_with("Cube")).unwrap();
    assert_eq!(cube.indices.len(), CUBE_TRIANGLES);
    assert_eq!((cube.positions.len(), cube.normals.len(), cube.uvs.len()), (24, 24, 24));

    let checker = t.materials.index_of("Checker").unwrap() as usize;
    assert_eq!(t.materials.materials[checker].base_color_texture, Some(0));
    assert!((t.materials.materials[checker].roughness - 0.7).abs() < 1e-6);
    let glow = &t.materials.materials[t.materials.index_of("Glow").unwrap() as usize];
    assert!(
        (glow.emission - Vec3::new(5.0, 4.0, 3.0)).length() < 1e-5,
        "emissive x strength: {}",
        glow.emission
    );

    // Hierarchy: Cube and Floor are children of Root.
    let root = t.nodes.iter().position(|n| n.name == "Root").unwrap();
    for child in ["Cube", "Floor"] {
        assert_eq!(
            t.nodes.iter().find(|n| n.name == child).unwrap().parent,
            Some(root),
            "{child}'s parent"
        );
    }
    // The matrix node decomposes to scale 4 x 1 x 4 and y = -0.5.
    let floor = t.nodes.iter().find(|n| n.name == "Floor").unwrap();
    assert!((floor.transform.scale - Vec3::new(4.0, 1.0, 4.0)).length() < 1e-5);
    assert!((floor.transform.translation - Vec3::new(0.0, -0.5, 0.0)).length() < 1e-6);

    let lights: Vec<&Light> = t.nodes.iter().filter_map(|n| n.light.as_ref()).collect();
    assert_eq!(lights.len(), LIGHTS);
    assert!(lights.iter().any(|l| matches!(l, Light::Directional { .. })));
    assert!(lights.iter().any(|l| matches!(l, Light::Point { intensity, .. } if (*intensity - Vec3::splat(20.0)).length() < 1e-5)));
    assert!(lights.iter().any(|l| matches!(l, Light::Spot { inner_angle, outer_angle, .. } if *inner_angle == 0.2 && *outer_angle == 0.5)));
    let cameras: Vec<f32> = t.nodes.iter().filter_map(|n| n.camera).collect();
    assert_eq!(cameras, vec![0.8]);
}

#[test]
fn imported_lights_point_along_their_node() {
    // SunNode turns -Z to -Y: the sun shines straight down once placed in the world.
    let scenario = sim::Scenario::from_ron(
        "Scenario(scene: Gltf(\"assets/test_scene.gltf\"), resolution: (8, 8), frames: 1, methods: [PathTracing(spp: 1)])",
        &Path::new(env!("CARGO_MANIFEST_DIR")).join("../scenarios/inline.ron"),
    )
    .unwrap();
    let s = sim::Simulation::new(&scenario).unwrap_or_else(|e| panic!("{e}"));
    let scene = s.scene();
    let sun = scene.lights.iter().find_map(|l| match l {
        Light::Directional { direction, .. } => Some(*direction),
        _ => None,
    });
    assert!((sun.unwrap() - Vec3::NEG_Y).length() < 1e-5, "{sun:?}");
    let bulb = scene.lights.iter().find_map(|l| match l {
        Light::Point { position, .. } => Some(*position),
        _ => None,
    });
    assert!((bulb.unwrap() - Vec3::new(1.0, 2.0, 1.0)).length() < 1e-5);
    assert!((scene.camera.position - Vec3::new(0.0, 1.0, 4.0)).length() < 1e-5);
    assert!((scene.camera.vfov - 0.8).abs() < 1e-6);
    // Cube sits under Root (y = 0.5).
    assert_eq!(scene.instances.len(), 3);
    assert!(
        scene
            .instances
            .iter()
            .any(|i| (i.transform.w_axis.truncate() - Vec3::new(0.0, 0.5, 0.0)).length() < 1e-6)
    );
}

#[test]
fn missing_file_is_named() {
    let path = Path::new("/nonexistent/dir/nothing.gltf");
    let e = import(path).unwrap_err().to_string();
    assert!(e.contains("/nonexistent/dir/nothing.gltf") && e.contains("not found"), "{e}");
}

#[test]
fn broken_json_is_named() {
    let tmp = temp_dir("broken");
    let dir = tmp.path().to_path_buf();
    let path = dir.join("broken.gltf");
    std::fs::write(&path, "{ \"asset\": { \"version\": \"2.0\" }, \"nodes\": [ {").unwrap();
    let e = import(&path).unwrap_err().to_string();
    assert!(e.starts_with(&path.display().to_string()), "{e}");
    assert!(e.contains("file: cannot import"), "{e}");
}

#[test]
fn unsupported_primitive_mode_names_mesh_and_primitive() {
    let tmp = temp_dir("lines");
    let dir = tmp.path().to_path_buf();
    let path = dir.join("lines.gltf");
    let text = support::test_asset::gltf_text().replacen("\"mode\": 4", "\"mode\": 1", 1);
    std::fs::write(&path, text).unwrap();
    let e = import(&path).unwrap_err().to_string();
    let expected = format!(
        "{}: mesh 'Cube' primitive 0: mode Lines is not supported; expected triangles",
        path.display()
    );
    assert_eq!(e, expected);
}

/// An attribute's accessor past the file's accessors is an error naming mesh, primitive and
/// attribute (the `gltf` crate's own validation indexes the POSITION accessor unchecked and
/// panics).
#[test]
fn attribute_accessor_out_of_range_names_mesh_and_primitive() {
    let tmp = temp_dir("accessor");
    let path = tmp.path().join("accessor.gltf");
    let mut doc: serde_json::Value =
        serde_json::from_str(&support::test_asset::gltf_text()).unwrap();
    let accessors = doc["accessors"].as_array().unwrap().len();
    doc["meshes"][0]["primitives"][0]["attributes"]["POSITION"] = serde_json::json!(accessors);
    std::fs::write(&path, serde_json::to_string(&doc).unwrap()).unwrap();
    let e = import(&path).unwrap_err().to_string();
    let expected = format!(
        "{}: mesh 'Cube' primitive 0: POSITION uses accessor {accessors}, but the file has {accessors} accessors",
        path.display()
    );
    assert_eq!(e, expected);
}

/// Float indices are an error naming mesh and primitive (the `gltf` crate's index reader treats
/// them as unreachable and panics).
#[test]
fn float_indices_name_mesh_and_primitive() {
    let tmp = temp_dir("indices");
    let path = tmp.path().join("indices.gltf");
    let mut doc: serde_json::Value =
        serde_json::from_str(&support::test_asset::gltf_text()).unwrap();
    let a = doc["meshes"][0]["primitives"][0]["indices"].as_u64().unwrap() as usize;
    doc["accessors"][a]["componentType"] = serde_json::json!(5126);
    std::fs::write(&path, serde_json::to_string(&doc).unwrap()).unwrap();
    let e = import(&path).unwrap_err().to_string();
    let expected = format!(
        "{}: mesh 'Cube' primitive 0: indices accessor {a} has component type F32; expected an unsigned byte, short or int",
        path.display()
    );
    assert_eq!(e, expected);
}

/// A GLB header declaring less than its own 12 bytes is an error naming the header.
#[test]
fn glb_header_shorter_than_itself_is_named() {
    let tmp = temp_dir("glb-header");
    let path = tmp.path().join("short.glb");
    let mut bytes = b"glTF".to_vec();
    bytes.extend(2u32.to_le_bytes());
    bytes.extend(4u32.to_le_bytes());
    bytes.extend([0; 20]);
    std::fs::write(&path, &bytes).unwrap();
    let e = import(&path).unwrap_err().to_string();
    let expected =
        format!("{}: GLB header: length 4; expected at least the 12-byte header", path.display());
    assert_eq!(e, expected);
}

/// A node outside the scene may carry a light and an animation: the scene imports without them.
#[test]
fn nodes_outside_the_scene_are_left_out() {
    let tmp = temp_dir("outside");
    let path = tmp.path().join("outside.gltf");
    let mut doc: serde_json::Value =
        serde_json::from_str(&support::test_asset::gltf_text()).unwrap();
    let before = import(&asset_path()).unwrap();
    // One more node, in no scene, holding light 0 and animated.
    let nodes = doc["nodes"].as_array_mut().unwrap();
    nodes.push(
        serde_json::json!({"name": "Outside", "extensions": {"KHR_lights_punctual": {"light": 0}}}),
    );
    let outside = nodes.len() - 1;
    doc["animations"] = serde_json::json!([{
        "samplers": [{"input": 0, "output": 0}],
        "channels": [{"sampler": 0, "target": {"node": outside, "path": "translation"}}],
    }]);
    std::fs::write(&path, serde_json::to_string(&doc).unwrap()).unwrap();
    let t = import(&path).unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(t.nodes.len(), before.nodes.len());
    assert!(t.nodes.iter().all(|n| n.name != "Outside"));
}

/// The test asset with material extensions set: FloorGrey diffusely transmitting with a volume
/// (subsurface), Checker with a volume only (no subsurface: KHR_materials_volume alone belongs
/// to refractive transmission).
fn with_material_extensions(floor: serde_json::Value) -> String {
    let mut doc: serde_json::Value =
        serde_json::from_str(&support::test_asset::gltf_text()).unwrap();
    let materials = doc["materials"].as_array_mut().unwrap();
    materials[0]["extensions"] = serde_json::json!({"KHR_materials_volume": {"attenuationDistance": 0.5, "attenuationColor": [0.5, 0.5, 0.5]}});
    materials[1]["extensions"] = floor;
    doc["extensionsUsed"].as_array_mut().unwrap().extend([
        serde_json::json!("KHR_materials_volume"),
        serde_json::json!(sim::gltf_import::DIFFUSE_TRANSMISSION),
    ]);
    serde_json::to_string_pretty(&doc).unwrap()
}

#[test]
fn subsurface_comes_from_diffuse_transmission_and_volume() {
    let tmp = temp_dir("subsurface");
    let dir = tmp.path().to_path_buf();
    let path = dir.join("skin.gltf");
    let volume =
        serde_json::json!({"attenuationDistance": 0.2, "attenuationColor": [0.8, 0.5, 0.25]});
    std::fs::write(&path, with_material_extensions(serde_json::json!({"KHR_materials_diffuse_transmission": {}, "KHR_materials_volume": volume}))).unwrap();
    let t = import(&path).unwrap_or_else(|e| panic!("{e}"));
    let material = |name: &str| t.materials.materials[t.materials.index_of(name).unwrap() as usize];
    let s = material("FloorGrey").subsurface.expect("FloorGrey is subsurface");
    // dmfp_c = distance / −ln(color_c): 0.2 / 0.2231, 0.2 / 0.6931, 0.2 / 1.3863.
    for (got, want) in s.dmfp.to_array().iter().zip([0.896_284, 0.288_539, 0.144_270]) {
        assert!((got - want).abs() < 1e-5, "dmfp {:?}", s.dmfp);
    }
    assert_eq!(material("Checker").subsurface, None, "volume without diffuse transmission");
    assert_eq!(material("Glow").subsurface, None);

    // No attenuation in a channel: infinite dmfp, refused with the file and the material named.
    let bad = serde_json::json!({"KHR_materials_diffuse_transmission": {}, "KHR_materials_volume": {"attenuationDistance": 0.2, "attenuationColor": [1.0, 0.5, 0.5]}});
    std::fs::write(&path, with_material_extensions(bad)).unwrap();
    let e = import(&path).unwrap_err().to_string();
    assert!(
        e.starts_with(&format!(
            "{}: material 'FloorGrey': KHR_materials_volume attenuationColor",
            path.display()
        )) && e.contains("(0, 1)"),
        "{e}"
    );
    let bad = serde_json::json!({"KHR_materials_diffuse_transmission": {}, "KHR_materials_volume": {"attenuationColor": [0.5, 0.5, 0.5]}});
    std::fs::write(&path, with_material_extensions(bad)).unwrap();
    let e = import(&path).unwrap_err().to_string();
    assert!(e.contains("material 'FloorGrey'") && e.contains("attenuationDistance inf"), "{e}");
}
