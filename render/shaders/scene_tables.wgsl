// The scene's materials and lights, read from @group(0)'s texel tables (src/texel_table.rs):
// shading reads them at per-ray addresses.

import package::scene_types::{GpuLight, GpuMaterial};
import package::scene_bindings::{light_table, material_table};
import package::texel_table::texel_fetch;

fn material(index: u32) -> GpuMaterial {
    let a = texel_fetch(material_table, index, 3u, 0u);
    let b = texel_fetch(material_table, index, 3u, 1u);
    let c = texel_fetch(material_table, index, 3u, 2u);
    return GpuMaterial(bitcast<vec3f>(a.xyz), a.w, bitcast<vec3f>(b.xyz), bitcast<f32>(b.w), bitcast<f32>(c.x), bitcast<f32>(c.y), c.z, c.w);
}

fn light(index: u32) -> GpuLight {
    let a = texel_fetch(light_table, index, 4u, 0u);
    let b = texel_fetch(light_table, index, 4u, 1u);
    let c = texel_fetch(light_table, index, 4u, 2u);
    let d = texel_fetch(light_table, index, 4u, 3u);
    return GpuLight(bitcast<vec3f>(a.xyz), a.w, bitcast<vec3f>(b.xyz), bitcast<f32>(b.w), bitcast<vec3f>(c.xyz), bitcast<f32>(c.w), bitcast<vec3f>(d.xyz), bitcast<f32>(d.w));
}

// The light's inclusive CDF entry alone (the emitter search reads nothing else).
fn light_cdf(index: u32) -> f32 {
    return bitcast<f32>(texel_fetch(light_table, index, 4u, 1u).w);
}
