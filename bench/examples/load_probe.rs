//! How fast one invocation's data-dependent 16-byte load is, from a storage buffer, from a sampled
//! `rgba32uint` texture and from the same texture bound as a read-only storage texture (both read
//! with textureLoad; texel tables are the latter), on the adapter at hand. Each invocation chases
//! a chain of loads whose next address depends on the last value, as BVH traversal does. A fourth variant
//! adds a branch that almost no invocation takes: on lavapipe its body still costs (a divergent
//! branch is run under a mask, not jumped over), which is why work for a few lanes is not free.
//! `cargo run -p bench --example load_probe`
use std::time::Instant;

const TEXELS_LOG2: u32 = 16; // 65 536 texels of 16 bytes: about a 100k-triangle BVH's size
const WIDTH_LOG2: u32 = render::texel_table::RECORDS_PER_ROW_LOG2; // a texel table of 1-texel records
const CHAIN: u32 = 64;
const INVOCATIONS: u32 = 65_536;

const SHADER: &str = r#"
@group(0) @binding(0) var<storage, read> buf: array<vec4u>;
@group(0) @binding(1) var tex: texture_2d<u32>;
@group(0) @binding(2) var<storage, read_write> out: array<u32>;
#ifdef STORAGE_TEXTURE
@group(0) @binding(3) var stex: texture_storage_2d<rgba32uint, read>;
#endif

fn hash(x: u32) -> u32 {
    var h = x * 0x9e3779b1u;
    h ^= h >> 15u;
    return h * 0x85ebca77u;
}

fn fetch(i: u32) -> vec4u {
#ifdef STORAGE_TEXTURE
    return textureLoad(stex, vec2u(i & WMASK, i >> WLOG2));
#endif
#ifdef TEXTURE
    return textureLoad(tex, vec2u(i & WMASK, i >> WLOG2), 0);
#endif
#ifdef BUFFER
    return buf[i];
#endif
}

@compute @workgroup_size(64)
fn main(@builtin(global_invocation_id) id: vec3u) {
    var i = hash(id.x) & MASK;
    var acc = 0u;
    for (var k = 0u; k < CHAIN; k++) {
        let v = fetch(i);
        acc += v.y ^ v.z ^ v.w;
        i = (v.x ^ k) & MASK;
#ifdef RARE
        if (v.y & 1023u) == 0u {
            for (var r = 0u; r < 16u; r++) {
                acc += buf[(i + r * 977u) & MASK].x;
            }
        }
#endif
    }
    out[id.x] = acc;
}
"#;

fn source(kind: Kind, rare: bool) -> String {
    let body = SHADER
        .replace("WMASK", &format!("{}u", (1u32 << WIDTH_LOG2) - 1))
        .replace("MASK", &format!("{}u", (1u32 << TEXELS_LOG2) - 1))
        .replace("WLOG2", &format!("{WIDTH_LOG2}u"))
        .replace("CHAIN", &format!("{CHAIN}u"));
    // A small preprocessor: #ifdef TEXTURE / #else / #ifdef RARE blocks.
    let mut out = String::new();
    let mut state = 0; // 0 outside, 1 keeping, 2 dropping
    for line in body.lines() {
        let t = line.trim();
        if t == "#ifdef TEXTURE" {
            state = if kind == Kind::Texture { 1 } else { 2 };
            continue;
        }
        if t == "#ifdef STORAGE_TEXTURE" {
            state = if kind == Kind::StorageTexture { 1 } else { 2 };
            continue;
        }
        if t == "#ifdef BUFFER" {
            state = if kind == Kind::Buffer { 1 } else { 2 };
            continue;
        }
        if t == "#ifdef RARE" {
            state = if rare { 1 } else { 2 };
            continue;
        }
        if t == "#else" {
            state = if state == 1 { 2 } else { 1 };
            continue;
        }
        if t == "#endif" {
            state = 0;
            continue;
        }
        if state != 2 {
            out.push_str(line);
            out.push('\n');
        }
    }
    out
}

#[derive(Clone, Copy, PartialEq, Eq)]
enum Kind {
    Buffer,
    Texture,
    StorageTexture,
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let gpu = render::gpu::Gpu::new()?;
    println!("adapter: {}", gpu.summary);
    let device = &gpu.device;
    let n = 1usize << TEXELS_LOG2;
    let mut state = 0x1234_5678u32;
    let data: Vec<u32> = (0..n * 4)
        .map(|_| {
            state ^= state << 13;
            state ^= state >> 17;
            state ^= state << 5;
            state
        })
        .collect();
    let bytes: &[u8] = bytemuck::cast_slice(&data);
    use wgpu::util::DeviceExt;
    let buf = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
        label: Some("probe data"),
        contents: bytes,
        usage: wgpu::BufferUsages::STORAGE,
    });
    let out = device.create_buffer(&wgpu::BufferDescriptor {
        label: Some("probe out"),
        size: 4 * INVOCATIONS as u64,
        usage: wgpu::BufferUsages::STORAGE,
        mapped_at_creation: false,
    });
    let table = render::texel_table::TexelTable::new(&gpu, "probe texture", 1, bytes, 0)?;
    let view = table.view();
    // The same texels in a texture that is read as a read-only storage texture.
    let storage_texture = device.create_texture_with_data(
        &gpu.queue,
        &wgpu::TextureDescriptor {
            label: Some("probe storage texture"),
            size: wgpu::Extent3d {
                width: 1 << WIDTH_LOG2,
                height: 1 << (TEXELS_LOG2 - WIDTH_LOG2),
                depth_or_array_layers: 1,
            },
            mip_level_count: 1,
            sample_count: 1,
            dimension: wgpu::TextureDimension::D2,
            format: wgpu::TextureFormat::Rgba32Uint,
            usage: wgpu::TextureUsages::STORAGE_BINDING | wgpu::TextureUsages::TEXTURE_BINDING,
            view_formats: &[],
        },
        wgpu::util::TextureDataOrder::LayerMajor,
        bytes,
    );
    let storage_view = storage_texture.create_view(&Default::default());
    use Kind::*;
    for (kind, rare) in [
        (Buffer, false),
        (Texture, false),
        (StorageTexture, false),
        (Texture, true),
        (Buffer, false),
        (Texture, false),
        (StorageTexture, false),
        (Texture, true),
    ] {
        let texture = kind == Texture;
        let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
            label: Some("probe"),
            source: wgpu::ShaderSource::Wgsl(source(kind, rare).into()),
        });
        let pipeline = device.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
            label: Some("probe"),
            layout: None,
            module: &module,
            entry_point: Some("main"),
            compilation_options: Default::default(),
            cache: None,
        });
        let layout = pipeline.get_bind_group_layout(0);
        let mut entries =
            vec![wgpu::BindGroupEntry { binding: 2, resource: out.as_entire_binding() }];
        if rare {
            entries.push(wgpu::BindGroupEntry { binding: 0, resource: buf.as_entire_binding() });
        }
        if texture {
            entries.push(wgpu::BindGroupEntry {
                binding: 1,
                resource: wgpu::BindingResource::TextureView(view),
            });
        } else if kind == StorageTexture {
            entries.push(wgpu::BindGroupEntry {
                binding: 3,
                resource: wgpu::BindingResource::TextureView(&storage_view),
            });
        } else {
            entries.push(wgpu::BindGroupEntry { binding: 0, resource: buf.as_entire_binding() });
        }
        let group = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("probe"),
            layout: &layout,
            entries: &entries,
        });
        let mut best = f64::INFINITY;
        for _ in 0..4 {
            let mut encoder = device.create_command_encoder(&Default::default());
            {
                let mut pass = encoder.begin_compute_pass(&Default::default());
                pass.set_pipeline(&pipeline);
                pass.set_bind_group(0, &group, &[]);
                pass.dispatch_workgroups(INVOCATIONS / 64, 1, 1);
            }
            let start = Instant::now();
            gpu.queue.submit([encoder.finish()]);
            device.poll(wgpu::PollType::wait_indefinitely())?;
            best = best.min(start.elapsed().as_secs_f64());
        }
        let loads = (INVOCATIONS * CHAIN) as f64;
        let what = match (kind, rare) {
            (Buffer, _) => "storage vec4u",
            (StorageTexture, _) => "read-only storage texture rgba32uint",
            (Texture, false) => "texture rgba32uint",
            (Texture, true) => {
                "texture rgba32uint, and a branch taken by 1 in 1024 invocations that loads 16 words from storage"
            }
        };
        println!("{what}: {:.1} M loads/s of 16 bytes (best of 4)", loads / best / 1e6);
    }
    Ok(())
}
