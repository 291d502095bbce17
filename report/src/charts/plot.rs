//! Drawing a [`Chart`] with plotters, to SVG (text stays text) and to PNG (text rasterised with
//! DejaVu Sans, shipped in the binary so the PNG looks the same on every machine): title, axis
//! labels, legend, event markers with their labels, the Pareto front, and a marker for every
//! point of a sparse series (one reference frame still shows up).

use std::io::Cursor;
use std::sync::Once;

use plotters::coord::Shift;
use plotters::prelude::*;
use plotters::style::FontStyle;

use super::{Chart, Frame, HEIGHT, Kind, WIDTH, color};

/// Series with at most this many points also get a marker per point.
const SPARSE: usize = 12;
const FONT: &str = "sans-serif";
const EVENT_RED: RGBColor = RGBColor(214, 39, 40);
/// Width of the legend column right of the plot (outside it, so it hides no data).
const LEGEND_WIDTH: u32 = 170;

/// A tick value without trailing zeros (frame 5, not 5.0).
fn tick_label(v: f64) -> String {
    let s = format!("{v:.4}");
    let s = s.trim_end_matches('0').trim_end_matches('.');
    if s == "-0" { "0".into() } else { s.into() }
}

fn register_font() {
    static FONT_ONCE: Once = Once::new();
    FONT_ONCE.call_once(|| {
        let bytes: &'static [u8] = include_bytes!("../../fonts/DejaVuSans.ttf");
        plotters::style::register_font(FONT, FontStyle::Normal, bytes)
            .unwrap_or_else(|_| panic!("the shipped DejaVu Sans is a valid font"));
    });
}

/// Where frames land on the image: x pixel of the axis' first and last value, for the
/// page's frame cursor.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct XMap {
    pub v0: f64,
    pub v1: f64,
    pub x0: i32,
    pub x1: i32,
}

fn rgb(i: usize) -> RGBColor {
    let [r, g, b] = color(i);
    RGBColor(r, g, b)
}

fn draw<DB: DrawingBackend>(
    chart: &Chart,
    root: &DrawingArea<DB, Shift>,
) -> Result<XMap, DrawingAreaErrorKind<DB::ErrorType>> {
    let f = Frame::of(chart);
    root.fill(&WHITE)?;
    // Long titles get a smaller font rather than being clipped (a glyph is about half an em wide).
    let caption_size = 21.0f64
        .min((WIDTH - LEGEND_WIDTH) as f64 / (0.5 * chart.title.chars().count().max(1) as f64));
    let mut cc = ChartBuilder::on(root)
        .caption(&chart.title, (FONT, caption_size))
        .margin(12)
        .margin_right(LEGEND_WIDTH)
        .x_label_area_size(42)
        .y_label_area_size(66)
        .build_cartesian_2d(f.x.min..f.x.max, f.y.min..f.y.max)?;
    cc.configure_mesh()
        .x_desc(&chart.x_label)
        .y_desc(&chart.y_label)
        .label_style((FONT, 15))
        .x_label_formatter(&|v| tick_label(*v))
        .y_label_formatter(&|v| tick_label(*v))
        .axis_desc_style((FONT, 17))
        .light_line_style(WHITE)
        .bold_line_style(RGBColor(228, 228, 228))
        .draw()?;
    for (x, label) in &chart.events {
        cc.draw_series(DashedLineSeries::new(
            [(*x, f.y.min), (*x, f.y.max)],
            5,
            4,
            EVENT_RED.stroke_width(1),
        ))?;
        let text = Text::new(label.clone(), (4, 4), (FONT, 14).into_font().color(&EVENT_RED));
        cc.draw_series(std::iter::once(EmptyElement::at((*x, f.y.max)) + text))?;
    }
    if chart.pareto.len() > 1 {
        cc.draw_series(DashedLineSeries::new(
            chart.pareto.iter().copied(),
            3,
            3,
            BLACK.stroke_width(1),
        ))?;
    }
    // Scatter points' names: (marker's pixel, name), placed once all are known.
    let mut labels: Vec<((i32, i32), String, RGBColor)> = Vec::new();
    for (i, series) in chart.series.iter().enumerate() {
        let c = rgb(i);
        let pts: Vec<(f64, f64)> =
            series.points.iter().copied().filter(|p| p.0.is_finite() && p.1.is_finite()).collect();
        match chart.kind {
            Kind::Lines => {
                if pts.len() <= SPARSE {
                    cc.draw_series(pts.iter().map(|&p| Circle::new(p, 4, c.filled())))?;
                }
                cc.draw_series(LineSeries::new(pts, c.stroke_width(2)))?;
            }
            Kind::Scatter => {
                cc.draw_series(pts.iter().map(|&p| Circle::new(p, 6, c.filled())))?;
                labels.extend(pts.iter().map(|p| (cc.backend_coord(p), series.name.clone(), c)));
            }
        }
    }
    place_labels(root, &labels, cc.plotting_area().get_pixel_range())?;
    // The legend, in its own column: a swatch and the name of each series, then the front.
    let x = (WIDTH - LEGEND_WIDTH + 16) as i32;
    let font = (FONT, 15).into_font();
    for (i, series) in chart.series.iter().enumerate() {
        let y = 50 + 22 * i as i32;
        root.draw(&Rectangle::new([(x, y - 6), (x + 12, y + 6)], rgb(i).filled()))?;
        root.draw(&Text::new(series.name.clone(), (x + 18, y - 8), font.clone()))?;
    }
    if chart.pareto.len() > 1 {
        let y = 50 + 22 * chart.series.len() as i32;
        root.draw(&PathElement::new([(x, y), (x + 12, y)], BLACK.stroke_width(2)))?;
        root.draw(&Text::new("Pareto front", (x + 18, y - 8), font))?;
    }
    let (x0, x1) =
        (cc.backend_coord(&(f.x.min, f.y.min)).0, cc.backend_coord(&(f.x.max, f.y.min)).0);
    root.present()?;
    Ok(XMap { v0: f.x.min, v1: f.x.max, x0, x1 })
}

/// Height of a label line and the width of a glyph, in pixels (15 px DejaVu Sans, roughly).
const LABEL_HEIGHT: i32 = 17;
const GLYPH_WIDTH: f64 = 8.5;

/// Writes each name beside its marker, in its colour, on the side facing the plot's centre (so it is not
/// clipped), moving a label to the nearest line where it overlaps none placed before (methods
/// with near-equal results).
fn place_labels<DB: DrawingBackend>(
    root: &DrawingArea<DB, Shift>,
    labels: &[((i32, i32), String, RGBColor)],
    area: (std::ops::Range<i32>, std::ops::Range<i32>),
) -> Result<(), DrawingAreaErrorKind<DB::ErrorType>> {
    let mid_x = (area.0.start + area.0.end) / 2;
    let mut order: Vec<&((i32, i32), String, RGBColor)> = labels.iter().collect();
    order.sort_by_key(|((x, y), ..)| (*y, *x));
    let mut placed: Vec<(i32, i32, i32, i32)> = Vec::new();
    for ((x, y), name, color) in order {
        let w = (GLYPH_WIDTH * name.chars().count() as f64) as i32;
        let x0 = if *x > mid_x { x - 10 - w } else { x + 10 };
        let start = (y - 8 - LABEL_HEIGHT).max(area.1.start);
        let free = |y0: i32| {
            !placed
                .iter()
                .any(|&(a, b, c, d)| x0 < c && a < x0 + w && y0 < d && b < y0 + LABEL_HEIGHT)
        };
        let inside = |y0: i32| y0 >= area.1.start && y0 + LABEL_HEIGHT <= area.1.end;
        // Nearest free line: below, above, two below, ...; inside the plot when possible.
        let tries = (0..labels.len() as i32 * 2 + 1)
            .map(|k| start + LABEL_HEIGHT * if k % 2 == 1 { (k + 1) / 2 } else { -(k / 2) });
        let y0 = tries
            .clone()
            .find(|&t| inside(t) && free(t))
            .or_else(|| tries.clone().find(|&t| free(t)))
            .unwrap_or(start);
        placed.push((x0, y0, x0 + w, y0 + LABEL_HEIGHT));
        // In the series' colour, so a displaced name still points to its marker.
        root.draw(&Text::new(name.clone(), (x0, y0), (FONT, 15).into_font().color(color)))?;
    }
    Ok(())
}

/// The chart as an SVG document, and where its x axis lies.
pub fn to_svg(chart: &Chart) -> anyhow::Result<(String, XMap)> {
    register_font();
    let mut s = String::new();
    let map = {
        let root = SVGBackend::with_string(&mut s, (WIDTH, HEIGHT)).into_drawing_area();
        draw(chart, &root)
            .map_err(|e| anyhow::anyhow!("drawing the SVG chart `{}`: {e}", chart.title))?
    };
    Ok((s, map))
}

/// The chart as an RGB image.
pub fn to_image(chart: &Chart) -> anyhow::Result<image::RgbImage> {
    register_font();
    let mut buf = vec![255u8; (WIDTH * HEIGHT * 3) as usize];
    {
        let root = BitMapBackend::with_buffer(&mut buf, (WIDTH, HEIGHT)).into_drawing_area();
        draw(chart, &root)
            .map_err(|e| anyhow::anyhow!("drawing the PNG chart `{}`: {e}", chart.title))?;
    }
    Ok(image::RgbImage::from_raw(WIDTH, HEIGHT, buf).expect("buffer of WIDTH * HEIGHT RGB pixels"))
}

pub fn to_png(chart: &Chart) -> anyhow::Result<Vec<u8>> {
    let mut out = Cursor::new(Vec::new());
    to_image(chart)?.write_to(&mut out, image::ImageFormat::Png)?;
    Ok(out.into_inner())
}

#[cfg(test)]
mod tests {
    use super::super::{Kind, Series};
    use super::*;

    fn chart(title: &str, x_label: &str, y_label: &str) -> Chart {
        Chart {
            title: title.into(),
            x_label: x_label.into(),
            y_label: y_label.into(),
            kind: Kind::Lines,
            series: vec![
                Series {
                    name: "alpha".into(),
                    points: (0..=10).map(|i| (i as f64 * 3.0, i as f64 * 0.1)).collect(),
                },
                Series { name: "beta".into(), points: vec![(12.0, 0.5)] },
            ],
            events: vec![(20.0, "light turns".into())],
            pareto: vec![],
            x_extent: vec![0.0, 30.0],
        }
    }

    /// The contents of the SVG's <text> elements.
    pub fn svg_texts(svg: &str) -> Vec<String> {
        svg.split("<text")
            .skip(1)
            .filter_map(|t| Some(t.split_once('>')?.1.split("</text>").next()?.trim().to_string()))
            .collect()
    }

    /// Pixels darker than light grey in a rectangle of the image.
    fn ink(img: &image::RgbImage, x0: u32, y0: u32, x1: u32, y1: u32) -> usize {
        (y0..y1)
            .flat_map(|y| (x0..x1).map(move |x| (x, y)))
            .filter(|&(x, y)| img.get_pixel(x, y).0.iter().all(|&c| c < 120))
            .count()
    }

    #[test]
    fn svg_carries_title_axis_labels_legend_and_event() {
        let (svg, map) = to_svg(&chart("FLIP vs reference", "frame", "mean FLIP")).unwrap();
        let texts = svg_texts(&svg);
        for text in ["FLIP vs reference", "frame", "mean FLIP", "alpha", "beta", "light turns"] {
            assert!(
                texts.iter().any(|t| t == text),
                "{text} missing from the SVG's texts {texts:?}"
            );
        }
        // The one-point series is a marker (a circle), not an invisible one-point line.
        assert!(svg.contains("<circle"), "no marker for the one-point series");
        assert!(map.x0 < map.x1 && map.v0 == 0.0 && map.v1 >= 30.0);
    }

    #[test]
    fn png_text_is_drawn_where_the_svg_puts_it() {
        // The same chart with and without text: title band, y-label band and x-label band gain ink.
        let with = to_image(&chart("A title in the PNG", "frame number", "value axis")).unwrap();
        let without = to_image(&chart("", "", "")).unwrap();
        let bands =
            [(0, 0, WIDTH, 28), (0, 40, 22, HEIGHT - 60), (200, HEIGHT - 20, WIDTH - 200, HEIGHT)];
        for (x0, y0, x1, y1) in bands {
            let (a, b) = (ink(&with, x0, y0, x1, y1), ink(&without, x0, y0, x1, y1));
            assert!(
                a > 40 && b < a / 4,
                "band {x0},{y0}..{x1},{y1}: {a} dark pixels with text, {b} without"
            );
        }
        // Series colours (lines, legend swatches, the one-point marker) are present.
        let count = |c: [u8; 3]| with.pixels().filter(|p| p.0 == c).count();
        assert!(count(color(0)) > 200 && count(color(1)) > 40, "series colours missing");
        assert!(count([214, 39, 40]) > 20, "event marker missing");
    }

    #[test]
    fn scatter_points_carry_their_method_name() {
        let c = Chart {
            title: "speed vs accuracy".into(),
            x_label: "ms".into(),
            y_label: "FLIP".into(),
            kind: Kind::Scatter,
            series: vec![
                Series { name: "taa".into(), points: vec![(1.0, 0.2)] },
                Series { name: "pt_4spp".into(), points: vec![(4.0, 0.1)] },
            ],
            events: vec![],
            pareto: vec![(1.0, 0.2), (4.0, 0.1)],
            x_extent: vec![],
        };
        let (svg, _) = to_svg(&c).unwrap();
        // Each name twice: beside its marker and in the legend.
        let texts = svg_texts(&svg);
        let count = |name: &str| texts.iter().filter(|t| *t == name).count();
        assert_eq!((count("taa"), count("pt_4spp"), count("Pareto front")), (2, 2, 1), "{texts:?}");
    }

    #[test]
    fn names_of_coinciding_points_do_not_overlap() {
        let series = ["nirc_ema", "nirc_blend", "nirc_switch"]
            .map(|n| Series { name: n.into(), points: vec![(2.0, 0.3)] })
            .to_vec();
        let c = Chart {
            title: "t".into(),
            x_label: "x".into(),
            y_label: "y".into(),
            kind: Kind::Scatter,
            series,
            events: vec![],
            pareto: vec![],
            x_extent: vec![],
        };
        let (svg, _) = to_svg(&c).unwrap();
        // The y of each label beside the markers (the legend's copies sit right of the plot).
        let ys: Vec<f64> = svg
            .split("<text")
            .skip(1)
            .filter(|t| t.contains(">nirc_") || t.contains("\nnirc_"))
            .filter_map(|t| {
                let num = |k: &str| {
                    t.split(&format!("{k}=\"")).nth(1)?.split('"').next()?.parse::<f64>().ok()
                };
                (num("x")? < (WIDTH - LEGEND_WIDTH) as f64).then(|| num("y")).flatten()
            })
            .collect();
        assert_eq!(ys.len(), 3, "{svg}");
        for (i, a) in ys.iter().enumerate() {
            for b in &ys[i + 1..] {
                assert!((a - b).abs() >= LABEL_HEIGHT as f64, "labels at y {ys:?} overlap");
            }
        }
    }
}
