//! Generates scenarios/assets/test_scene.gltf: a small glTF 2.0 file with embedded
//! buffers and texture, a node hierarchy (TRS and matrix), metallic-roughness and emissive
//! materials, three KHR_lights_punctual lights and a perspective camera.

use serde_json::{Value, json};

pub const MESHES: usize = 3;
pub const MATERIALS: usize = 3;
pub const NODES: usize = 8;
pub const LIGHTS: usize = 3;
pub const CUBE_TRIANGLES: usize = 12;

fn base64(bytes: &[u8]) -> String {
    const ALPHABET: &[u8; 64] = b"ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    let mut out = String::new();
    for chunk in bytes.chunks(3) {
        let b = [chunk[0], *chunk.get(1).unwrap_or(&0), *chunk.get(2).unwrap_or(&0)];
        let n = (b[0] as u32) << 16 | (b[1] as u32) << 8 | b[2] as u32;
        for k in 0..4 {
            if k <= chunk.len() {
                out.push(ALPHABET[(n >> (18 - 6 * k) & 63) as usize] as char);
            } else {
                out.push('=');
            }
        }
    }
    out
}

/// A 4x4 red/white checkerboard, PNG-encoded.
fn checker_png() -> Vec<u8> {
    let img = image::RgbaImage::from_fn(4, 4, |x, y| {
        if (x + y) % 2 == 0 {
            image::Rgba([220, 30, 30, 255])
        } else {
            image::Rgba([255, 255, 255, 255])
        }
    });
    let mut png = Vec::new();
    img.write_to(&mut std::io::Cursor::new(&mut png), image::ImageFormat::Png).unwrap();
    png
}

struct Geometry {
    positions: Vec<[f32; 3]>,
    normals: Vec<[f32; 3]>,
    uvs: Vec<[f32; 2]>,
    indices: Vec<u16>,
}

fn cube() -> Geometry {
    let mut g = Geometry { positions: vec![], normals: vec![], uvs: vec![], indices: vec![] };
    for axis in 0..3 {
        for sign in [-1.0f32, 1.0] {
            let mut n = [0.0; 3];
            n[axis] = sign;
            let (u, v) = ((axis + 1) % 3, (axis + 2) % 3);
            let base = g.positions.len() as u16;
            for (su, sv) in [(-1.0, -1.0), (1.0, -1.0), (1.0, 1.0), (-1.0, 1.0)] {
                let mut p = [0.0; 3];
                p[axis] = 0.5 * sign;
                p[u] = 0.5 * su;
                p[v] = 0.5 * sv;
                g.positions.push(p);
                g.normals.push(n);
                g.uvs.push([0.5 * (su + 1.0), 0.5 * (sv + 1.0)]);
            }
            // (u, v, axis) is right-handed, so this order faces +axis; flip for -axis.
            let tris = if sign > 0.0 { [0, 1, 2, 0, 2, 3] } else { [0, 2, 1, 0, 3, 2] };
            g.indices.extend(tris.iter().map(|i| base + i));
        }
    }
    g
}

fn quad(normal_y: f32) -> Geometry {
    let positions = vec![[-0.5, 0.0, -0.5], [0.5, 0.0, -0.5], [0.5, 0.0, 0.5], [-0.5, 0.0, 0.5]];
    let indices = if normal_y > 0.0 { vec![0, 2, 1, 0, 3, 2] } else { vec![0, 1, 2, 0, 2, 3] };
    Geometry {
        normals: vec![[0.0, normal_y, 0.0]; 4],
        uvs: vec![[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]],
        positions,
        indices,
    }
}

/// The asset's JSON text.
pub fn gltf_text() -> String {
    let meshes = [("Cube", cube(), 0), ("Floor", quad(1.0), 1), ("Lamp", quad(-1.0), 2)];
    let mut bin: Vec<u8> = Vec::new();
    let mut views = Vec::new();
    let mut accessors = Vec::new();
    let mut gltf_meshes = Vec::new();
    for (name, g, material) in &meshes {
        let mut attribute = |bytes: Vec<u8>,
                             count: usize,
                             kind: &str,
                             component: u32,
                             target: u32,
                             extra: Value| {
            while !bin.len().is_multiple_of(4) {
                bin.push(0);
            }
            views.push(json!({"buffer": 0, "byteOffset": bin.len(), "byteLength": bytes.len(), "target": target}));
            bin.extend_from_slice(&bytes);
            let mut acc = json!({"bufferView": views.len() - 1, "componentType": component, "count": count, "type": kind});
            if let (Value::Object(a), Value::Object(e)) = (&mut acc, extra) {
                a.extend(e);
            }
            accessors.push(acc);
            accessors.len() - 1
        };
        let f32s = |v: &[f32]| v.iter().flat_map(|x| x.to_le_bytes()).collect::<Vec<u8>>();
        let flat: Vec<f32> = g.positions.iter().flatten().copied().collect();
        let (mut lo, mut hi) = ([f32::MAX; 3], [f32::MIN; 3]);
        for p in &g.positions {
            for k in 0..3 {
                lo[k] = lo[k].min(p[k]);
                hi[k] = hi[k].max(p[k]);
            }
        }
        let pos = attribute(
            f32s(&flat),
            g.positions.len(),
            "VEC3",
            5126,
            34962,
            json!({"min": lo, "max": hi}),
        );
        let nflat: Vec<f32> = g.normals.iter().flatten().copied().collect();
        let nor = attribute(f32s(&nflat), g.normals.len(), "VEC3", 5126, 34962, json!({}));
        let uflat: Vec<f32> = g.uvs.iter().flatten().copied().collect();
        let uv = attribute(f32s(&uflat), g.uvs.len(), "VEC2", 5126, 34962, json!({}));
        let ibytes: Vec<u8> = g.indices.iter().flat_map(|i| i.to_le_bytes()).collect();
        let idx = attribute(ibytes, g.indices.len(), "SCALAR", 5123, 34963, json!({}));
        gltf_meshes.push(json!({
            "name": name,
            "primitives": [{
                "attributes": {"POSITION": pos, "NORMAL": nor, "TEXCOORD_0": uv},
                "indices": idx,
                "material": material,
                "mode": 4
            }]
        }));
    }
    let s = std::f32::consts::FRAC_1_SQRT_2;
    let doc = json!({
        "asset": {"version": "2.0", "generator": "flicker sim tests/support/test_asset.rs"},
        "extensionsUsed": ["KHR_lights_punctual", "KHR_materials_emissive_strength"],
        "extensions": {"KHR_lights_punctual": {"lights": [
            {"name": "Sun", "type": "directional", "color": [1.0, 0.9, 0.8], "intensity": 3.0},
            {"name": "Bulb", "type": "point", "color": [1.0, 1.0, 1.0], "intensity": 20.0},
            {"name": "Spot", "type": "spot", "color": [0.5, 0.5, 1.0], "intensity": 40.0,
             "spot": {"innerConeAngle": 0.2, "outerConeAngle": 0.5}}
        ]}},
        "scene": 0,
        "scenes": [{"name": "TestScene", "nodes": [0, 3, 4, 5, 6, 7]}],
        "nodes": [
            {"name": "Root", "translation": [0.0, 0.5, 0.0], "children": [1, 2]},
            {"name": "Cube", "mesh": 0, "rotation": [0.0, 0.38268343, 0.0, 0.9238795], "scale": [0.8, 0.8, 0.8]},
            {"name": "Floor", "mesh": 1,
             "matrix": [4.0, 0.0, 0.0, 0.0,  0.0, 1.0, 0.0, 0.0,  0.0, 0.0, 4.0, 0.0,  0.0, -0.5, 0.0, 1.0]},
            {"name": "Lamp", "mesh": 2, "translation": [0.0, 2.5, 0.0], "scale": [0.5, 1.0, 0.5]},
            // The sun points its -Z straight down: a -90° turn about X.
            {"name": "SunNode", "extensions": {"KHR_lights_punctual": {"light": 0}}, "rotation": [-s, 0.0, 0.0, s]},
            {"name": "BulbNode", "extensions": {"KHR_lights_punctual": {"light": 1}}, "translation": [1.0, 2.0, 1.0]},
            {"name": "SpotNode", "extensions": {"KHR_lights_punctual": {"light": 2}}, "translation": [-1.0, 2.0, 0.0],
             "rotation": [-s, 0.0, 0.0, s]},
            {"name": "CameraNode", "camera": 0, "translation": [0.0, 1.0, 4.0]}
        ],
        "cameras": [{"name": "MainCamera", "type": "perspective",
                     "perspective": {"yfov": 0.8, "znear": 0.01, "zfar": 100.0, "aspectRatio": 1.777}}],
        "meshes": gltf_meshes,
        "materials": [
            {"name": "Checker", "pbrMetallicRoughness": {"baseColorFactor": [1.0, 1.0, 1.0, 1.0],
             "baseColorTexture": {"index": 0}, "metallicFactor": 0.0, "roughnessFactor": 0.7}},
            {"name": "FloorGrey", "pbrMetallicRoughness": {"baseColorFactor": [0.5, 0.5, 0.5, 1.0],
             "metallicFactor": 0.25, "roughnessFactor": 0.9}},
            {"name": "Glow", "emissiveFactor": [1.0, 0.8, 0.6],
             "extensions": {"KHR_materials_emissive_strength": {"emissiveStrength": 5.0}}}
        ],
        "textures": [{"source": 0}],
        "images": [{"name": "checker", "uri": format!("data:image/png;base64,{}", base64(&checker_png()))}],
        "buffers": [{"byteLength": bin.len(), "uri": format!("data:application/octet-stream;base64,{}", base64(&bin))}],
        "bufferViews": views,
        "accessors": accessors
    });
    serde_json::to_string_pretty(&doc).unwrap() + "\n"
}
