//! A scene in Mitsuba 3's XML, and Mitsuba's scalar CPU path tracer run on it: the independent
//! CPU renderer that `flicker bench` measures the WGSL path tracer against (issue 17). The
//! export covers what the built-in scenes use: triangle meshes in world space (OBJ), the
//! metallic-roughness material as Mitsuba's `principled` BSDF, emissive materials as area
//! lights, point lights, a constant environment and the pinhole camera. Mitsuba's principled
//! BSDF is not our BSDF term for term, so images agree in the mean to a few percent, not pixel
//! for pixel; the bench prints both means.

use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use std::process::Command;

use anyhow::{Context, Result, bail};
use glam::{Mat3, Vec3};
use render::scene::{Light, SceneDesc};

/// The built-in Cornell box with every material Lambertian (specular 0): the scene both our
/// path tracer and Mitsuba's `diffuse` BSDF render exactly (the bench's reference measurement
/// and systems/tests/mitsuba_agreement.rs).
pub fn lambertian_cornell_box(resolution: (u32, u32)) -> Result<SceneDesc> {
    let mut scene = crate::scenario::builtin_scene("cornell_box", resolution)?;
    for m in &mut scene.materials {
        m.specular = 0.0;
    }
    Ok(scene)
}

/// Path-tracer settings shared by both renderers.
pub struct Integrator {
    /// Longest path in vertices; `None` is unlimited (Mitsuba's -1).
    pub max_depth: Option<u32>,
    /// Depth at which Russian roulette starts.
    pub rr_depth: u32,
}

/// Writes `dir/scene.xml` and one OBJ per instance (world space); returns the XML's path.
pub fn write_scene(
    scene: &SceneDesc,
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
        "  <integrator type=\"path\"><integer name=\"max_depth\" value=\"{depth}\"/><integer name=\"rr_depth\" value=\"{}\"/></integrator>",
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
    for light in &scene.lights {
        match light {
            Light::Point { position, intensity } => writeln!(
                xml,
                "  <emitter type=\"point\"><point name=\"position\" value=\"{}\"/><rgb name=\"intensity\" value=\"{}\"/></emitter>",
                rgb(*position),
                rgb(*intensity)
            )?,
            other => bail!("the Mitsuba export covers point lights only, not {other:?}"),
        }
    }
    for (i, instance) in scene.instances.iter().enumerate() {
        let mesh = &scene.meshes[instance.mesh as usize];
        let material = &scene.materials[instance.material as usize];
        if material.base_color_texture.is_some() {
            bail!(
                "the Mitsuba export has no textures (material of instance {i}, mesh {:?})",
                mesh.name
            );
        }
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
        for t in &mesh.indices {
            let [a, b, c] = t.map(|k| k + 1);
            if mesh.normals.is_empty() {
                writeln!(obj, "f {a} {b} {c}")?;
            } else {
                writeln!(obj, "f {a}//{a} {b}//{b} {c}//{c}")?;
            }
        }
        std::fs::write(dir.join(&file), obj)
            .with_context(|| format!("writing {}", dir.join(&file).display()))?;
        // Without specular and metal our BSDF is Lambertian, as Mitsuba's `diffuse`. Otherwise
        // `principled`: our specular factor scales F0 = 0.04, Mitsuba's `specular` gives F0 = 0.08 s.
        let bsdf = if material.specular == 0.0 && material.metallic == 0.0 {
            format!(
                "<bsdf type=\"diffuse\"><rgb name=\"reflectance\" value=\"{}\"/></bsdf>",
                rgb(material.base_color)
            )
        } else {
            format!(
                "<bsdf type=\"principled\"><rgb name=\"base_color\" value=\"{}\"/><float name=\"roughness\" value=\"{}\"/>\
                 <float name=\"metallic\" value=\"{}\"/><float name=\"specular\" value=\"{}\"/></bsdf>",
                rgb(material.base_color),
                material.roughness,
                material.metallic,
                0.5 * material.specular
            )
        };
        writeln!(
            xml,
            "  <shape type=\"obj\"><string name=\"filename\" value=\"{file}\"/><boolean name=\"face_normals\" value=\"{}\"/>\n    {bsdf}",
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

/// The Python that has Mitsuba 3, if any: `$FLICKER_PYTHON` or `python3`.
pub fn python() -> Option<String> {
    let python = std::env::var("FLICKER_PYTHON").unwrap_or_else(|_| "python3".into());
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
