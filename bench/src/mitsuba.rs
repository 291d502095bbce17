//! A scene in Mitsuba 3's XML, and Mitsuba's scalar CPU path tracer run on it: the independent
//! CPU renderer that `flicker bench` measures the WGSL path tracer against and that
//! bench/tests/mitsuba_matrix.rs compares it with pixel by pixel. The export covers triangle
//! meshes in world space (OBJ, with uvs), base-colour textures (PNG, sRGB, bilinear, repeat),
//! emissive materials as one-sided area lights, point lights, spot lights with a hard cone,
//! delta directional lights, a constant environment, the pinhole camera and media filling their
//! box (homogeneous, or our baked density grid as a `gridvolume`). Materials are
//! exported exactly, never approximately: Lambertian ones (specular and metallic 0) as Mitsuba's
//! `diffuse`, a white near-mirror metal as `conductor` without Fresnel, and every other
//! metallic-roughness material as the `gltf` plugin of scripts/mitsuba_gltf_bsdf.py (no stock
//! Mitsuba BSDF is the glTF model term for term; the plugin says where they differ). All BSDFs
//! are two-sided, as ours.
//!
//! What it refuses, with the reason: spot lights with a soft edge (ours a smoothstep in the
//! cosine, Mitsuba's linear in the angle), directional lights with an angular radius (Mitsuba's
//! `directional` is a delta), a texture on a diffuse material whose base colour is not white
//! (Mitsuba's `diffuse` cannot multiply), subsurface materials (no diffusion profile in Mitsuba).

use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use std::process::Command;

use anyhow::{Context, Result, bail};
use glam::{Mat3, Vec3};
use render::scene::{Light, Material, SceneDesc};
use scene::{DensityKind, MediumDesc};

/// Below this GGX alpha our BSDF clamps (pt_bsdf.wgsl's MIN_ALPHA): a near-mirror.
const MIN_ALPHA: f32 = 1.0e-3;

/// The built-in Cornell box with every material Lambertian (specular 0): the scene both our
/// path tracer and Mitsuba's `diffuse` BSDF render exactly (the bench's reference measurement
/// and bench/tests/mitsuba_agreement.rs).
pub fn lambertian_cornell_box(resolution: (u32, u32)) -> Result<SceneDesc> {
    let mut scene = playback::scenario::builtin_scene("cornell_box", resolution)?;
    for m in &mut scene.materials {
        m.specular = 0.0;
    }
    Ok(scene)
}

/// Path-tracer settings shared by both renderers.
pub struct Integrator {
    /// Mitsuba's `max_depth`: the longest path in segments, 1 = emitters seen directly only,
    /// 2 = direct lighting (our `PathTracerSettings::max_depth` + 1); `None` is unlimited
    /// (Mitsuba's -1).
    pub max_depth: Option<u32>,
    /// Depth at which Russian roulette starts.
    pub rr_depth: u32,
}

/// Mitsuba's BSDF element for one of our materials, exactly the same function.
fn bsdf_xml(material: &Material, texture: Option<&str>, what: &str) -> Result<String> {
    let rgb = |v: Vec3| format!("{} {} {}", v.x, v.y, v.z);
    if material.subsurface.is_some() {
        bail!("{what}: subsurface scattering has no Mitsuba counterpart (no diffusion profile)");
    }
    let alpha = (material.roughness.clamp(0.0, 1.0)).powi(2).max(MIN_ALPHA);
    let inner = if material.specular == 0.0 && material.metallic == 0.0 {
        let reflectance = match texture {
            None => format!("<rgb name=\"reflectance\" value=\"{}\"/>", rgb(material.base_color)),
            Some(_) if material.base_color != Vec3::ONE => bail!(
                "{what}: a texture times a base colour other than white (Mitsuba's `diffuse` \
                 takes one reflectance)"
            ),
            Some(file) => format!(
                "<texture type=\"bitmap\" name=\"reflectance\"><string name=\"filename\" value=\"{file}\"/>\
                 <string name=\"filter_type\" value=\"bilinear\"/><string name=\"wrap_mode\" value=\"repeat\"/></texture>"
            ),
        };
        format!("<bsdf type=\"diffuse\">{reflectance}</bsdf>")
    } else if texture.is_some() {
        bail!("{what}: textures are exported on Lambertian materials only");
    } else if material.metallic == 1.0 && material.base_color == Vec3::ONE && alpha <= MIN_ALPHA {
        // F0 = 1 makes Schlick's Fresnel 1, and alpha = 1e-3 is a mirror to float precision.
        "<bsdf type=\"conductor\"><string name=\"material\" value=\"none\"/></bsdf>".to_string()
    } else {
        format!(
            "<bsdf type=\"gltf\"><rgb name=\"base_color\" value=\"{}\"/><float name=\"metallic\" value=\"{}\"/>\
             <float name=\"roughness\" value=\"{}\"/><float name=\"specular\" value=\"{}\"/></bsdf>",
            rgb(material.base_color),
            material.metallic,
            material.roughness,
            material.specular
        )
    };
    Ok(format!("<bsdf type=\"twosided\">{inner}</bsdf>"))
}

/// Writes `dir/scene.xml`, one OBJ per instance (world space) and one PNG per texture; returns
/// the XML's path.
pub fn write_scene(
    scene: &SceneDesc,
    size: (u32, u32),
    integrator: &Integrator,
    dir: &Path,
) -> Result<PathBuf> {
    write_scene_with_media(scene, &[], size, integrator, dir)
}

/// A medium filling its box (boundary index-matched, isotropic phase, as our volumetric path
/// tracer's) as a Mitsuba medium inside a `cube` with a `null` BSDF: a homogeneous one as
/// `homogeneous`; any other density as `heterogeneous` over a `gridvolume` holding our baked
/// grid itself (`media::DensityGrid`, written to `dir/medium_{index}.vol`), looked up
/// nearest-neighbour as ours: voxel (i, j, k) covers [i, i + 1) x [j, j + 1) x [k, k + 1) of
/// the box in voxel units, in both renderers. Refused: other bounds, emission and motion.
fn medium_xml(m: &MediumDesc, index: usize, dir: &Path) -> Result<String> {
    let what = format!("medium '{}'", m.name);
    if m.bound != scene::MediumBound::Box || m.emission.is_some() || !m.motion.is_still() {
        bail!("{what}: only a still, non-emissive medium filling its box is exported");
    }
    let (centre, half) = (0.5 * (m.box_min + m.box_max), 0.5 * (m.box_max - m.box_min));
    let v = |v: Vec3| format!("{} {} {}", v.x, v.y, v.z);
    let medium = if m.kind == DensityKind::Homogeneous {
        format!(
            "<medium type=\"homogeneous\" name=\"interior\"><float name=\"sigma_t\" value=\"{}\"/>\
             <rgb name=\"albedo\" value=\"{}\"/><phase type=\"isotropic\"/></medium>",
            m.sigma_t,
            v(m.albedo)
        )
    } else {
        let grid = media::DensityGrid::from_desc(m);
        let file = format!("medium_{index}.vol");
        write_grid_volume(&grid, &dir.join(&file))?;
        // The grid volume maps the unit cube to world space; Mitsuba ignores the file's box.
        // Its majorant is the grid's maximum (exact for nearest-neighbour lookups).
        format!(
            "<medium type=\"heterogeneous\" name=\"interior\">\
             <volume type=\"gridvolume\" name=\"sigma_t\"><string name=\"filename\" value=\"{file}\"/>\
             <string name=\"filter_type\" value=\"nearest\"/><transform name=\"to_world\"><scale value=\"{}\"/>\
             <translate value=\"{}\"/></transform></volume>\
             <float name=\"scale\" value=\"1\"/><rgb name=\"albedo\" value=\"{}\"/><phase type=\"isotropic\"/></medium>",
            v(grid.box_max - grid.box_min),
            v(grid.box_min),
            v(m.albedo)
        )
    };
    Ok(format!(
        "  <shape type=\"cube\"><transform name=\"to_world\"><scale value=\"{}\"/><translate value=\"{}\"/></transform>\
         <bsdf type=\"null\"/>\n    {medium}</shape>\n",
        v(half),
        v(centre),
    ))
}

/// Mitsuba's binary grid volume (`.vol`, version 3): "VOL", 3, encoding 1 (f32), the
/// resolution, 1 channel, the bounding box, then the values with x fastest, then y, then z
/// (`data[(z * ny + y) * nx + x]`, our `DensityGrid` order), all little-endian.
fn write_grid_volume(grid: &media::DensityGrid, path: &Path) -> Result<()> {
    let mut bytes = b"VOL\x03".to_vec();
    let ints = [1, grid.res.x as i32, grid.res.y as i32, grid.res.z as i32, 1];
    bytes.extend(ints.iter().flat_map(|i| i.to_le_bytes()));
    let bbox = [grid.box_min.to_array(), grid.box_max.to_array()].concat();
    bytes.extend(bbox.iter().chain(&grid.data).flat_map(|f| f.to_le_bytes()));
    std::fs::write(path, bytes).with_context(|| format!("writing {}", path.display()))
}

/// [`write_scene`] with participating media (see [`medium_xml`]); Mitsuba's `volpath` then
/// renders it.
pub fn write_scene_with_media(
    scene: &SceneDesc,
    media: &[MediumDesc],
    (width, height): (u32, u32),
    integrator: &Integrator,
    dir: &Path,
) -> Result<PathBuf> {
    std::fs::create_dir_all(dir).with_context(|| format!("creating {}", dir.display()))?;
    let rgb = |v: Vec3| format!("{} {} {}", v.x, v.y, v.z);
    let mut xml = String::from("<scene version=\"3.0.0\">\n");
    let depth = integrator.max_depth.map_or(-1, |d| d as i64);
    writeln!(
        xml,
        "  <integrator type=\"{}\"><integer name=\"max_depth\" value=\"{depth}\"/><integer name=\"rr_depth\" value=\"{}\"/></integrator>",
        if media.is_empty() { "path" } else { "volpath" },
        integrator.rr_depth
    )?;
    let c = &scene.camera;
    writeln!(
        xml,
        "  <sensor type=\"perspective\"><float name=\"fov\" value=\"{}\"/><string name=\"fov_axis\" value=\"y\"/>\n    \
         <transform name=\"to_world\"><lookat origin=\"{}\" target=\"{}\" up=\"{}\"/></transform>\n    \
         <sampler type=\"independent\"/><film type=\"hdrfilm\"><integer name=\"width\" value=\"{width}\"/><integer name=\"height\" value=\"{height}\"/>\
         <rfilter type=\"box\"/></film></sensor>",
        c.vfov.to_degrees(),
        rgb(c.position),
        rgb(c.target),
        rgb(c.up)
    )?;
    if scene.environment != Vec3::ZERO {
        writeln!(
            xml,
            "  <emitter type=\"constant\"><rgb name=\"radiance\" value=\"{}\"/></emitter>",
            rgb(scene.environment)
        )?;
    }
    for (i, light) in scene.lights.iter().enumerate() {
        match *light {
            Light::Point { position, intensity } => writeln!(
                xml,
                "  <emitter type=\"point\"><point name=\"position\" value=\"{}\"/><rgb name=\"intensity\" value=\"{}\"/></emitter>",
                rgb(position),
                rgb(intensity)
            )?,
            Light::Spot { position, direction, intensity, inner_angle, outer_angle } => {
                if inner_angle != outer_angle {
                    bail!(
                        "light {i}: a spot light with a soft edge (inner {inner_angle} rad, outer \
                         {outer_angle} rad): our falloff is a smoothstep in the cosine, Mitsuba's \
                         linear in the angle; only a hard cone (inner = outer) is the same light"
                    );
                }
                // Mitsuba's spot points along +z of its frame; beam_width = cutoff_angle is a
                // hard cone (no transition band).
                let target = position + direction.normalize();
                let up = if direction.normalize().y.abs() > 0.9 { Vec3::X } else { Vec3::Y };
                writeln!(
                    xml,
                    "  <emitter type=\"spot\"><rgb name=\"intensity\" value=\"{}\"/><float name=\"cutoff_angle\" value=\"{a}\"/>\
                     <float name=\"beam_width\" value=\"{a}\"/><transform name=\"to_world\"><lookat origin=\"{}\" target=\"{}\" up=\"{}\"/></transform></emitter>",
                    rgb(intensity),
                    rgb(position),
                    rgb(target),
                    rgb(up),
                    a = outer_angle.to_degrees(),
                )?
            }
            Light::Directional { direction, irradiance, angular_radius } => {
                if angular_radius != 0.0 {
                    bail!(
                        "light {i}: a directional light with an angular radius ({angular_radius} \
                         rad): Mitsuba's `directional` is a delta light"
                    );
                }
                writeln!(
                    xml,
                    "  <emitter type=\"directional\"><vector name=\"direction\" value=\"{}\"/><rgb name=\"irradiance\" value=\"{}\"/></emitter>",
                    rgb(direction.normalize()),
                    rgb(irradiance)
                )?
            }
        }
    }
    for (t, texture) in scene.textures.iter().enumerate() {
        let rgb8: Vec<u8> =
            texture.rgba8.chunks_exact(4).flat_map(|p| [p[0], p[1], p[2]]).collect();
        let image = image::RgbImage::from_raw(texture.width, texture.height, rgb8)
            .with_context(|| format!("texture {t} '{}': texel count", texture.name))?;
        let file = dir.join(format!("texture_{t}.png"));
        image.save(&file).with_context(|| format!("writing {}", file.display()))?;
    }
    for (i, instance) in scene.instances.iter().enumerate() {
        let mesh = &scene.meshes[instance.mesh as usize];
        let material = &scene.materials[instance.material as usize];
        let texture = material.base_color_texture.map(|t| format!("texture_{t}.png"));
        let file = format!("instance_{i}.obj");
        let normal_matrix = Mat3::from_mat4(instance.transform).inverse().transpose();
        let mut obj = String::new();
        for p in &mesh.positions {
            let w = instance.transform.transform_point3(*p);
            writeln!(obj, "v {} {} {}", w.x, w.y, w.z)?;
        }
        for n in &mesh.normals {
            let w = (normal_matrix * *n).normalize_or_zero();
            writeln!(obj, "vn {} {} {}", w.x, w.y, w.z)?;
        }
        for uv in &mesh.uvs {
            writeln!(obj, "vt {} {}", uv.x, uv.y)?;
        }
        let (vn, vt) = (!mesh.normals.is_empty(), !mesh.uvs.is_empty());
        for t in &mesh.indices {
            let corners = t.map(|k| {
                let k = k + 1;
                match (vt, vn) {
                    (false, false) => format!("{k}"),
                    (true, false) => format!("{k}/{k}"),
                    (false, true) => format!("{k}//{k}"),
                    (true, true) => format!("{k}/{k}/{k}"),
                }
            });
            writeln!(obj, "f {} {} {}", corners[0], corners[1], corners[2])?;
        }
        std::fs::write(dir.join(&file), obj)
            .with_context(|| format!("writing {}", dir.join(&file).display()))?;
        let bsdf = bsdf_xml(
            material,
            texture.as_deref(),
            &format!("material {} of instance {i} (mesh {:?})", instance.material, mesh.name),
        )?;
        // Our uvs are glTF's (v down the image, row 0 at v = 0), so no flip.
        writeln!(
            xml,
            "  <shape type=\"obj\"><string name=\"filename\" value=\"{file}\"/><boolean name=\"face_normals\" value=\"{}\"/>\
             <boolean name=\"flip_tex_coords\" value=\"false\"/>\n    {bsdf}",
            mesh.normals.is_empty(),
        )?;
        if material.emission != Vec3::ZERO {
            writeln!(
                xml,
                "    <emitter type=\"area\"><rgb name=\"radiance\" value=\"{}\"/></emitter>",
                rgb(material.emission)
            )?;
        }
        xml.push_str("  </shape>\n");
    }
    for (i, m) in media.iter().enumerate() {
        xml.push_str(&medium_xml(m, i, dir)?);
    }
    xml.push_str("</scene>\n");
    let path = dir.join("scene.xml");
    std::fs::write(&path, xml).with_context(|| format!("writing {}", path.display()))?;
    Ok(path)
}

/// One timed Mitsuba render.
#[derive(Clone, Debug, serde::Deserialize)]
pub struct MitsubaRun {
    pub seconds: f64,
    pub paths: u64,
    pub threads: u32,
    pub mean_rgb: [f64; 3],
    pub version: String,
}

impl MitsubaRun {
    pub fn paths_per_second(&self) -> f64 {
        self.paths as f64 / self.seconds
    }
}

/// The Python that has Mitsuba 3, if any (metrics::python's rule: `$FLICKER_PYTHON`, the
/// checkout's .venv, or `python3`).
pub fn python() -> Option<String> {
    let python = metrics::python::interpreter().to_string_lossy().into_owned();
    let ok = Command::new(&python)
        .args(["-c", "import mitsuba"])
        .output()
        .map(|o| o.status.success())
        .unwrap_or(false);
    ok.then_some(python)
}

/// Renders `xml` at `spp` with Mitsuba's scalar_rgb variant (all CPU threads), image to `exr`.
pub fn render(python: &str, xml: &Path, spp: u32, exr: &Path) -> Result<MitsubaRun> {
    let script = xml.with_file_name("mitsuba_render.py");
    std::fs::write(&script, include_str!("../../scripts/mitsuba_render.py"))?;
    std::fs::write(
        xml.with_file_name("mitsuba_gltf_bsdf.py"),
        include_str!("../../scripts/mitsuba_gltf_bsdf.py"),
    )?;
    let out = Command::new(python)
        .arg(&script)
        .arg(xml)
        .arg(spp.to_string())
        .arg(exr)
        .output()
        .with_context(|| format!("running {python} {}", script.display()))?;
    if !out.status.success() {
        bail!("Mitsuba failed on {}:\n{}", xml.display(), String::from_utf8_lossy(&out.stderr));
    }
    let stdout = String::from_utf8_lossy(&out.stdout);
    let line = stdout.lines().last().unwrap_or_default();
    serde_json::from_str(line).with_context(|| format!("reading Mitsuba's result line {line:?}"))
}
