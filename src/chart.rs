//! Charts for docs/ and study outputs, drawn with plotters into PNG and SVG:
//! line charts (optionally log-log), particle images coloured by a value,
//! and categorical grids (the stability map). Text uses an embedded copy of
//! DejaVu Sans (assets/fonts), so charts render the same on a bare machine.

use crate::error::{Error, Result};
use plotters::coord::Shift;
use plotters::prelude::*;
use plotters::style::colors::colormaps::ColorMap;
use std::path::Path;
use std::sync::Once;

static FONT: Once = Once::new();

/// Registers the embedded font once (every drawing calls it first).
pub fn register_font() {
    FONT.call_once(|| {
        let bytes: &'static [u8] = include_bytes!("../assets/fonts/DejaVuSans.ttf");
        for style in [
            FontStyle::Normal,
            FontStyle::Bold,
            FontStyle::Italic,
            FontStyle::Oblique,
        ] {
            // The embedded font is a valid TTF; registration cannot fail on it.
            let _ = plotters::style::register_font("sans-serif", style, bytes);
        }
    });
}

fn err(path: &Path, e: impl std::fmt::Display) -> Error {
    Error::io(
        "cannot draw chart",
        path,
        std::io::Error::other(e.to_string()),
    )
}

/// PNG bytes of an RGB image of `size` (width, height) pixels.
pub fn png_bytes(rgb: &[u8], size: (u32, u32)) -> Result<Vec<u8>> {
    let mut out = Vec::new();
    let e = |e: png::EncodingError| {
        Error::io(
            "cannot encode PNG",
            Path::new("(memory)"),
            std::io::Error::other(e.to_string()),
        )
    };
    {
        let mut enc = png::Encoder::new(&mut out, size.0, size.1);
        enc.set_color(png::ColorType::Rgb);
        enc.set_depth(png::BitDepth::Eight);
        let mut w = enc.write_header().map_err(e)?;
        w.write_image_data(rgb).map_err(e)?;
    }
    Ok(out)
}

/// A categorical palette readable on white (Tableau 10).
pub const PALETTE: [RGBColor; 10] = [
    RGBColor(31, 119, 180),
    RGBColor(255, 127, 14),
    RGBColor(44, 160, 44),
    RGBColor(214, 39, 40),
    RGBColor(148, 103, 189),
    RGBColor(140, 86, 75),
    RGBColor(227, 119, 194),
    RGBColor(127, 127, 127),
    RGBColor(188, 189, 34),
    RGBColor(23, 190, 207),
];

/// One line of a chart.
#[derive(Debug, Clone)]
pub struct Series {
    pub label: String,
    pub points: Vec<(f64, f64)>,
    /// Index into `PALETTE`.
    pub color: usize,
    /// Dashed line (for exact solutions and references).
    pub dashed: bool,
    /// Draw a marker at each point.
    pub markers: bool,
    /// Draw no line, markers only.
    pub scatter: bool,
}

impl Series {
    pub fn line(label: impl Into<String>, points: Vec<(f64, f64)>, color: usize) -> Self {
        Series {
            label: label.into(),
            points,
            color,
            dashed: false,
            markers: false,
            scatter: false,
        }
    }

    pub fn dashed(mut self) -> Self {
        self.dashed = true;
        self
    }

    pub fn markers(mut self) -> Self {
        self.markers = true;
        self
    }

    pub fn scatter(mut self) -> Self {
        self.scatter = true;
        self.markers = true;
        self
    }
}

/// A line chart.
#[derive(Debug, Clone)]
pub struct LineChart {
    pub title: String,
    pub x_label: String,
    pub y_label: String,
    pub log_x: bool,
    pub log_y: bool,
    pub series: Vec<Series>,
    /// Pixels.
    pub size: (u32, u32),
    /// Where the legend goes (pick the corner the data leave empty).
    pub legend: SeriesLabelPosition,
}

impl LineChart {
    pub fn new(
        title: impl Into<String>,
        x_label: impl Into<String>,
        y_label: impl Into<String>,
    ) -> Self {
        LineChart {
            title: title.into(),
            x_label: x_label.into(),
            y_label: y_label.into(),
            log_x: false,
            log_y: false,
            series: Vec::new(),
            size: (800, 500),
            legend: SeriesLabelPosition::UpperLeft,
        }
    }

    /// Puts the legend in the corner the data leave emptiest: the one
    /// whose quarter of the plot (in the axes' own scale) holds the fewest
    /// points, line segments sampled between them.
    pub fn place_legend(&mut self) {
        let xa = self.axis(0, self.log_x);
        let ya = self.axis(1, self.log_y);
        let unit = |v: f64, a: &Axis, log: bool| {
            if log {
                (v.ln() - a.lo.ln()) / (a.hi.ln() - a.lo.ln())
            } else {
                (v - a.lo) / (a.hi - a.lo)
            }
        };
        let mut count = [0usize; 4]; // UL, UR, LL, LR
        for s in &self.series {
            let pts: Vec<(f64, f64)> = s
                .points
                .iter()
                .filter(|p| p.0.is_finite() && p.1.is_finite())
                .filter(|p| (!self.log_x || p.0 > 0.0) && (!self.log_y || p.1 > 0.0))
                .map(|p| (unit(p.0, &xa, self.log_x), unit(p.1, &ya, self.log_y)))
                .collect();
            for w in pts.windows(2).chain(pts.chunks(1).take(1)) {
                let (a, b) = (w[0], *w.last().expect("non-empty window"));
                for k in 0..=8 {
                    let f = f64::from(k) / 8.0;
                    let (u, v) = (a.0 + f * (b.0 - a.0), a.1 + f * (b.1 - a.1));
                    // The legend's box: about 40 % of the width, 45 % of the height.
                    let left = u < 0.4;
                    let right = u > 0.6;
                    let top = v > 0.55;
                    let bottom = v < 0.45;
                    count[0] += usize::from(left && top);
                    count[1] += usize::from(right && top);
                    count[2] += usize::from(left && bottom);
                    count[3] += usize::from(right && bottom);
                }
            }
        }
        let best = (0..4).min_by_key(|&k| count[k]).unwrap_or(0);
        self.legend = [
            SeriesLabelPosition::UpperLeft,
            SeriesLabelPosition::UpperRight,
            SeriesLabelPosition::LowerLeft,
            SeriesLabelPosition::LowerRight,
        ][best]
            .clone();
    }

    pub fn log_log(mut self) -> Self {
        self.log_x = true;
        self.log_y = true;
        self
    }

    /// Writes `<stem>.png` and `<stem>.svg`.
    pub fn save(&self, stem: &Path) -> Result<()> {
        register_font();
        let png = stem.with_extension("png");
        let svg = stem.with_extension("svg");
        {
            let root = BitMapBackend::new(&png, self.size).into_drawing_area();
            self.draw(&root).map_err(|e| err(&png, e))?;
            root.present().map_err(|e| err(&png, e))?;
        }
        {
            let root = SVGBackend::new(&svg, self.size).into_drawing_area();
            self.draw(&root).map_err(|e| err(&svg, e))?;
            root.present().map_err(|e| err(&svg, e))?;
        }
        Ok(())
    }

    /// The data's extent on `axis` (0: x, 1: y), with a margin; without
    /// data, a unit range.
    fn extent(&self, axis: usize, log: bool) -> (f64, f64) {
        let vals = self
            .series
            .iter()
            .flat_map(|s| {
                s.points
                    .iter()
                    .map(move |p| if axis == 0 { p.0 } else { p.1 })
            })
            .filter(|v| v.is_finite() && (!log || *v > 0.0));
        let (lo, hi) = vals.fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), v| {
            (a.min(v), b.max(v))
        });
        if !lo.is_finite() {
            return if log { (1.0, 10.0) } else { (0.0, 1.0) };
        }
        if log {
            if hi > lo {
                (lo, hi)
            } else {
                (lo * 0.5, hi * 2.0)
            }
        } else if hi > lo {
            (lo, hi)
        } else {
            let pad = 0.5 * lo.abs().max(1.0);
            (lo - pad, hi + pad)
        }
    }

    /// The axis range and its labelled ticks: the range runs from a tick
    /// at or below the lowest point to one at or above the highest, so
    /// every point can be read against a labelled value on both sides.
    fn axis(&self, axis: usize, log: bool) -> Axis {
        let (lo, hi) = self.extent(axis, log);
        if log {
            Axis::log(lo, hi)
        } else {
            Axis::linear(lo, hi, axis == 1)
        }
    }

    /// Draws the chart on `root` (a whole image or a panel of one).
    pub fn draw<DB: DrawingBackend>(
        &self,
        root: &DrawingArea<DB, Shift>,
    ) -> std::result::Result<(), String>
    where
        DB::ErrorType: 'static,
    {
        root.fill(&WHITE).map_err(|e| e.to_string())?;
        let xa = self.axis(0, self.log_x);
        let ya = self.axis(1, self.log_y);
        let mut b = ChartBuilder::on(root);
        b.caption(&self.title, ("sans-serif", 20))
            .margin(12)
            .margin_right(28)
            .x_label_area_size(40)
            .y_label_area_size(70);
        macro_rules! body {
            ($chart:expr) => {{
                let mut chart = $chart;
                let fx = |v: &f64| xa.label(*v);
                let fy = |v: &f64| ya.label(*v);
                chart
                    .configure_mesh()
                    .x_desc(self.x_label.as_str())
                    .y_desc(self.y_label.as_str())
                    .label_style(("sans-serif", 13))
                    .x_label_formatter(&fx)
                    .y_label_formatter(&fy)
                    .x_labels(8)
                    .y_labels(8)
                    .light_line_style(RGBColor(240, 240, 240))
                    .draw()
                    .map_err(|e| e.to_string())?;
                for s in &self.series {
                    let color = PALETTE[s.color % PALETTE.len()];
                    let pts: Vec<(f64, f64)> = s
                        .points
                        .iter()
                        .copied()
                        .filter(|p| p.0.is_finite() && p.1.is_finite())
                        .filter(|p| (!self.log_x || p.0 > 0.0) && (!self.log_y || p.1 > 0.0))
                        .collect();
                    let style = ShapeStyle::from(&color).stroke_width(2);
                    let legend = if s.scatter {
                        chart
                            .draw_series(pts.iter().map(|p| Circle::new(*p, 3, color.filled())))
                            .map_err(|e| e.to_string())?
                    } else if s.dashed {
                        chart
                            .draw_series(DashedLineSeries::new(pts.clone(), 6, 4, style))
                            .map_err(|e| e.to_string())?
                    } else {
                        chart
                            .draw_series(LineSeries::new(pts.clone(), style))
                            .map_err(|e| e.to_string())?
                    };
                    if s.scatter && !s.label.is_empty() {
                        // Markers only: a marker, as drawn.
                        legend.label(s.label.as_str()).legend(move |(x, y)| {
                            EmptyElement::at((x, y)) + Circle::new((9, 0), 3, color.filled())
                        });
                    } else if !s.label.is_empty() {
                        // A dashed series shows two short strokes, a solid one a line.
                        let gap = if s.dashed { 11 } else { 7 };
                        legend.label(s.label.as_str()).legend(move |(x, y)| {
                            EmptyElement::at((x, y))
                                + PathElement::new(vec![(0, 0), (7, 0)], color.stroke_width(2))
                                + PathElement::new(vec![(gap, 0), (18, 0)], color.stroke_width(2))
                        });
                    }
                    if s.markers && !s.scatter {
                        chart
                            .draw_series(pts.iter().map(|p| Circle::new(*p, 3, color.filled())))
                            .map_err(|e| e.to_string())?;
                    }
                }
                if self.series.iter().any(|s| !s.label.is_empty()) {
                    chart
                        .configure_series_labels()
                        .background_style(WHITE.mix(0.85))
                        .border_style(RGBColor(200, 200, 200))
                        .label_font(("sans-serif", 12))
                        .position(self.legend.clone())
                        .draw()
                        .map_err(|e| e.to_string())?;
                }
            }};
        }
        // Every axis carries its own ticks (`Axis`): plotters' log ticks
        // start at a power of ten, so a range inside one decade got none,
        // and its linear ones need not reach the top point.
        let log_axis = |a: &Axis| {
            (a.lo..a.hi)
                .log_scale()
                .with_key_points(a.ticks.clone())
                .with_light_points(a.light.clone())
        };
        let lin_axis = |a: &Axis| LinearTicks {
            lo: a.lo,
            hi: a.hi,
            ticks: a.ticks.clone(),
        };
        match (self.log_x, self.log_y) {
            (false, false) => body!(
                b.build_cartesian_2d(lin_axis(&xa), lin_axis(&ya))
                    .map_err(|e| e.to_string())?
            ),
            (true, false) => body!(
                b.build_cartesian_2d(log_axis(&xa), lin_axis(&ya))
                    .map_err(|e| e.to_string())?
            ),
            (false, true) => body!(
                b.build_cartesian_2d(lin_axis(&xa), log_axis(&ya))
                    .map_err(|e| e.to_string())?
            ),
            (true, true) => {
                body!(
                    b.build_cartesian_2d(log_axis(&xa), log_axis(&ya))
                        .map_err(|e| e.to_string())?
                )
            }
        }
        Ok(())
    }
}

/// One panel of a particle image: positions and the value that colours them.
#[derive(Debug, Clone)]
pub struct Panel {
    pub title: String,
    /// (x, y, value) per particle (m, m, any unit).
    pub points: Vec<(f64, f64, f64)>,
    /// Side of the square drawn for each particle (m): the particle spacing,
    /// so the particles tile the body.
    pub size: f64,
}

/// Panels of particles coloured by a value (viridis), on a grid of
/// `cols` columns, with one shared colour scale and a colour bar.
#[derive(Debug, Clone)]
pub struct ParticleImage {
    pub title: String,
    pub value_label: String,
    pub panels: Vec<Panel>,
    pub cols: usize,
    /// Colour scale (values outside are clamped).
    pub range: (f64, f64),
    /// Pixels per panel.
    pub panel_size: (u32, u32),
    /// Draw each panel's axes, x (m) and y (m), with their ticks.
    pub axes: bool,
}

impl ParticleImage {
    /// Writes `<stem>.png` (a particle image is too heavy for SVG).
    pub fn save(&self, stem: &Path) -> Result<()> {
        register_font();
        let png = stem.with_extension("png");
        let rows = self.panels.len().div_ceil(self.cols.max(1));
        let (pw, ph) = self.panel_size;
        let size = (pw * self.cols as u32 + 90, ph * rows as u32 + 40);
        let root = BitMapBackend::new(&png, size).into_drawing_area();
        self.draw(&root, rows).map_err(|e| err(&png, e))?;
        root.present().map_err(|e| err(&png, e))
    }

    /// Draws the panels on `root` in `rows` rows.
    pub fn draw<DB: DrawingBackend>(
        &self,
        root: &DrawingArea<DB, Shift>,
        rows: usize,
    ) -> std::result::Result<(), String>
    where
        DB::ErrorType: 'static,
    {
        use plotters::style::colors::colormaps::ViridisRGB;
        root.fill(&WHITE).map_err(|e| e.to_string())?;
        let root = root
            .titled(&self.title, ("sans-serif", 18))
            .map_err(|e| e.to_string())?;
        let (w, h) = root.dim_in_pixel();
        let (plots, bar_area) = root.split_horizontally(w - 90);
        let cells = plots.split_evenly((rows, self.cols.max(1)));
        let (lo, hi) = self.range;
        let norm = |v: f64| ((v - lo) / (hi - lo)).clamp(0.0, 1.0);
        for (panel, area) in self.panels.iter().zip(cells.iter()) {
            let (x0, x1, y0, y1) = panel.points.iter().fold(
                (
                    f64::INFINITY,
                    f64::NEG_INFINITY,
                    f64::INFINITY,
                    f64::NEG_INFINITY,
                ),
                |b, p| (b.0.min(p.0), b.1.max(p.0), b.2.min(p.1), b.3.max(p.1)),
            );
            if !x0.is_finite() {
                continue;
            }
            // Same scale on both axes.
            let span = (x1 - x0).max(y1 - y0) * 1.04 + 1e-12;
            let (cx, cy) = (0.5 * (x0 + x1), 0.5 * (y0 + y1));
            let mut builder = ChartBuilder::on(area);
            builder.caption(&panel.title, ("sans-serif", 14)).margin(6);
            if self.axes {
                builder.x_label_area_size(34).y_label_area_size(52);
            }
            let mut chart = builder
                .build_cartesian_2d(
                    cx - 0.5 * span..cx + 0.5 * span,
                    cy - 0.5 * span..cy + 0.5 * span,
                )
                .map_err(|e| e.to_string())?;
            if self.axes {
                chart
                    .configure_mesh()
                    .disable_mesh()
                    .x_desc("x (m)")
                    .y_desc("y (m)")
                    .label_style(("sans-serif", 12))
                    .x_labels(6)
                    .y_labels(6)
                    .draw()
                    .map_err(|e| e.to_string())?;
            }
            // Slightly larger than the spacing, so pixel rounding leaves no gaps.
            let half = 0.6 * panel.size;
            chart
                .draw_series(panel.points.iter().map(|p| {
                    let c: RGBColor = ViridisRGB.get_color(norm(p.2) as f32);
                    Rectangle::new(
                        [(p.0 - half, p.1 - half), (p.0 + half, p.1 + half)],
                        c.filled(),
                    )
                }))
                .map_err(|e| e.to_string())?;
        }
        // Colour bar.
        let steps = 100;
        // The label above the bar, inside the bar's column (90 px), so it
        // is never cut at the picture's edge.
        let bar = bar_area.margin(36, 30, 10, 40);
        let (_, bh) = bar.dim_in_pixel();
        for k in 0..steps {
            let f = k as f64 / (steps - 1) as f64;
            let c: RGBColor = ViridisRGB.get_color(f as f32);
            let y = (bh as f64 * (1.0 - f)) as i32;
            let half = (bh as i32 / steps).max(1);
            bar.draw(&Rectangle::new([(0, y - half), (14, y + half)], c.filled()))
                .map_err(|e| e.to_string())?;
        }
        let style = ("sans-serif", 12).into_font().color(&BLACK);
        bar.draw(&Text::new(tick(hi, 0.0), (18, 0), style.clone()))
            .map_err(|e| e.to_string())?;
        bar.draw(&Text::new(
            tick(lo, 0.0),
            (18, bh as i32 - 12),
            style.clone(),
        ))
        .map_err(|e| e.to_string())?;
        bar_area
            .draw(&Text::new(self.value_label.clone(), (6, 14), style))
            .map_err(|e| e.to_string())?;
        let _ = h;
        Ok(())
    }
}

/// How a cell of a status grid is coloured.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Status {
    Ok,
    Failed,
    Error,
    Missing,
}

/// A table of coloured cells with short texts (the stability map).
#[derive(Debug, Clone)]
pub struct StatusGrid {
    pub title: String,
    pub rows: Vec<String>,
    pub cols: Vec<String>,
    /// `cells[r][c]`.
    pub cells: Vec<Vec<(Status, String)>>,
}

impl StatusGrid {
    /// Writes `<stem>.png` and `<stem>.svg`.
    pub fn save(&self, stem: &Path) -> Result<()> {
        register_font();
        let (cw, rh, lw, th) = (118u32, 44u32, 150u32, 70u32);
        let size = (
            lw + cw * self.cols.len() as u32 + 10,
            th + rh * self.rows.len() as u32 + 10,
        );
        let png = stem.with_extension("png");
        let svg = stem.with_extension("svg");
        {
            let root = BitMapBackend::new(&png, size).into_drawing_area();
            self.draw(&root, (cw, rh, lw, th))
                .map_err(|e| err(&png, e))?;
            root.present().map_err(|e| err(&png, e))?;
        }
        let root = SVGBackend::new(&svg, size).into_drawing_area();
        self.draw(&root, (cw, rh, lw, th))
            .map_err(|e| err(&svg, e))?;
        root.present().map_err(|e| err(&svg, e))
    }

    fn draw<DB: DrawingBackend>(
        &self,
        root: &DrawingArea<DB, Shift>,
        (cw, rh, lw, th): (u32, u32, u32, u32),
    ) -> std::result::Result<(), String>
    where
        DB::ErrorType: 'static,
    {
        root.fill(&WHITE).map_err(|e| e.to_string())?;
        let font = |s: u32| ("sans-serif", s).into_font().color(&BLACK);
        root.draw(&Text::new(self.title.clone(), (10, 8), font(17)))
            .map_err(|e| e.to_string())?;
        for (c, name) in self.cols.iter().enumerate() {
            let x = (lw + cw * c as u32) as i32 + 4;
            for (k, line) in name.split('\n').enumerate() {
                root.draw(&Text::new(
                    line.to_string(),
                    (x, 34 + 14 * k as i32),
                    font(12),
                ))
                .map_err(|e| e.to_string())?;
            }
        }
        for (r, name) in self.rows.iter().enumerate() {
            let y = (th + rh * r as u32) as i32;
            root.draw(&Text::new(
                name.clone(),
                (10, y + rh as i32 / 2 - 7),
                font(13),
            ))
            .map_err(|e| e.to_string())?;
            for (c, (status, text)) in self.cells[r].iter().enumerate() {
                let x = (lw + cw * c as u32) as i32;
                let fill = match status {
                    Status::Ok => RGBColor(190, 230, 190),
                    Status::Failed => RGBColor(240, 170, 160),
                    Status::Error => RGBColor(200, 200, 200),
                    Status::Missing => RGBColor(245, 245, 245),
                };
                root.draw(&Rectangle::new(
                    [(x + 1, y + 1), (x + cw as i32 - 1, y + rh as i32 - 1)],
                    fill.filled(),
                ))
                .map_err(|e| e.to_string())?;
                for (k, line) in text.split('\n').take(3).enumerate() {
                    root.draw(&Text::new(
                        line.to_string(),
                        (x + 5, y + 5 + 13 * k as i32),
                        font(11),
                    ))
                    .map_err(|e| e.to_string())?;
                }
            }
        }
        Ok(())
    }
}

/// Labelled and light ticks of a log axis from `lo` to `hi` (> 0): powers
/// of ten, with 2 and 5 times them over up to three decades and every
/// digit within about one; light lines at every digit.
fn log_ticks(lo: f64, hi: f64) -> (Vec<f64>, Vec<f64>) {
    let decades = (hi / lo).log10();
    let (k0, k1) = (lo.log10().floor() as i32, hi.log10().ceil() as i32);
    let step = (decades / 8.0).ceil().max(1.0) as i32;
    let digits: &[f64] = if decades <= 1.2 {
        &[1.0, 2.0, 3.0, 4.0, 5.0, 6.0, 7.0, 8.0, 9.0]
    } else if decades <= 3.0 {
        &[1.0, 2.0, 5.0]
    } else {
        &[1.0]
    };
    let inside = |v: &f64| *v >= lo * (1.0 - 1e-9) && *v <= hi * (1.0 + 1e-9);
    let at = |ms: &[f64], every: i32| -> Vec<f64> {
        (k0..=k1)
            .filter(|k| (k - k0) % every == 0)
            .flat_map(|k| ms.iter().map(move |m| m * 10f64.powi(k)))
            .filter(inside)
            .collect()
    };
    let bold = at(digits, step);
    let light = at(&[1.0, 2.0, 3.0, 4.0, 5.0, 6.0, 7.0, 8.0, 9.0], 1);
    (bold, light)
}

/// One axis of a line chart: its range and labelled ticks.
#[derive(Debug, Clone)]
struct Axis {
    lo: f64,
    hi: f64,
    /// Labelled ticks.
    ticks: Vec<f64>,
    /// Unlabelled grid lines (log axes).
    light: Vec<f64>,
    /// Tick spacing (linear axes; 0 on log axes).
    step: f64,
}

/// A linear axis with the given labelled ticks (plotters' own linear axis
/// picks its ticks itself, and `with_key_points` on it loses the label
/// formatter `configure_mesh` needs).
#[derive(Debug, Clone)]
struct LinearTicks {
    lo: f64,
    hi: f64,
    ticks: Vec<f64>,
}

impl plotters::coord::ranged1d::Ranged for LinearTicks {
    type FormatOption = plotters::coord::ranged1d::DefaultFormatting;
    type ValueType = f64;

    fn map(&self, v: &f64, limit: (i32, i32)) -> i32 {
        let f = (v - self.lo) / (self.hi - self.lo);
        limit.0 + (f * f64::from(limit.1 - limit.0)).round() as i32
    }

    fn key_points<H: plotters::coord::ranged1d::KeyPointHint>(&self, hint: H) -> Vec<f64> {
        if hint.weight().allow_light_points() {
            Vec::new()
        } else {
            self.ticks.clone()
        }
    }

    fn range(&self) -> std::ops::Range<f64> {
        self.lo..self.hi
    }
}

/// A tick above the data when the data come within this fraction of the
/// range of the last tick (a point on the frame's edge is hard to read).
const EDGE: f64 = 0.02;

impl Axis {
    /// Ticks every 1, 2, 2.5 or 5 × 10^k, about six of them, the range
    /// snapped out to a tick on each side; with `pad` (a y axis) one step
    /// more where the data come within `EDGE` of the frame (zero stays the
    /// edge when the data start or end there).
    fn linear(lo: f64, hi: f64, pad: bool) -> Axis {
        let span = hi - lo;
        let raw = span / 6.0;
        let k = raw.log10().floor();
        let base = 10f64.powf(k);
        let step = [1.0, 2.0, 2.5, 5.0, 10.0]
            .into_iter()
            .map(|m| m * base)
            .find(|s| *s >= raw * (1.0 - 1e-9))
            .unwrap_or(10.0 * base);
        let mut a = (lo / step + 1e-9).floor() * step;
        if pad && lo != 0.0 && lo - a < EDGE * span {
            a -= step;
        }
        let mut b = (hi / step - 1e-9).ceil() * step;
        if pad && hi != 0.0 && b - hi < EDGE * span {
            b += step;
        }
        let n = ((b - a) / step).round() as i64;
        let ticks = (0..=n).map(|i| a + i as f64 * step).collect();
        Axis {
            lo: a,
            hi: b,
            ticks,
            light: Vec::new(),
            step,
        }
    }

    /// `log_ticks` on a range widened to a labelled tick at or beyond the
    /// data on each side.
    fn log(lo: f64, hi: f64) -> Axis {
        let (mut a, mut b) = (lo, hi);
        for _ in 0..6 {
            let (bold, _) = log_ticks(a, b);
            let top = bold.last().copied().unwrap_or(0.0);
            let bottom = bold.first().copied().unwrap_or(f64::INFINITY);
            let up = top < hi * (1.0 - 1e-9);
            let down = bottom > lo * (1.0 + 1e-9);
            if !up && !down {
                break;
            }
            if up {
                b = nice_beyond(hi, true);
            }
            if down {
                a = nice_beyond(lo, false);
            }
            if bold.is_empty() || (b / a) > 1e3 * (hi / lo) {
                // Widening no longer helps: powers of ten around the data.
                a = 10f64.powf(lo.log10().floor());
                b = 10f64.powf(hi.log10().ceil());
            }
        }
        let (ticks, light) = log_ticks(a, b);
        Axis {
            lo: a / 1.04,
            hi: b * 1.04,
            ticks,
            light,
            step: 0.0,
        }
    }

    fn label(&self, v: f64) -> String {
        tick(v, self.step)
    }
}

/// The next 1, 2 or 5 × 10^k strictly beyond `v` (> 0), up or down.
fn nice_beyond(v: f64, up: bool) -> f64 {
    let k = v.log10().floor() as i32;
    let mut c: Vec<f64> = (k - 1..=k + 1)
        .flat_map(|k| [1.0, 2.0, 5.0].map(|m| m * 10f64.powi(k)))
        .collect();
    c.sort_by(f64::total_cmp);
    if up {
        c.into_iter()
            .find(|x| *x > v * (1.0 + 1e-9))
            .unwrap_or(10.0 * v)
    } else {
        c.into_iter()
            .rev()
            .find(|x| *x < v * (1.0 - 1e-9))
            .unwrap_or(0.1 * v)
    }
}

/// Tick label: plain decimals from 0.001 to 99999 (as many decimals as the
/// tick spacing `step` needs; on a log axis, `step` = 0, up to four
/// significant digits), else a mantissa and exponent such as 2.5e-5.
fn tick(v: f64, step: f64) -> String {
    if v == 0.0 || v.abs() < step * 1e-9 {
        return "0".into();
    }
    let a = v.abs();
    let trim = |s: String| {
        if s.contains('.') {
            s.trim_end_matches('0').trim_end_matches('.').to_string()
        } else {
            s
        }
    };
    let plain = (1e-3..1e5).contains(&a) && (step == 0.0 || step >= 1e-4);
    if plain {
        let decimals = if step > 0.0 {
            // 2.5 × 10^k needs one digit more than 10^k.
            let d = -(step.log10() - 1e-9).floor();
            let extra = usize::from(((step / 10f64.powf(-d)) - 2.5).abs() < 1e-6);
            d.max(0.0) as usize + extra
        } else {
            (3.0 - a.log10().floor()).max(0.0) as usize
        };
        trim(format!("{v:.decimals$}"))
    } else {
        let e = a.log10().floor();
        let m = v / 10f64.powf(e);
        format!("{}e{}", trim(format!("{m:.2}")), e)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn log_axes_inside_one_decade_are_labelled() {
        let (bold, light) = log_ticks(0.55, 1.09);
        assert_eq!(bold.len(), 5, "{bold:?}"); // 0.6, 0.7, 0.8, 0.9, 1
        assert!((bold[0] - 0.6).abs() < 1e-12 && (bold[4] - 1.0).abs() < 1e-12);
        assert_eq!(light.len(), 5);
        let (bold, _) = log_ticks(3e-4, 2e2);
        // Six decades: powers of ten only.
        assert_eq!(bold.len(), 6, "{bold:?}");
        for (b, e) in bold.iter().zip(-3..=2) {
            assert!((b.log10() - f64::from(e)).abs() < 1e-12, "{bold:?}");
        }
        let (bold, _) = log_ticks(0.03, 3.0);
        assert_eq!(bold.len(), 6, "{bold:?}"); // 0.05, 0.1, 0.2, 0.5, 1, 2
    }

    #[test]
    fn ticks_are_plain_decimals_and_reach_past_the_data() {
        // The issue's `9e-1`, `5e0`, `6e0 %` read 0.9, 5 and 6.
        assert_eq!(tick(0.9, 0.0), "0.9");
        assert_eq!(tick(5.0, 0.0), "5");
        assert_eq!(tick(6.0, 1.0), "6");
        assert_eq!(tick(0.25, 0.05), "0.25");
        assert_eq!(tick(2.5e-5, 5e-6), "2.5e-5");
        assert_eq!(tick(3e-4, 0.0), "3e-4");
        // A log axis whose top point is 1.3 gets a labelled tick above it.
        let a = Axis::log(0.55, 1.3);
        assert!(a.ticks.iter().any(|t| *t >= 1.3), "{:?}", a.ticks);
        assert!(a.ticks.iter().any(|t| *t <= 0.55), "{:?}", a.ticks);
        assert!(a.hi > 1.3 && a.lo < 0.55);
        // Linear: ticks on both sides of the data, a tick at the edge.
        let a = Axis::linear(0.12, 4.9, true);
        assert!(
            *a.ticks.last().unwrap() >= 4.9 && a.ticks[0] <= 0.12,
            "{:?}",
            a.ticks
        );
        assert_eq!(a.hi, *a.ticks.last().unwrap());
        let a = Axis::linear(0.0, 1e-4, true);
        assert_eq!(a.lo, 0.0);
        // A time axis ends at the tick its data end on.
        assert_eq!(Axis::linear(0.0, 20.0, false).hi, 20.0);
        let a = Axis::linear(0.0, 1e-4, false);
        assert_eq!(a.lo, 0.0);
        assert!(a.ticks.iter().all(|t| !a.label(*t).contains("e0")));
    }

    #[test]
    fn charts_render_to_png_and_svg() {
        let dir = std::env::temp_dir().join(format!("lme-mpm-chart-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let mut c = LineChart::new("test", "x", "y").log_log();
        c.series
            .push(Series::line("a", vec![(1.0, 1.0), (10.0, 0.1), (100.0, 0.01)], 0).markers());
        c.series
            .push(Series::line("b", vec![(1.0, 2.0), (100.0, 0.02)], 1).dashed());
        c.save(&dir.join("c")).unwrap();
        let png = std::fs::read(dir.join("c.png")).unwrap();
        assert_eq!(&png[1..4], b"PNG");
        let svg = std::fs::read_to_string(dir.join("c.svg")).unwrap();
        assert!(
            svg.contains("<svg") && svg.contains(">\na\n</text>"),
            "legend text missing"
        );
        let _ = std::fs::remove_dir_all(dir);
    }
}
