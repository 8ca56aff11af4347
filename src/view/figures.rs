//! Figures drawn with plotters, each renderable as PNG (file) or SVG (file or string):
//! history curves, the mesh, the deformed shape, colour maps of stress fields, crack
//! patterns and joint diagrams.
// long: one figure type per kind (curves, mesh, deformed shape, contours, cracks, joints, stages) over the shared frame, legend, tick and colour helpers of this file; none over 150 lines

use super::data::{bounds, Grid};
use super::glyphs::GlyphText;
use super::ViewError;
use plotters::coord::Shift;
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};
use std::path::{Path, PathBuf};

/// Font family registered with plotters (the bundled DejaVu Sans).
pub const FONT: &str = "sans-serif";

/// Register the bundled font once (plotters' `ab_glyph` backend needs one to measure and
/// draw text).
pub fn init_font() {
    static ONCE: std::sync::Once = std::sync::Once::new();
    ONCE.call_once(|| {
        plotters::style::register_font(FONT, FontStyle::Normal, super::glyphs::DEJAVU_SANS)
            .unwrap_or_else(|_| panic!("the bundled font is a valid TTF"));
    });
}

type DrawResult = Result<(), String>;

fn de<E: std::fmt::Display>(e: E) -> String {
    e.to_string()
}

/// A figure: a size and a drawing routine for any plotters backend.
pub trait Figure {
    /// Size in pixels (width, height).
    fn size(&self) -> (u32, u32);
    /// Draw on `root` (already filled white).
    fn draw<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> DrawResult;
}

/// Render a figure to an SVG string.
pub fn svg_string(fig: &impl Figure) -> Result<String, ViewError> {
    init_font();
    let mut s = String::new();
    {
        let root = SVGBackend::with_string(&mut s, fig.size()).into_drawing_area();
        root.fill(&WHITE).map_err(|e| ViewError::Io(de(e)))?;
        fig.draw(&root).map_err(ViewError::Io)?;
        root.present().map_err(|e| ViewError::Io(de(e)))?;
    }
    Ok(s)
}

/// Render a figure to a PNG file.
pub fn write_png(fig: &impl Figure, path: &Path) -> Result<(), ViewError> {
    init_font();
    let io = |e: String| ViewError::Io(format!("{}: {e}", path.display()));
    // Text through GlyphText: plotters' bitmap text ignores glyph side bearings.
    let root = GlyphText::new(BitMapBackend::new(path, fig.size())).into_drawing_area();
    root.fill(&WHITE).map_err(|e| io(de(e)))?;
    fig.draw(&root).map_err(io)?;
    root.present().map_err(|e| io(de(e)))?;
    Ok(())
}

/// Render a figure to PNG bytes (through a temporary file).
pub fn png_bytes(fig: &impl Figure) -> Result<Vec<u8>, ViewError> {
    static N: std::sync::atomic::AtomicUsize = std::sync::atomic::AtomicUsize::new(0);
    let k = N.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
    let tmp = std::env::temp_dir().join(format!("segfem-view-{}-{k}.png", std::process::id()));
    write_png(fig, &tmp)?;
    let bytes = std::fs::read(&tmp).map_err(|e| ViewError::Io(format!("{}: {e}", tmp.display())));
    let _ = std::fs::remove_file(&tmp);
    bytes
}

/// Write `<dir>/<stem>.png` and `<dir>/<stem>.svg`; returns both paths.
pub fn save(fig: &impl Figure, dir: &Path, stem: &str) -> Result<Vec<PathBuf>, ViewError> {
    let png_path = dir.join(format!("{stem}.png"));
    let svg_path = dir.join(format!("{stem}.svg"));
    let io = |p: &Path, e: std::io::Error| ViewError::Io(format!("{}: {e}", p.display()));
    write_png(fig, &png_path)?;
    std::fs::write(&svg_path, svg_string(fig)?).map_err(|e| io(&svg_path, e))?;
    Ok(vec![png_path, svg_path])
}

/// Tick label for a value on an axis spanning `span`: fixed decimals for ordinary spans,
/// scientific notation for very small or large ones.
pub fn fmt_tick(v: f64, span: f64) -> String {
    let span = span.abs();
    if v == 0.0 || v.abs() < 1e-9 * span {
        return "0".into();
    }
    if !(1e-3..1e6).contains(&span) {
        return format!("{v:.2e}");
    }
    let step = span / 5.0;
    let dec = (-step.log10().floor()).max(0.0) as usize;
    format!("{v:.dec$}")
}

/// A padded range around the values; never empty.
fn padded(lo: f64, hi: f64, frac: f64) -> (f64, f64) {
    if !lo.is_finite() || !hi.is_finite() {
        return (0.0, 1.0);
    }
    if hi - lo <= f64::EPSILON * hi.abs().max(lo.abs()).max(1e-300) {
        let d = if lo == 0.0 { 1.0 } else { 0.1 * lo.abs() };
        return (lo - d, hi + d);
    }
    let d = (hi - lo) * frac;
    (lo - d, hi + d)
}

/// Colours for successive curves.
const PALETTE: [RGBColor; 6] = [
    RGBColor(31, 119, 180),
    RGBColor(214, 39, 40),
    RGBColor(44, 160, 44),
    RGBColor(148, 103, 189),
    RGBColor(255, 127, 14),
    RGBColor(23, 190, 207),
];

/// One plotted curve (x, y) in the units of its columns.
#[derive(Debug, Clone)]
pub struct Series {
    /// Legend text.
    pub label: String,
    /// Points in file order.
    pub points: Vec<(f64, f64)>,
    /// Panel (one per y unit; 0 is the top one).
    pub panel: usize,
}

/// Curves against a common x axis, with optional reference markers.
#[derive(Debug, Clone)]
pub struct CurveFigure {
    /// Title.
    pub title: String,
    /// x-axis label with unit.
    pub x_label: String,
    /// y-axis label with unit (of the first panel).
    pub y_label: String,
    /// y-axis label of each panel (one panel per unit).
    pub y_labels: Vec<String>,
    /// Computed curves (lines with a dot at each converged increment).
    pub series: Vec<Series>,
    /// Reference points (hollow black circles).
    pub reference: Option<Series>,
}

impl Figure for CurveFigure {
    fn size(&self) -> (u32, u32) {
        (1000, 680 + 380 * (self.panels() as u32 - 1))
    }

    fn draw<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> DrawResult {
        let n = self.panels();
        let area = if n > 1 {
            title_area(root, &self.title)?
        } else {
            root.clone()
        };
        let cells = area.split_evenly((n, 1));
        for (p, cell) in cells.iter().enumerate() {
            self.draw_panel(cell, p, n == 1)?;
        }
        Ok(())
    }
}

impl CurveFigure {
    /// Number of panels (one per y unit).
    pub fn panels(&self) -> usize {
        self.y_labels.len().max(1)
    }

    /// Panel `p`: its series (and the reference on the first), the x axis shared.
    fn draw_panel<DB: DrawingBackend>(
        &self,
        root: &DrawingArea<DB, Shift>,
        p: usize,
        with_title: bool,
    ) -> DrawResult {
        let here = |s: &&Series| s.panel == p;
        let reference = self.reference.iter().filter(|_| p == 0);
        let xs = self
            .series
            .iter()
            .chain(self.reference.iter())
            .flat_map(|s| s.points.iter().map(|q| q.0))
            .filter(|x| x.is_finite());
        let (x_lo, x_hi) = xs.fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), x| {
            (a.min(x), b.max(x))
        });
        let all = self
            .series
            .iter()
            .filter(here)
            .chain(reference.clone())
            .flat_map(|s| s.points.iter().copied())
            .filter(|p| p.0.is_finite() && p.1.is_finite());
        let (lo, hi) = bounds(all.map(|(x, y)| [x, y]));
        let (x0, x1) = padded(x_lo, x_hi, 0.04);
        let (y0, y1) = padded(lo[1], hi[1], 0.06);
        let (dx, dy) = (label_step(x1 - x0, X_LABELS), label_step(y1 - y0, Y_LABELS));
        let mut b = ChartBuilder::on(root);
        if with_title {
            b.caption(&self.title, (FONT, 22));
        }
        let mut chart = b
            .margin(18)
            .x_label_area_size(55)
            .y_label_area_size(95)
            .build_cartesian_2d(x0..x1, y0..y1)
            .map_err(de)?;
        let label = self.y_labels.get(p).unwrap_or(&self.y_label);
        chart
            .configure_mesh()
            .x_desc(&self.x_label)
            .y_desc(label)
            .label_style((FONT, 15))
            .axis_desc_style((FONT, 17))
            .x_labels(X_LABELS)
            .y_labels(Y_LABELS)
            .x_label_formatter(&|v| tick_label(*v, dx))
            .y_label_formatter(&|v| tick_label(*v, dy))
            .light_line_style(RGBColor(235, 235, 235))
            .bold_line_style(RGBColor(205, 205, 205))
            .draw()
            .map_err(de)?;
        for (i, s) in self.series.iter().enumerate() {
            if s.panel != p {
                continue;
            }
            let c = PALETTE[i % PALETTE.len()];
            // A non-finite point breaks the line (a part of the girder not yet placed).
            let finite = |p: &(f64, f64)| p.0.is_finite() && p.1.is_finite();
            let runs = s.points.split(|p| !finite(p)).filter(|r| !r.is_empty());
            for (k, run) in runs.enumerate() {
                let drawn = chart
                    .draw_series(LineSeries::new(run.iter().copied(), c.stroke_width(2)))
                    .map_err(de)?;
                if k == 0 {
                    drawn.label(&s.label).legend(move |(x, y)| {
                        PathElement::new(vec![(x, y), (x + 24, y)], c.stroke_width(2))
                    });
                }
            }
            chart
                .draw_series(
                    s.points
                        .iter()
                        .filter(|p| finite(p))
                        .map(|&p| Circle::new(p, 3, c.filled())),
                )
                .map_err(de)?;
        }
        for r in reference.clone() {
            chart
                .draw_series(
                    r.points
                        .iter()
                        .map(|&p| Circle::new(p, 5, BLACK.stroke_width(2))),
                )
                .map_err(de)?
                .label(&r.label)
                .legend(|(x, y)| Circle::new((x + 12, y), 5, BLACK.stroke_width(2)));
        }
        let all: Vec<(f64, f64)> = self
            .series
            .iter()
            .filter(here)
            .chain(reference)
            .flat_map(|s| s.points.iter().copied())
            .collect();
        chart
            .configure_series_labels()
            .position(emptiest_corner(&all, (x0, x1), (y0, y1)))
            .background_style(WHITE.mix(0.85))
            .border_style(RGBColor(160, 160, 160))
            .label_font((FONT, 15))
            .draw()
            .map_err(de)?;
        Ok(())
    }
}

/// Most tick labels on the x axis of a curve.
const X_LABELS: usize = 8;
/// Most tick labels on the y axis of a curve.
const Y_LABELS: usize = 6;

/// The smallest tick spacing the plotting library can choose for at most `n` labels over
/// `span`: its spacings are 1, 2 or 5 × 10^k, so labels with the decimals of this one
/// never print two ticks alike.
pub fn label_step(span: f64, n: usize) -> f64 {
    let span = span.abs();
    if !(span > 0.0 && span.is_finite()) {
        return 1.0;
    }
    let mut k = 10f64.powf((span / n.max(1) as f64).log10().floor() - 1.0);
    loop {
        for m in [1.0, 2.0, 5.0] {
            if 1.0 + (span / (m * k)).floor() <= n as f64 {
                return m * k;
            }
        }
        k *= 10.0;
    }
}

/// Label of a tick at `v` on an axis whose ticks are at least `step` apart: the decimals
/// the step needs, scientific notation for very small or large values.
pub fn tick_label(v: f64, step: f64) -> String {
    let step = step.abs();
    if v == 0.0 || v.abs() < 1e-9 * step {
        return "0".into();
    }
    let m = v.abs().max(step);
    if !(1e-3..1e6).contains(&m) {
        // Mantissa digits enough to tell ticks apart.
        let d = ((m / step).log10().ceil().max(0.0) as usize).min(8);
        return format!("{v:.d$e}");
    }
    let dec = (-step.log10().floor()).max(0.0) as usize;
    format!("{v:.dec$}")
}

/// The labels of the ticks at every multiple of the smallest spacing [`label_step`] allows
/// on [lo, hi] with at most `n` labels (the densest the plotting library draws).
pub fn tick_labels(lo: f64, hi: f64, n: usize) -> Vec<String> {
    let step = label_step(hi - lo, n);
    let first = (lo / step).ceil() as i64;
    let last = (hi / step).floor() as i64;
    (first..=last)
        .map(|k| tick_label(k as f64 * step, step))
        .collect()
}

/// Outline of a cell as point indices in drawing order (mid-side nodes between corners);
/// line cells give an open polyline.
pub fn cell_outline(ty: u8, nodes: &[usize]) -> Vec<usize> {
    let pick = |ix: &[usize]| -> Vec<usize> {
        if ix.iter().all(|&i| i < nodes.len()) {
            ix.iter().map(|&i| nodes[i]).collect()
        } else {
            nodes.to_vec()
        }
    };
    match ty {
        9 => pick(&[0, 1, 2, 3]),
        23 | 28 => pick(&[0, 4, 1, 5, 2, 6, 3, 7]),
        5 => pick(&[0, 1, 2]),
        22 => pick(&[0, 3, 1, 4, 2, 5]),
        3 => pick(&[0, 1]),
        21 => pick(&[0, 2, 1]),
        _ => nodes.to_vec(),
    }
}

/// Boundary of the continuum cells: polylines (point indices) of edges used by one cell only.
pub fn boundary_edges(grid: &Grid) -> Vec<Vec<usize>> {
    use std::collections::HashMap;
    let mut count: HashMap<(usize, usize), (usize, Vec<usize>)> = HashMap::new();
    for (i, c) in grid.cells.iter().enumerate() {
        if grid.is_line(i) {
            continue;
        }
        let o = cell_outline(grid.types[i], c);
        let quadratic = matches!(grid.types[i], 22 | 23 | 28) && o.len() % 2 == 0;
        let step = if quadratic { 2 } else { 1 };
        let n = o.len();
        let mut k = 0;
        while k < n {
            let a = o[k];
            let b = o[(k + step) % n];
            let mut e: Vec<usize> = (0..=step).map(|j| o[(k + j) % n]).collect();
            let key = (a.min(b), a.max(b));
            if a > b {
                e.reverse();
            }
            count.entry(key).or_insert((0, e)).0 += 1;
            k += step;
        }
    }
    let mut out: Vec<Vec<usize>> = count
        .into_values()
        .filter(|(n, _)| *n == 1)
        .map(|(_, e)| e)
        .collect();
    out.sort();
    out
}

/// Plot area geometry for a drawing in model coordinates with equal scales: the figure
/// size and the (x, y) ranges that fill its plotting area.
struct Frame {
    size: (u32, u32),
    x: (f64, f64),
    y: (f64, f64),
}

const TITLE_H: u32 = 40;
/// Height of the legend strip under a mesh drawing [px].
const LEGEND_H: u32 = 28;
const MARGIN: u32 = 12;
const XLAB: u32 = 45;
const YLAB: u32 = 70;

/// Frame for a model box [lo, hi] [m] with `extra_h` pixels below (colour bar).
fn frame(lo: [f64; 2], hi: [f64; 2], extra_h: u32) -> Frame {
    let (x0, x1) = padded(lo[0], hi[0], 0.02);
    let (y0, y1) = padded(lo[1], hi[1], 0.05);
    let (dx, dy) = (x1 - x0, y1 - y0);
    let max_w = 1300.0;
    let max_h = 620.0;
    let ppm = (max_w / dx).min(max_h / dy);
    let pw = (dx * ppm).max(320.0);
    let ph = (dy * ppm).max(90.0);
    // Widen the ranges so that both axes keep the same metres per pixel.
    let ppm = (pw / dx).min(ph / dy);
    let (cx, cy) = (0.5 * (x0 + x1), 0.5 * (y0 + y1));
    let (hx, hy) = (0.5 * pw / ppm, 0.5 * ph / ppm);
    Frame {
        size: (
            pw as u32 + 2 * MARGIN + YLAB,
            ph as u32 + TITLE_H + 2 * MARGIN + XLAB + extra_h,
        ),
        x: (cx - hx, cx + hx),
        y: (cy - hy, cy + hy),
    }
}

macro_rules! model_chart {
    ($area:expr, $f:expr) => {{
        let mut chart = ChartBuilder::on($area)
            .margin(MARGIN)
            .x_label_area_size(XLAB)
            .y_label_area_size(YLAB)
            .build_cartesian_2d($f.x.0..$f.x.1, $f.y.0..$f.y.1)
            .map_err(de)?;
        let (sx, sy) = ($f.x.1 - $f.x.0, $f.y.1 - $f.y.0);
        chart
            .configure_mesh()
            .disable_mesh()
            .x_desc("x [m]")
            .y_desc("y [m]")
            .label_style((FONT, 14))
            .axis_desc_style((FONT, 15))
            .x_label_formatter(&|v| tick_label(*v, label_step(sx, 12)))
            .y_label_formatter(&|v| tick_label(*v, label_step(sy, 6)))
            .x_labels(12)
            .y_labels(6)
            .draw()
            .map_err(de)?;
        chart
    }};
}

/// Height of a title band [px]: [`TITLE_H`] for one line, 24 px more per further line
/// (a title's lines are separated by `\n`; a note under the title, such as the joints
/// hidden, gets its own line rather than running off the edge).
fn title_h(title: &str) -> u32 {
    TITLE_H + TITLE_LINE_H * (title.lines().count().max(1) as u32 - 1)
}

/// Height of each further title line [px].
const TITLE_LINE_H: u32 = 24;

fn title_area<DB: DrawingBackend>(
    root: &DrawingArea<DB, Shift>,
    title: &str,
) -> Result<DrawingArea<DB, Shift>, String> {
    let (top, rest) = root.split_vertically(title_h(title));
    let (w, _) = top.dim_in_pixel();
    for (i, line) in title.lines().enumerate() {
        // The first line as before; further lines smaller, one below the other.
        let (size, y) = if i == 0 {
            (20, TITLE_H as i32 / 2 + 4)
        } else {
            (16, (TITLE_H + TITLE_LINE_H * i as u32) as i32 - 6)
        };
        let style =
            TextStyle::from((FONT, size).into_font()).pos(Pos::new(HPos::Center, VPos::Center));
        top.draw(&Text::new(line.to_string(), (w as i32 / 2, y), style))
            .map_err(de)?;
    }
    Ok(rest)
}

/// Colour of tendon spans in the mesh figure (dark green: apart from the red joints and
/// the pastel regions).
const TENDON: RGBColor = RGBColor(0, 120, 60);

/// Pastel fill colours for regions.
const REGION_FILL: [RGBColor; 6] = [
    RGBColor(190, 210, 235),
    RGBColor(235, 215, 180),
    RGBColor(200, 230, 200),
    RGBColor(230, 200, 225),
    RGBColor(240, 235, 190),
    RGBColor(205, 205, 205),
];

fn pts(grid: &Grid, idx: &[usize], disp: Option<&[[f64; 2]]>, scale: f64) -> Vec<(f64, f64)> {
    idx.iter()
        .map(|&i| {
            let p = grid.points[i];
            match disp {
                Some(u) => (p[0] + scale * u[i][0], p[1] + scale * u[i][1]),
                None => (p[0], p[1]),
            }
        })
        .collect()
}

/// The undeformed mesh, cells filled by region (a legend names each region's colour); line
/// cells of the grid (joints) in red, tendon spans in dark green over them.
pub struct MeshFigure<'g> {
    /// Grid.
    pub grid: &'g Grid,
    /// Region names by index (summary.json `regions`); `region k` where missing.
    pub regions: Vec<String>,
    /// Tendon spans, each from one end (x, y) [m] to the other ([`Output::tendon_spans`]).
    ///
    /// [`Output::tendon_spans`]: super::data::Output::tendon_spans
    pub tendons: Vec<[[f64; 2]; 2]>,
    /// Title.
    pub title: String,
}

impl Figure for MeshFigure<'_> {
    fn size(&self) -> (u32, u32) {
        let (lo, hi) = self.grid.bounds();
        let w = frame(lo, hi, 0).size.0;
        let rows = legend_rows(&self.legend_entries(), w);
        frame(lo, hi, LEGEND_H * rows.max(1) as u32).size
    }

    fn draw<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> DrawResult {
        let g = self.grid;
        let (lo, hi) = g.bounds();
        let entries = self.legend_entries();
        let w = frame(lo, hi, 0).size.0;
        let layout = legend_layout(&entries, w);
        let rows = layout.iter().map(|p| p.0 + 1).max().unwrap_or(1);
        let legend_h = LEGEND_H * rows as u32;
        let f = frame(lo, hi, legend_h);
        let area = title_area(root, &self.title)?;
        let (_, h) = area.dim_in_pixel();
        let (area, strip) = area.split_vertically(h.saturating_sub(legend_h));
        let mut chart = model_chart!(&area, f);
        let region = g.cell_array("region");
        let colour_of = region_colours(&self.regions);
        let edge = RGBColor(90, 90, 90);
        for (i, c) in g.cells.iter().enumerate() {
            let o = pts(g, &cell_outline(g.types[i], c), None, 0.0);
            if g.is_line(i) {
                chart
                    .draw_series(std::iter::once(PathElement::new(o, RED.stroke_width(2))))
                    .map_err(de)?;
                continue;
            }
            let r = region.map_or(0, |a| a.get(i, 0).max(0.0) as usize);
            let fill = colour_of.get(r).copied().unwrap_or(r);
            let mut closed = o.clone();
            closed.push(o[0]);
            chart
                .draw_series([
                    Polygon::new(o, REGION_FILL[fill % REGION_FILL.len()].filled()).into_dyn(),
                    PathElement::new(closed, edge.stroke_width(1)).into_dyn(),
                ])
                .map_err(de)?;
        }
        // Tendons last, over the cells and joints they cross.
        chart
            .draw_series(self.tendons.iter().map(|t| {
                PathElement::new(
                    vec![(t[0][0], t[0][1]), (t[1][0], t[1][1])],
                    TENDON.stroke_width(2),
                )
            }))
            .map_err(de)?;
        // The legend, in a strip below the drawing (never over the mesh), wrapped into as
        // many rows as it needs: a swatch per region group present, and the line cells.
        let style = TextStyle::from((FONT, 14).into_font()).pos(Pos::new(HPos::Left, VPos::Center));
        for ((name, c, line), (row, x)) in entries.into_iter().zip(layout) {
            let y = (LEGEND_H / 2 + LEGEND_H * row as u32) as i32;
            if line {
                strip
                    .draw(&PathElement::new(
                        vec![(x, y), (x + 18, y)],
                        c.stroke_width(2),
                    ))
                    .map_err(de)?;
            } else {
                strip
                    .draw(&Rectangle::new([(x, y - 6), (x + 18, y + 6)], c.filled()))
                    .map_err(de)?;
                strip
                    .draw(&Rectangle::new(
                        [(x, y - 6), (x + 18, y + 6)],
                        RGBColor(90, 90, 90),
                    ))
                    .map_err(de)?;
            }
            strip
                .draw(&Text::new(name, (x + 24, y), style.clone()))
                .map_err(de)?;
        }
        Ok(())
    }
}

impl MeshFigure<'_> {
    /// Legend entries: (label, colour, drawn as a line rather than a swatch).
    fn legend_entries(&self) -> Vec<(String, RGBColor, bool)> {
        let g = self.grid;
        let mut entries: Vec<(String, RGBColor, bool)> = region_legend(g, &self.regions)
            .into_iter()
            .map(|(r, name)| (name, REGION_FILL[r % REGION_FILL.len()], false))
            .collect();
        if (0..g.cells.len()).any(|i| g.is_line(i)) {
            entries.push(("joints".into(), RED, true));
        }
        if !self.tendons.is_empty() {
            entries.push(("tendons".into(), TENDON, true));
        }
        entries
    }
}

/// Width of a legend entry [px]: swatch, gap, label (8 px a character at 14 px, a little
/// more than DejaVu Sans needs, so labels never touch), gap.
fn legend_entry_w(name: &str) -> i32 {
    24 + 8 * name.chars().count() as i32 + 24
}

/// Legend entries placed left to right from the plot's left edge, wrapped to a new row
/// when the next would pass the figure's right edge `width` [px]: (row, x) per entry.
fn legend_layout(entries: &[(String, RGBColor, bool)], width: u32) -> Vec<(usize, i32)> {
    let x0 = (MARGIN + YLAB) as i32;
    let right = width as i32 - MARGIN as i32;
    let (mut row, mut x) = (0, x0);
    entries
        .iter()
        .map(|(name, _, _)| {
            let w = legend_entry_w(name);
            if x > x0 && x + w - 24 > right {
                row += 1;
                x = x0;
            }
            let at = (row, x);
            x += w;
            at
        })
        .collect()
}

/// Number of legend rows for `entries` in a figure `width` px wide.
fn legend_rows(entries: &[(String, RGBColor, bool)], width: u32) -> usize {
    legend_layout(entries, width).last().map_or(1, |p| p.0 + 1)
}

/// The base name of a region: the part before `@` of a staged copy (`webs@S13` → `webs`;
/// the construction-stage generator names the copy of region R for segment S `R@S`).
pub fn region_base(name: &str) -> &str {
    name.split_once('@').map_or(name, |(b, _)| b)
}

/// Colour index of each region (by region index): regions that share a base name
/// ([`region_base`]) share a colour, numbered in the order base names first appear.
pub fn region_colours(names: &[String]) -> Vec<usize> {
    let mut bases: Vec<&str> = Vec::new();
    names
        .iter()
        .map(|n| {
            let b = region_base(n);
            match bases.iter().position(|x| *x == b) {
                Some(k) => k,
                None => {
                    bases.push(b);
                    bases.len() - 1
                }
            }
        })
        .collect()
}

/// The legend entries of a mesh figure: (colour index, label) for each group of regions
/// some cell belongs to. Regions that are staged copies of one region (`webs`, `webs@S1`,
/// `webs@S2`, …) form one group under the base name, labelled `webs (N regions)` when
/// more than one of them is present; groups in the order their base names first appear.
/// Regions without a name are `region k`, each its own group.
pub fn region_legend(g: &Grid, names: &[String]) -> Vec<(usize, String)> {
    let Some(region) = g.cell_array("region") else {
        return Vec::new();
    };
    let mut present: Vec<usize> = (0..g.cells.len())
        .filter(|&i| !g.is_line(i))
        .map(|i| region.get(i, 0).max(0.0) as usize)
        .collect();
    present.sort_unstable();
    present.dedup();
    let colours = region_colours(names);
    // (colour index, base name, regions present)
    let mut groups: Vec<(usize, String, usize)> = Vec::new();
    for r in present {
        let (colour, base) = match names.get(r) {
            Some(n) => (colours[r], region_base(n).to_string()),
            // Unnamed: its own group, coloured by its index as before.
            None => (r, format!("region {r}")),
        };
        match groups.iter_mut().find(|gr| gr.1 == base) {
            Some(gr) => gr.2 += 1,
            None => groups.push((colour, base, 1)),
        }
    }
    groups.sort_by_key(|gr| gr.0);
    groups
        .into_iter()
        .map(|(c, base, n)| {
            let label = if n > 1 {
                format!("{base} ({n} regions)")
            } else {
                base
            };
            (c, label)
        })
        .collect()
}

/// Magnification for a deformed shape: the largest displacement drawn as 5 % of the model
/// size (the larger side of the bounding box).
pub fn auto_scale(grid: &Grid, disp: &[[f64; 2]]) -> f64 {
    let (lo, hi) = grid.bounds();
    let size = (hi[0] - lo[0]).max(hi[1] - lo[1]);
    let umax = disp.iter().map(|u| u[0].hypot(u[1])).fold(0.0, f64::max);
    if umax > 0.0 && size > 0.0 {
        0.05 * size / umax
    } else {
        1.0
    }
}

/// The deformed mesh (blue) magnified by `scale`, over the undeformed outline (grey).
pub struct DeformedFigure<'g> {
    /// Grid.
    pub grid: &'g Grid,
    /// Nodal displacements (ux, uy) [m].
    pub disp: Vec<[f64; 2]>,
    /// Magnification [-].
    pub scale: f64,
    /// Title.
    pub title: String,
}

impl Figure for DeformedFigure<'_> {
    fn size(&self) -> (u32, u32) {
        self.frame().size
    }

    fn draw<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> DrawResult {
        let g = self.grid;
        let f = self.frame();
        let area = title_area(root, &self.title)?;
        let mut chart = model_chart!(&area, f);
        let grey = RGBColor(150, 150, 150);
        for e in boundary_edges(g) {
            chart
                .draw_series(std::iter::once(PathElement::new(
                    pts(g, &e, None, 0.0),
                    grey.stroke_width(2),
                )))
                .map_err(de)?;
        }
        let blue = RGBColor(31, 90, 180);
        for (i, c) in g.cells.iter().enumerate() {
            let mut o = cell_outline(g.types[i], c);
            let colour = if g.is_line(i) {
                RED.stroke_width(2)
            } else {
                o.push(o[0]);
                blue.stroke_width(1)
            };
            chart
                .draw_series(std::iter::once(PathElement::new(
                    pts(g, &o, Some(&self.disp), self.scale),
                    colour,
                )))
                .map_err(de)?;
        }
        Ok(())
    }
}

impl DeformedFigure<'_> {
    fn frame(&self) -> Frame {
        let g = self.grid;
        let def = (0..g.points.len()).map(|i| {
            [
                g.points[i][0] + self.scale * self.disp[i][0],
                g.points[i][1] + self.scale * self.disp[i][1],
            ]
        });
        let (lo, hi) = bounds(g.points.iter().copied().chain(def));
        frame(lo, hi, 0)
    }
}

/// Diverging colour map: blue (most negative) – white (zero) – red (most positive); each
/// side is scaled to its own extreme so that zero stays white.
pub fn colour(v: f64, lo: f64, hi: f64) -> RGBColor {
    let neg = RGBColor(33, 102, 172);
    let mid = RGBColor(247, 247, 247);
    let pos = RGBColor(178, 24, 43);
    let (t, a, b) = if lo >= 0.0 {
        // All non-negative: white at lo to red at hi.
        ((v - lo) / (hi - lo).max(1e-300), mid, pos)
    } else if hi <= 0.0 {
        ((v - lo) / (hi - lo).max(1e-300), neg, mid)
    } else if v < 0.0 {
        (1.0 - v / lo, neg, mid)
    } else {
        (v / hi, mid, pos)
    };
    let t = t.clamp(0.0, 1.0);
    let l = |x: u8, y: u8| (x as f64 + t * (y as f64 - x as f64)).round() as u8;
    RGBColor(l(a.0, b.0), l(a.1, b.1), l(a.2, b.2))
}

/// Shape functions of a cell at natural coordinates (ξ, η) ∈ [−1, 1]², VTK node order;
/// `None` for cells that are not Q4/Q8/Q9/T6. A 6-node triangle (VTK 22) is reached through
/// the collapsed square: area coordinates L₂ = (1 + ξ)(1 − η)/4, L₃ = (1 + η)/2 (the side
/// η = 1 of the square is its third corner).
fn shape(ty: u8, xi: f64, eta: f64) -> Option<Vec<f64>> {
    let c = [(-1.0, -1.0), (1.0, -1.0), (1.0, 1.0), (-1.0, 1.0)];
    match ty {
        22 => {
            let l2 = 0.25 * (1.0 + xi) * (1.0 - eta);
            let l3 = 0.5 * (1.0 + eta);
            let l1 = 1.0 - l2 - l3;
            Some(vec![
                l1 * (2.0 * l1 - 1.0),
                l2 * (2.0 * l2 - 1.0),
                l3 * (2.0 * l3 - 1.0),
                4.0 * l1 * l2,
                4.0 * l2 * l3,
                4.0 * l3 * l1,
            ])
        }
        9 => Some(
            c.iter()
                .map(|&(a, b)| 0.25 * (1.0 + a * xi) * (1.0 + b * eta))
                .collect(),
        ),
        23 => {
            let mut n: Vec<f64> = c
                .iter()
                .map(|&(a, b)| 0.25 * (1.0 + a * xi) * (1.0 + b * eta) * (a * xi + b * eta - 1.0))
                .collect();
            n.push(0.5 * (1.0 - xi * xi) * (1.0 - eta));
            n.push(0.5 * (1.0 + xi) * (1.0 - eta * eta));
            n.push(0.5 * (1.0 - xi * xi) * (1.0 + eta));
            n.push(0.5 * (1.0 - xi) * (1.0 - eta * eta));
            Some(n)
        }
        28 => {
            let l = |s: f64, k: i32| match k {
                -1 => 0.5 * s * (s - 1.0),
                0 => 1.0 - s * s,
                _ => 0.5 * s * (s + 1.0),
            };
            let ix = [
                (-1, -1),
                (1, -1),
                (1, 1),
                (-1, 1),
                (0, -1),
                (1, 0),
                (0, 1),
                (-1, 0),
                (0, 0),
            ];
            Some(ix.iter().map(|&(a, b)| l(xi, a) * l(eta, b)).collect())
        }
        _ => None,
    }
}

/// A scalar field to map.
#[derive(Debug, Clone)]
pub enum FieldValues {
    /// One value per point (smoothed nodal values), interpolated inside cells.
    Nodal(Vec<f64>),
    /// One value per cell, drawn flat.
    Cell(Vec<f64>),
}

/// A colour map of a scalar field over the continuum cells, with a colour bar.
pub struct ContourFigure<'g> {
    /// Grid.
    pub grid: &'g Grid,
    /// Values in display units (e.g. MPa).
    pub values: FieldValues,
    /// Colour bar label with unit, e.g. `σx [MPa]`.
    pub label: String,
    /// Title.
    pub title: String,
}

const BAR_H: u32 = 80;

impl ContourFigure<'_> {
    /// Range of the values drawn (min, max).
    pub fn range(&self) -> (f64, f64) {
        let v = match &self.values {
            FieldValues::Nodal(v) | FieldValues::Cell(v) => v,
        };
        let lo = v
            .iter()
            .copied()
            .filter(|x| x.is_finite())
            .fold(f64::INFINITY, f64::min);
        let hi = v
            .iter()
            .copied()
            .filter(|x| x.is_finite())
            .fold(f64::NEG_INFINITY, f64::max);
        if lo.is_finite() {
            (lo, hi)
        } else {
            (0.0, 0.0)
        }
    }

    /// Colour polygons: (outline in model coordinates, value).
    fn patches(&self) -> Vec<(Vec<(f64, f64)>, f64)> {
        let g = self.grid;
        let ncont = (0..g.cells.len()).filter(|&i| !g.is_line(i)).count().max(1);
        let n = ((40_000.0 / ncont as f64).sqrt().floor() as usize).clamp(1, 4);
        let mut out = Vec::new();
        for (i, c) in g.cells.iter().enumerate() {
            if g.is_line(i) {
                continue;
            }
            let outline = pts(g, &cell_outline(g.types[i], c), None, 0.0);
            match &self.values {
                FieldValues::Cell(v) => out.push((outline, v[i])),
                FieldValues::Nodal(v) => {
                    let ok = shape(g.types[i], 0.0, 0.0).filter(|s| s.len() == c.len());
                    if ok.is_none() || n == 1 && g.types[i] == 9 {
                        let mean = c.iter().map(|&k| v[k]).sum::<f64>() / c.len() as f64;
                        out.push((outline, mean));
                        continue;
                    }
                    let at = |xi: f64, eta: f64| -> ((f64, f64), f64) {
                        let s = shape(g.types[i], xi, eta).expect("checked");
                        let mut p = (0.0, 0.0);
                        let mut val = 0.0;
                        for (k, &node) in c.iter().enumerate() {
                            p.0 += s[k] * g.points[node][0];
                            p.1 += s[k] * g.points[node][1];
                            val += s[k] * v[node];
                        }
                        (p, val)
                    };
                    let h = 2.0 / n as f64;
                    for a in 0..n {
                        for b in 0..n {
                            let (x0, y0) = (-1.0 + a as f64 * h, -1.0 + b as f64 * h);
                            let corners = [
                                at(x0, y0),
                                at(x0 + h, y0),
                                at(x0 + h, y0 + h),
                                at(x0, y0 + h),
                            ];
                            let val = corners.iter().map(|c| c.1).sum::<f64>() / 4.0;
                            out.push((corners.iter().map(|c| c.0).collect(), val));
                        }
                    }
                }
            }
        }
        out
    }
}

impl Figure for ContourFigure<'_> {
    fn size(&self) -> (u32, u32) {
        let (lo, hi) = self.grid.bounds();
        frame(lo, hi, BAR_H).size
    }

    fn draw<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> DrawResult {
        let g = self.grid;
        let (lo, hi) = g.bounds();
        let f = frame(lo, hi, BAR_H);
        let area = title_area(root, &self.title)?;
        let (_, h) = area.dim_in_pixel();
        let (main, bar) = area.split_vertically(h - BAR_H);
        let mut chart = model_chart!(&main, f);
        let (vlo, vhi) = self.range();
        chart
            .draw_series(self.patches().into_iter().map(|(p, v)| {
                let c = colour(v, vlo, vhi);
                Polygon::new(p, c.filled())
            }))
            .map_err(de)?;
        let edge = RGBColor(60, 60, 60).mix(0.35);
        for (i, c) in g.cells.iter().enumerate() {
            let mut o = cell_outline(g.types[i], c);
            if !g.is_line(i) {
                o.push(o[0]);
            }
            chart
                .draw_series(std::iter::once(PathElement::new(
                    pts(g, &o, None, 0.0),
                    edge,
                )))
                .map_err(de)?;
        }
        colour_bar(&bar, vlo, vhi, &self.label)
    }
}

/// A horizontal colour bar with ticks and a label, in the strip `area`.
fn colour_bar<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    lo: f64,
    hi: f64,
    label: &str,
) -> DrawResult {
    let (w, _) = area.dim_in_pixel();
    let (x0, x1) = ((MARGIN + YLAB) as i32, w as i32 - MARGIN as i32 - 150);
    let (y0, y1) = (8, 30);
    let (lo_d, hi_d) = if hi > lo {
        (lo, hi)
    } else {
        (lo - 1.0, hi + 1.0)
    };
    let n = (x1 - x0).max(1);
    for k in 0..n {
        let v = lo_d + (hi_d - lo_d) * (k as f64 + 0.5) / n as f64;
        area.draw(&Rectangle::new(
            [(x0 + k, y0), (x0 + k + 1, y1)],
            colour(v, lo, hi).filled(),
        ))
        .map_err(de)?;
    }
    area.draw(&Rectangle::new([(x0, y0), (x1, y1)], BLACK.stroke_width(1)))
        .map_err(de)?;
    let ticks = nice_ticks(lo_d, hi_d, 7);
    let span = hi_d - lo_d;
    let ts = TextStyle::from((FONT, 14).into_font()).pos(Pos::new(HPos::Center, VPos::Top));
    for t in ticks {
        let x = x0 + ((t - lo_d) / span * (x1 - x0) as f64).round() as i32;
        area.draw(&PathElement::new(vec![(x, y1), (x, y1 + 5)], BLACK))
            .map_err(de)?;
        area.draw(&Text::new(fmt_tick(t, span), (x, y1 + 7), ts.clone()))
            .map_err(de)?;
    }
    let ls = TextStyle::from((FONT, 16).into_font()).pos(Pos::new(HPos::Left, VPos::Center));
    area.draw(&Text::new(label.to_string(), (x1 + 12, (y0 + y1) / 2), ls))
        .map_err(de)?;
    let ms = TextStyle::from((FONT, 13).into_font()).pos(Pos::new(HPos::Left, VPos::Top));
    area.draw(&Text::new(
        format!("min {} / max {}", sig4(lo), sig4(hi)),
        (x1 + 12, y1 + 7),
        ms,
    ))
    .map_err(de)?;
    Ok(())
}

/// A value with 4 significant digits.
pub fn sig4(v: f64) -> String {
    if v == 0.0 || !v.is_finite() {
        return format!("{v}");
    }
    if (1e-3..1e5).contains(&v.abs()) {
        let d = (3 - v.abs().log10().floor() as i32).clamp(0, 6) as usize;
        format!("{v:.d$}")
    } else {
        format!("{v:.3e}")
    }
}

/// The corner of the data box holding the fewest points (for the legend).
fn emptiest_corner(points: &[(f64, f64)], x: (f64, f64), y: (f64, f64)) -> SeriesLabelPosition {
    let mut n = [0usize; 4];
    for &(px, py) in points {
        let right = px > 0.5 * (x.0 + x.1);
        let top = py > 0.5 * (y.0 + y.1);
        n[(top as usize) * 2 + right as usize] += 1;
    }
    let order = [
        (n[2], SeriesLabelPosition::UpperLeft),
        (n[3], SeriesLabelPosition::UpperRight),
        (n[0], SeriesLabelPosition::LowerLeft),
        (n[1], SeriesLabelPosition::LowerRight),
    ];
    order
        .into_iter()
        .min_by_key(|o| o.0)
        .map(|o| o.1)
        .unwrap_or(SeriesLabelPosition::UpperLeft)
}

/// About `n` round tick values inside [lo, hi].
pub fn nice_ticks(lo: f64, hi: f64, n: usize) -> Vec<f64> {
    let raw = (hi - lo) / n.max(1) as f64;
    if raw <= 0.0 || !raw.is_finite() {
        return vec![lo];
    }
    let mag = 10f64.powf(raw.log10().floor());
    let step = [1.0, 2.0, 2.5, 5.0, 10.0]
        .iter()
        .map(|m| m * mag)
        .find(|s| *s >= raw)
        .unwrap_or(10.0 * mag);
    let mut t = (lo / step).ceil() * step;
    let mut out = Vec::new();
    while t <= hi + 1e-9 * step {
        out.push(if t.abs() < 1e-12 * step { 0.0 } else { t });
        t += step;
    }
    out
}

/// Crack pattern: a short line per cracked cell along the crack, over the mesh outline.
pub struct CrackFigure<'g> {
    /// Grid.
    pub grid: &'g Grid,
    /// Per cell: (crack angle from the x axis [rad], number of cracks).
    pub cracks: Vec<(f64, usize)>,
    /// Title.
    pub title: String,
}

impl Figure for CrackFigure<'_> {
    fn size(&self) -> (u32, u32) {
        let (lo, hi) = self.grid.bounds();
        frame(lo, hi, 0).size
    }

    fn draw<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> DrawResult {
        let g = self.grid;
        let (lo, hi) = g.bounds();
        let f = frame(lo, hi, 0);
        let area = title_area(root, &self.title)?;
        let mut chart = model_chart!(&area, f);
        let light = RGBColor(215, 215, 215);
        for (i, c) in g.cells.iter().enumerate() {
            let mut o = cell_outline(g.types[i], c);
            if !g.is_line(i) {
                o.push(o[0]);
            }
            chart
                .draw_series(std::iter::once(PathElement::new(
                    pts(g, &o, None, 0.0),
                    light,
                )))
                .map_err(de)?;
        }
        for e in boundary_edges(g) {
            chart
                .draw_series(std::iter::once(PathElement::new(
                    pts(g, &e, None, 0.0),
                    RGBColor(110, 110, 110).stroke_width(2),
                )))
                .map_err(de)?;
        }
        let red = RGBColor(200, 20, 20);
        for (i, c) in g.cells.iter().enumerate() {
            let (angle, n) = self.cracks[i];
            if n == 0 || g.is_line(i) || !angle.is_finite() {
                continue;
            }
            let o = pts(g, &cell_outline(g.types[i], c), None, 0.0);
            let m = o.len() as f64;
            let cx = o.iter().map(|p| p.0).sum::<f64>() / m;
            let cy = o.iter().map(|p| p.1).sum::<f64>() / m;
            let (blo, bhi) = bounds(o.iter().map(|p| [p.0, p.1]));
            let half = 0.35 * (bhi[0] - blo[0]).min(bhi[1] - blo[1]);
            for k in 0..n.min(2) {
                let a = angle + k as f64 * std::f64::consts::FRAC_PI_2;
                let (dx, dy) = (half * a.cos(), half * a.sin());
                chart
                    .draw_series(std::iter::once(PathElement::new(
                        vec![(cx - dx, cy - dy), (cx + dx, cy + dy)],
                        red.stroke_width(2),
                    )))
                    .map_err(de)?;
            }
        }
        Ok(())
    }
}

/// Profile of one joint along its height.
#[derive(Debug, Clone)]
pub struct JointProfile {
    /// Joint name (e.g. `joint 1 (x = 2.400 m)`).
    pub name: String,
    /// Points (y [m], opening [mm], normal stress [MPa] or NaN when absent), by height.
    pub points: Vec<(f64, f64, f64)>,
}

/// Joint diagrams: per joint, opening and normal stress against the height.
pub struct JointFigure {
    /// Joints.
    pub joints: Vec<JointProfile>,
    /// Title.
    pub title: String,
}

const JOINT_ROW_H: u32 = 260;

impl Figure for JointFigure {
    fn size(&self) -> (u32, u32) {
        (
            1000,
            title_h(&self.title) + JOINT_ROW_H * self.joints.len().max(1) as u32,
        )
    }

    fn draw<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> DrawResult {
        let area = title_area(root, &self.title)?;
        let rows = area.split_evenly((self.joints.len().max(1), 2));
        for (j, joint) in self.joints.iter().enumerate() {
            for (k, (what, colour)) in [
                ("opening [mm]", RGBColor(200, 20, 20)),
                ("normal stress [MPa]", RGBColor(31, 90, 180)),
            ]
            .into_iter()
            .enumerate()
            {
                let cell = &rows[2 * j + k];
                let data: Vec<(f64, f64)> = joint
                    .points
                    .iter()
                    .map(|p| (if k == 0 { p.1 } else { p.2 }, p.0))
                    .filter(|p| p.0.is_finite())
                    .collect();
                let (lo, hi) = bounds(data.iter().map(|p| [p.0, p.1]));
                let (x0, x1) = padded(lo[0].min(0.0), hi[0].max(0.0), 0.08);
                let (y0, y1) = padded(lo[1], hi[1], 0.05);
                let mut chart = ChartBuilder::on(cell)
                    .caption(format!("{}: {what}", joint.name), (FONT, 15))
                    .margin(10)
                    .x_label_area_size(40)
                    .y_label_area_size(60)
                    .build_cartesian_2d(x0..x1, y0..y1)
                    .map_err(de)?;
                let (sx, sy) = (x1 - x0, y1 - y0);
                chart
                    .configure_mesh()
                    .x_desc(what)
                    .y_desc("y [m]")
                    .label_style((FONT, 12))
                    .axis_desc_style((FONT, 13))
                    .x_labels(6)
                    .y_labels(6)
                    .x_label_formatter(&|v| tick_label(*v, label_step(sx, 6)))
                    .y_label_formatter(&|v| tick_label(*v, label_step(sy, 6)))
                    .light_line_style(RGBColor(240, 240, 240))
                    .draw()
                    .map_err(de)?;
                if data.is_empty() {
                    continue;
                }
                chart
                    .draw_series(std::iter::once(PathElement::new(
                        vec![(0.0, y0), (0.0, y1)],
                        BLACK.stroke_width(1),
                    )))
                    .map_err(de)?;
                let mut poly = vec![(0.0, data[0].1)];
                poly.extend(data.iter().copied());
                poly.push((0.0, data[data.len() - 1].1));
                chart
                    .draw_series(std::iter::once(Polygon::new(
                        poly,
                        colour.mix(0.25).filled(),
                    )))
                    .map_err(de)?;
                chart
                    .draw_series(LineSeries::new(data, colour.stroke_width(2)))
                    .map_err(de)?;
            }
        }
        Ok(())
    }
}

/// One construction stage in the stage-history figure.
#[derive(Debug, Clone, PartialEq)]
pub struct StageBand {
    /// Step number (1-based).
    pub step: usize,
    /// Step name.
    pub name: String,
    /// First and last history.csv data row of the stage (1-based).
    pub rows: (usize, usize),
    /// Largest joint opening during the stage [mm].
    pub opening_mm: f64,
}

/// The stage history of a staged run: per stage, a bar over its history rows as high as
/// the largest joint opening reached during it, the stage boundaries marked and labelled
/// with the stage names.
#[derive(Debug, Clone)]
pub struct StageFigure {
    /// Title.
    pub title: String,
    /// Stages that produced history rows, in order.
    pub stages: Vec<StageBand>,
}

impl StageFigure {
    /// The figure of `stages` (summary.json `stages`); None when no stage produced a
    /// history row (nothing to draw).
    pub fn new(stages: &[crate::results::stages::StageResult]) -> Option<Self> {
        let bands: Vec<StageBand> = stages
            .iter()
            .filter_map(|s| {
                s.history_rows.map(|rows| StageBand {
                    step: s.step,
                    name: s.name.clone(),
                    rows,
                    opening_mm: s.max_joint_opening * 1e3,
                })
            })
            .collect();
        (!bands.is_empty()).then(|| StageFigure {
            title: "Construction stages: largest joint opening per stage".into(),
            stages: bands,
        })
    }
}

impl Figure for StageFigure {
    fn size(&self) -> (u32, u32) {
        (1000, 560)
    }

    fn draw<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> DrawResult {
        // Each history row is a unit-wide slot centred on its number.
        let x0 = self.stages.iter().map(|s| s.rows.0).min().unwrap_or(1) as f64 - 0.5;
        let x1 = self.stages.iter().map(|s| s.rows.1).max().unwrap_or(1) as f64 + 0.5;
        let top = self
            .stages
            .iter()
            .map(|s| s.opening_mm)
            .filter(|v| v.is_finite())
            .fold(0.0, f64::max);
        // Room above the tallest bar for the stage names; 1 mm when no joint opens.
        let y1 = if top > 0.0 { top * 1.5 } else { 1.0 };
        let (dx, dy) = (label_step(x1 - x0, X_LABELS), label_step(y1, Y_LABELS));
        let mut chart = ChartBuilder::on(root)
            .caption(&self.title, (FONT, 22))
            .margin(18)
            .x_label_area_size(55)
            .y_label_area_size(95)
            .build_cartesian_2d(x0..x1, 0.0..y1)
            .map_err(de)?;
        chart
            .configure_mesh()
            .x_desc("history row")
            .y_desc("largest joint opening [mm]")
            .label_style((FONT, 15))
            .axis_desc_style((FONT, 17))
            .x_labels(X_LABELS)
            .y_labels(Y_LABELS)
            .x_label_formatter(&|v| tick_label(*v, dx))
            .y_label_formatter(&|v| tick_label(*v, dy))
            .disable_x_mesh()
            .light_line_style(RGBColor(235, 235, 235))
            .bold_line_style(RGBColor(205, 205, 205))
            .draw()
            .map_err(de)?;
        let name_style = TextStyle::from((FONT, 12).into_font())
            .transform(FontTransform::Rotate90)
            .color(&RGBColor(60, 60, 60));
        for (i, s) in self.stages.iter().enumerate() {
            let (a, b) = (s.rows.0 as f64 - 0.5, s.rows.1 as f64 + 0.5);
            let c = PALETTE[i % PALETTE.len()];
            chart
                .draw_series(std::iter::once(Rectangle::new(
                    [(a, 0.0), (b, s.opening_mm.max(0.0))],
                    c.mix(0.45).filled(),
                )))
                .map_err(de)?;
            chart
                .draw_series(std::iter::once(PathElement::new(
                    vec![(a, 0.0), (a, y1)],
                    RGBColor(150, 150, 150).stroke_width(1),
                )))
                .map_err(de)?;
            let (px, py) = chart.backend_coord(&(0.5 * (a + b), y1));
            root.draw(&Text::new(
                format!("{} {}", s.step, s.name),
                (px + 6, py + 6),
                name_style.clone(),
            ))
            .map_err(de)?;
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The T6 cell's shape functions through the collapsed square are the quadratic
    /// triangle's: 1 at their own node's image and 0 at the others (Kronecker), summing to 1.
    #[test]
    fn t6_cell_shape_interpolates_its_nodes() {
        let images = [
            (-1.0, -1.0),
            (1.0, -1.0),
            (0.3, 1.0),
            (0.0, -1.0),
            (1.0, 0.0),
            (-1.0, 0.0),
        ];
        for (j, &(x, e)) in images.iter().enumerate() {
            let n = shape(22, x, e).unwrap();
            for (i, v) in n.iter().enumerate() {
                let d = if i == j { 1.0 } else { 0.0 };
                assert!((v - d).abs() < 1e-15, "N{i} at node {j}: {v}");
            }
        }
        let sum: f64 = shape(22, 0.2, -0.4).unwrap().iter().sum();
        assert!((sum - 1.0).abs() < 1e-15);
    }

    /// Tick labels never repeat, over spans from 1e-7 to 1e9 and offsets that put the
    /// ticks far from zero (the case that printed "0.001" twice before).
    #[test]
    fn tick_labels_are_unique() {
        for e in -7..=9 {
            for m in [1.0, 1.3, 2.2, 3.7, 4.9, 7.5] {
                let span = m * 10f64.powi(e);
                for offset in [0.0, -0.37 * span, 12.3 * span, -1e3 * span] {
                    for n in [6, 8, 12] {
                        let l = tick_labels(offset, offset + span, n);
                        assert!(l.len() >= 2 && l.len() <= n, "{span} {offset} {n}: {l:?}");
                        let mut u = l.clone();
                        u.dedup();
                        assert_eq!(u.len(), l.len(), "repeated labels {l:?}");
                    }
                }
            }
        }
    }

    /// The step is the smallest 1, 2, 5 × 10^k giving at most n labels.
    #[test]
    fn label_step_is_the_densest_allowed() {
        assert_eq!(label_step(1.0, 6), 0.2);
        assert_eq!(label_step(1.0, 11), 0.1);
        assert_eq!(label_step(0.0021, 8), 0.0005);
    }
}
