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

fn register_font() {
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

    fn range(&self, axis: usize, log: bool) -> (f64, f64) {
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
            let (lo, hi) = if hi > lo {
                (lo, hi)
            } else {
                (lo * 0.5, hi * 2.0)
            };
            (lo / 1.3, hi * 1.3)
        } else {
            let pad = if hi > lo {
                0.05 * (hi - lo)
            } else {
                0.5 * lo.abs().max(1.0)
            };
            (lo - pad, hi + pad)
        }
    }

    fn draw<DB: DrawingBackend>(
        &self,
        root: &DrawingArea<DB, Shift>,
    ) -> std::result::Result<(), String>
    where
        DB::ErrorType: 'static,
    {
        root.fill(&WHITE).map_err(|e| e.to_string())?;
        let (x0, x1) = self.range(0, self.log_x);
        let (y0, y1) = self.range(1, self.log_y);
        let mut b = ChartBuilder::on(root);
        b.caption(&self.title, ("sans-serif", 20))
            .margin(12)
            .x_label_area_size(40)
            .y_label_area_size(70);
        macro_rules! body {
            ($chart:expr) => {{
                let mut chart = $chart;
                let fx = |v: &f64| tick(*v, self.log_x);
                let fy = |v: &f64| tick(*v, self.log_y);
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
                    if !s.label.is_empty() {
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
        // Log axes carry their own ticks (`log_ticks`): plotters' own
        // start at a power of ten, so a range inside one decade got none.
        let log_axis = |lo: f64, hi: f64| {
            let (bold, light) = log_ticks(lo, hi);
            (lo..hi)
                .log_scale()
                .with_key_points(bold)
                .with_light_points(light)
        };
        match (self.log_x, self.log_y) {
            (false, false) => body!(
                b.build_cartesian_2d(x0..x1, y0..y1)
                    .map_err(|e| e.to_string())?
            ),
            (true, false) => body!(
                b.build_cartesian_2d(log_axis(x0, x1), y0..y1)
                    .map_err(|e| e.to_string())?
            ),
            (false, true) => body!(
                b.build_cartesian_2d(x0..x1, log_axis(y0, y1))
                    .map_err(|e| e.to_string())?
            ),
            (true, true) => {
                body!(
                    b.build_cartesian_2d(log_axis(x0, x1), log_axis(y0, y1))
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

    fn draw<DB: DrawingBackend>(
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
        let (plots, bar) = root.split_horizontally(w - 90);
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
            let mut chart = ChartBuilder::on(area)
                .caption(&panel.title, ("sans-serif", 14))
                .margin(6)
                .build_cartesian_2d(
                    cx - 0.5 * span..cx + 0.5 * span,
                    cy - 0.5 * span..cy + 0.5 * span,
                )
                .map_err(|e| e.to_string())?;
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
        let bar = bar.margin(30, 30, 10, 40);
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
        bar.draw(&Text::new(format!("{hi:.3}"), (18, 0), style.clone()))
            .map_err(|e| e.to_string())?;
        bar.draw(&Text::new(
            format!("{lo:.3}"),
            (18, bh as i32 - 12),
            style.clone(),
        ))
        .map_err(|e| e.to_string())?;
        bar.draw(&Text::new(
            self.value_label.clone(),
            (0, bh as i32 + 8),
            style,
        ))
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

/// Tick label: powers of ten and 2/5 multiples as 1e3, 2e3; plain numbers otherwise.
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

fn tick(v: f64, log: bool) -> String {
    if v == 0.0 {
        return "0".into();
    }
    let a = v.abs();
    if log || !(1e-3..1e5).contains(&a) {
        let e = a.log10().floor();
        let m = v / 10f64.powf(e);
        if (m - m.round()).abs() < 1e-6 {
            format!("{}e{}", m.round(), e)
        } else {
            format!("{m:.1}e{e}")
        }
    } else {
        let s = format!("{v:.3}");
        s.trim_end_matches('0').trim_end_matches('.').to_string()
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
