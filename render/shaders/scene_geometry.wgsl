// Scene geometry: two-level CWBVH traversal (Ylitie, Karras & Laine 2017, "Efficient Incoherent
// Ray Traversal on GPUs Through Compressed Wide BVHs") and hit attributes.
// A pass imports it (SceneGeometry::modules) and binds the geometry at @group(1); internal names
// start with `sg_`.

import package::scene_geometry_types::{SgNode, SgTriangle, SgTlasLeaf, SgMesh, SgVertex, SgInstance};
import package::scene_geometry_bindings::{sg_instance_header, sg_nodes, sg_triangles, sg_tlas_leaves, sg_instances, sg_meshes, sg_vertices, sg_indices};
import package::texel_table::texel_fetch;
import package::scene_features::TRAVERSAL_STACK_ENTRIES;

const NO_HIT: u32 = 0xffffffffu;

// instance == NO_HIT on a miss; barycentrics = (u, v), the weights of vertices 1 and 2.
struct Hit { t: f32, instance: u32, primitive: u32, barycentrics: vec2f }

struct SurfacePoint {
    position: vec3f,
    geometric_normal: vec3f,
    shading_normal: vec3f,
    uv: vec2f,
    material: u32,
}

// The node, triangle, mesh, vertex and instance structs and the @group(1) bindings are declared
// once with their Rust twins (src/bvh/scene_geometry.rs).

// Every table but the instance header is a texel table (src/texel_table.rs): texel_fetch(table,
// record, texels per record, j) reads texel j of a record.

// A BLAS node (records from 0) or a TLAS node (records from header.tlas_root).
fn sg_node(index: u32) -> SgNode {
    let a = texel_fetch(sg_nodes, index, 5u, 0u);
    let b = texel_fetch(sg_nodes, index, 5u, 1u);
    return SgNode(bitcast<vec3f>(a.xyz), a.w, b.x, b.y, b.zw, texel_fetch(sg_nodes, index, 5u, 2u), texel_fetch(sg_nodes, index, 5u, 3u), texel_fetch(sg_nodes, index, 5u, 4u));
}

fn sg_triangle(slot: u32) -> SgTriangle {
    let a = texel_fetch(sg_triangles, slot, 3u, 0u);
    let b = texel_fetch(sg_triangles, slot, 3u, 1u);
    let c = texel_fetch(sg_triangles, slot, 3u, 2u);
    return SgTriangle(bitcast<vec3f>(a.xyz), a.w, bitcast<vec3f>(b.xyz), b.w, bitcast<vec3f>(c.xyz), c.w);
}

// A TLAS leaf's padded world box and instance (texels 0 and 1; the transform left zero), and its
// transform (2-5), read apart: the transform only when the ray meets the box.
fn sg_tlas_leaf_box(slot: u32) -> SgTlasLeaf {
    let a = texel_fetch(sg_tlas_leaves, slot, 6u, 0u);
    let b = texel_fetch(sg_tlas_leaves, slot, 6u, 1u);
    return SgTlasLeaf(bitcast<vec3f>(a.xyz), a.w, bitcast<vec3f>(b.xyz), b.w, mat4x4f());
}

fn sg_tlas_leaf_transform(slot: u32) -> mat4x4f {
    return mat4x4f(
        bitcast<vec4f>(texel_fetch(sg_tlas_leaves, slot, 6u, 2u)),
        bitcast<vec4f>(texel_fetch(sg_tlas_leaves, slot, 6u, 3u)),
        bitcast<vec4f>(texel_fetch(sg_tlas_leaves, slot, 6u, 4u)),
        bitcast<vec4f>(texel_fetch(sg_tlas_leaves, slot, 6u, 5u)),
    );
}

fn sg_texel_f(table: texture_storage_2d<rgba32uint, read>, record: u32, texels: u32, j: u32) -> vec4f {
    return bitcast<vec4f>(texel_fetch(table, record, texels, j));
}

fn sg_instance(index: u32) -> SgInstance {
    let t = texel_fetch(sg_instances, index, 13u, 12u);
    return SgInstance(
        mat4x4f(sg_texel_f(sg_instances, index, 13u, 0u), sg_texel_f(sg_instances, index, 13u, 1u), sg_texel_f(sg_instances, index, 13u, 2u), sg_texel_f(sg_instances, index, 13u, 3u)),
        mat4x4f(sg_texel_f(sg_instances, index, 13u, 4u), sg_texel_f(sg_instances, index, 13u, 5u), sg_texel_f(sg_instances, index, 13u, 6u), sg_texel_f(sg_instances, index, 13u, 7u)),
        mat4x4f(sg_texel_f(sg_instances, index, 13u, 8u), sg_texel_f(sg_instances, index, 13u, 9u), sg_texel_f(sg_instances, index, 13u, 10u), sg_texel_f(sg_instances, index, 13u, 11u)),
        t.x, t.y, t.zw,
    );
}

fn sg_mesh(index: u32) -> SgMesh {
    let a = texel_fetch(sg_meshes, index, 2u, 0u);
    let b = texel_fetch(sg_meshes, index, 2u, 1u);
    return SgMesh(a.x, a.y, a.z, a.w, b.x, b.y, b.z, b.w);
}

fn sg_vertex(index: u32) -> SgVertex {
    let a = sg_texel_f(sg_vertices, index, 2u, 0u);
    let b = sg_texel_f(sg_vertices, index, 2u, 1u);
    return SgVertex(a.xyz, a.w, b.xyz, b.w);
}

fn sg_vertex_position(index: u32) -> vec3f {
    return sg_texel_f(sg_vertices, index, 2u, 0u).xyz;
}

// Node groups on the traversal stack: TRAVERSAL_STACK_ENTRIES (scene_features.rs), what the
// scene's BVH can need (src/bvh/stack_need.rs; refused on the CPU above TRAVERSAL_STACK_SIZE). Were it ever exceeded, the push is dropped: the siblings in that group
// are skipped (possible missed hits, no hang).
const SG_STACK_SIZE: u32 = TRAVERSAL_STACK_ENTRIES;
const SG_FLT_EPSILON: f32 = 1.1920929e-7;

struct SgRay {
    origin: vec3f,
    direction: vec3f,
    inv_direction: vec3f,
    octant_inv4: u32,   // (7 - octant) in every byte: child slots are visited in ray order
    axes: vec3u,        // watertight test: kx, ky, kz (kz = dominant axis of the direction)
    shear: vec3f,       // d[kx] / d[kz], d[ky] / d[kz], 1 / d[kz]
}

// 1/x, kept finite for |x| <= epsilon (as obvhs's safe_inverse); the sign follows `x < 0`, like
// the octant, so a -0.0 component does not flip one without the other.
fn sg_safe_inverse(x: f32) -> f32 {
    if abs(x) <= SG_FLT_EPSILON {
        return select(1.0, -1.0, x < 0.0) / SG_FLT_EPSILON;
    }
    return 1.0 / x;
}

fn sg_make_ray(origin: vec3f, direction: vec3f) -> SgRay {
    var r: SgRay;
    r.origin = origin;
    r.direction = direction;
    r.inv_direction = vec3f(sg_safe_inverse(direction.x), sg_safe_inverse(direction.y), sg_safe_inverse(direction.z));
    r.octant_inv4 = select(0x04040404u, 0u, direction.x < 0.0)
        | select(0x02020202u, 0u, direction.y < 0.0)
        | select(0x01010101u, 0u, direction.z < 0.0);
    let a = abs(direction);
    var kz = 2u;
    if a.x >= a.y && a.x >= a.z {
        kz = 0u;
    } else if a.y >= a.z {
        kz = 1u;
    }
    var kx = (kz + 1u) % 3u;
    var ky = (kx + 1u) % 3u;
    if direction[kz] < 0.0 {
        let swap = kx;
        kx = ky;
        ky = swap;
    }
    let inv = 1.0 / direction[kz];
    r.axes = vec3u(kx, ky, kz);
    r.shear = vec3f(direction[kx] * inv, direction[ky] * inv, inv);
    return r;
}

// Watertight ray-triangle test (Woop, Benthin & Wald 2013), the twin of bvh/triangle.rs.
// Returns (t, u, v, 1) for a hit with 0 < t < t_max, else vec4f(0).
fn sg_intersect_triangle(ray: SgRay, v0: vec3f, v1: vec3f, v2: vec3f, t_max: f32) -> vec4f {
    let kx = ray.axes.x;
    let ky = ray.axes.y;
    let kz = ray.axes.z;
    let s = ray.shear;
    let a = v0 - ray.origin;
    let b = v1 - ray.origin;
    let c = v2 - ray.origin;
    let ax = a[kx] - s.x * a[kz];
    let ay = a[ky] - s.y * a[kz];
    let bx = b[kx] - s.x * b[kz];
    let by = b[ky] - s.y * b[kz];
    let cx = c[kx] - s.x * c[kz];
    let cy = c[ky] - s.y * c[kz];
    let u = cx * by - cy * bx;
    let v = ax * cy - ay * cx;
    let w = bx * ay - by * ax;
    if (u < 0.0 || v < 0.0 || w < 0.0) && (u > 0.0 || v > 0.0 || w > 0.0) {
        return vec4f(0.0);
    }
    let det = u + v + w;
    if det == 0.0 {
        return vec4f(0.0);
    }
    let az = s.z * a[kz];
    let bz = s.z * b[kz];
    let cz = s.z * c[kz];
    let t = (u * az + v * bz + w * cz) / det;
    if !(t > 0.0 && t < t_max) {
        return vec4f(0.0);
    }
    return vec4f(t, v / det, w / det, 1.0);
}

// Intersects the ray with the 8 quantized child boxes of a node, in the node's grid frame
// (t = q * e / d + (p - o) / d). Returns the hit mask: bits 24-31 for inner children at
// 24 + (slot ^ octant_inv) (so the highest bit is the nearest in ray order), bits 0-23 for the
// primitives of hit leaves.
//
// The two terms of t cancel where the node's origin p is far from the ray (a node spanning a
// scene with geometry 500 m away), so t's rounding error scales with |p - o| / |d|, not with
// t: near and far distances move apart by SG_NODE_SLACK of the terms' magnitude, a bound on
// that error (1/d, p - o, the product and the sum each round once, within 2^-23 of it; 2^-20
// leaves a factor 2 over their sum). Without it, a ray hitting a quad 1e-5 inside its edge
// near the origin missed it once the scene held a quad 1000 m away (obvhs's CPU traversal,
// the same formula, misses it too; render/tests/traversal.rs). One slack per node, folded
// into the offsets, costs the children's tests nothing.
const SG_NODE_SLACK: f32 = 9.5367431640625e-7; // 2^-20

fn sg_intersect_node(node: SgNode, ray: SgRay, t_max: f32) -> u32 {
    let e = vec3f(
        bitcast<f32>((node.exponents_imask & 0xffu) << 23u),
        bitcast<f32>(((node.exponents_imask >> 8u) & 0xffu) << 23u),
        bitcast<f32>(((node.exponents_imask >> 16u) & 0xffu) << 23u),
    );
    let scale = e * ray.inv_direction;
    let offset = (node.origin - ray.origin) * ray.inv_direction;
    let slack = (abs(offset) + 255.0 * abs(scale)) * SG_NODE_SLACK;
    let offset_near = offset - slack;
    let offset_far = offset + slack;
    let negative = ray.direction < vec3f(0.0);
    var hits = 0u;
    for (var half = 0u; half < 2u; half++) {
        let meta4 = node.child_meta[half];
        let is_inner4 = (meta4 & (meta4 << 1u)) & 0x10101010u;
        let inner_mask4 = (is_inner4 >> 4u) * 0xffu;
        let bit_index4 = (meta4 ^ (ray.octant_inv4 & inner_mask4)) & 0x1f1f1f1fu;
        let child_bits4 = (meta4 >> 5u) & 0x07070707u;
        // Near and far planes per axis: swap min and max where the direction is negative.
        let near_x = select(node.bounds_x[half], node.bounds_x[half + 2u], negative.x);
        let far_x = select(node.bounds_x[half + 2u], node.bounds_x[half], negative.x);
        let near_y = select(node.bounds_y[half], node.bounds_y[half + 2u], negative.y);
        let far_y = select(node.bounds_y[half + 2u], node.bounds_y[half], negative.y);
        let near_z = select(node.bounds_z[half], node.bounds_z[half + 2u], negative.z);
        let far_z = select(node.bounds_z[half + 2u], node.bounds_z[half], negative.z);
        for (var j = 0u; j < 4u; j++) {
            let shift = j * 8u;
            let q_near = vec3f(f32(extractBits(near_x, shift, 8u)), f32(extractBits(near_y, shift, 8u)), f32(extractBits(near_z, shift, 8u)));
            let q_far = vec3f(f32(extractBits(far_x, shift, 8u)), f32(extractBits(far_y, shift, 8u)), f32(extractBits(far_z, shift, 8u)));
            let t_near = q_near * scale + offset_near;
            let t_far = q_far * scale + offset_far;
            let t0 = max(max(t_near.x, t_near.y), max(t_near.z, 0.0));
            let t1 = min(min(t_far.x, t_far.y), min(t_far.z, t_max));
            if t0 <= t1 {
                hits |= extractBits(child_bits4, shift, 8u) << extractBits(bit_index4, shift, 8u);
            }
        }
    }
    return hits;
}

// Whether the ray meets the box before t_max: a slab test in world space, its far distance grown
// by 2 gamma_3 (Ize 2013, "Robust BVH Ray Traversal") against rounding; the boxes are grown too
// (LEAF_BOX_PAD). Why: a TLAS node's 8-bit boxes are coarse (1.6 cm steps in a 2 m room), so
// without it a ray entered every instance whose box lay within a step of it: the wall it leaves
// (its origin is 1e-4 off the surface) and, for a shadow ray ending 1 mm short of a ceiling
// light, the light and the ceiling (Cornell box: 2.7 instances entered per shadow ray, 0.3 with
// the test; docs/lab/reference-speed.md). Entering costs the transform and the BLAS root's fetch
// and test.
const SG_BOX_ROBUST: f32 = 1.0000004;

fn sg_box_entered(ray: SgRay, lo: vec3f, hi: vec3f, t_max: f32) -> bool {
    let a = (lo - ray.origin) * ray.inv_direction;
    let b = (hi - ray.origin) * ray.inv_direction;
    let near = min(a, b);
    let far = max(a, b);
    let t0 = max(max(near.x, near.y), max(near.z, 0.0));
    let t1 = min(min(far.x, far.y), min(far.z, t_max));
    return t0 <= t1 * SG_BOX_ROBUST;
}

// The stack is read and written at constant indices only, one select per entry, so that it stays
// in registers: an array indexed at run time goes to per-invocation scratch memory on lavapipe,
// accessed one lane at a time (docs/lab/render-speed.md). The cost grows with the stack's size, hence a
// stack sized for the scene.
fn sg_push(stack: ptr<function, array<vec2u, SG_STACK_SIZE>>, size: u32, group: vec2u) {
    for (var i = 0u; i < SG_STACK_SIZE; i++) {
        (*stack)[i] = select((*stack)[i], group, i == size);
    }
}

fn sg_top(stack: ptr<function, array<vec2u, SG_STACK_SIZE>>, size: u32) -> vec2u {
    var group = vec2u(0u);
    for (var i = 0u; i < SG_STACK_SIZE; i++) {
        group = select(group, (*stack)[i], i + 1u == size);
    }
    return group;
}

// The next node group and primitive group of a trip (Ylitie et al., Algorithm 1): the nearest
// inner child of `node_group` is intersected and the rest of the group pushed; a group without
// inner children is a primitive group.
struct SgTrip { node_group: vec2u, primitive_group: vec2u }

fn sg_trip(
    stack: ptr<function, array<vec2u, SG_STACK_SIZE>>,
    stack_size: ptr<function, u32>,
    group: vec2u,
    ray: SgRay,
    t_max: f32,
) -> SgTrip {
    var node_group = group;
    if (node_group.y & 0xff000000u) != 0u {
        let hits_imask = node_group.y;
        let child_bit = firstLeadingBit(hits_imask);
        node_group.y &= ~(1u << child_bit);
        if (node_group.y & 0xff000000u) != 0u && *stack_size < SG_STACK_SIZE {
            sg_push(stack, *stack_size, node_group);
            *stack_size += 1u;
        }
        let slot = (child_bit - 24u) ^ (ray.octant_inv4 & 0xffu);
        let node_index = node_group.x + countOneBits(hits_imask & ~(0xffffffffu << slot));
        let node = sg_node(node_index);
        let hitmask = sg_intersect_node(node, ray, t_max);
        return SgTrip(vec2u(node.child_base, (hitmask & 0xff000000u) | (node.exponents_imask >> 24u)), vec2u(node.primitive_base, hitmask & 0x00ffffffu));
    }
    // Only primitive groups are pushed without inner-child bits.
    return SgTrip(vec2u(0u), node_group);
}

// Two-level traversal, one loop per level: TLAS leaves are instances, and entering one runs the
// BLAS loop to its end (the ray in object space; t is unchanged: the direction is transformed,
// not normalised) before the TLAS loop's next trip. lavapipe runs every statement of a loop's
// body on every trip, under a mask when no invocation needs it (docs/lab/render-speed.md), so the
// instance entry lives in the TLAS loop, which few trips reach, and not in the BLAS loop, where
// it would cost every node visit. Both loops share one stack: the BLAS pushes above the TLAS's
// entries and stops when it falls back to them. The visiting order is that of a single loop:
// the leaf group's other instances are pushed before entering one, and the TLAS's node group is
// taken up after the BLAS.
fn sg_traverse(world_origin: vec3f, world_direction: vec3f, t_max: f32, any_hit: bool) -> Hit {
    var hit = Hit(t_max, NO_HIT, NO_HIT, vec2f(0.0));
    if sg_instance_header.tlas_node_count == 0u || !(t_max > 0.0) {
        return hit;
    }
    let world_ray = sg_make_ray(world_origin, world_direction);
    var stack: array<vec2u, SG_STACK_SIZE>;
    var stack_size = 0u;
    // A group: x = base index, y = hit bits (24-31 inner children, 0-23 primitives) | imask (0-7).
    var node_group = vec2u(sg_instance_header.tlas_root, 0x80000000u);
    loop {
        let trip = sg_trip(&stack, &stack_size, node_group, world_ray, hit.t);
        node_group = trip.node_group;
        var instances = trip.primitive_group;
        var blas_group = vec2u(0u);
        var ray = world_ray;
        var instance = NO_HIT;
        if instances.y != 0u {
            let local = firstLeadingBit(instances.y);
            instances.y &= ~(1u << local);
            if instances.y != 0u && stack_size < SG_STACK_SIZE {
                sg_push(&stack, stack_size, instances);
                stack_size += 1u;
            }
            let slot = instances.x + local;
            let leaf = sg_tlas_leaf_box(slot);
            if sg_box_entered(world_ray, leaf.box_min, leaf.box_max, hit.t) {
                let world_to_object = sg_tlas_leaf_transform(slot);
                instance = leaf.instance;
                ray = sg_make_ray((world_to_object * vec4f(world_origin, 1.0)).xyz, (world_to_object * vec4f(world_direction, 0.0)).xyz);
                blas_group = vec2u(leaf.blas_root, 0x80000000u);
            }
        }
        let tlas_stack_size = stack_size;
        while (blas_group.y & 0xff000000u) != 0u {
            let blas_trip = sg_trip(&stack, &stack_size, blas_group, ray, hit.t);
            blas_group = blas_trip.node_group;
            var triangles = blas_trip.primitive_group;
            while triangles.y != 0u {
                let local = firstLeadingBit(triangles.y);
                triangles.y &= ~(1u << local);
                let tri = sg_triangle(triangles.x + local);
                let r = sg_intersect_triangle(ray, tri.v0, tri.v1, tri.v2, hit.t);
                if r.w > 0.0 {
                    hit = Hit(r.x, instance, tri.primitive, r.yz);
                    if any_hit {
                        return hit;
                    }
                }
            }
            if (blas_group.y & 0xff000000u) == 0u && stack_size > tlas_stack_size {
                blas_group = sg_top(&stack, stack_size);
                stack_size -= 1u;
            }
        }
        if (node_group.y & 0xff000000u) == 0u {
            if stack_size == 0u {
                break;
            }
            node_group = sg_top(&stack, stack_size);
            stack_size -= 1u;
        }
    }
    return hit;
}

// Rays this invocation traced (trace_closest + trace_any). A pass that reports rays adds it to
// its own atomic counter once at the end of the invocation (one atomic per invocation, not per
// ray); passes that do not report ignore it.
var<private> sg_rays_traced: u32 = 0u;

// Closest hit with 0 < t < t_max (direction need not be normalised; t in units of direction).
fn trace_closest(origin: vec3f, direction: vec3f, t_max: f32) -> Hit {
    sg_rays_traced += 1u;
    return sg_traverse(origin, direction, t_max, false);
}

// True if anything is hit with 0 < t < t_max; stops at the first hit (shadow rays).
fn trace_any(origin: vec3f, direction: vec3f, t_max: f32) -> bool {
    sg_rays_traced += 1u;
    return sg_traverse(origin, direction, t_max, true).instance != NO_HIT;
}

fn instance_count() -> u32 {
    return sg_instance_header.count;
}

// Vertex indices (into the vertex table) of a mesh triangle.
fn sg_triangle_vertex_indices(mesh: SgMesh, primitive: u32) -> vec3u {
    return texel_fetch(sg_indices, mesh.index_offset + primitive, 1u, 0u).xyz + vec3u(mesh.vertex_offset);
}

fn sg_normalize_or(v: vec3f, fallback: vec3f) -> vec3f {
    let len2 = dot(v, v);
    if !(len2 > 0.0) || len2 > 3.0e38 {
        return fallback;
    }
    return v * inverseSqrt(len2);
}

fn sg_object_point(hit: Hit) -> vec3f {
    let mesh = sg_mesh(sg_instance(hit.instance).mesh);
    let idx = sg_triangle_vertex_indices(mesh, hit.primitive);
    let b = hit.barycentrics;
    return (1.0 - b.x - b.y) * sg_vertex_position(idx.x) + b.x * sg_vertex_position(idx.y) + b.y * sg_vertex_position(idx.z);
}

// World-space attributes of a hit. The position is the barycentric point on the triangle (not
// origin + t * direction) so that it lies on the surface. The geometric normal follows the
// winding (cross(v1 - v0, v2 - v0)) and is NOT flipped towards the ray; both normals go through
// the inverse transpose of object_to_world, so they stay on the same side under mirroring.
fn surface_point(hit: Hit, origin: vec3f, direction: vec3f) -> SurfacePoint {
    let record = sg_instance(hit.instance);
    let mesh = sg_mesh(record.mesh);
    let idx = sg_triangle_vertex_indices(mesh, hit.primitive);
    let v0 = sg_vertex(idx.x);
    let v1 = sg_vertex(idx.y);
    let v2 = sg_vertex(idx.z);
    let b = vec3f(1.0 - hit.barycentrics.x - hit.barycentrics.y, hit.barycentrics.x, hit.barycentrics.y);
    let object_position = b.x * v0.position + b.y * v1.position + b.z * v2.position;
    let w2o = record.world_to_object;
    let normal_matrix = transpose(mat3x3f(w2o[0].xyz, w2o[1].xyz, w2o[2].xyz));
    let object_geometric = cross(v1.position - v0.position, v2.position - v0.position);
    var p: SurfacePoint;
    p.position = (record.object_to_world * vec4f(object_position, 1.0)).xyz;
    p.geometric_normal = sg_normalize_or(normal_matrix * object_geometric, vec3f(0.0, 0.0, 1.0));
    p.shading_normal = p.geometric_normal;
    if (mesh.flags & 1u) != 0u {
        let n = b.x * v0.normal + b.y * v1.normal + b.z * v2.normal;
        p.shading_normal = sg_normalize_or(normal_matrix * n, p.geometric_normal);
    }
    p.uv = vec2f(0.0);
    if (mesh.flags & 2u) != 0u {
        p.uv = b.x * vec2f(v0.u, v0.v) + b.y * vec2f(v1.u, v1.v) + b.z * vec2f(v2.u, v2.v);
    }
    p.material = record.material;
    return p;
}

// The hit's object-space point through last frame's transform (motion vectors).
fn previous_world_position(hit: Hit) -> vec3f {
    return (sg_instance(hit.instance).previous_object_to_world * vec4f(sg_object_point(hit), 1.0)).xyz;
}

// World-space vertices of a triangle of an instance (area-light sampling).
fn triangle_world_vertices(instance: u32, primitive: u32) -> array<vec3f, 3> {
    let record = sg_instance(instance);
    let idx = sg_triangle_vertex_indices(sg_mesh(record.mesh), primitive);
    let m = record.object_to_world;
    return array<vec3f, 3>(
        (m * vec4f(sg_vertex_position(idx.x), 1.0)).xyz,
        (m * vec4f(sg_vertex_position(idx.y), 1.0)).xyz,
        (m * vec4f(sg_vertex_position(idx.z), 1.0)).xyz,
    );
}
