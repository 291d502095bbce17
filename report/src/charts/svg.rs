//! SVG rendering of a [`Chart`], with title, axes, ticks, legend and event labels.

use std::fmt::Write as _;

use super::{Chart, Frame, HEIGHT, Kind, MARGIN, WIDTH, color};

fn esc(s: &str) -> String {
    s.replace('&', "&amp;").replace('<', "&lt;").replace('>', "&gt;").replace('"', "&quot;")
}

fn tick_label(v: f64) -> String {
    let s = format!("{v:.4}");
    let s = s.trim_end_matches('0').trim_end_matches('.');
    if s == "-0" { "0".into() } else { s.into() }
}

pub fn to_svg(chart: &Chart) -> String {
    let f = Frame::of(chart);
    let [l, r, t, b] = MARGIN;
    let (w, h) = (WIDTH as f64, HEIGHT as f64);
    let mut s = String::new();
    let _ = writeln!(
        s,
        r#"<svg xmlns="http://www.w3.org/2000/svg" width="{WIDTH}" height="{HEIGHT}" viewBox="0 0 {WIDTH} {HEIGHT}" font-family="sans-serif" font-size="12">"#
    );
    let _ = writeln!(s, r#"<rect width="100%" height="100%" fill="white"/>"#);
    let _ = writeln!(s, r#"<text x="{}" y="22" text-anchor="middle" font-size="15">{}</text>"#, l + (w - l - r) / 2.0, esc(&chart.title));
    // Grid and ticks.
    for &v in &f.y.ticks {
        let y = f.py(v);
        let _ = writeln!(s, r##"<line x1="{l}" y1="{y:.1}" x2="{:.1}" y2="{y:.1}" stroke="#e5e5e5"/>"##, w - r);
        let _ = writeln!(s, r#"<text x="{:.1}" y="{:.1}" text-anchor="end">{}</text>"#, l - 6.0, y + 4.0, tick_label(v));
    }
    for &v in &f.x.ticks {
        let x = f.px(v);
        let _ = writeln!(s, r##"<line x1="{x:.1}" y1="{t}" x2="{x:.1}" y2="{:.1}" stroke="#f0f0f0"/>"##, h - b);
        let _ = writeln!(s, r#"<text x="{x:.1}" y="{:.1}" text-anchor="middle">{}</text>"#, h - b + 16.0, tick_label(v));
    }
    let _ = writeln!(s, r#"<rect x="{l}" y="{t}" width="{}" height="{}" fill="none" stroke="black"/>"#, w - l - r, h - t - b);
    let _ = writeln!(s, r#"<text x="{}" y="{}" text-anchor="middle">{}</text>"#, l + (w - l - r) / 2.0, h - 12.0, esc(&chart.x_label));
    let _ = writeln!(
        s,
        r#"<text x="16" y="{0}" text-anchor="middle" transform="rotate(-90 16 {0})">{1}</text>"#,
        t + (h - t - b) / 2.0,
        esc(&chart.y_label)
    );
    // Events.
    for (x, label) in &chart.events {
        let px = f.px(*x);
        let _ = writeln!(s, r##"<line x1="{px:.1}" y1="{t}" x2="{px:.1}" y2="{:.1}" stroke="#d62728" stroke-dasharray="5,4"/>"##, h - b);
        let _ = writeln!(s, r##"<text x="{:.1}" y="{:.1}" fill="#d62728" font-size="11">{}</text>"##, px + 4.0, t + 14.0, esc(label));
    }
    // Pareto front.
    if chart.pareto.len() > 1 {
        let pts: Vec<String> = chart.pareto.iter().map(|&(x, y)| format!("{:.1},{:.1}", f.px(x), f.py(y))).collect();
        let _ = writeln!(s, r#"<polyline points="{}" fill="none" stroke="black" stroke-width="1.5" stroke-dasharray="2,3"/>"#, pts.join(" "));
    }
    // Data.
    for (i, series) in chart.series.iter().enumerate() {
        let [cr, cg, cb] = color(i);
        let rgb = format!("rgb({cr},{cg},{cb})");
        let finite: Vec<(f64, f64)> = series.points.iter().copied().filter(|p| p.0.is_finite() && p.1.is_finite()).collect();
        match chart.kind {
            Kind::Lines => {
                let pts: Vec<String> = finite.iter().map(|&(x, y)| format!("{:.1},{:.1}", f.px(x), f.py(y))).collect();
                let _ = writeln!(s, r#"<polyline points="{}" fill="none" stroke="{rgb}" stroke-width="2"/>"#, pts.join(" "));
            }
            Kind::Scatter => {
                for &(x, y) in &finite {
                    let _ = writeln!(s, r#"<circle cx="{:.1}" cy="{:.1}" r="5" fill="{rgb}"><title>{}: ({x:.4}, {y:.4})</title></circle>"#, f.px(x), f.py(y), esc(&series.name));
                }
            }
        }
        // Legend entry.
        let ly = t + 10.0 + 18.0 * i as f64;
        let _ = writeln!(s, r#"<rect x="{:.1}" y="{:.1}" width="12" height="12" fill="{rgb}"/>"#, w - r + 12.0, ly - 10.0);
        let _ = writeln!(s, r#"<text x="{:.1}" y="{ly:.1}">{}</text>"#, w - r + 30.0, esc(&series.name));
    }
    if chart.pareto.len() > 1 {
        let ly = t + 10.0 + 18.0 * chart.series.len() as f64;
        let _ = writeln!(s, r#"<text x="{:.1}" y="{ly:.1}">⋯ Pareto front</text>"#, w - r + 12.0);
    }
    s.push_str("</svg>\n");
    s
}
