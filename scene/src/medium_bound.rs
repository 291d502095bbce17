//! What bounds a medium besides its box: nothing (the box), or a closed triangle mesh, a
//! built-in UV sphere inscribed in the box or a Wavefront OBJ file. The medium is the part of
//! its box inside the mesh; `media` bakes it by zeroing the voxels whose centres lie outside.
//!
//! A mesh is kept in the box's unit coordinates ([0, 1]³ spans the declared box), so it moves,
//! scales and turns with an animated medium.

use std::collections::HashMap;
use std::path::{Path, PathBuf};

use glam::Vec3;
use serde::{Deserialize, Serialize};

/// A scenario's `bound:` of a medium.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub enum MediumBound {
    /// The medium fills its box.
    #[default]
    Box,
    /// A UV sphere (an ellipsoid where the box is not a cube) touching the box's faces, with
    /// `segments` around the equator and `segments / 2` from pole to pole (4 to 256, even).
    Sphere { segments: u32 },
    /// A closed, consistently oriented triangle mesh (polygons are fanned) from a Wavefront OBJ
    /// file, its vertices in world coordinates at the declared box (a relative path is resolved
    /// against the scenario's folder). Only `v` and `f` lines are read.
    Obj { file: PathBuf },
}

/// A closed triangle mesh in the unit coordinates of a medium's box.
#[derive(Clone, Debug, PartialEq)]
pub struct ClosedMesh {
    pub positions: Vec<Vec3>,
    pub triangles: Vec<[u32; 3]>,
}

impl MediumBound {
    /// The mesh, in the unit coordinates of the box [box_min, box_max]; None for `Box`.
    pub fn mesh(&self, box_min: Vec3, box_max: Vec3) -> Result<Option<ClosedMesh>, String> {
        match self {
            MediumBound::Box => Ok(None),
            MediumBound::Sphere { segments } => ClosedMesh::sphere(*segments).map(Some),
            MediumBound::Obj { file } => {
                let mut mesh = ClosedMesh::load_obj(file)?;
                let size = box_max - box_min;
                for p in &mut mesh.positions {
                    *p = (*p - box_min) / size;
                }
                Ok(Some(mesh))
            }
        }
    }

    /// Resolves a relative OBJ path against `folder` (the scenario's).
    pub fn resolve(&mut self, folder: &Path) {
        if let MediumBound::Obj { file } = self
            && file.is_relative()
        {
            *file = folder.join(&*file);
        }
    }
}

impl ClosedMesh {
    /// The UV sphere of [`MediumBound::Sphere`] in [0, 1]³ (centre 0.5, radius 0.5).
    pub fn sphere(segments: u32) -> Result<ClosedMesh, String> {
        if !(4..=256).contains(&segments) || !segments.is_multiple_of(2) {
            return Err(format!(
                "sphere segments {segments}; expected an even number from 4 to 256"
            ));
        }
        let (around, rings) = (segments, segments / 2);
        // Vertex 0 is the south pole, 1 the north pole, then rings 1..rings-1 of `around` each.
        let mut positions = vec![Vec3::new(0.5, 0.0, 0.5), Vec3::new(0.5, 1.0, 0.5)];
        for r in 1..rings {
            let theta = std::f32::consts::PI * r as f32 / rings as f32;
            for a in 0..around {
                let phi = std::f32::consts::TAU * a as f32 / around as f32;
                positions.push(
                    Vec3::splat(0.5)
                        + 0.5
                            * Vec3::new(
                                theta.sin() * phi.cos(),
                                -theta.cos(),
                                theta.sin() * phi.sin(),
                            ),
                );
            }
        }
        let ring = |r: u32, a: u32| 2 + (r - 1) * around + a % around;
        let mut triangles = Vec::new();
        for a in 0..around {
            // Counter-clockwise seen from outside (outward normals).
            triangles.push([0, ring(1, a), ring(1, a + 1)]);
            triangles.push([1, ring(rings - 1, a + 1), ring(rings - 1, a)]);
            for r in 1..rings - 1 {
                triangles.push([ring(r, a), ring(r + 1, a), ring(r + 1, a + 1)]);
                triangles.push([ring(r, a), ring(r + 1, a + 1), ring(r, a + 1)]);
            }
        }
        let mesh = ClosedMesh { positions, triangles };
        let lines = vec![0; mesh.triangles.len()];
        mesh.check_closed(&lines, "built-in sphere")?;
        Ok(mesh)
    }

    pub fn load_obj(path: &Path) -> Result<ClosedMesh, String> {
        let text = std::fs::read_to_string(path)
            .map_err(|e| format!("{}: cannot read the OBJ mesh: {e}", path.display()))?;
        Self::parse_obj(&text, &path.display().to_string())
    }

    /// Parses OBJ `text`; errors read `FILE:LINE: what was found, what was expected`, and a mesh
    /// that is not closed names the line of a face on an open or doubled edge.
    pub fn parse_obj(text: &str, file: &str) -> Result<ClosedMesh, String> {
        let mut positions = Vec::new();
        let mut triangles = Vec::new();
        let mut lines = Vec::new();
        for (i, line) in text.lines().enumerate() {
            let n = i + 1;
            let line = line.split('#').next().unwrap_or("").trim();
            let mut words = line.split_whitespace();
            match words.next() {
                Some("v") => {
                    let c: Vec<Option<f32>> =
                        words.map(|w| w.parse().ok().filter(|v: &f32| v.is_finite())).collect();
                    match c.as_slice() {
                        [Some(x), Some(y), Some(z)] | [Some(x), Some(y), Some(z), Some(_)] => {
                            positions.push(Vec3::new(*x, *y, *z))
                        }
                        _ => {
                            return Err(format!(
                                "{file}:{n}: found '{line}'; expected a vertex 'v X Y Z' with finite coordinates"
                            ));
                        }
                    }
                }
                Some("f") => {
                    let mut face = Vec::new();
                    for w in words {
                        let index = w.split('/').next().and_then(|s| s.parse::<i64>().ok());
                        let count = positions.len() as i64;
                        // 1-based, or negative: relative to the vertices read so far.
                        let resolved = match index {
                            Some(k) if k >= 1 && k <= count => k - 1,
                            Some(k) if k < 0 && -k <= count => count + k,
                            _ => {
                                return Err(format!(
                                    "{file}:{n}: found '{w}'; expected a vertex index 1 to {count} (or -1 to -{count}) of the vertices above"
                                ));
                            }
                        };
                        face.push(resolved as u32);
                    }
                    if face.len() < 3 {
                        return Err(format!(
                            "{file}:{n}: found '{line}'; expected a face of at least 3 vertices"
                        ));
                    }
                    for k in 1..face.len() - 1 {
                        triangles.push([face[0], face[k], face[k + 1]]);
                        lines.push(n);
                    }
                }
                _ => {}
            }
        }
        if triangles.is_empty() {
            return Err(format!(
                "{file}:{}: no faces; expected a closed mesh of 'v' and 'f' lines",
                text.lines().count().max(1)
            ));
        }
        let mesh = ClosedMesh { positions, triangles };
        mesh.check_closed(&lines, file)?;
        Ok(mesh)
    }

    /// Closed and consistently oriented: every directed edge appears once and its reverse once
    /// (what makes the winding number of every point outside the surface 0 and inside ±1).
    fn check_closed(&self, lines: &[usize], file: &str) -> Result<(), String> {
        let mut edges: HashMap<(u32, u32), usize> = HashMap::new();
        for (t, tri) in self.triangles.iter().enumerate() {
            if tri[0] == tri[1] || tri[1] == tri[2] || tri[2] == tri[0] {
                return Err(format!(
                    "{file}:{}: a face repeats a vertex; expected distinct vertices",
                    lines[t]
                ));
            }
            for k in 0..3 {
                let e = (tri[k], tri[(k + 1) % 3]);
                if let Some(&other) = edges.get(&e) {
                    return Err(format!(
                        "{file}:{}: the edge from vertex {} to {} is also on the face of line {}, in the same direction; expected a closed surface with consistently oriented faces",
                        lines[t],
                        e.0 + 1,
                        e.1 + 1,
                        lines[other]
                    ));
                }
                edges.insert(e, t);
            }
        }
        // In face order, so that the error names the same edge every run.
        for (t, tri) in self.triangles.iter().enumerate() {
            let open = (0..3)
                .map(|k| (tri[k], tri[(k + 1) % 3]))
                .find(|&(a, b)| !edges.contains_key(&(b, a)));
            if let Some((a, b)) = open {
                return Err(format!(
                    "{file}:{}: the edge from vertex {} to {} has no face on its other side; expected a closed mesh (every edge shared by two faces)",
                    lines[t],
                    a + 1,
                    b + 1
                ));
            }
        }
        Ok(())
    }
}
