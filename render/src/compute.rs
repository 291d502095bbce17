//! Compute pipelines from one WGSL module: the set-up every pass shares (bind group layout of
//! plain buffers, pipeline layout, the module validated inside an error scope so that a WGSL
//! error names its pass, one pipeline per entry point).

use crate::error::RenderError;
use crate::gpu::Gpu;
use crate::shader::{Module, Program};

/// How a pass may access a buffer of its bind group. There is no uniform access: a pass's
/// parameters are a read-only storage buffer, because Mesa 22.3's lavapipe compiles a shader
/// anew on every bind of a pipeline whose branches or loops read a uniform at a constant offset
/// (it inlines the values) and never frees the one before: 1.5 MB and tens of ms per bind.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Access {
    Read,
    ReadWrite,
}

/// One buffer of a bind group, declared once: its WGSL `var` ([`declare`]) and its layout entry
/// ([`binding_layout`]) both come from it, so the shader and the Rust side cannot disagree.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct BufferBinding {
    pub name: &'static str,
    pub access: Access,
    /// The WGSL type, e.g. `array<vec4f>` or `SscParams`.
    pub wgsl_type: &'static str,
}

impl BufferBinding {
    pub const fn read(name: &'static str, wgsl_type: &'static str) -> Self {
        Self { name, access: Access::Read, wgsl_type }
    }

    pub const fn read_write(name: &'static str, wgsl_type: &'static str) -> Self {
        Self { name, access: Access::ReadWrite, wgsl_type }
    }

    pub const fn kind(&self) -> wgpu::BufferBindingType {
        match self.access {
            Access::Read => wgpu::BufferBindingType::Storage { read_only: true },
            Access::ReadWrite => wgpu::BufferBindingType::Storage { read_only: false },
        }
    }
}

/// Storage buffers among `bindings` (what counts against the adapter's per-stage limit): all.
pub const fn storage_buffers(bindings: &[BufferBinding]) -> u32 {
    bindings.len() as u32
}

/// The WGSL declarations of `bindings` as @group(`group`), binding i = `bindings[i]`.
pub fn declare(group: u32, bindings: &[BufferBinding]) -> String {
    declare_range(group, bindings, 0..bindings.len())
}

/// [`declare`] of `bindings[range]` only, each at its index in `bindings`.
pub fn declare_range(
    group: u32,
    bindings: &[BufferBinding],
    range: std::ops::Range<usize>,
) -> String {
    bindings
        .iter()
        .enumerate()
        .filter(|(i, _)| range.contains(i))
        .map(|(i, b)| {
            let space = match b.access {
                Access::Read => "<storage, read>",
                Access::ReadWrite => "<storage, read_write>",
            };
            format!("@group({group}) @binding({i}) var{space} {}: {};\n", b.name, b.wgsl_type)
        })
        .collect()
}

/// A module importable as `path` that declares `bindings` as @group(`group`) ([`declare`]),
/// importing each struct type they name from the module of `types` that declares it.
pub fn group_module(
    path: &str,
    group: u32,
    bindings: &[BufferBinding],
    types: &[&Module],
) -> Module {
    group_module_range(path, group, bindings, 0..bindings.len(), types)
}

/// [`group_module`] of `bindings[range]` only, each at its index in `bindings`: a group split
/// over two modules (a pass that shares another pass's uniform and the functions importing it).
pub fn group_module_range(
    path: &str,
    group: u32,
    bindings: &[BufferBinding],
    range: std::ops::Range<usize>,
    types: &[&Module],
) -> Module {
    let mut imports: Vec<(String, Vec<String>)> = Vec::new();
    for b in &bindings[range.clone()] {
        // `array<atomic<u32>>`, `array<SscSlot>`, `SscParams`: the struct names start upper case.
        for name in b
            .wgsl_type
            .split(|c: char| !c.is_alphanumeric() && c != '_')
            .filter(|w| w.starts_with(|c: char| c.is_ascii_uppercase()))
        {
            let module = types.iter().find(|m| m.declares_struct(name)).unwrap_or_else(|| {
                panic!(
                    "binding {} of {path}: no module among its types declares struct {name}",
                    b.name
                )
            });
            let from = &*module.path;
            match imports.iter_mut().find(|(p, _)| p == from) {
                Some((_, names)) if names.iter().any(|n| n == name) => {}
                Some((_, names)) => names.push(name.to_string()),
                None => imports.push((from.to_string(), vec![name.to_string()])),
            }
        }
    }
    let imports: String = imports
        .iter()
        .map(|(p, names)| format!("import {p}::{{{}}};\n", names.join(", ")))
        .collect();
    Module::generated(path, &[&imports, &declare_range(group, bindings, range)])
}

/// The layout of `bindings` ([`buffer_layout`] of their kinds).
pub fn binding_layout(gpu: &Gpu, label: &str, bindings: &[BufferBinding]) -> wgpu::BindGroupLayout {
    buffer_layout(gpu, label, &bindings.iter().map(BufferBinding::kind).collect::<Vec<_>>())
}

/// A bind group layout whose binding i is a buffer of kind `kinds[i]`, visible to compute.
pub fn buffer_layout(
    gpu: &Gpu,
    label: &str,
    kinds: &[wgpu::BufferBindingType],
) -> wgpu::BindGroupLayout {
    gpu.device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
        label: Some(label),
        entries: &buffer_entries(kinds),
    })
}

/// Layout entries whose binding i is a buffer of kind `kinds[i]`, visible to compute.
pub fn buffer_entries(kinds: &[wgpu::BufferBindingType]) -> Vec<wgpu::BindGroupLayoutEntry> {
    kinds
        .iter()
        .enumerate()
        .map(|(i, &ty)| wgpu::BindGroupLayoutEntry {
            binding: i as u32,
            visibility: wgpu::ShaderStages::COMPUTE,
            ty: wgpu::BindingType::Buffer { ty, has_dynamic_offset: false, min_binding_size: None },
            count: None,
        })
        .collect()
}

/// A bind group binding `buffers[i]` whole at binding i.
pub fn buffer_group(
    gpu: &Gpu,
    label: &str,
    layout: &wgpu::BindGroupLayout,
    buffers: &[&wgpu::Buffer],
) -> wgpu::BindGroup {
    let entries: Vec<_> = buffers
        .iter()
        .enumerate()
        .map(|(i, b)| wgpu::BindGroupEntry { binding: i as u32, resource: b.as_entire_binding() })
        .collect();
    gpu.device.create_bind_group(&wgpu::BindGroupDescriptor {
        label: Some(label),
        layout,
        entries: &entries,
    })
}

/// The pipelines of `entries` in `program`'s entry-point files (named `pass` in errors), bound
/// with `groups` as @group(0), @group(1), ...
pub fn pipelines<const N: usize>(
    gpu: &Gpu,
    pass: &str,
    program: &Program,
    groups: &[&wgpu::BindGroupLayout],
    entries: [&str; N],
) -> Result<[wgpu::ComputePipeline; N], RenderError> {
    let device = &gpu.device;
    let layouts: Vec<Option<&wgpu::BindGroupLayout>> = groups.iter().map(|&g| Some(g)).collect();
    let layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
        label: Some(pass),
        bind_group_layouts: &layouts,
        immediate_size: 0,
    });
    validated(gpu, pass, program, Some(&layout), entries)
}

/// [`pipelines`] whose bind group layouts are derived from the shader (each entry point's own
/// @group(0), fetched with `get_bind_group_layout`): for passes whose entry points bind
/// different subsets of one module's buffers.
pub fn pipelines_auto_layout<const N: usize>(
    gpu: &Gpu,
    pass: &str,
    program: &Program,
    entries: [&str; N],
) -> Result<[wgpu::ComputePipeline; N], RenderError> {
    validated(gpu, pass, program, None, entries)
}

fn validated<const N: usize>(
    gpu: &Gpu,
    pass: &str,
    program: &Program,
    layout: Option<&wgpu::PipelineLayout>,
    entries: [&str; N],
) -> Result<[wgpu::ComputePipeline; N], RenderError> {
    let linked = program.compose()?;
    // The file of each entry point.
    let mut file_of = [0usize; N];
    for (slot, entry) in file_of.iter_mut().zip(entries) {
        *slot = linked.iter().position(|wgsl| wgsl.contains(&format!("fn {entry}("))).ok_or_else(
            || RenderError::Shader {
                pass: pass.into(),
                message: format!(
                    "no entry point '{entry}' in {:?}",
                    program.entry_files.iter().map(|m| &m.file).collect::<Vec<_>>()
                ),
            },
        )?;
    }
    let device = &gpu.device;
    let scope = device.push_error_scope(wgpu::ErrorFilter::Validation);
    let modules: Vec<wgpu::ShaderModule> = linked
        .into_iter()
        .zip(&program.entry_files)
        .map(|(wgsl, file)| {
            device.create_shader_module(wgpu::ShaderModuleDescriptor {
                label: Some(&file.file),
                source: wgpu::ShaderSource::Wgsl(wgsl.into()),
            })
        })
        .collect();
    let mut i = 0;
    let made = entries.map(|entry| {
        let module = &modules[file_of[i]];
        i += 1;
        device.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
            label: Some(entry),
            layout,
            module,
            entry_point: Some(entry),
            compilation_options: Default::default(),
            cache: None,
        })
    });
    if let Some(e) = pollster::block_on(scope.pop()) {
        return Err(RenderError::Shader { pass: pass.into(), message: e.to_string() });
    }
    Ok(made)
}
