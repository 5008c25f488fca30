//! Charts for docs/ and study outputs, drawn with plotters into PNG and SVG:
//! line charts (optionally log-log), particle images coloured by a value,
//! and categorical grids (the stability map). Text uses an embedded copy of
//! DejaVu Sans (assets/fonts), so charts render the same on a bare machine.

use crate::error::{Error, Result};
use plotters::coord::Shift;
use plotters::prelude::*;
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
                        .position(SeriesLabelPosition::UpperLeft)
                        .draw()
                        .map_err(|e| e.to_string())?;
                }
            }};
        }
        match (self.log_x, self.log_y) {
            (false, false) => body!(
                b.build_cartesian_2d(x0..x1, y0..y1)
                    .map_err(|e| e.to_string())?
            ),
            (true, false) => body!(
                b.build_cartesian_2d((x0..x1).log_scale(), y0..y1)
                    .map_err(|e| e.to_string())?
            ),
            (false, true) => body!(
                b.build_cartesian_2d(x0..x1, (y0..y1).log_scale())
                    .map_err(|e| e.to_string())?
            ),
            (true, true) => {
                body!(
                    b.build_cartesian_2d((x0..x1).log_scale(), (y0..y1).log_scale())
                        .map_err(|e| e.to_string())?
                )
            }
        }
        Ok(())
    }
}

/// Tick label: powers of ten and 2/5 multiples as 1e3, 2e3; plain numbers otherwise.
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
