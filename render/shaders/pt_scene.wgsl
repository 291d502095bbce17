// The scene as the path tracer's passes see it: frame uniform, materials, lights, camera, and
// the helpers every pass that shades surfaces needs. @group(0), read only (layout in
// src/scene_group.rs); every pass binds it and puts its own buffers in @group(2). The structs
// Frame, CameraFrame and GpuMaterial are declared once in Rust (render/src/frame.rs,
// materials.rs: gpu_struct!) as package::scene_types (PassLibrary::modules).

import package::scene_types::{CameraFrame, GpuMaterial};
import package::scene_bindings::{frame, texels};
import package::scene_features::{HAS_ANALYTIC_LIGHTS, HAS_TEXTURES};
import package::scene_tables::{light};
import package::scene_geometry::{Hit, NO_HIT, SurfacePoint, previous_world_position};
import package::pt_sampling::{PI, max_component, power_heuristic};
import package::pt_bsdf::{bsdf_pdf};
import package::pt_lights::{directional_pdf};

const NO_TEXTURE: u32 = 0xffffffffu;

fn srgb_to_linear(c: vec3f) -> vec3f {
    let lo = c / 12.92;
    let hi = pow((c + 0.055) / 1.055, vec3f(2.4));
    return select(hi, lo, c <= vec3f(0.04045));
}

fn texel(m: GpuMaterial, x: i32, y: i32) -> vec3f {
    let w = i32(m.texture_width);
    let h = i32(m.texture_height);
    let xi = ((x % w) + w) % w;
    let yi = ((y % h) + h) % h;
    let packed = texels[m.texture_offset + u32(yi * w + xi)];
    return srgb_to_linear(unpack4x8unorm(packed).rgb);
}

// Bilinear, repeat wrap, filtered in linear space (sRGB decoded per texel). Compiled out of a
// scene without textures (scene_features.rs).
fn base_color_at(m: GpuMaterial, uv: vec2f) -> vec3f {
    if !HAS_TEXTURES || m.texture_offset == NO_TEXTURE || m.texture_width == 0u || m.texture_height == 0u {
        return m.base_color;
    }
    let st = uv * vec2f(f32(m.texture_width), f32(m.texture_height)) - 0.5;
    let base = floor(st);
    let f = st - base;
    let x = i32(base.x);
    let y = i32(base.y);
    let top = mix(texel(m, x, y), texel(m, x + 1, y), f.x);
    let bottom = mix(texel(m, x, y + 1), texel(m, x + 1, y + 1), f.x);
    return m.base_color * mix(top, bottom, f.y);
}

fn camera_ray_direction(c: CameraFrame, pixel: vec2f) -> vec3f {
    let w = f32(frame.width);
    let h = f32(frame.height);
    let ndc = vec2f(2.0 * pixel.x / w - 1.0, 1.0 - 2.0 * pixel.y / h);
    let d = c.forward + ndc.x * c.tan_half_fov * c.aspect * c.right + ndc.y * c.tan_half_fov * c.up;
    return normalize(d);
}

// Pixel coordinates (x right, y down, pixel centres at +0.5) of a camera-space offset `d`.
fn project_offset(c: CameraFrame, d: vec3f) -> vec2f {
    let z = dot(d, c.forward);
    if z <= 0.0 {
        return vec2f(-1.0e9);
    }
    let ndc = vec2f(dot(d, c.right) / (z * c.tan_half_fov * c.aspect), dot(d, c.up) / (z * c.tan_half_fov));
    return vec2f((0.5 * ndc.x + 0.5) * f32(frame.width), (0.5 - 0.5 * ndc.y) * f32(frame.height));
}

// Motion (previous image position - current, pixels) of what the camera ray (origin, dir) hit:
// the hit point moved by the previous instance transforms, seen by the previous camera; a miss
// moves like the direction at infinity.
fn primary_motion(hit: Hit, origin: vec3f, dir: vec3f, hit_point: vec3f) -> vec2f {
    if hit.instance == NO_HIT {
        return project_offset(frame.previous_camera, dir) - project_offset(frame.camera, dir);
    }
    let before = project_offset(frame.previous_camera, previous_world_position(hit) - frame.previous_camera.position);
    return before - project_offset(frame.camera, hit_point - origin);
}

// Origin offset off the surface along the geometric normal, on the side `dir` leaves to.
fn offset_origin(p: vec3f, ng: vec3f, dir: vec3f) -> vec3f {
    let scale = 1.0e-4 * (1.0 + max(abs(p.x), max(abs(p.y), abs(p.z))));
    return p + ng * select(-scale, scale, dot(dir, ng) >= 0.0);
}

fn environment_pdf() -> f32 {
    return select(0.0, 1.0 / (4.0 * PI), max_component(frame.environment) > 0.0);
}

// Radiance arriving along a ray that left the scene: environment plus the disks of directional
// lights with an angular radius, each MIS-weighted against the BSDF pdf that chose the ray
// (`bsdf_pdf` <= 0: camera ray, no MIS).
fn escaped_radiance(dir: vec3f, bsdf_pdf: f32) -> vec3f {
    var l = frame.environment;
    if bsdf_pdf > 0.0 {
        l *= power_heuristic(bsdf_pdf, environment_pdf());
    }
    if !HAS_ANALYTIC_LIGHTS {
        return l;
    }
    for (var i = 0u; i < frame.analytic_lights; i++) {
        let light = light(i);
        let light_pdf = directional_pdf(light, dir);
        if light_pdf > 0.0 {
            var w = 1.0;
            if bsdf_pdf > 0.0 {
                w = power_heuristic(bsdf_pdf, light_pdf);
            }
            l += light.radiance * light.b * w;
        }
    }
    return l;
}

struct Shading {
    ng: vec3f,   // geometric normal, turned towards wo
    ns: vec3f,   // shading normal, on the same side as ng
}

fn orient(sp: SurfacePoint, wo: vec3f) -> Shading {
    var s: Shading;
    s.ng = select(-sp.geometric_normal, sp.geometric_normal, dot(sp.geometric_normal, wo) >= 0.0);
    s.ns = select(-sp.shading_normal, sp.shading_normal, dot(sp.shading_normal, s.ng) >= 0.0);
    return s;
}
