//! glTF animations at import: node transform channels (read by the `gltf` crate) and
//! KHR_animation_pointer channels of light colour and intensity, material factors and camera
//! field of view. The `gltf` crate (1.4) knows no pointer channels (their target has no node):
//! [`split_pointer_channels`] takes them out of a .glb's JSON before the crate reads it, and
//! [`read_animations`] reads both kinds into the template's clips.

use std::collections::HashMap;

use glam::{Quat, Vec3, Vec4};
use gltf::animation::util::ReadOutputs;
use serde_json::Value;

use crate::animation::{CameraClip, Interpolation, LightClip, MaterialTrack, NodeClip, Track};
use crate::template::WorldTemplate;

pub const ANIMATION_POINTER: &str = "KHR_animation_pointer";

/// A channel whose target is a JSON pointer: the pointer and its sampler's accessors.
#[derive(Clone, Debug, PartialEq)]
pub struct PointerChannel {
    /// e.g. "animation 1 channel 0", for errors.
    pub part: String,
    pub pointer: String,
    pub input: usize,
    pub output: usize,
    pub interpolation: String,
}

/// The .glb without its pointer channels (animations left without channels removed; their
/// samplers stay, unused) and the channels taken out. A file without them is returned as it is.
pub fn split_pointer_channels(bytes: &[u8]) -> Result<(Vec<u8>, Vec<PointerChannel>), String> {
    if !bytes.starts_with(b"glTF") {
        return Ok((bytes.to_vec(), Vec::new()));
    }
    let glb = gltf::Glb::from_slice(bytes).map_err(|e| format!("cannot read the GLB: {e}"))?;
    let mut json: Value =
        serde_json::from_slice(&glb.json).map_err(|e| format!("the GLB's JSON chunk: {e}"))?;
    let Some(animations) = json.get_mut("animations").and_then(Value::as_array_mut) else {
        return Ok((bytes.to_vec(), Vec::new()));
    };
    let mut taken = Vec::new();
    for (a, animation) in animations.iter_mut().enumerate() {
        let samplers = animation.get("samplers").cloned().unwrap_or(Value::Null);
        let Some(channels) = animation.get_mut("channels").and_then(Value::as_array_mut) else {
            continue;
        };
        let mut kept = Vec::new();
        for (c, channel) in channels.drain(..).enumerate() {
            let target = &channel["target"];
            if target["path"] != "pointer" {
                kept.push(channel);
                continue;
            }
            let part = format!("animation {a} channel {c}");
            let pointer = target["extensions"][ANIMATION_POINTER]["pointer"]
                .as_str()
                .ok_or_else(|| {
                    format!("{part}: path \"pointer\" without a {ANIMATION_POINTER} pointer")
                })?
                .to_string();
            let sampler = channel["sampler"]
                .as_u64()
                .and_then(|s| samplers.get(s as usize))
                .ok_or_else(|| format!("{part}: no such sampler"))?;
            let index = |key: &str| {
                sampler[key]
                    .as_u64()
                    .map(|i| i as usize)
                    .ok_or_else(|| format!("{part}: its sampler has no {key} accessor"))
            };
            taken.push(PointerChannel {
                pointer,
                input: index("input")?,
                output: index("output")?,
                interpolation: sampler["interpolation"].as_str().unwrap_or("LINEAR").to_string(),
                part,
            });
        }
        *channels = kept;
    }
    animations.retain(|a| a["channels"].as_array().is_some_and(|c| !c.is_empty()));
    if taken.is_empty() {
        return Ok((bytes.to_vec(), Vec::new()));
    }
    let json = serde_json::to_vec(&json).map_err(|e| e.to_string())?;
    let out = gltf::Glb { header: glb.header, json: std::borrow::Cow::Owned(json), bin: glb.bin };
    Ok((out.to_vec().map_err(|e| e.to_string())?, taken))
}

fn interpolation(name: &str) -> Result<Interpolation, String> {
    match name {
        "LINEAR" => Ok(Interpolation::Linear),
        "STEP" => Ok(Interpolation::Step),
        other => Err(format!("interpolation {other}; expected LINEAR or STEP")),
    }
}

fn accessor_values<T: gltf::accessor::Item>(
    doc: &gltf::Document,
    buffers: &[gltf::buffer::Data],
    index: usize,
) -> Result<Vec<T>, String> {
    let accessor = doc.accessors().nth(index).ok_or(format!("no accessor {index}"))?;
    gltf::accessor::Iter::<T>::new(accessor, |b| buffers.get(b.index()).map(|d| &d.0[..]))
        .map(|it| it.collect())
        .ok_or(format!("accessor {index} cannot be read as the pointer's type"))
}

/// Reads every animation into `template`: `nodes` maps a glTF node index to its template node.
pub fn read_animations(
    doc: &gltf::Document,
    buffers: &[gltf::buffer::Data],
    pointers: &[PointerChannel],
    nodes: &HashMap<usize, usize>,
    template: &mut WorldTemplate,
) -> Result<(), (String, String)> {
    let read = |b: gltf::Buffer| buffers.get(b.index()).map(|d| &d.0[..]);
    for animation in doc.animations() {
        for channel in animation.channels() {
            let part = format!("animation {} channel {}", animation.index(), channel.index());
            let fail = |m: String| (part.clone(), m);
            // A node outside the rendered scene: nothing it moves is drawn.
            let Some(&node) = nodes.get(&channel.target().node().index()) else {
                continue;
            };
            let reader = channel.reader(read);
            let times: Vec<f32> =
                reader.read_inputs().ok_or_else(|| fail("no key times".into()))?.collect();
            let interp = match channel.sampler().interpolation() {
                gltf::animation::Interpolation::Linear => Interpolation::Linear,
                gltf::animation::Interpolation::Step => Interpolation::Step,
                gltf::animation::Interpolation::CubicSpline => {
                    return Err(fail("interpolation CUBICSPLINE; expected LINEAR or STEP".into()));
                }
            };
            let clip = template.nodes[node].clip.get_or_insert_with(NodeClip::default);
            match reader.read_outputs().ok_or_else(|| fail("no key values".into()))? {
                ReadOutputs::Translations(v) => {
                    clip.translation =
                        Some(Track::new(times, v.map(Vec3::from).collect(), interp).map_err(fail)?)
                }
                ReadOutputs::Rotations(v) => {
                    let q = v.into_f32().map(|q| Quat::from_array(q).normalize()).collect();
                    clip.rotation = Some(Track::new(times, q, interp).map_err(fail)?)
                }
                ReadOutputs::Scales(v) => {
                    clip.scale =
                        Some(Track::new(times, v.map(Vec3::from).collect(), interp).map_err(fail)?)
                }
                ReadOutputs::MorphTargetWeights(_) => {
                    return Err(fail("morph target weights are not supported".into()));
                }
            }
        }
    }
    let light_nodes: HashMap<usize, usize> =
        doc.nodes().filter_map(|n| Some((n.light()?.index(), *nodes.get(&n.index())?))).collect();
    let camera_nodes: HashMap<usize, usize> =
        doc.nodes().filter_map(|n| Some((n.camera()?.index(), *nodes.get(&n.index())?))).collect();
    for p in pointers {
        let fail = |m: String| (p.part.clone(), format!("pointer {}: {m}", p.pointer));
        let times: Vec<f32> = accessor_values(doc, buffers, p.input).map_err(fail)?;
        let interp = interpolation(&p.interpolation).map_err(fail)?;
        let f1 = || -> Result<Track<f32>, String> {
            Track::new(times.clone(), accessor_values(doc, buffers, p.output)?, interp)
        };
        let f3 = || -> Result<Track<Vec3>, String> {
            let v: Vec<[f32; 3]> = accessor_values(doc, buffers, p.output)?;
            Track::new(times.clone(), v.into_iter().map(Vec3::from).collect(), interp)
        };
        let parts: Vec<&str> = p.pointer.trim_start_matches('/').split('/').collect();
        let index = |i: usize| parts.get(i).and_then(|s| s.parse::<usize>().ok());
        match parts.as_slice() {
            ["extensions", "KHR_lights_punctual", "lights", _, what] => {
                let light = index(3).ok_or_else(|| fail("no light index".into()))?;
                let node = *light_nodes
                    .get(&light)
                    .ok_or_else(|| fail(format!("light {light} is on no node of the scene")))?;
                let spec = doc
                    .lights()
                    .and_then(|mut l| l.nth(light))
                    .ok_or_else(|| fail(format!("no light {light}")))?;
                let clip = template.nodes[node].light_clip.get_or_insert_with(|| LightClip {
                    color: Vec3::from(spec.color()),
                    intensity: spec.intensity(),
                    color_track: None,
                    intensity_track: None,
                });
                match *what {
                    "intensity" => clip.intensity_track = Some(f1().map_err(fail)?),
                    "color" => clip.color_track = Some(f3().map_err(fail)?),
                    other => {
                        return Err(fail(format!(
                            "light property {other} cannot be animated; expected intensity or color"
                        )));
                    }
                }
            }
            ["cameras", _, "perspective", "yfov"] => {
                let camera = index(1).ok_or_else(|| fail("no camera index".into()))?;
                let node = *camera_nodes
                    .get(&camera)
                    .ok_or_else(|| fail(format!("camera {camera} is on no node of the scene")))?;
                template.nodes[node].camera_clip = Some(CameraClip(f1().map_err(fail)?));
            }
            ["materials", _, rest @ ..] => {
                let m = index(1).ok_or_else(|| fail("no material index".into()))?;
                if m >= template.materials.materials.len() {
                    return Err(fail(format!("no material {m}")));
                }
                let track = match rest {
                    ["emissiveFactor"] => {
                        let strength = doc
                            .materials()
                            .nth(m)
                            .and_then(|mat| mat.emissive_strength())
                            .unwrap_or(1.0);
                        MaterialTrack::Emissive { factor: f3().map_err(fail)?, strength }
                    }
                    ["pbrMetallicRoughness", "baseColorFactor"] => {
                        let v: Vec<[f32; 4]> =
                            accessor_values(doc, buffers, p.output).map_err(fail)?;
                        MaterialTrack::BaseColor(
                            Track::new(times.clone(), v.into_iter().map(Vec4::from).collect(), interp)
                                .map_err(fail)?,
                        )
                    }
                    ["pbrMetallicRoughness", "roughnessFactor"] => {
                        MaterialTrack::Roughness(f1().map_err(fail)?)
                    }
                    ["pbrMetallicRoughness", "metallicFactor"] => {
                        MaterialTrack::Metallic(f1().map_err(fail)?)
                    }
                    _ => return Err(fail("this material property cannot be animated; expected emissiveFactor or a pbrMetallicRoughness factor".into())),
                };
                template.material_clips.0.push((m as u32, track));
            }
            _ => {
                return Err(fail(
                    "expected a light's intensity or color, a material factor or a camera's yfov"
                        .into(),
                ));
            }
        }
    }
    Ok(())
}
