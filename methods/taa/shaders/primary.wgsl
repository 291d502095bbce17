// Primary-hit attributes of a jittered sample, written by every pass that feeds the TAA resolve
// (trace.wgsl, the hash cache). Needs the shading library (pt_scene: frame, camera helpers).

import package::scene_bindings::{frame};
import package::scene_geometry::{Hit, NO_HIT, previous_world_position, surface_point};
import package::pt_scene::{orient, project_offset};
import package::taa_types::{TaaPrimary};

// The primary hit's attributes for the ray (origin, dir); shared with the hash cache's pass.
fn primary_attributes(hit: Hit, origin: vec3f, dir: vec3f) -> TaaPrimary {
    var p: TaaPrimary;
    p.instance = hit.instance;
    if hit.instance == NO_HIT {
        p.depth = 0.0;
        p.previous_depth = 0.0;
        p.normal = vec3f(0.0);
        p.motion = project_offset(frame.previous_camera, dir) - project_offset(frame.camera, dir);
    } else {
        let sp = surface_point(hit, origin, dir);
        let sh = orient(sp, -dir);
        let before = previous_world_position(hit) - frame.previous_camera.position;
        p.depth = length(sp.position - origin);
        p.previous_depth = length(before);
        p.normal = sh.ns;
        p.motion = project_offset(frame.previous_camera, before) - project_offset(frame.camera, sp.position - origin);
    }
    return p;
}
