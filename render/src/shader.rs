//! WGSL composed from modules with WESL imports (the wesl crate, a source-to-source linker).
//! Each file is a module named by its path under `shaders/` (`package::pt_sampling`,
//! `package::sample_cache::storage`; another crate's files under `package::CRATE::`), and imports
//! what it uses (`import package::pt_sampling::{PI, rng_next};`). Generated declarations (the
//! structs of `gpu_struct!`, a bind group's variables, constants derived from settings) are
//! modules too ([`Module::generated`]). A [`Program`] is the modules a pass may import and its
//! entry-point files; imported names are mangled, entry points keep theirs.
//!
//! naga_oil was tried first: it round-trips every module through naga's WGSL writer, which
//! renames struct members ending in a digit (`p0`, `beta1`, `epsilon0`, `f90`), so it cannot
//! import the structs that carry the papers' names.

use std::borrow::Cow;

use wesl::{CompileOptions, ManglerKind, VirtualResolver, Wesl};

use crate::error::RenderError;

/// One WGSL module: a file of the repository or generated text, with its module path.
#[derive(Clone, Debug, PartialEq, Eq, Hash)]
pub struct Module {
    /// Its WESL module path, e.g. `package::pt_sampling`.
    pub path: Cow<'static, str>,
    /// Where it comes from: the file's path in the repository, or `generated`.
    pub file: Cow<'static, str>,
    pub source: Cow<'static, str>,
}

impl Module {
    /// A file `relative` to crate `krate`'s `shaders/` folder (`include_str!`): module
    /// `package::STEM` for the render crate, `package::CRATE::STEM` for others.
    pub fn file(krate: &str, relative: &str, source: &'static str) -> Self {
        let stem = relative.trim_end_matches(".wgsl").replace('/', "::");
        let path = if krate == "render" {
            format!("package::{stem}")
        } else {
            format!("package::{krate}::{stem}")
        };
        Self {
            path: Cow::Owned(path),
            file: Cow::Owned(format!("{krate}/shaders/{relative}")),
            source: Cow::Borrowed(source),
        }
    }

    /// Generated declarations importable as `path` (e.g. `package::scene_bindings`).
    pub fn generated(path: &str, parts: &[&str]) -> Self {
        Self {
            path: Cow::Owned(path.to_string()),
            file: Cow::Borrowed("generated"),
            source: Cow::Owned(parts.join("\n")),
        }
    }

    /// This module under another path: a file that plays a role each program fills with its own
    /// (e.g. the pass's bindings).
    pub fn at(mut self, path: &str) -> Self {
        self.path = Cow::Owned(path.to_string());
        self
    }

    /// Whether it declares `struct NAME`.
    pub fn declares_struct(&self, name: &str) -> bool {
        self.source.lines().any(|l| {
            l.trim_start()
                .strip_prefix("struct ")
                .and_then(|r| r.strip_prefix(name))
                .is_some_and(|r| r.starts_with([' ', '{']))
        })
    }
}

/// The `include_str!` of a file under this crate's `shaders/` as a [`Module`].
#[macro_export]
macro_rules! wgsl_file {
    ($path:literal) => {
        $crate::shader::Module::file(
            env!("CARGO_PKG_NAME"),
            $path,
            include_str!(concat!(env!("CARGO_MANIFEST_DIR"), "/shaders/", $path)),
        )
    };
}

/// The modules a pass may import and the files holding its entry points (each linked into a
/// WGSL module of its own).
#[derive(Clone, Debug, Default, PartialEq, Eq, Hash)]
pub struct Program {
    pub modules: Vec<Module>,
    pub entry_files: Vec<Module>,
}

impl Program {
    pub fn new(modules: Vec<Module>) -> Self {
        Self { modules, entry_files: Vec::new() }
    }

    /// A program of one self-contained source (its constants generated in front of it, no
    /// imports), as module `path`.
    pub fn single(path: &str, source: &str) -> Self {
        Self::new(Vec::new()).entry(Module::generated(path, &[source]))
    }

    /// This program with `more` modules.
    pub fn with(mut self, more: impl IntoIterator<Item = Module>) -> Self {
        self.modules.extend(more);
        self
    }

    /// This program with `module` in place of its module of the same path; unchanged when it has
    /// none (a program that does not import it).
    pub fn replacing(&self, module: &Module) -> Self {
        let mut program = self.clone();
        for m in program.modules.iter_mut().filter(|m| m.path == module.path) {
            *m = module.clone();
        }
        program
    }

    /// This program with `file` as an entry-point file.
    pub fn entry(mut self, file: Module) -> Self {
        self.entry_files.push(file);
        self
    }

    /// Every source, in order: what a cache of this program's results is keyed by.
    pub fn fingerprint(&self) -> String {
        self.modules
            .iter()
            .chain(&self.entry_files)
            .map(|m| format!("// {} ({})\n{}\n", m.path, m.file, m.source))
            .collect()
    }

    /// Links every entry-point file and parses the result with naga: the first failure as
    /// "FILE: message" (tests of each pass's program, without a device).
    pub fn check_links(&self) -> Result<(), String> {
        let sources = self.compose().map_err(|e| e.to_string())?;
        for (wgsl, file) in sources.iter().zip(&self.entry_files) {
            if let Err(e) = naga::front::wgsl::parse_str(wgsl) {
                return Err(format!("{}: {}", file.file, e.emit_to_string(wgsl)));
            }
        }
        Ok(())
    }

    /// Each entry-point file linked with the modules it imports: one WGSL source per file.
    pub fn compose(&self) -> Result<Vec<String>, RenderError> {
        let mut resolver = VirtualResolver::new();
        for m in self.modules.iter().chain(&self.entry_files) {
            resolver.add_module(parse_path(&m.path)?, m.source.clone());
        }
        let mut compiler = Wesl::new_barebones().set_custom_resolver(resolver);
        // Imports only: no dead-code stripping or lowering, so the linked WGSL is the files'
        // own declarations, renamed.
        compiler.set_options(CompileOptions {
            imports: true,
            condcomp: false,
            generics: false,
            strip: false,
            lower: false,
            validate: false,
            lazy: false,
            mangle_root: false,
            keep: None,
            keep_root: false,
            features: Default::default(),
        });
        compiler.set_mangler(ManglerKind::Escape);
        self.entry_files
            .iter()
            .map(|m| {
                compiler.compile(&parse_path(&m.path)?).map(|linked| linked.to_string()).map_err(
                    |e| RenderError::Shader {
                        pass: m.file.to_string(),
                        message: format!("linking {}: {e}", m.path),
                    },
                )
            })
            .collect()
    }
}

fn parse_path(path: &str) -> Result<wesl::ModulePath, RenderError> {
    path.parse().map_err(|e| RenderError::Shader {
        pass: path.to_string(),
        message: format!("not a module path: {e:?}"),
    })
}
