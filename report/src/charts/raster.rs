//! Text-free PNG rendering of a [`Chart`]: the same layout as the SVG (grid, axes, events, data,
//! legend swatches) drawn with discs along segments, so no font or rasteriser crate is needed.

use std::io::Cursor;

use image::{Rgb, RgbImage};

use super::{Chart, Frame, HEIGHT, Kind, MARGIN, WIDTH, color};

struct Canvas(RgbImage);

impl Canvas {
    fn disc(&mut self, cx: f64, cy: f64, r: f64, c: [u8; 3]) {
        let (x0, x1) = ((cx - r).floor().max(0.0) as u32, (cx + r).ceil().min(WIDTH as f64 - 1.0) as u32);
        let (y0, y1) = ((cy - r).floor().max(0.0) as u32, (cy + r).ceil().min(HEIGHT as f64 - 1.0) as u32);
        for y in y0..=y1 {
            for x in x0..=x1 {
                let (dx, dy) = (x as f64 - cx, y as f64 - cy);
                if dx * dx + dy * dy <= r * r + 0.25 {
                    self.0.put_pixel(x, y, Rgb(c));
                }
            }
        }
    }

    /// A segment of half-width `r`; `dash` = (on, off) lengths in pixels, if dashed.
    fn line(&mut self, a: (f64, f64), b: (f64, f64), r: f64, c: [u8; 3], dash: Option<(f64, f64)>) {
        let len = ((b.0 - a.0).powi(2) + (b.1 - a.1).powi(2)).sqrt();
        let steps = (len * 2.0).ceil().max(1.0) as usize;
        for i in 0..=steps {
            let s = i as f64 / steps as f64;
            if let Some((on, off)) = dash
                && (s * len) % (on + off) > on
            {
                continue;
            }
            self.disc(a.0 + (b.0 - a.0) * s, a.1 + (b.1 - a.1) * s, r, c);
        }
    }

    fn rect(&mut self, x0: f64, y0: f64, x1: f64, y1: f64, c: [u8; 3]) {
        for y in y0.max(0.0) as u32..(y1.min(HEIGHT as f64)) as u32 {
            for x in x0.max(0.0) as u32..(x1.min(WIDTH as f64)) as u32 {
                self.0.put_pixel(x, y, Rgb(c));
            }
        }
    }
}

pub fn to_image(chart: &Chart) -> RgbImage {
    let f = Frame::of(chart);
    let [l, r, t, b] = MARGIN;
    let (w, h) = (WIDTH as f64, HEIGHT as f64);
    let mut cv = Canvas(RgbImage::from_pixel(WIDTH, HEIGHT, Rgb([255, 255, 255])));
    for &v in &f.y.ticks {
        cv.line((l, f.py(v)), (w - r, f.py(v)), 0.3, [225, 225, 225], None);
        cv.line((l - 5.0, f.py(v)), (l, f.py(v)), 0.5, [0, 0, 0], None);
    }
    for &v in &f.x.ticks {
        cv.line((f.px(v), t), (f.px(v), h - b), 0.3, [235, 235, 235], None);
        cv.line((f.px(v), h - b), (f.px(v), h - b + 5.0), 0.5, [0, 0, 0], None);
    }
    for (a, bb) in [((l, t), (w - r, t)), ((w - r, t), (w - r, h - b)), ((w - r, h - b), (l, h - b)), ((l, h - b), (l, t))] {
        cv.line(a, bb, 0.5, [0, 0, 0], None);
    }
    for (x, _) in &chart.events {
        cv.line((f.px(*x), t), (f.px(*x), h - b), 0.7, [214, 39, 40], Some((5.0, 4.0)));
    }
    for pair in chart.pareto.windows(2) {
        cv.line((f.px(pair[0].0), f.py(pair[0].1)), (f.px(pair[1].0), f.py(pair[1].1)), 0.8, [0, 0, 0], Some((2.0, 3.0)));
    }
    for (i, series) in chart.series.iter().enumerate() {
        let c = color(i);
        let pts: Vec<(f64, f64)> =
            series.points.iter().filter(|p| p.0.is_finite() && p.1.is_finite()).map(|&(x, y)| (f.px(x), f.py(y))).collect();
        match chart.kind {
            Kind::Lines => {
                for pair in pts.windows(2) {
                    cv.line(pair[0], pair[1], 1.0, c, None);
                }
                if pts.len() == 1 {
                    cv.disc(pts[0].0, pts[0].1, 2.0, c);
                }
            }
            Kind::Scatter => pts.iter().for_each(|p| cv.disc(p.0, p.1, 5.0, c)),
        }
        let ly = t + 10.0 + 18.0 * i as f64;
        cv.rect(w - r + 12.0, ly - 10.0, w - r + 24.0, ly + 2.0, c);
    }
    cv.0
}

pub fn to_png(chart: &Chart) -> Vec<u8> {
    let mut out = Cursor::new(Vec::new());
    to_image(chart).write_to(&mut out, image::ImageFormat::Png).expect("encoding a PNG in memory");
    out.into_inner()
}

#[cfg(test)]
mod tests {
    use super::super::{Kind, Series};
    use super::*;

    #[test]
    fn draws_series_in_their_colours_and_events_in_red() {
        let chart = Chart {
            title: "t".into(),
            x_label: "frame".into(),
            y_label: "v".into(),
            kind: Kind::Lines,
            series: vec![
                Series { name: "a".into(), points: vec![(0.0, 0.0), (10.0, 1.0)] },
                Series { name: "b".into(), points: vec![(0.0, 1.0), (10.0, 0.0)] },
            ],
            events: vec![(5.0, "e".into())],
            pareto: vec![],
            x_extent: vec![],
        };
        let img = to_image(&chart);
        let count = |c: [u8; 3]| img.pixels().filter(|p| p.0 == c).count();
        assert!(count(color(0)) > 200 && count(color(1)) > 200);
        assert!(count([214, 39, 40]) > 50);
        // The event line sits at x = 5 of the 0..10 axis.
        let f = Frame::of(&chart);
        let ex = f.px(5.0).round() as u32;
        assert!((0..HEIGHT).any(|y| img.get_pixel(ex, y).0 == [214, 39, 40]));
        let svg = super::super::svg::to_svg(&chart);
        assert!(svg.starts_with("<svg") && svg.contains(">a</text>") && svg.contains("stroke-dasharray"));
    }
}
