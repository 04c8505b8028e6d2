//! The report's figure, drawn with plotters' SVG backend: panels of error
//! against run time, one numbered point per method and setting, log axes
//! where the values span decades, and each panel's Pareto front (the
//! settings no other setting beats on both time and error) drawn as a
//! dashed staircase.
//!
//! plotters draws the frame, the grid, the tick labels and the text; this
//! module chooses the scales ([`Scale`], a plotters coordinate that puts a
//! zero below a log axis's lowest decade) and the Pareto front. Text is
//! left to the SVG viewer's sans-serif font (no font is read at build or
//! run time), so plotters only estimates its width for the layout.

use plotters::coord::ranged1d::{KeyPointHint, NoDefaultFormatting, Ranged, ValueFormatter};
use plotters::coord::Shift;
use plotters::element::DashedPathElement;
use plotters::prelude::*;

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

/// Where a log axis with zeros puts its "0" row, and where its lowest
/// decade starts, as shares of the axis.
const ZERO_ROW: f64 = 0.03;
const LOG_START: f64 = 0.12;

/// One axis of a panel as a plotters coordinate: linear, or logarithmic
/// with an optional row for zeros below its lowest decade.
#[derive(Clone, Debug, PartialEq)]
pub struct Scale {
    log: bool,
    /// The ends: log10 of the values on a log axis.
    lo: f64,
    hi: f64,
    /// A log axis with zero values: they get a row of their own.
    zero: bool,
}

impl Scale {
    /// The scale that shows `values` (non-finite ones are ignored).
    pub fn new(values: &[f64], log: bool) -> Scale {
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
            Scale { log, lo, hi, zero: finite.iter().any(|&v| v <= 0.0) }
        } else {
            let min = finite.iter().copied().fold(0.0, f64::min);
            let max = finite.iter().copied().fold(0.0, f64::max);
            let hi = if max > min { max + 0.08 * (max - min) } else { min + 1.0 };
            Scale { log, lo: min, hi, zero: false }
        }
    }

    /// Where `v` lies along the axis, 0 at the start and 1 at the end.
    fn share(&self, v: f64) -> f64 {
        if !self.log {
            return (v - self.lo) / (self.hi - self.lo);
        }
        if v <= 0.0 {
            return if self.zero { ZERO_ROW } else { 0.0 };
        }
        let start = if self.zero { LOG_START } else { 0.0 };
        start + (v.log10() - self.lo) / (self.hi - self.lo) * (1.0 - start)
    }

    /// Where the dashed line between the zero row and the lowest decade
    /// goes, as a share of the axis; `None` without a zero row.
    fn zero_gap(&self) -> Option<f64> {
        self.zero.then_some((ZERO_ROW + LOG_START) / 2.0)
    }

    /// The largest value on the axis.
    fn top(&self) -> f64 {
        if self.log { 10f64.powf(self.hi) } else { self.hi }
    }

    /// The ticks: 0 below a log axis with zeros; 1, 2 and 5 times each
    /// power of ten when a log axis spans under three decades, the powers
    /// alone otherwise; 1, 2 or 5 times a power of ten apart on a linear
    /// axis, at most six of them.
    fn ticks(&self) -> Vec<f64> {
        let mut t = vec![];
        if self.log {
            if self.zero {
                t.push(0.0);
            }
            let steps: &[f64] = if self.hi - self.lo < 3.0 { &[1.0, 2.0, 5.0] } else { &[1.0] };
            for e in self.lo.floor() as i32..=self.hi.ceil() as i32 {
                for &m in steps {
                    let v = m * 10f64.powi(e);
                    let l = v.log10();
                    if l >= self.lo - 1e-9 && l <= self.hi + 1e-9 {
                        t.push(v);
                    }
                }
            }
        } else {
            let span = self.hi - self.lo;
            let mag = 10f64.powf((span / 5.0).log10().floor());
            let step = [1.0, 2.0, 5.0, 10.0].iter().map(|m| m * mag).find(|s| span / s <= 6.0).unwrap_or(10.0 * mag);
            let mut v = (self.lo / step).ceil() * step;
            while v <= self.hi + 1e-12 * span {
                t.push(v);
                v += step;
            }
        }
        t
    }

    /// Light grid lines of a log axis that shows only the powers of ten:
    /// 2 to 9 times each.
    fn minor_ticks(&self) -> Vec<f64> {
        if !self.log || self.hi - self.lo < 3.0 {
            return vec![];
        }
        (self.lo.floor() as i32..=self.hi.ceil() as i32)
            .flat_map(|e| (2..=9).map(move |m| f64::from(m) * 10f64.powi(e)))
            .filter(|v| (self.lo..=self.hi).contains(&v.log10()))
            .collect()
    }

    /// A tick's label.
    fn label(&self, v: f64) -> String {
        if !self.log {
            return crate::table::sig(v);
        }
        if v <= 0.0 {
            return "0".into();
        }
        let e = v.log10().floor() as i32;
        if (-3..=4).contains(&e) {
            format!("{}", (v / 10f64.powi(e)).round() * 10f64.powi(e))
        } else {
            format!("{}e{e}", (v / 10f64.powi(e)).round())
        }
    }
}

impl Ranged for Scale {
    type FormatOption = NoDefaultFormatting;
    type ValueType = f64;

    fn map(&self, v: &f64, limit: (i32, i32)) -> i32 {
        let px = f64::from(limit.0) + self.share(*v) * f64::from(limit.1 - limit.0);
        px.round() as i32
    }

    fn key_points<H: KeyPointHint>(&self, hint: H) -> Vec<f64> {
        // plotters asks for the bold (labelled) lines with a hint that
        // allows no light points, and for the light ones with one that does.
        if hint.weight().allow_light_points() { self.minor_ticks() } else { self.ticks() }
    }

    fn range(&self) -> std::ops::Range<f64> {
        let bottom = if self.zero { 0.0 } else if self.log { 10f64.powf(self.lo) } else { self.lo };
        bottom..self.top()
    }
}

impl ValueFormatter<f64> for Scale {
    fn format_ext(&self, v: &f64) -> String {
        self.label(*v)
    }
}

/// The colours of the points, in order.
const PALETTE: [RGBColor; 12] = [
    RGBColor(0x1f, 0x77, 0xb4),
    RGBColor(0xff, 0x7f, 0x0e),
    RGBColor(0x2c, 0xa0, 0x2c),
    RGBColor(0xd6, 0x27, 0x28),
    RGBColor(0x94, 0x67, 0xbd),
    RGBColor(0x8c, 0x56, 0x4b),
    RGBColor(0xe3, 0x77, 0xc2),
    RGBColor(0x7f, 0x7f, 0x7f),
    RGBColor(0xbc, 0xbd, 0x22),
    RGBColor(0x17, 0xbe, 0xcf),
    RGBColor(0x39, 0x3b, 0x79),
    RGBColor(0x63, 0x79, 0x39),
];

const PANEL_W: u32 = 640;
const PANEL_H: u32 = 400;
/// Width of a panel's chart; the legend takes the rest.
const CHART_W: u32 = 400;
const FONT: &str = "sans-serif";

/// A font of `px` pixels: plotters' SVG backend writes a size `s` as
/// `font-size = s / 1.24`.
fn font(px: f64) -> FontDesc<'static> {
    (FONT, px * 1.24).into_font()
}

type Area<'a> = DrawingArea<SVGBackend<'a>, Shift>;
type Failure = Box<dyn std::error::Error>;

/// The dashed line of the Pareto front.
fn front_style() -> ShapeStyle {
    BLACK.stroke_width(2)
}

fn panel(area: &Area, p: &Panel) -> Result<(), Failure> {
    let (chart_area, legend_area) = area.split_horizontally(CHART_W);
    let xs: Vec<f64> = p.points.iter().map(|q| q.x).collect();
    let ys: Vec<f64> = p.points.iter().map(|q| q.y).collect();
    let (sx, sy) = (Scale::new(&xs, p.log_x), Scale::new(&ys, p.log_y));
    let mut chart = ChartBuilder::on(&chart_area)
        .caption(&p.title, font(15.0).style(FontStyle::Bold))
        .margin(10)
        .x_label_area_size(40)
        .y_label_area_size(62)
        .build_cartesian_2d(sx.clone(), sy.clone())?;
    chart
        .configure_mesh()
        .x_desc(&p.x_label)
        .y_desc(&p.y_label)
        .label_style(font(11.0))
        .axis_desc_style(font(12.0))
        .bold_line_style(RGBColor(0xdd, 0xdd, 0xdd))
        .light_line_style(RGBColor(0xf0, 0xf0, 0xf0))
        .draw()?;

    let plot = chart.plotting_area().strip_coord_spec();
    let (w, h) = plot.dim_in_pixel();
    plot.draw(&Rectangle::new([(0, 0), (w as i32 - 1, h as i32 - 1)], RGBColor(0x44, 0x44, 0x44)))?;
    if let Some(gap) = sy.zero_gap() {
        let y = ((1.0 - gap) * f64::from(h)).round() as i32;
        plot.draw(&DashedPathElement::new([(0, y), (w as i32, y)], 3, 3, RGBColor(0x99, 0x99, 0x99)))?;
    }

    // The Pareto front: from the top of the panel down to the fastest
    // point on it, a staircase through the others, then on to the right
    // edge: everything above and to the right of it is beaten.
    let front = pareto(&p.points);
    if let (Some(&first), Some(&last)) = (front.first(), front.last()) {
        let mut path = vec![(p.points[first].x, sy.top()), (p.points[first].x, p.points[first].y)];
        for pair in front.windows(2) {
            let (a, b) = (&p.points[pair[0]], &p.points[pair[1]]);
            path.extend([(b.x, a.y), (b.x, b.y)]);
        }
        path.push((sx.top(), p.points[last].y));
        chart.draw_series(std::iter::once(DashedPathElement::new(path, 6, 3, front_style())))?;
    }
    let numbered = |i: usize, q: &Point| {
        let ring = if front.contains(&i) { BLACK.stroke_width(2) } else { TRANSPARENT.into() };
        EmptyElement::at((q.x, q.y))
            + Circle::new((0, 0), 5, PALETTE[i % PALETTE.len()].filled())
            + Circle::new((0, 0), 5, ring)
            + Text::new(format!("{}", i + 1), (6, -16), font(10.0))
    };
    chart.draw_series(p.points.iter().enumerate().filter(|(_, q)| q.x.is_finite() && q.y.is_finite()).map(|(i, q)| numbered(i, q)))?;

    // The legend, beside the chart, level with its plotting area.
    let legend = legend_area.margin(44, 0, 10, 0);
    for (i, q) in p.points.iter().enumerate() {
        let y = 16 * i as i32;
        let mark = if front.contains(&i) { " *" } else { "" };
        legend.draw(&Circle::new((4, y + 6), 4, PALETTE[i % PALETTE.len()].filled()))?;
        legend.draw(&Text::new(format!("{}. {}{mark}", i + 1, q.label), (12, y), font(11.0)))?;
    }
    let y = 16 * p.points.len() as i32 + 8;
    legend.draw(&DashedPathElement::new([(0, y), (18, y)], 6, 3, front_style()))?;
    legend.draw(&Text::new("Pareto front (* on it)", (24, y - 7), font(11.0)))?;
    Ok(())
}

/// The figure: `panels` in rows of `columns`, as SVG text.
pub fn svg(title: &str, panels: &[Panel], columns: usize) -> Result<String, Failure> {
    let columns = columns.max(1);
    let rows = panels.len().div_ceil(columns);
    let size = (PANEL_W * columns as u32, PANEL_H * rows as u32 + 40);
    let mut out = String::new();
    {
        let root = SVGBackend::with_string(&mut out, size).into_drawing_area();
        root.fill(&WHITE)?;
        let body = root.titled(title, font(18.0).style(FontStyle::Bold))?;
        for (area, p) in body.split_evenly((rows, columns)).iter().zip(panels) {
            panel(area, p)?;
        }
        root.present()?;
    }
    Ok(out)
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
        let a = Scale::new(&[0.0, 0.01, 3.0], true);
        assert_eq!((a.lo, a.hi), (-2.0, 1.0));
        // Pixels grow upwards here, as on plotters' y axis.
        let px = |v: f64| a.map(&v, (300, 0));
        assert!(px(0.0) > px(0.01) && px(0.01) > px(3.0));
        let t: Vec<String> = a.ticks().into_iter().map(|v| a.label(v)).collect();
        assert_eq!(t, ["0", "0.01", "0.1", "1", "10"]);
    }

    #[test]
    fn narrow_log_axis_gets_margins_and_intermediate_ticks() {
        let a = Scale::new(&[0.08, 0.1], true);
        assert!(a.lo < 0.08f64.log10() && a.hi > -1.0 && a.hi - a.lo >= 1.0 - 1e-12);
        let t: Vec<String> = a.ticks().into_iter().map(|v| a.label(v)).collect();
        assert!(t.contains(&"0.05".to_string()) && t.contains(&"0.1".to_string()), "{t:?}");
        assert!(a.minor_ticks().is_empty());
    }

    #[test]
    fn wide_log_axis_labels_powers_and_draws_light_lines_between() {
        let a = Scale::new(&[1e-7, 2e-3], true);
        let t: Vec<String> = a.ticks().into_iter().map(|v| a.label(v)).collect();
        assert_eq!(t, ["1e-7", "1e-6", "1e-5", "1e-4", "0.001", "0.01"]);
        assert_eq!(a.minor_ticks().len(), 5 * 8);
    }

    #[test]
    fn figure_is_well_formed() {
        let panel = Panel {
            title: "t <1>".into(),
            x_label: "x".into(),
            y_label: "y".into(),
            log_x: true,
            log_y: false,
            points: vec![Point { label: "a & b".into(), x: 1.0, y: 2.0 }, pt(10.0, 1.0)],
        };
        let s = svg("fig", &[panel], 1).expect("draws");
        assert!(s.starts_with("<svg") && s.trim_end().ends_with("</svg>"), "{s}");
        assert!(s.contains("t &lt;1&gt;") && s.contains("1. a &amp; b *"), "{s}");
        // Two circles per point (fill and ring) and one in the legend.
        assert_eq!(s.matches("<circle").count(), 6);
    }
}
