//! Minimal SVG charts for the reports (no plotting dependency): line, step
//! and marker series on linear or log-x axes with ticks, labels and a legend.

use std::fmt::Write as _;

/// How a series is drawn.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Style {
    /// Polyline through the points.
    Line,
    /// Circles at the points, with their labels.
    Markers,
}

/// One data series.
#[derive(Debug, Clone)]
pub(crate) struct Series {
    pub(crate) label: String,
    pub(crate) points: Vec<(f64, f64)>,
    pub(crate) style: Style,
    /// Per-point labels (markers only).
    pub(crate) point_labels: Vec<String>,
}

impl Series {
    pub(crate) fn line(label: &str, points: Vec<(f64, f64)>) -> Self {
        Self {
            label: label.into(),
            points,
            style: Style::Line,
            point_labels: Vec::new(),
        }
    }
}

/// A chart.
#[derive(Debug, Clone)]
pub(crate) struct Chart {
    pub(crate) title: String,
    pub(crate) x_label: String,
    pub(crate) y_label: String,
    pub(crate) log_x: bool,
    pub(crate) series: Vec<Series>,
}

const COLOURS: [&str; 6] = [
    "#1f77b4", "#d62728", "#2ca02c", "#ff7f0e", "#9467bd", "#8c564b",
];

fn nice_ticks(lo: f64, hi: f64, n: usize) -> Vec<f64> {
    let span = (hi - lo).max(1e-300);
    let raw = span / n as f64;
    let mag = 10f64.powf(raw.log10().floor());
    let step = [1.0, 2.0, 2.5, 5.0, 10.0]
        .iter()
        .map(|m| m * mag)
        .find(|s| *s >= raw)
        .unwrap_or(10.0 * mag);
    let mut t = (lo / step).ceil() * step;
    let mut out = Vec::new();
    while t <= hi + 1e-9 * span {
        out.push(t);
        t += step;
    }
    out
}

fn fmt_tick(v: f64) -> String {
    let a = v.abs();
    if a != 0.0 && !(1e-3..1e5).contains(&a) {
        format!("{v:.1e}")
    } else if (v - v.round()).abs() < 1e-9 {
        format!("{v:.0}")
    } else {
        let s = format!("{v:.3}");
        s.trim_end_matches('0').trim_end_matches('.').to_owned()
    }
}

fn escape(s: &str) -> String {
    s.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
}

/// `x` in axis units: log10 on a log-x axis.
fn axis_x(log_x: bool, x: f64) -> f64 {
    if log_x { x.max(1e-300).log10() } else { x }
}

/// Page size, margins and data ranges of a chart, and its coordinate maps.
struct Frame {
    /// Page width and height (px).
    w: f64,
    h: f64,
    /// Left, right, top and bottom margins (px).
    ml: f64,
    mr: f64,
    mt: f64,
    mb: f64,
    log_x: bool,
    /// Padded x range, in axis units (log10 on a log-x axis).
    x0: f64,
    x1: f64,
    /// Padded y range.
    y0: f64,
    y1: f64,
}

impl Frame {
    /// The frame of `chart`: margins (wider on the right for point labels)
    /// and the padded range of its finite (and, on a log-x axis, positive-x)
    /// points.
    fn new(chart: &Chart) -> Self {
        let (w, h) = (640.0, 420.0);
        let labelled = chart.series.iter().any(|s| !s.point_labels.is_empty());
        let (ml, mr, mt, mb) = (70.0, if labelled { 150.0 } else { 20.0 }, 40.0, 55.0);
        let tx = |x: f64| axis_x(chart.log_x, x);
        let pts: Vec<(f64, f64)> = chart
            .series
            .iter()
            .flat_map(|s| s.points.iter().copied())
            .filter(|(x, y)| x.is_finite() && y.is_finite() && (!chart.log_x || *x > 0.0))
            .collect();
        let (mut x0, mut x1, mut y0, mut y1) = (f64::INFINITY, f64::NEG_INFINITY, 0.0f64, 0.0f64);
        for (x, y) in &pts {
            x0 = x0.min(tx(*x));
            x1 = x1.max(tx(*x));
            y0 = y0.min(*y);
            y1 = y1.max(*y);
        }
        if x1.partial_cmp(&x0) != Some(std::cmp::Ordering::Greater) {
            x0 -= 0.5;
            x1 += 0.5;
        }
        if y1.partial_cmp(&y0) != Some(std::cmp::Ordering::Greater) {
            y1 = y0 + 1.0;
        }
        let pad = 0.05 * (x1 - x0);
        let (x0, x1) = (x0 - pad, x1 + pad);
        let y1 = y1 + 0.08 * (y1 - y0);
        Self {
            w,
            h,
            ml,
            mr,
            mt,
            mb,
            log_x: chart.log_x,
            x0,
            x1,
            y0,
            y1,
        }
    }

    /// `x` in axis units.
    fn tx(&self, x: f64) -> f64 {
        axis_x(self.log_x, x)
    }

    /// Page x of the data value `x`.
    fn px(&self, x: f64) -> f64 {
        self.pxt(self.tx(x))
    }

    /// Page x of `t` in axis units.
    fn pxt(&self, t: f64) -> f64 {
        self.ml + (t - self.x0) / (self.x1 - self.x0) * (self.w - self.ml - self.mr)
    }

    /// Page y of the data value `y`.
    fn py(&self, y: f64) -> f64 {
        self.h - self.mb - (y - self.y0) / (self.y1 - self.y0) * (self.h - self.mt - self.mb)
    }
}

/// Renders `chart` as a standalone SVG document.
pub(crate) fn render(chart: &Chart) -> String {
    let f = Frame::new(chart);
    let (w, h, ml, mr, mt, mb) = (f.w, f.h, f.ml, f.mr, f.mt, f.mb);
    let mut s = String::new();
    let _ = writeln!(
        s,
        r#"<svg xmlns="http://www.w3.org/2000/svg" width="{w}" height="{h}" viewBox="0 0 {w} {h}" font-family="sans-serif" font-size="12">"#
    );
    let _ = writeln!(s, r#"<rect width="{w}" height="{h}" fill="white"/>"#);
    let _ = writeln!(
        s,
        r#"<text x="{}" y="22" text-anchor="middle" font-size="15">{}</text>"#,
        w / 2.0,
        escape(&chart.title)
    );
    let _ = writeln!(
        s,
        r#"<rect x="{ml}" y="{mt}" width="{}" height="{}" fill="none" stroke="black"/>"#,
        w - ml - mr,
        h - mt - mb
    );
    write_axes(&mut s, chart, &f);
    for (k, series) in chart.series.iter().enumerate() {
        write_series(&mut s, &f, k, series);
    }
    s.push_str("</svg>\n");
    s
}

/// Grid lines and tick labels of both axes (decades 1-2-5 on a log-x axis),
/// and the axis labels.
fn write_axes(s: &mut String, chart: &Chart, f: &Frame) {
    let (w, h, ml, mr, mt, mb) = (f.w, f.h, f.ml, f.mr, f.mt, f.mb);
    let (x0, x1) = (f.x0, f.x1);
    let xticks: Vec<(f64, String)> = if chart.log_x {
        let (a, b) = (x0.floor() as i32, x1.ceil() as i32);
        (a..=b)
            .flat_map(|e| [1.0, 2.0, 5.0].map(|m| m * 10f64.powi(e)))
            .filter(|v| (x0..=x1).contains(&v.log10()))
            .map(|v| (v.log10(), fmt_tick(v)))
            .collect()
    } else {
        nice_ticks(x0, x1, 6)
            .into_iter()
            .map(|v| (v, fmt_tick(v)))
            .collect()
    };
    for (t, label) in xticks {
        let x = f.pxt(t);
        let _ = writeln!(
            s,
            r##"<line x1="{x:.1}" y1="{}" x2="{x:.1}" y2="{mt}" stroke="#ddd"/><text x="{x:.1}" y="{}" text-anchor="middle">{label}</text>"##,
            h - mb,
            h - mb + 16.0
        );
    }
    for v in nice_ticks(f.y0, f.y1, 6) {
        let y = f.py(v);
        let _ = writeln!(
            s,
            r##"<line x1="{ml}" y1="{y:.1}" x2="{}" y2="{y:.1}" stroke="#ddd"/><text x="{}" y="{:.1}" text-anchor="end">{}</text>"##,
            w - mr,
            ml - 6.0,
            y + 4.0,
            fmt_tick(v)
        );
    }
    let _ = writeln!(
        s,
        r#"<text x="{}" y="{}" text-anchor="middle">{}</text>"#,
        ml + (w - ml - mr) / 2.0,
        h - 14.0,
        escape(&chart.x_label)
    );
    let _ = writeln!(
        s,
        r#"<text x="16" y="{}" text-anchor="middle" transform="rotate(-90 16 {})">{}</text>"#,
        mt + (h - mt - mb) / 2.0,
        mt + (h - mt - mb) / 2.0,
        escape(&chart.y_label)
    );
}

/// The `k`-th series of a chart (its visible points as a polyline or as
/// labelled markers) and its legend entry.
fn write_series(s: &mut String, f: &Frame, k: usize, series: &Series) {
    let c = COLOURS[k % COLOURS.len()];
    let visible: Vec<(usize, (f64, f64))> = series
        .points
        .iter()
        .copied()
        .enumerate()
        .filter(|(_, (x, y))| x.is_finite() && y.is_finite() && (!f.log_x || *x > 0.0))
        .collect();
    match series.style {
        Style::Line => {
            let path: Vec<String> = visible
                .iter()
                .map(|(_, (x, y))| format!("{:.1},{:.1}", f.px(*x), f.py(*y)))
                .collect();
            let _ = writeln!(
                s,
                r#"<polyline fill="none" stroke="{c}" stroke-width="1.8" points="{}"/>"#,
                path.join(" ")
            );
        }
        Style::Markers => {
            for (i, (x, y)) in &visible {
                let _ = writeln!(
                    s,
                    r#"<circle cx="{:.1}" cy="{:.1}" r="4" fill="{c}"/>"#,
                    f.px(*x),
                    f.py(*y)
                );
                if let Some(l) = series.point_labels.get(*i) {
                    let _ = writeln!(
                        s,
                        r#"<text x="{:.1}" y="{:.1}" font-size="10" fill="{c}">{}</text>"#,
                        f.px(*x) + 6.0,
                        f.py(*y) - 4.0,
                        escape(l)
                    );
                }
            }
        }
    }
    let ly = f.mt + 16.0 + 16.0 * k as f64;
    let lx = f.w - f.mr - 120.0;
    let _ = writeln!(
        s,
        r#"<rect x="{lx}" y="{}" width="12" height="4" fill="{c}"/><text x="{}" y="{ly}">{}</text>"#,
        ly - 5.0,
        lx + 18.0,
        escape(&series.label)
    );
}

/// Density histogram of `x` on `bins` bins over `[lo, hi]` as a step line.
pub(crate) fn density_steps(x: &[f64], lo: f64, hi: f64, bins: usize) -> Vec<(f64, f64)> {
    let w = (hi - lo) / bins as f64;
    let mut counts = vec![0usize; bins];
    for v in x {
        let k = (((v - lo) / w).floor().max(0.0) as usize).min(bins - 1);
        counts[k] += 1;
    }
    let n = x.len().max(1) as f64;
    let mut pts = vec![(lo, 0.0)];
    for (k, c) in counts.iter().enumerate() {
        let d = *c as f64 / (n * w);
        pts.push((lo + k as f64 * w, d));
        pts.push((lo + (k + 1) as f64 * w, d));
    }
    pts.push((hi, 0.0));
    pts
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn renders_a_closed_document_with_every_series() {
        let chart = Chart {
            title: "t <1>".into(),
            x_label: "x".into(),
            y_label: "y".into(),
            log_x: true,
            series: vec![
                Series::line("a", vec![(1.0, 1.0), (10.0, 2.0), (-1.0, 3.0)]),
                Series {
                    label: "b".into(),
                    points: vec![(2.0, 0.5)],
                    style: Style::Markers,
                    point_labels: vec!["p".into()],
                },
            ],
        };
        let s = render(&chart);
        assert!(s.starts_with("<svg") && s.trim_end().ends_with("</svg>"));
        assert!(s.contains("t &lt;1&gt;") && s.contains("polyline") && s.contains("circle"));
        assert!(!s.contains("NaN"));
    }

    #[test]
    fn density_steps_integrate_to_one() {
        let x: Vec<f64> = (0..100).map(|i| i as f64 / 100.0).collect();
        let p = density_steps(&x, 0.0, 1.0, 10);
        let mass: f64 = p.windows(2).map(|w| (w[1].0 - w[0].0) * w[1].1).sum();
        assert!((mass - 1.0).abs() < 1e-9, "{mass}");
    }
}
