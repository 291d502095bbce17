//! A winding corridor of square cells lit only by an emissive wall at its far end: every
//! visible pixel near the camera is reached after several bounces.

use glam::{IVec2, Vec3};
use scene::Material;

use super::geometry::MeshBuilder;
use crate::template::WorldTemplate;
use crate::transform::Transform;

/// Cell size and ceiling height in metres.
const CELL: f32 = 2.0;
const HEIGHT: f32 = 2.5;

/// The corridor's path on a grid, from the camera's cell to the lit end.
pub const PATH: [(i32, i32); 11] = [
    (0, 0),
    (0, -1),
    (0, -2),
    (1, -2),
    (2, -2),
    (2, -3),
    (2, -4),
    (1, -4),
    (0, -4),
    (0, -5),
    (0, -6),
];

fn cell_center(c: IVec2) -> Vec3 {
    Vec3::new(c.x as f32 * CELL, 0.0, c.y as f32 * CELL)
}

pub fn build() -> WorldTemplate {
    let cells: Vec<IVec2> = PATH.iter().map(|&(x, z)| IVec2::new(x, z)).collect();
    let mut b = MeshBuilder::new("corridor");
    let h = 0.5 * CELL;
    let dirs = [IVec2::new(1, 0), IVec2::new(-1, 0), IVec2::new(0, 1), IVec2::new(0, -1)];
    let last = cells.len() - 1;
    let exit = cells[last] - cells[last - 1];
    for (k, &c) in cells.iter().enumerate() {
        let o = cell_center(c);
        let corners = |y: f32| {
            [
                o + Vec3::new(-h, y, -h),
                o + Vec3::new(h, y, -h),
                o + Vec3::new(h, y, h),
                o + Vec3::new(-h, y, h),
            ]
        };
        b.quad(corners(0.0), Vec3::Y);
        b.quad(corners(HEIGHT), Vec3::NEG_Y);
        for d in dirs {
            // Open only towards the previous and the next cell of the path.
            let open = (k > 0 && cells[k - 1] == c + d) || (k < last && cells[k + 1] == c + d);
            let is_light = k == last && d == exit;
            if open || is_light {
                continue;
            }
            let n = Vec3::new(d.x as f32, 0.0, d.y as f32);
            let side = Vec3::new(-n.z, 0.0, n.x) * h;
            let f = o + n * h;
            b.quad(
                [f - side, f + side, f + side + Vec3::Y * HEIGHT, f - side + Vec3::Y * HEIGHT],
                -n,
            );
        }
    }
    let mut t = WorldTemplate::default();
    let walls = t.add_mesh(b.build());
    let plaster =
        t.add_material("plaster", Material { base_color: Vec3::splat(0.7), ..Default::default() });
    t.add_object("corridor", walls, plaster, Transform::IDENTITY);

    // The lit far wall, facing back into the corridor.
    let n = Vec3::new(exit.x as f32, 0.0, exit.y as f32);
    let side = Vec3::new(-n.z, 0.0, n.x) * h;
    let f = cell_center(cells[last]) + n * h;
    let mut lb = MeshBuilder::new("end_light");
    lb.quad([f - side, f + side, f + side + Vec3::Y * HEIGHT, f - side + Vec3::Y * HEIGHT], -n);
    let panel = t.add_mesh(lb.build());
    let glow = t.add_material(
        "glow",
        Material {
            base_color: Vec3::splat(0.8),
            emission: Vec3::splat(20.0),
            ..Default::default()
        },
    );
    t.add_object("end_light", panel, glow, Transform::IDENTITY);

    let start = cell_center(cells[0]) + Vec3::new(0.0, 1.5, 0.6);
    let ahead = cell_center(cells[1]) + Vec3::new(0.0, 1.2, 0.0);
    t.add_camera("camera", start, ahead, 60.0);
    t
}
