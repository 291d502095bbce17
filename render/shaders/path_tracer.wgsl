// Megakernel path tracer: one thread per pixel, `spp` paths per dispatch, and a separate G-buffer
// entry point that traces the un-jittered pixel-centre ray. Concatenated after the library
// (PathTracer::library_source).

fn trace_path(pixel: vec2u, sample_index: u32) -> vec3f {
    var rng = rng_seed(frame.seed.xy, frame.seed.z, pixel.y * frame.size.x + pixel.x, sample_index);
    let jitter = rng_next2(&rng);
    let dir = camera_ray_direction(frame.camera, vec2f(pixel) + jitter);
    return path_radiance(frame.camera.position.xyz, dir, 0.0, 0u, &rng);
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
