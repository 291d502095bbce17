//! glTF 2.0 import: meshes, node hierarchy, metallic-roughness materials with base-colour
//! textures, emission (with KHR_materials_emissive_strength), KHR_lights_punctual,
//! perspective cameras, and subsurface parameters from KHR_materials_diffuse_transmission +
//! KHR_materials_volume ([`subsurface_from_volume`]).
//!
//! Light units are taken as they are (lux for directional, candela for point and spot) and
//! used as the renderer's linear radiometric scale.

use std::collections::HashMap;
use std::f32::consts::PI;
use std::path::{Path, PathBuf};

use glam::{Mat4, Quat, Vec2, Vec3};
use scene::{Light, Material, Mesh, Subsurface, Texture};

use crate::components::MeshInstance;
use crate::template::{NodeTemplate, WorldTemplate};
use crate::transform::Transform;

/// A glTF file that could not be imported: which file, which part, what was wrong.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("{}: {part}: {message}", file.display())]
pub struct GltfError {
    pub file: PathBuf,
    /// The part that failed, e.g. "mesh 'Foo' primitive 0" or "file".
    pub part: String,
    pub message: String,
}

fn label(kind: &str, name: Option<&str>, index: usize) -> String {
    match name {
        Some(n) if !n.is_empty() => format!("{kind} '{n}'"),
        _ => format!("{kind} {index}"),
    }
}

/// Converts a decoded image to RGBA8 (16-bit channels keep their high byte).
fn to_rgba8(data: &gltf::image::Data) -> Result<Vec<u8>, String> {
    use gltf::image::Format;
    let (channels, bytes_per) = match data.format {
        Format::R8 => (1, 1),
        Format::R8G8 => (2, 1),
        Format::R8G8B8 => (3, 1),
        Format::R8G8B8A8 => (4, 1),
        Format::R16 => (1, 2),
        Format::R16G16 => (2, 2),
        Format::R16G16B16 => (3, 2),
        Format::R16G16B16A16 => (4, 2),
        other => {
            return Err(format!(
                "pixel format {other:?} is not supported; expected 8 or 16 bits per channel"
            ));
        }
    };
    let texels = data.width as usize * data.height as usize;
    if data.pixels.len() != texels * channels * bytes_per {
        return Err(format!(
            "{} bytes of pixels for {}x{}",
            data.pixels.len(),
            data.width,
            data.height
        ));
    }
    let mut out = Vec::with_capacity(texels * 4);
    for t in 0..texels {
        // Little-endian 16-bit: the high byte is the second one.
        let c = |k: usize| data.pixels[(t * channels + k) * bytes_per + bytes_per - 1];
        let (r, g, b, a) = match channels {
            1 => (c(0), c(0), c(0), 255),
            2 => (c(0), c(0), c(0), c(1)),
            3 => (c(0), c(1), c(2), 255),
            _ => (c(0), c(1), c(2), c(3)),
        };
        out.extend_from_slice(&[r, g, b, a]);
    }
    Ok(out)
}

fn node_transform(t: gltf::scene::Transform) -> Result<Transform, String> {
    let transform = match t {
        gltf::scene::Transform::Matrix { matrix } => {
            Transform::from_matrix(Mat4::from_cols_array_2d(&matrix))
        }
        gltf::scene::Transform::Decomposed { translation, rotation, scale } => Transform::from_trs(
            Vec3::from(translation),
            Quat::from_array(rotation).normalize(),
            Vec3::from(scale),
        ),
    };
    // A zero quaternion normalizes to NaN; an infinite number stays infinite.
    let Transform { translation, rotation, scale } = transform;
    match translation.is_finite() && rotation.is_finite() && scale.is_finite() {
        true => Ok(transform),
        false => Err(format!(
            "transform (translation {translation}, rotation {rotation}, scale {scale}) is not finite; expected finite numbers and a non-zero rotation"
        )),
    }
}

/// An error naming the first of `numbers` (name, values) that is not finite.
fn check_finite(numbers: &[(&str, Vec<f32>)]) -> Result<(), String> {
    match numbers.iter().find(|(_, v)| v.iter().any(|x| !x.is_finite())) {
        Some((name, v)) => Err(format!("{name} {v:?} is not finite; expected finite numbers")),
        None => Ok(()),
    }
}

fn read_primitive(
    primitive: &gltf::Primitive,
    buffers: &[gltf::buffer::Data],
    name: String,
) -> Result<Mesh, String> {
    if primitive.mode() != gltf::mesh::Mode::Triangles {
        return Err(format!("mode {:?} is not supported; expected triangles", primitive.mode()));
    }
    // The `gltf` crate's index reader treats any other component type as unreachable.
    if let Some(indices) = primitive.indices() {
        use gltf::accessor::DataType;
        if !matches!(indices.data_type(), DataType::U8 | DataType::U16 | DataType::U32) {
            return Err(format!(
                "indices accessor {} has component type {:?}; expected an unsigned byte, short or int",
                indices.index(),
                indices.data_type()
            ));
        }
    }
    let reader = primitive.reader(|b| buffers.get(b.index()).map(|d| &d.0[..]));
    let positions: Vec<Vec3> = reader
        .read_positions()
        .ok_or("no POSITION attribute; expected vertex positions")?
        .map(Vec3::from)
        .collect();
    let normals: Vec<Vec3> =
        reader.read_normals().map(|n| n.map(Vec3::from).collect()).unwrap_or_default();
    if !normals.is_empty() && normals.len() != positions.len() {
        return Err(format!("{} normals for {} positions", normals.len(), positions.len()));
    }
    let uvs: Vec<Vec2> = reader
        .read_tex_coords(0)
        .map(|t| t.into_f32().map(Vec2::from).collect())
        .unwrap_or_default();
    if !uvs.is_empty() && uvs.len() != positions.len() {
        return Err(format!("{} TEXCOORD_0 for {} positions", uvs.len(), positions.len()));
    }
    // A non-finite number would reach the BVH and every shaded pixel: refused at its vertex.
    for (what, values) in [
        ("POSITION", positions.iter().map(|p| p.to_array().to_vec()).collect::<Vec<_>>()),
        ("NORMAL", normals.iter().map(|n| n.to_array().to_vec()).collect()),
        ("TEXCOORD_0", uvs.iter().map(|u| u.to_array().to_vec()).collect()),
    ] {
        if let Some(v) = values.iter().position(|v| v.iter().any(|c| !c.is_finite())) {
            return Err(format!(
                "{what} of vertex {v} is {:?}; expected finite numbers",
                values[v]
            ));
        }
    }
    // Where the BVH's surface areas overflow (render::bvh::MAX_COORDINATE, refused there too).
    if let Some(v) = positions.iter().position(|p| p.abs().max_element() > 1e18) {
        return Err(format!(
            "POSITION of vertex {v} is {}; expected coordinates within ±1e18",
            positions[v]
        ));
    }
    let flat: Vec<u32> = match reader.read_indices() {
        Some(i) => i.into_u32().collect(),
        None => (0..positions.len() as u32).collect(),
    };
    if !flat.len().is_multiple_of(3) {
        return Err(format!("{} indices; expected a multiple of 3", flat.len()));
    }
    if let Some(bad) = flat.iter().find(|&&i| i as usize >= positions.len()) {
        return Err(format!("index {bad} out of range; expected < {}", positions.len()));
    }
    let indices = flat.chunks_exact(3).map(|c| [c[0], c[1], c[2]]).collect();
    Ok(Mesh { name, positions, normals, uvs, indices })
}

/// The extension that marks a material as diffusely transmitting (light enters and leaves
/// through the surface): with KHR_materials_volume it is read as subsurface scattering.
pub const DIFFUSE_TRANSMISSION: &str = "KHR_materials_diffuse_transmission";

/// Burley's parameters from KHR_materials_volume: light travels `attenuationDistance` before
/// it is attenuated to `attenuationColor`, so the extinction coefficient per channel is
/// σ_c = −ln(color_c) / distance, and the diffuse mean free path is taken as 1/σ_c. A
/// departure: glTF defines no diffusion profile, and Burley's dmfp is the profile's mean free
/// path on the surface, not the medium's 1/σ_t; the mapping keeps dmfp's ordering over
/// channels and its scale. Errors: an infinite distance or a channel of colour 1 (no
/// attenuation, an infinite dmfp), or a colour outside (0, 1].
pub fn subsurface_from_volume(distance: f32, color: [f32; 3]) -> Result<Subsurface, String> {
    if !(distance.is_finite() && distance > 0.0) {
        return Err(format!(
            "KHR_materials_volume attenuationDistance {distance}; expected a finite positive distance for subsurface scattering"
        ));
    }
    if let Some(c) = color.iter().find(|c| !(**c > 0.0 && **c < 1.0)) {
        return Err(format!(
            "KHR_materials_volume attenuationColor {color:?} has {c}; expected each channel in (0, 1) for subsurface scattering"
        ));
    }
    Ok(Subsurface { dmfp: Vec3::from(color.map(|c| distance / -c.ln())) })
}

/// Reads `path` (a .gltf with its buffers and images, or a .glb).
pub fn import(path: &Path) -> Result<WorldTemplate, GltfError> {
    let err = |part: &str, message: String| GltfError {
        file: path.to_path_buf(),
        part: part.to_string(),
        message,
    };
    if !path.is_file() {
        return Err(err("file", "not found; expected a .gltf or .glb file".into()));
    }
    // A .glb may carry KHR_animation_pointer channels, which the `gltf` crate cannot read:
    // they are taken out first (crate::gltf_animation).
    let bytes = std::fs::read(path).map_err(|e| err("file", format!("cannot read: {e}")))?;
    // The `gltf` crate subtracts the 12-byte header from the length the header declares.
    if bytes.starts_with(b"glTF") && bytes.len() >= 12 {
        let length = u32::from_le_bytes([bytes[8], bytes[9], bytes[10], bytes[11]]);
        if length < 12 {
            return Err(err(
                "GLB header",
                format!("length {length}; expected at least the 12-byte header"),
            ));
        }
    }
    // The `gltf` crate panics on an image with no source (neither `uri` nor `bufferView`), a
    // `bufferView` image without `mimeType`, or (in its own validation) a POSITION accessor
    // index past the accessors; refused here first, on the unvalidated JSON. A file that does
    // not parse is reported by the import below.
    if let Ok(parsed) = gltf::Gltf::from_slice_without_validation(&bytes) {
        let json = parsed.document.as_json();
        for (m, mesh) in json.meshes.iter().enumerate() {
            for (p, primitive) in mesh.primitives.iter().enumerate() {
                for (semantic, accessor) in &primitive.attributes {
                    if accessor.value() >= json.accessors.len() {
                        let part =
                            format!("{} primitive {p}", label("mesh", mesh.name.as_deref(), m));
                        let semantic = semantic.to_string();
                        return Err(err(
                            &part,
                            format!(
                                "{semantic} uses accessor {}, but the file has {} accessors",
                                accessor.value(),
                                json.accessors.len()
                            ),
                        ));
                    }
                }
            }
        }
        for (i, image) in json.images.iter().enumerate() {
            let missing = match (&image.buffer_view, &image.uri, &image.mime_type) {
                (Some(_), _, None) => "a bufferView image without mimeType",
                (None, None, _) => "neither uri nor bufferView",
                _ => continue,
            };
            let part = label("image", image.name.as_deref(), i);
            return Err(err(
                &part,
                format!("{missing}; expected a uri, or a bufferView and mimeType"),
            ));
        }
    }
    let (doc, buffers, images, pointers) = if bytes.starts_with(b"glTF") {
        let (glb, pointers) =
            crate::gltf_animation::split_pointer_channels(&bytes).map_err(|m| err("file", m))?;
        let (d, b, i) =
            gltf::import_slice(glb).map_err(|e| err("file", format!("cannot import: {e}")))?;
        (d, b, i, pointers)
    } else {
        let (d, b, i) =
            gltf::import(path).map_err(|e| err("file", format!("cannot import: {e}")))?;
        (d, b, i, Vec::new())
    };

    let mut t = WorldTemplate::default();
    for (i, image) in images.iter().enumerate() {
        let name = label("image", doc.images().nth(i).and_then(|im| im.name()), i);
        let rgba8 = to_rgba8(image).map_err(|m| err(&name, m))?;
        t.textures.push(Texture {
            name: name.clone(),
            width: image.width,
            height: image.height,
            rgba8,
        });
    }
    for (i, m) in doc.materials().enumerate() {
        let pbr = m.pbr_metallic_roughness();
        let c = pbr.base_color_factor();
        let strength = m.emissive_strength().unwrap_or(1.0);
        let subsurface = match (m.extension_value(DIFFUSE_TRANSMISSION), m.volume()) {
            (Some(_), Some(v)) => Some(
                subsurface_from_volume(v.attenuation_distance(), v.attenuation_color())
                    .map_err(|e| err(&label("material", m.name(), i), e))?,
            ),
            _ => None,
        };
        let factors = [
            ("baseColorFactor", c.to_vec()),
            (
                "emissiveFactor times emissiveStrength",
                m.emissive_factor().map(|e| e * strength).to_vec(),
            ),
            ("roughnessFactor", vec![pbr.roughness_factor()]),
            ("metallicFactor", vec![pbr.metallic_factor()]),
            ("specularFactor", vec![m.specular().map_or(1.0, |s| s.specular_factor())]),
        ];
        check_finite(&factors).map_err(|e| err(&label("material", m.name(), i), e))?;
        let material = Material {
            base_color: Vec3::new(c[0], c[1], c[2]),
            base_color_texture: pbr
                .base_color_texture()
                .map(|info| info.texture().source().index() as u32),
            emission: Vec3::from(m.emissive_factor()) * strength,
            roughness: pbr.roughness_factor(),
            metallic: pbr.metallic_factor(),
            specular: m.specular().map_or(1.0, |s| s.specular_factor()),
            subsurface,
        };
        t.add_material(m.name().unwrap_or(&format!("material{i}")), material);
    }
    let mut default_material = None;

    // Each primitive becomes one renderer mesh (it has one material).
    let mut primitives: Vec<Vec<MeshInstance>> = Vec::new();
    for mesh in doc.meshes() {
        let mesh_label = label("mesh", mesh.name(), mesh.index());
        let mut list = Vec::new();
        for p in mesh.primitives() {
            let part = format!("{mesh_label} primitive {}", p.index());
            let name = format!("{}#{}", mesh.name().unwrap_or("mesh"), p.index());
            let geometry = read_primitive(&p, &buffers, name).map_err(|m| err(&part, m))?;
            let material = match p.material().index() {
                Some(i) => i as u32,
                None => *default_material
                    .get_or_insert_with(|| t.add_material("default", Material::default())),
            };
            list.push(MeshInstance { mesh: t.add_mesh(geometry), material });
        }
        primitives.push(list);
    }

    let scene = doc.default_scene().or_else(|| doc.scenes().next());
    let roots: Vec<gltf::Node> = match &scene {
        Some(s) => s.nodes().collect(),
        None => {
            return Err(err("scenes", "no scene; expected at least one scene with nodes".into()));
        }
    };
    let mut indices: HashMap<usize, usize> = HashMap::new();
    let mut stack: Vec<(gltf::Node, Option<usize>)> =
        roots.into_iter().rev().map(|n| (n, None)).collect();
    while let Some((node, parent)) = stack.pop() {
        let name =
            node.name().map(str::to_string).unwrap_or_else(|| format!("node{}", node.index()));
        let part = label("node", node.name(), node.index());
        // glTF's nodes form trees: a node reached twice (a cycle, or two parents) is refused
        // before it loops or is spawned twice.
        if indices.contains_key(&node.index()) {
            return Err(err(&part, "is a child of two nodes or of itself; expected a tree".into()));
        }
        let transform = node_transform(node.transform()).map_err(|m| err(&part, m))?;
        let mut tn = NodeTemplate::new(name.clone(), transform);
        tn.parent = parent;
        let mut extra_primitives = Vec::new();
        if let Some(mesh) = node.mesh() {
            let list = &primitives[mesh.index()];
            tn.mesh = list.first().copied();
            extra_primitives.extend(list.iter().skip(1).copied());
        }
        if let Some(light) = node.light() {
            let mut numbers = vec![
                ("color", light.color().to_vec()),
                ("intensity", vec![light.intensity()]),
                ("flicker_angular_radius", vec![angular_radius(light.extras())]),
            ];
            if let gltf::khr_lights_punctual::Kind::Spot { inner_cone_angle, outer_cone_angle } =
                light.kind()
            {
                numbers.push(("spot cone angles", vec![inner_cone_angle, outer_cone_angle]));
            }
            let at = || format!("{part} light {}", light.index());
            check_finite(&numbers).map_err(|m| err(&at(), m))?;
            let color = Vec3::from(light.color()) * light.intensity();
            tn.light = Some(match light.kind() {
                gltf::khr_lights_punctual::Kind::Directional => Light::Directional {
                    direction: Vec3::NEG_Z,
                    irradiance: color,
                    angular_radius: angular_radius(light.extras()),
                },
                gltf::khr_lights_punctual::Kind::Point => {
                    Light::Point { position: Vec3::ZERO, intensity: color }
                }
                gltf::khr_lights_punctual::Kind::Spot { inner_cone_angle, outer_cone_angle } => {
                    Light::Spot {
                        position: Vec3::ZERO,
                        direction: Vec3::NEG_Z,
                        intensity: color,
                        inner_angle: inner_cone_angle,
                        outer_angle: outer_cone_angle,
                    }
                }
            });
        }
        if let Some(camera) = node.camera() {
            match camera.projection() {
                gltf::camera::Projection::Perspective(p) if !(p.yfov() > 0.0 && p.yfov() < PI) => {
                    return Err(err(
                        &format!("{part} {}", label("camera", camera.name(), camera.index())),
                        format!("yfov {}; expected an angle in (0, pi) radians", p.yfov()),
                    ));
                }
                gltf::camera::Projection::Perspective(p) => tn.camera = Some(p.yfov()),
                gltf::camera::Projection::Orthographic(_) => {
                    return Err(err(
                        &format!("{part} {}", label("camera", camera.name(), camera.index())),
                        "orthographic projection is not supported; expected perspective".into(),
                    ));
                }
            }
        }
        let index = t.add_node(tn);
        indices.insert(node.index(), index);
        for (k, instance) in extra_primitives.into_iter().enumerate() {
            let mut child = NodeTemplate::new(format!("{name}#{}", k + 1), Transform::IDENTITY);
            child.parent = Some(index);
            child.mesh = Some(instance);
            t.add_node(child);
        }
        for child in node.children().collect::<Vec<_>>().into_iter().rev() {
            stack.push((child, Some(index)));
        }
    }
    crate::gltf_animation::read_animations(&doc, &buffers, &pointers, &indices, &mut t)
        .map_err(|(part, message)| err(&part, message))?;
    Ok(t)
}

/// The extras key that carries a directional light's angular radius (radians): glTF's
/// directional lights are infinitely far points, flicker's may be discs (soft shadows).
pub const ANGULAR_RADIUS: &str = "flicker_angular_radius";

fn angular_radius(extras: &gltf::json::Extras) -> f32 {
    extras
        .as_ref()
        .and_then(|raw| serde_json::from_str::<serde_json::Value>(raw.get()).ok())
        .and_then(|v| v[ANGULAR_RADIUS].as_f64())
        .map_or(0.0, |r| r as f32)
}
