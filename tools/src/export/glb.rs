//! The scenario's frames as one binary glTF 2.0 file: every mesh instance, light and the camera
//! as a root node placed in world space, materials (metallic-roughness, with
//! KHR_materials_emissive_strength and KHR_materials_specular where needed), lights
//! (KHR_lights_punctual), and two animations sampled at the frame times: `transforms` (node
//! translation, rotation, scale) and `properties` (KHR_animation_pointer: light colour and
//! intensity, material factors, the camera's field of view). Whatever moves, however the
//! scenario moves it (keyframes, boids, events), is a sampled track; only what changes gets one.
//!
//! Written as JSON (serde_json) rather than through `gltf-json`'s types: gltf-json 1.4 cannot
//! express a pointer channel (its `Target` requires a node and knows no "pointer" path). The
//! Khronos validator checks every file in tests/export.rs.

use anyhow::{Result, bail};
use glam::{Mat4, Quat, Vec3, Vec4};
use scene::{Light, SceneDesc};
use serde_json::{Value, json};

/// Extras of the scene: constant environment radiance (glTF has none).
pub const ENVIRONMENT: &str = "flicker_environment";

const ARRAY_BUFFER: u32 = 34962;
const ELEMENT_ARRAY_BUFFER: u32 = 34963;
const FLOAT: u32 = 5126;
const UNSIGNED_INT: u32 = 5125;

/// The binary chunk and the accessors over it.
#[derive(Default)]
struct Builder {
    bin: Vec<u8>,
    views: Vec<Value>,
    accessors: Vec<Value>,
}

impl Builder {
    fn view(&mut self, bytes: &[u8], target: Option<u32>) -> usize {
        while !self.bin.len().is_multiple_of(4) {
            self.bin.push(0);
        }
        let mut v = json!({"buffer": 0, "byteOffset": self.bin.len(), "byteLength": bytes.len()});
        if let Some(t) = target {
            v["target"] = t.into();
        }
        self.bin.extend_from_slice(bytes);
        self.views.push(v);
        self.views.len() - 1
    }

    /// Float accessor of `width` components per element, with min and max.
    fn floats(&mut self, data: &[f32], width: usize, target: Option<u32>, bounds: bool) -> usize {
        let kind = ["SCALAR", "VEC2", "VEC3", "VEC4"][width - 1];
        let bytes: Vec<u8> = data.iter().flat_map(|f| f.to_le_bytes()).collect();
        let view = self.view(&bytes, target);
        let mut a = json!({"bufferView": view, "componentType": FLOAT, "count": data.len() / width, "type": kind});
        if bounds {
            let (mut lo, mut hi) = (vec![f32::INFINITY; width], vec![f32::NEG_INFINITY; width]);
            for e in data.chunks_exact(width) {
                for k in 0..width {
                    lo[k] = lo[k].min(e[k]);
                    hi[k] = hi[k].max(e[k]);
                }
            }
            a["min"] = json!(lo);
            a["max"] = json!(hi);
        }
        self.accessors.push(a);
        self.accessors.len() - 1
    }

    fn indices(&mut self, data: &[u32]) -> usize {
        let bytes: Vec<u8> = data.iter().flat_map(|i| i.to_le_bytes()).collect();
        let view = self.view(&bytes, Some(ELEMENT_ARRAY_BUFFER));
        self.accessors.push(
            json!({"bufferView": view, "componentType": UNSIGNED_INT, "count": data.len(), "type": "SCALAR"}),
        );
        self.accessors.len() - 1
    }
}

/// Translation, rotation, scale of a world matrix; refuses a shear (no TRS node holds it).
fn trs(m: Mat4, what: &str) -> Result<(Vec3, Quat, Vec3)> {
    let (s, r, t) = m.to_scale_rotation_translation();
    let back = Mat4::from_scale_rotation_translation(s, r, t);
    let scale = m.abs().to_cols_array().iter().fold(1.0f32, |a, b| a.max(*b));
    if !back.abs_diff_eq(m, 1e-4 * scale) {
        bail!("{what}: its world matrix has a shear; expected translation, rotation and scale");
    }
    Ok((t, r.normalize(), s))
}

/// A light's node pose (the light shines along the node's -Z) and its colour x intensity.
fn light_pose(light: &Light) -> (Vec3, Quat, Vec3) {
    let aim = |d: Vec3| Quat::from_rotation_arc(Vec3::NEG_Z, d.normalize());
    match *light {
        Light::Directional { direction, irradiance, .. } => {
            (Vec3::ZERO, aim(direction), irradiance)
        }
        Light::Point { position, intensity } => (position, Quat::IDENTITY, intensity),
        Light::Spot { position, direction, intensity, .. } => (position, aim(direction), intensity),
    }
}

/// Colour in [0, 1] (largest channel 1) and intensity; an unlit light keeps `previous` colour.
fn color_intensity(power: Vec3, previous: Vec3) -> (Vec3, f32) {
    let max = power.max_element();
    if max > 0.0 { (power / max, max) } else { (previous, 0.0) }
}

fn arr3(v: Vec3) -> Value {
    json!([v.x, v.y, v.z])
}

/// Keeps successive quaternions in one hemisphere, so interpolation takes the short way.
fn continuous(qs: &mut [Quat]) {
    for k in 1..qs.len() {
        if qs[k].dot(qs[k - 1]) < 0.0 {
            qs[k] = -qs[k];
        }
    }
}

/// Samples of one property over the frames, and the animation channels made of them.
struct Tracks<'a> {
    b: &'a mut Builder,
    times: usize,
    samplers: Vec<Value>,
    node_channels: Vec<Value>,
    pointer_samplers: Vec<Value>,
    pointer_channels: Vec<Value>,
}

impl Tracks<'_> {
    fn node(&mut self, node: usize, path: &str, data: &[f32], width: usize) {
        let output = self.b.floats(data, width, None, false);
        self.samplers
            .push(json!({"input": self.times, "output": output, "interpolation": "LINEAR"}));
        self.node_channels.push(json!({
            "sampler": self.samplers.len() - 1,
            "target": {"node": node, "path": path},
        }));
    }

    fn pointer(&mut self, pointer: String, data: &[f32], width: usize) {
        let output = self.b.floats(data, width, None, false);
        self.pointer_samplers
            .push(json!({"input": self.times, "output": output, "interpolation": "LINEAR"}));
        self.pointer_channels.push(json!({
            "sampler": self.pointer_samplers.len() - 1,
            "target": {"path": "pointer", "extensions": {"KHR_animation_pointer": {"pointer": pointer}}},
        }));
    }
}

fn changes<T: PartialEq>(values: &[T]) -> bool {
    values.windows(2).any(|w| w[0] != w[1])
}

fn flat3(v: &[Vec3]) -> Vec<f32> {
    v.iter().flat_map(|x| x.to_array()).collect()
}

/// The .glb of `frames` (frame k at time k x `time_step`); `frames[0]` holds the meshes and
/// textures. Refuses what glTF cannot hold or what would change the scene's structure between
/// frames (instances, lights, materials coming or going).
pub fn write(frames: &[SceneDesc], time_step: f32, aspect: f32, name: &str) -> Result<Vec<u8>> {
    let first = &frames[0];
    for (k, f) in frames.iter().enumerate() {
        if f.instances.len() != first.instances.len()
            || f.lights.len() != first.lights.len()
            || f.materials.len() != first.materials.len()
            || f.instances
                .iter()
                .zip(&first.instances)
                .any(|(a, b)| (a.mesh, a.material) != (b.mesh, b.material))
            || f.lights
                .iter()
                .zip(&first.lights)
                .any(|(a, b)| std::mem::discriminant(a) != std::mem::discriminant(b))
        {
            bail!(
                "frame {k}: the scene's instances, lights or materials differ from frame 0's; expected a fixed set that moves"
            );
        }
    }
    if let Some((i, _)) = first.materials.iter().enumerate().find(|(_, m)| m.subsurface.is_some()) {
        bail!(
            "material {i} is a subsurface material; the export holds glTF metallic-roughness materials only"
        );
    }
    let mut b = Builder::default();
    let mut root = json!({
        "asset": {"version": "2.0", "generator": format!("flicker {} export", env!("CARGO_PKG_VERSION"))},
        "scene": 0,
    });

    // Textures as PNG images in the binary chunk.
    let mut images = Vec::new();
    for t in &first.textures {
        let mut png = Vec::new();
        image::codecs::png::PngEncoder::new(&mut png)
            .write_image(&t.rgba8, t.width, t.height, image::ExtendedColorType::Rgba8)
            .map_err(|e| anyhow::anyhow!("texture '{}': {e}", t.name))?;
        let view = b.view(&png, None);
        images.push(json!({"name": t.name, "bufferView": view, "mimeType": "image/png"}));
    }
    use image::ImageEncoder;

    // Materials: emission = emissiveFactor x a constant strength, the largest emission over
    // the frames, so that the factor stays within [0, 1] while it is animated.
    let mut extensions_used: Vec<&str> = vec!["KHR_lights_punctual"];
    let mut materials = Vec::new();
    let mut strengths = Vec::new();
    for (i, m) in first.materials.iter().enumerate() {
        let strength =
            frames.iter().map(|f| f.materials[i].emission.max_element()).fold(1.0f32, f32::max);
        strengths.push(strength);
        let c = m.base_color;
        let mut pbr = json!({
            "baseColorFactor": [c.x, c.y, c.z, 1.0],
            "metallicFactor": m.metallic,
            "roughnessFactor": m.roughness,
        });
        if let Some(t) = m.base_color_texture {
            pbr["baseColorTexture"] = json!({"index": t});
        }
        let mut mat = json!({"name": format!("material{i}"), "pbrMetallicRoughness": pbr, "emissiveFactor": arr3(m.emission / strength)});
        if strength > 1.0 {
            mat["extensions"]["KHR_materials_emissive_strength"] =
                json!({"emissiveStrength": strength});
            extensions_used.push("KHR_materials_emissive_strength");
        }
        if m.specular != 1.0 {
            mat["extensions"]["KHR_materials_specular"] = json!({"specularFactor": m.specular});
            extensions_used.push("KHR_materials_specular");
        }
        materials.push(mat);
    }

    // Meshes: one glTF mesh per (mesh, material) pair in use, sharing the vertex accessors.
    let mut geometry: Vec<Option<Value>> = vec![None; first.meshes.len()];
    let mut meshes = Vec::new();
    let mut mesh_of: Vec<((u32, u32), usize)> = Vec::new();
    let mut nodes = Vec::new();
    let times: Vec<f32> = (0..frames.len()).map(|k| k as f32 * time_step).collect();
    for (i, inst) in first.instances.iter().enumerate() {
        let key = (inst.mesh, inst.material);
        let mesh = match mesh_of.iter().find(|(k, _)| *k == key) {
            Some((_, m)) => *m,
            None => {
                let src = &first.meshes[inst.mesh as usize];
                let attributes = match &geometry[inst.mesh as usize] {
                    Some(a) => a.clone(),
                    None => {
                        let p = flat3(&src.positions);
                        let mut a = json!({"POSITION": b.floats(&p, 3, Some(ARRAY_BUFFER), true)});
                        if !src.normals.is_empty() {
                            let n: Vec<Vec3> =
                                src.normals.iter().map(|n| n.normalize_or(Vec3::Z)).collect();
                            a["NORMAL"] = b.floats(&flat3(&n), 3, Some(ARRAY_BUFFER), false).into();
                        }
                        if !src.uvs.is_empty() {
                            let uv: Vec<f32> = src.uvs.iter().flat_map(|u| u.to_array()).collect();
                            a["TEXCOORD_0"] = b.floats(&uv, 2, Some(ARRAY_BUFFER), false).into();
                        }
                        let idx: Vec<u32> = src.indices.iter().flatten().copied().collect();
                        a["_indices"] = b.indices(&idx).into();
                        geometry[inst.mesh as usize] = Some(a.clone());
                        a
                    }
                };
                let mut attributes = attributes;
                let indices = attributes.as_object_mut().unwrap().remove("_indices").unwrap();
                meshes.push(json!({
                    "name": src.name,
                    "primitives": [{"attributes": attributes, "indices": indices, "material": inst.material, "mode": 4}],
                }));
                mesh_of.push((key, meshes.len() - 1));
                meshes.len() - 1
            }
        };
        let (t, r, s) = trs(inst.transform, &format!("instance {i}"))?;
        nodes.push(json!({
            "name": format!("instance{i}"),
            "mesh": mesh,
            "translation": arr3(t), "rotation": r.to_array(), "scale": arr3(s),
        }));
    }

    let time_accessor = b.floats(&times, 1, None, true);
    let mut tr = Tracks {
        b: &mut b,
        times: time_accessor,
        samplers: vec![],
        node_channels: vec![],
        pointer_samplers: vec![],
        pointer_channels: vec![],
    };
    // Instance transforms over the frames.
    for i in 0..first.instances.len() {
        let mut ts = Vec::new();
        let mut rs = Vec::new();
        let mut ss = Vec::new();
        for (k, f) in frames.iter().enumerate() {
            let (t, r, s) = trs(f.instances[i].transform, &format!("frame {k} instance {i}"))?;
            ts.push(t);
            rs.push(r);
            ss.push(s);
        }
        continuous(&mut rs);
        if changes(&ts) {
            tr.node(i, "translation", &flat3(&ts), 3);
        }
        if changes(&rs) {
            let q: Vec<f32> = rs.iter().flat_map(|q| q.to_array()).collect();
            tr.node(i, "rotation", &q, 4);
        }
        if changes(&ss) {
            tr.node(i, "scale", &flat3(&ss), 3);
        }
    }

    // Lights.
    let mut lights = Vec::new();
    for (l, light) in first.lights.iter().enumerate() {
        let node = first.instances.len() + l;
        let (mut ts, mut rs, mut colors, mut intensities) = (vec![], vec![], vec![], vec![]);
        let mut previous = Vec3::ONE;
        for f in frames {
            let (t, r, power) = light_pose(&f.lights[l]);
            let (c, i) = color_intensity(power, previous);
            previous = c;
            ts.push(t);
            rs.push(r);
            colors.push(c);
            intensities.push(i);
        }
        continuous(&mut rs);
        let mut def = json!({"name": format!("light{l}"), "color": arr3(colors[0]), "intensity": intensities[0]});
        match *light {
            Light::Directional { angular_radius, .. } => {
                def["type"] = "directional".into();
                if angular_radius > 0.0 {
                    def["extras"] = json!({ sim::gltf_import::ANGULAR_RADIUS: angular_radius });
                }
            }
            Light::Point { .. } => def["type"] = "point".into(),
            Light::Spot { inner_angle, outer_angle, .. } => {
                def["type"] = "spot".into();
                def["spot"] = json!({"innerConeAngle": inner_angle, "outerConeAngle": outer_angle});
            }
        }
        lights.push(def);
        nodes.push(json!({
            "name": format!("light{l}"),
            "translation": arr3(ts[0]), "rotation": rs[0].to_array(),
            "extensions": {"KHR_lights_punctual": {"light": l}},
        }));
        if changes(&ts) {
            tr.node(node, "translation", &flat3(&ts), 3);
        }
        if changes(&rs) {
            let q: Vec<f32> = rs.iter().flat_map(|q| q.to_array()).collect();
            tr.node(node, "rotation", &q, 4);
        }
        if changes(&intensities) {
            tr.pointer(
                format!("/extensions/KHR_lights_punctual/lights/{l}/intensity"),
                &intensities,
                1,
            );
        }
        if changes(&colors) {
            tr.pointer(
                format!("/extensions/KHR_lights_punctual/lights/{l}/color"),
                &flat3(&colors),
                3,
            );
        }
    }

    // Materials over the frames.
    for (i, strength) in strengths.iter().enumerate() {
        let emission: Vec<Vec3> =
            frames.iter().map(|f| f.materials[i].emission / strength).collect();
        if changes(&emission) {
            tr.pointer(format!("/materials/{i}/emissiveFactor"), &flat3(&emission), 3);
        }
        let base: Vec<Vec4> =
            frames.iter().map(|f| f.materials[i].base_color.extend(1.0)).collect();
        if changes(&base) {
            let v: Vec<f32> = base.iter().flat_map(|c| c.to_array()).collect();
            tr.pointer(format!("/materials/{i}/pbrMetallicRoughness/baseColorFactor"), &v, 4);
        }
        let rough: Vec<f32> = frames.iter().map(|f| f.materials[i].roughness).collect();
        if changes(&rough) {
            tr.pointer(format!("/materials/{i}/pbrMetallicRoughness/roughnessFactor"), &rough, 1);
        }
        let metal: Vec<f32> = frames.iter().map(|f| f.materials[i].metallic).collect();
        if changes(&metal) {
            tr.pointer(format!("/materials/{i}/pbrMetallicRoughness/metallicFactor"), &metal, 1);
        }
    }

    // The camera: looks down its node's -Z with +Y up.
    let camera_node = nodes.len();
    let pose = |c: &scene::Camera| {
        let m = c.view().inverse();
        let (_, r, t) = m.to_scale_rotation_translation();
        (t, r.normalize())
    };
    let (mut cts, mut crs, mut fovs) = (vec![], vec![], vec![]);
    for f in frames {
        let (t, r) = pose(&f.camera);
        cts.push(t);
        crs.push(r);
        fovs.push(f.camera.vfov);
    }
    continuous(&mut crs);
    nodes.push(json!({"name": "camera", "camera": 0, "translation": arr3(cts[0]), "rotation": crs[0].to_array()}));
    if changes(&cts) {
        tr.node(camera_node, "translation", &flat3(&cts), 3);
    }
    if changes(&crs) {
        let q: Vec<f32> = crs.iter().flat_map(|q| q.to_array()).collect();
        tr.node(camera_node, "rotation", &q, 4);
    }
    if changes(&fovs) {
        tr.pointer("/cameras/0/perspective/yfov".into(), &fovs, 1);
    }

    let mut animations = Vec::new();
    let Tracks { samplers, node_channels, pointer_samplers, pointer_channels, .. } = tr;
    if !node_channels.is_empty() {
        animations
            .push(json!({"name": "transforms", "channels": node_channels, "samplers": samplers}));
    }
    if !pointer_channels.is_empty() {
        animations.push(json!({"name": "properties", "channels": pointer_channels, "samplers": pointer_samplers}));
        extensions_used.push("KHR_animation_pointer");
    }
    if animations.is_empty() {
        // The times accessor would be unused (a validator warning): keep it only when animated.
        b.accessors.pop();
        b.views.pop();
    }
    extensions_used.sort();
    extensions_used.dedup();

    let node_list: Vec<usize> = (0..nodes.len()).collect();
    let obj = root.as_object_mut().unwrap();
    obj.insert("scenes".into(), json!([{"name": name, "nodes": node_list, "extras": {ENVIRONMENT: arr3(first.environment)}}]));
    obj.insert("nodes".into(), nodes.into());
    obj.insert("meshes".into(), meshes.into());
    obj.insert("materials".into(), materials.into());
    obj.insert("cameras".into(), json!([{"type": "perspective", "perspective": {"yfov": fovs[0], "aspectRatio": aspect, "znear": 0.01, "zfar": 1000.0}}]));
    if !images.is_empty() {
        let textures: Vec<Value> =
            (0..images.len()).map(|i| json!({"source": i, "sampler": 0})).collect();
        obj.insert("images".into(), images.into());
        obj.insert("textures".into(), textures.into());
        obj.insert("samplers".into(), json!([{"wrapS": 10497, "wrapT": 10497}]));
    }
    if !animations.is_empty() {
        obj.insert("animations".into(), animations.into());
    }
    if lights.is_empty() {
        // An empty list is an error to the validator: no lights, no extension.
        extensions_used.retain(|e| *e != "KHR_lights_punctual");
    } else {
        obj.insert("extensions".into(), json!({"KHR_lights_punctual": {"lights": lights}}));
    }
    obj.insert("extensionsUsed".into(), json!(extensions_used));
    while !b.bin.len().is_multiple_of(4) {
        b.bin.push(0);
    }
    obj.insert("buffers".into(), json!([{"byteLength": b.bin.len()}]));
    obj.insert("bufferViews".into(), b.views.into());
    obj.insert("accessors".into(), b.accessors.into());

    let json = serde_json::to_vec(&root)?;
    let glb = gltf::Glb {
        header: gltf::binary::Header { magic: *b"glTF", version: 2, length: 0 },
        json: std::borrow::Cow::Owned(json),
        bin: Some(std::borrow::Cow::Owned(b.bin)),
    };
    // Glb::to_writer computes the header's length from the chunks.
    Ok(glb.to_vec()?)
}
