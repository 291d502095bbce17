// Megakernel path tracer: one thread per pixel, `spp` paths per dispatch, next-event estimation
// with MIS (power heuristic) against BSDF sampling, Russian roulette, and a separate G-buffer
// entry point that traces the un-jittered pixel-centre ray.
// Concatenated after scene_geometry.wgsl (@group(1)), pt_sampling.wgsl, pt_bsdf.wgsl and
// pt_lights.wgsl. Bindings of this pass are in @group(0) (layout in path_tracer.rs).

struct CameraFrame {
    position: vec4f,  // w: tan(vfov / 2)
    forward: vec4f,   // w: aspect (width / height)
    right: vec4f,
    up: vec4f,
}

struct Frame {
    camera: CameraFrame,
    previous_camera: CameraFrame,
    environment: vec4f,   // w: total emitter weight W = sum luminance(Le) * area
    size: vec4u,          // width, height, spp of this dispatch, index of its first sample
    seed: vec4u,          // seed low, seed high, frame, max depth
    counts: vec4u,        // Russian-roulette start depth, analytic lights, emissive triangles, accumulate
}

struct GpuMaterial {
    base_color: vec3f,
    texture_offset: u32,  // first texel in `texels`, NO_TEXTURE if none
    emission: vec3f,
    roughness: f32,
    metallic: f32,
    specular: f32,
    texture_width: u32,
    texture_height: u32,
}

struct GBufferTexel {
    normal: vec3f,
    depth: f32,
    albedo: vec3f,
    instance: u32,
    motion: vec2f,
    primitive: u32,
    pad: u32,
}

const NO_TEXTURE: u32 = 0xffffffffu;

@group(0) @binding(0) var<uniform> frame: Frame;
@group(0) @binding(1) var<storage, read> materials: array<GpuMaterial>;
@group(0) @binding(2) var<storage, read> texels: array<u32>;
@group(0) @binding(3) var<storage, read> lights: array<GpuLight>;
@group(0) @binding(4) var<storage, read_write> radiance_sum: array<vec4f>;
@group(0) @binding(5) var<storage, read_write> gbuffer: array<GBufferTexel>;

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

// Bilinear, repeat wrap, filtered in linear space (sRGB decoded per texel).
fn base_color_at(m: GpuMaterial, uv: vec2f) -> vec3f {
    if m.texture_offset == NO_TEXTURE || m.texture_width == 0u || m.texture_height == 0u {
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
    let w = f32(frame.size.x);
    let h = f32(frame.size.y);
    let ndc = vec2f(2.0 * pixel.x / w - 1.0, 1.0 - 2.0 * pixel.y / h);
    let d = c.forward.xyz + ndc.x * c.position.w * c.forward.w * c.right.xyz + ndc.y * c.position.w * c.up.xyz;
    return normalize(d);
}

// Pixel coordinates (x right, y down, pixel centres at +0.5) of a camera-space offset `d`.
fn project_offset(c: CameraFrame, d: vec3f) -> vec2f {
    let z = dot(d, c.forward.xyz);
    if z <= 0.0 {
        return vec2f(-1.0e9);
    }
    let ndc = vec2f(dot(d, c.right.xyz) / (z * c.position.w * c.forward.w), dot(d, c.up.xyz) / (z * c.position.w));
    return vec2f((0.5 * ndc.x + 0.5) * f32(frame.size.x), (0.5 - 0.5 * ndc.y) * f32(frame.size.y));
}

// Origin offset off the surface along the geometric normal, on the side `dir` leaves to.
fn offset_origin(p: vec3f, ng: vec3f, dir: vec3f) -> vec3f {
    let scale = 1.0e-4 * (1.0 + max(abs(p.x), max(abs(p.y), abs(p.z))));
    return p + ng * select(-scale, scale, dot(dir, ng) >= 0.0);
}

fn environment_pdf() -> f32 {
    return select(0.0, 1.0 / (4.0 * PI), max_component(frame.environment.xyz) > 0.0);
}

// Radiance arriving along a ray that left the scene: environment plus the disks of directional
// lights with an angular radius, each MIS-weighted against the BSDF pdf that chose the ray
// (`bsdf_pdf` <= 0: camera ray, no MIS).
fn escaped_radiance(dir: vec3f, bsdf_pdf: f32) -> vec3f {
    var l = frame.environment.xyz;
    if bsdf_pdf > 0.0 {
        l *= power_heuristic(bsdf_pdf, environment_pdf());
    }
    for (var i = 0u; i < frame.counts.y; i++) {
        let light = lights[i];
        if light.kind == LIGHT_DIRECTIONAL && light.a > 0.0 && 1.0 - dot(dir, -normalize(light.p1)) <= light.a {
            var w = 1.0;
            if bsdf_pdf > 0.0 {
                w = power_heuristic(bsdf_pdf, 1.0 / cone_solid_angle(light.a));
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

fn trace_path(pixel: vec2u, sample_index: u32) -> vec3f {
    var rng = rng_seed(frame.seed.xy, frame.seed.z, pixel.y * frame.size.x + pixel.x, sample_index);
    let jitter = rng_next2(&rng);
    var origin = frame.camera.position.xyz;
    var dir = camera_ray_direction(frame.camera, vec2f(pixel) + jitter);
    var throughput = vec3f(1.0);
    var radiance = vec3f(0.0);
    var prev_bsdf_pdf = 0.0;
    let max_depth = frame.seed.w;
    let analytic_count = frame.counts.y;
    let emitter_count = frame.counts.z;
    let emitter_weight = frame.environment.w;
    for (var depth = 0u; depth <= max_depth; depth++) {
        let hit = trace_closest(origin, dir, FAR);
        if hit.instance == NO_HIT {
            radiance += throughput * escaped_radiance(dir, prev_bsdf_pdf);
            break;
        }
        let sp = surface_point(hit, origin, dir);
        let m = materials[sp.material];
        let wo = -dir;
        let sh = orient(sp, wo);
        let le_lum = luminance(m.emission);
        // Emitters are one-sided (front face by winding, as pbrt's area lights and glTF's
        // emissive): a two-sided light a few millimetres under a ceiling traps light between
        // its back face and the ceiling, an unbounded-variance source of fireflies.
        let cos_light = -dot(sp.geometric_normal, dir);
        if le_lum > 0.0 && cos_light > 0.0 {
            var w = 1.0;
            if prev_bsdf_pdf > 0.0 && emitter_weight > 0.0 {
                let dist = hit.t;
                let light_pdf = select(0.0, le_lum / emitter_weight * dist * dist / cos_light, cos_light > 0.0);
                w = power_heuristic(prev_bsdf_pdf, light_pdf);
            }
            radiance += throughput * m.emission * w;
        }
        if depth == max_depth {
            break;
        }
        let bsdf = make_bsdf(base_color_at(m, sp.uv), m.metallic, m.roughness, m.specular);
        let p = sp.position;

        // Next-event estimation: every analytic light, one emissive triangle, the environment.
        for (var i = 0u; i < analytic_count; i++) {
            let ls = sample_analytic_light(lights[i], p, rng_next2(&rng));
            if dot(ls.wi, sh.ng) <= 0.0 || max_component(ls.weight) <= 0.0 {
                continue;
            }
            let f = bsdf_eval(bsdf, sh.ns, wo, ls.wi);
            if max_component(f) <= 0.0 {
                continue;
            }
            let o = offset_origin(p, sh.ng, ls.wi);
            if trace_any(o, ls.wi, ls.dist * (1.0 - 1.0e-4)) {
                continue;
            }
            var w = 1.0;
            if ls.pdf > 0.0 {
                w = power_heuristic(ls.pdf, bsdf_pdf(bsdf, sh.ns, wo, ls.wi));
            }
            radiance += throughput * f * dot(sh.ns, ls.wi) * ls.weight * w;
        }
        if emitter_count > 0u {
            let u_select = rng_next(&rng);
            let ls = sample_emitter(analytic_count, emitter_count, p, u_select, rng_next2(&rng));
            if ls.pdf > 0.0 && dot(ls.wi, sh.ng) > 0.0 {
                let f = bsdf_eval(bsdf, sh.ns, wo, ls.wi);
                if max_component(f) > 0.0 {
                    let o = offset_origin(p, sh.ng, ls.wi);
                    if !trace_any(o, ls.wi, ls.dist * (1.0 - 1.0e-3)) {
                        let w = power_heuristic(ls.pdf, bsdf_pdf(bsdf, sh.ns, wo, ls.wi));
                        radiance += throughput * f * dot(sh.ns, ls.wi) * ls.weight * w;
                    }
                }
            }
        }
        let env_pdf = environment_pdf();
        if env_pdf > 0.0 {
            let wi = sample_uniform_sphere(rng_next2(&rng));
            if dot(wi, sh.ng) > 0.0 {
                let f = bsdf_eval(bsdf, sh.ns, wo, wi);
                if max_component(f) > 0.0 && !trace_any(offset_origin(p, sh.ng, wi), wi, FAR) {
                    let w = power_heuristic(env_pdf, bsdf_pdf(bsdf, sh.ns, wo, wi));
                    radiance += throughput * f * dot(sh.ns, wi) * frame.environment.xyz * (w / env_pdf);
                }
            }
        }

        // Continue the path by sampling the BSDF.
        let u_lobe = rng_next(&rng);
        let bs = bsdf_sample(bsdf, sh.ns, wo, u_lobe, rng_next2(&rng));
        if !bs.valid || dot(bs.wi, sh.ng) <= 0.0 {
            break;
        }
        throughput *= bs.f * (dot(sh.ns, bs.wi) / bs.pdf);
        prev_bsdf_pdf = bs.pdf;
        if depth + 1u >= frame.counts.x {
            let survive = min(max_component(throughput), 0.95);
            if rng_next(&rng) >= survive {
                break;
            }
            throughput /= survive;
        }
        origin = offset_origin(p, sh.ng, bs.wi);
        dir = bs.wi;
    }
    return radiance;
}

@compute @workgroup_size(8, 8, 1)
fn trace_main(@builtin(global_invocation_id) id: vec3u) {
    if id.x >= frame.size.x || id.y >= frame.size.y {
        return;
    }
    var sum = vec3f(0.0);
    for (var s = 0u; s < frame.size.z; s++) {
        sum += trace_path(id.xy, frame.size.w + s);
    }
    let index = id.y * frame.size.x + id.x;
    var previous = vec4f(0.0);
    if frame.counts.w != 0u {
        previous = radiance_sum[index];
    }
    radiance_sum[index] = previous + vec4f(sum, f32(frame.size.z));
}

// Primary-hit G-buffer from the pixel-centre ray. Misses: depth 0 (the CPU turns it into +inf),
// zero normal and albedo, NO_HIT ids, motion of the direction at infinity.
@compute @workgroup_size(8, 8, 1)
fn gbuffer_main(@builtin(global_invocation_id) id: vec3u) {
    if id.x >= frame.size.x || id.y >= frame.size.y {
        return;
    }
    let centre = vec2f(id.xy) + 0.5;
    let origin = frame.camera.position.xyz;
    let dir = camera_ray_direction(frame.camera, centre);
    let hit = trace_closest(origin, dir, FAR);
    var g: GBufferTexel;
    g.instance = hit.instance;
    g.primitive = hit.primitive;
    if hit.instance == NO_HIT {
        g.depth = 0.0;
        g.normal = vec3f(0.0);
        g.albedo = vec3f(0.0);
        g.motion = project_offset(frame.previous_camera, dir) - project_offset(frame.camera, dir);
    } else {
        let sp = surface_point(hit, origin, dir);
        let sh = orient(sp, -dir);
        g.depth = length(sp.position - origin);
        g.normal = sh.ns;
        g.albedo = base_color_at(materials[sp.material], sp.uv);
        let now = project_offset(frame.camera, sp.position - origin);
        let before = project_offset(frame.previous_camera, previous_world_position(hit) - frame.previous_camera.position.xyz);
        g.motion = before - now;
    }
    gbuffer[id.y * frame.size.x + id.x] = g;
}
