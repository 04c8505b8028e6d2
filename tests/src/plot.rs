//! The report's figure, written by hand as SVG: panels of error against run
//! time, one numbered point per method and setting, log axes where the
//! values span decades, and each panel's Pareto front (the settings no other
//! setting beats on both time and error) drawn as a staircase line.

use std::fmt::Write;

/// One setting's run time and error.
#[derive(Clone, Debug, PartialEq)]
pub struct Point {
    /// The legend's text.
    pub label: String,
    /// Run time.
    pub x: f64,
    /// Error (0 is drawn on a row below a log axis's lowest decade).
    pub y: f64,
}

/// One panel.
#[derive(Clone, Debug)]
pub struct Panel {
    /// Heading.
    pub title: String,
    /// Label of the time axis, with its unit.
    pub x_label: String,
    /// Label of the error axis, with its unit.
    pub y_label: String,
    /// Logarithmic time axis.
    pub log_x: bool,
    /// Logarithmic error axis.
    pub log_y: bool,
    /// The settings.
    pub points: Vec<Point>,
}

/// Indices of the points no other point beats on both coordinates (lower
/// time and lower error, one of them strictly), in increasing time. Of
/// equal points the first is kept.
pub fn pareto(points: &[Point]) -> Vec<usize> {
    let mut order: Vec<usize> = (0..points.len()).filter(|&i| points[i].x.is_finite() && points[i].y.is_finite()).collect();
    order.sort_by(|&a, &b| points[a].x.total_cmp(&points[b].x).then(points[a].y.total_cmp(&points[b].y)));
    let mut front = vec![];
    let mut best = f64::INFINITY;
    for i in order {
        if points[i].y < best {
            best = points[i].y;
            front.push(i);
        }
    }
    front
}

/// Maps data to pixels along one axis.
struct Axis {
    log: bool,
    lo: f64,
    hi: f64,
    /// Pixel positions of `lo` and `hi`.
    from: f64,
    to: f64,
    /// Log axes with zeros: the pixel of the "0" row.
    zero: Option<f64>,
}

impl Axis {
    fn new(values: &[f64], log: bool, from: f64, to: f64) -> Axis {
        let finite: Vec<f64> = values.iter().copied().filter(|v| v.is_finite()).collect();
        if log {
            let pos: Vec<f64> = finite.iter().copied().filter(|&v| v > 0.0).collect();
            let min = pos.iter().copied().fold(f64::INFINITY, f64::min);
            let max = pos.iter().copied().fold(0.0, f64::max);
            // Whole decades when the data spans several; otherwise a tenth
            // of a decade of margin, so a cluster of points is not squeezed
            // into a corner.
            let (mut lo, mut hi) = if pos.is_empty() { (0.0, 1.0) } else { (min.log10(), max.log10()) };
            if hi - lo >= 2.0 {
                (lo, hi) = (lo.floor(), hi.ceil());
            } else {
                let pad = 0.1f64.max((1.0 - (hi - lo)) / 2.0);
                (lo, hi) = (lo - pad, hi + pad);
            }
            let has_zero = finite.iter().any(|&v| v <= 0.0);
            // Zeros get a row 10% of the axis beyond the lowest value.
            let (start, zero) = if has_zero { (from + 0.12 * (to - from), Some(from + 0.03 * (to - from))) } else { (from, None) };
            Axis { log, lo, hi, from: start, to, zero }
        } else {
            let min = finite.iter().copied().fold(0.0, f64::min);
            let max = finite.iter().copied().fold(0.0, f64::max);
            let hi = if max > min { max + 0.08 * (max - min) } else { min + 1.0 };
            Axis { log, lo: min, hi, from, to, zero: None }
        }
    }

    fn px(&self, v: f64) -> f64 {
        if self.log {
            if v <= 0.0 {
                return self.zero.unwrap_or(self.from);
            }
            self.from + (v.log10() - self.lo) / (self.hi - self.lo) * (self.to - self.from)
        } else {
            self.from + (v - self.lo) / (self.hi - self.lo) * (self.to - self.from)
        }
    }

    /// (value, label) of the ticks.
    fn ticks(&self) -> Vec<(f64, String)> {
        let mut t = vec![];
        if self.log {
            if self.zero.is_some() {
                t.push((0.0, "0".to_string()));
            }
            // 1, 2 and 5 times each power of ten when the axis spans under
            // three decades, the powers alone otherwise.
            let steps: &[f64] = if self.hi - self.lo < 3.0 { &[1.0, 2.0, 5.0] } else { &[1.0] };
            for e in self.lo.floor() as i32..=self.hi.ceil() as i32 {
                for &m in steps {
                    let v = m * 10f64.powi(e);
                    let l = v.log10();
                    if l < self.lo - 1e-9 || l > self.hi + 1e-9 {
                        continue;
                    }
                    let label = if (-3..=4).contains(&e) { format!("{v}") } else { format!("{m}e{e}") };
                    t.push((v, label));
                }
            }
        } else {
            let span = self.hi - self.lo;
            let raw = span / 5.0;
            let mag = 10f64.powf(raw.log10().floor());
            let step = [1.0, 2.0, 5.0, 10.0].iter().map(|m| m * mag).find(|s| span / s <= 6.0).unwrap_or(10.0 * mag);
            let mut v = (self.lo / step).ceil() * step;
            while v <= self.hi + 1e-12 * span {
                t.push((v, crate::table::sig(v)));
                v += step;
            }
        }
        t
    }
}

const PALETTE: [&str; 12] = [
    "#1f77b4", "#ff7f0e", "#2ca02c", "#d62728", "#9467bd", "#8c564b", "#e377c2", "#7f7f7f", "#bcbd22", "#17becf",
    "#393b79", "#637939",
];

fn escape(s: &str) -> String {
    s.replace('&', "&amp;").replace('<', "&lt;").replace('>', "&gt;")
}

const PANEL_W: f64 = 640.0;
const PANEL_H: f64 = 400.0;

fn panel(out: &mut String, p: &Panel, ox: f64, oy: f64) {
    let (left, top, width, height) = (ox + 72.0, oy + 44.0, 300.0, 290.0);
    let xs: Vec<f64> = p.points.iter().map(|q| q.x).collect();
    let ys: Vec<f64> = p.points.iter().map(|q| q.y).collect();
    let ax = Axis::new(&xs, p.log_x, left, left + width);
    let ay = Axis::new(&ys, p.log_y, top + height, top);
    let _ = writeln!(out, r#"<text x="{}" y="{}" font-size="15" font-weight="bold">{}</text>"#, ox + 12.0, oy + 24.0, escape(&p.title));
    let _ = writeln!(out, r##"<rect x="{left}" y="{top}" width="{width}" height="{height}" fill="none" stroke="#444"/>"##);
    for (v, label) in ax.ticks() {
        let x = ax.px(v);
        let _ = writeln!(out, r##"<line x1="{x:.1}" y1="{top}" x2="{x:.1}" y2="{}" stroke="#ddd"/>"##, top + height);
        let _ = writeln!(out, r#"<text x="{x:.1}" y="{}" font-size="11" text-anchor="middle">{label}</text>"#, top + height + 15.0);
    }
    for (v, label) in ay.ticks() {
        let y = ay.px(v);
        let _ = writeln!(out, r##"<line x1="{left}" y1="{y:.1}" x2="{}" y2="{y:.1}" stroke="#ddd"/>"##, left + width);
        let _ = writeln!(out, r#"<text x="{}" y="{:.1}" font-size="11" text-anchor="end">{label}</text>"#, left - 5.0, y + 4.0);
    }
    if let Some(z) = ay.zero {
        let zb = ay.from;
        let _ = writeln!(out, r##"<line x1="{left}" y1="{:.1}" x2="{}" y2="{:.1}" stroke="#999" stroke-dasharray="3,3"/>"##, (z + zb) / 2.0, left + width, (z + zb) / 2.0);
    }
    let _ = writeln!(out, r#"<text x="{}" y="{}" font-size="12" text-anchor="middle">{}</text>"#, left + width / 2.0, top + height + 34.0, escape(&p.x_label));
    let (yx, yy) = (ox + 16.0, top + height / 2.0);
    let _ = writeln!(out, r#"<text x="{yx}" y="{yy}" font-size="12" text-anchor="middle" transform="rotate(-90 {yx} {yy})">{}</text>"#, escape(&p.y_label));

    // The Pareto front: a staircase through the non-dominated points.
    let front = pareto(&p.points);
    if !front.is_empty() {
        let mut d = String::new();
        for (j, &i) in front.iter().enumerate() {
            let (x, y) = (ax.px(p.points[i].x), ay.px(p.points[i].y));
            if j == 0 {
                let _ = write!(d, "M{x:.1},{y:.1}");
            } else {
                let _ = write!(d, " H{x:.1} V{y:.1}");
            }
        }
        // Everything right of the last point and above the first is beaten.
        let _ = write!(d, " H{:.1}", left + width);
        let _ = write!(d, " M{:.1},{top} V{:.1}", ax.px(p.points[front[0]].x), ay.px(p.points[front[0]].y));
        let _ = writeln!(out, r##"<path d="{d}" fill="none" stroke="#000" stroke-width="1.5" stroke-dasharray="6,3"/>"##);
    }
    for (i, q) in p.points.iter().enumerate() {
        if !(q.x.is_finite() && q.y.is_finite()) {
            continue;
        }
        let (x, y) = (ax.px(q.x), ay.px(q.y));
        let c = PALETTE[i % PALETTE.len()];
        let ring = if front.contains(&i) { r##" stroke="#000" stroke-width="1.5""## } else { "" };
        let _ = writeln!(out, r#"<circle cx="{x:.1}" cy="{y:.1}" r="5" fill="{c}"{ring}><title>{}</title></circle>"#, escape(&q.label));
        let _ = writeln!(out, r#"<text x="{:.1}" y="{:.1}" font-size="10">{}</text>"#, x + 6.0, y - 5.0, i + 1);
    }
    // Legend.
    let lx = left + width + 18.0;
    let mut ly = top + 6.0;
    for (i, q) in p.points.iter().enumerate() {
        let c = PALETTE[i % PALETTE.len()];
        let mark = if front.contains(&i) { " *" } else { "" };
        let _ = writeln!(out, r#"<circle cx="{lx}" cy="{ly}" r="4" fill="{c}"/>"#);
        let _ = writeln!(out, r#"<text x="{}" y="{}" font-size="11">{}. {}{mark}</text>"#, lx + 8.0, ly + 4.0, i + 1, escape(&q.label));
        ly += 16.0;
    }
    let _ = writeln!(out, r##"<line x1="{}" y1="{}" x2="{}" y2="{}" stroke="#000" stroke-width="1.5" stroke-dasharray="6,3"/>"##, lx - 4.0, ly + 2.0, lx + 14.0, ly + 2.0);
    let _ = writeln!(out, r#"<text x="{}" y="{}" font-size="11">Pareto front (* on it)</text>"#, lx + 20.0, ly + 6.0);
}

/// The figure: `panels` in rows of `columns`.
pub fn svg(title: &str, panels: &[Panel], columns: usize) -> String {
    let rows = panels.len().div_ceil(columns.max(1));
    let (w, h) = (PANEL_W * columns as f64, PANEL_H * rows as f64 + 40.0);
    let mut out = String::new();
    let _ = writeln!(out, r#"<svg xmlns="http://www.w3.org/2000/svg" width="{w}" height="{h}" viewBox="0 0 {w} {h}" font-family="Helvetica, Arial, sans-serif">"#);
    let _ = writeln!(out, r#"<rect width="{w}" height="{h}" fill="white"/>"#);
    let _ = writeln!(out, r#"<text x="12" y="26" font-size="18" font-weight="bold">{}</text>"#, escape(title));
    for (i, p) in panels.iter().enumerate() {
        let (c, r) = (i % columns, i / columns);
        panel(&mut out, p, c as f64 * PANEL_W, 40.0 + r as f64 * PANEL_H);
    }
    out.push_str("</svg>\n");
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    fn pt(x: f64, y: f64) -> Point {
        Point { label: String::new(), x, y }
    }

    #[test]
    fn pareto_keeps_the_non_dominated() {
        // 1 (fast, bad), 2 (slow, exact), 0 dominated by 1, 3 dominated by 2.
        let p = [pt(3.0, 5.0), pt(1.0, 4.0), pt(5.0, 0.0), pt(6.0, 0.0), pt(2.0, 1.0)];
        assert_eq!(pareto(&p), vec![1, 4, 2]);
    }

    #[test]
    fn log_axis_puts_zero_below_the_decades() {
        let a = Axis::new(&[0.0, 0.01, 3.0], true, 300.0, 0.0);
        assert_eq!((a.lo, a.hi), (-2.0, 1.0));
        assert!(a.px(0.0) > a.px(0.01) && a.px(0.01) > a.px(3.0));
        let t: Vec<String> = a.ticks().into_iter().map(|t| t.1).collect();
        assert_eq!(t, ["0", "0.01", "0.1", "1", "10"]);
    }

    #[test]
    fn narrow_log_axis_gets_margins_and_intermediate_ticks() {
        let a = Axis::new(&[0.08, 0.1], true, 300.0, 0.0);
        assert!(a.lo < 0.08f64.log10() && a.hi > -1.0 && a.hi - a.lo >= 1.0 - 1e-12);
        let t: Vec<String> = a.ticks().into_iter().map(|t| t.1).collect();
        assert!(t.contains(&"0.05".to_string()) && t.contains(&"0.1".to_string()), "{t:?}");
    }

    #[test]
    fn figure_is_well_formed() {
        let panel = Panel {
            title: "t <1>".into(),
            x_label: "x".into(),
            y_label: "y".into(),
            log_x: true,
            log_y: false,
            points: vec![pt(1.0, 2.0), pt(10.0, 1.0)],
        };
        let s = svg("fig", &[panel], 1);
        assert!(s.starts_with("<svg") && s.ends_with("</svg>\n") && s.contains("t &lt;1&gt;"));
        assert_eq!(s.matches("<circle").count(), 4);
    }
}
