//! `lme-mpm render DIR`: a run's VTK snapshots (`particles.pvd` and
//! `vtk/*.vtu`) as pictures: one PNG per snapshot and an animated GIF (and
//! an MP4 when `ffmpeg` is on the PATH), in `DIR/render/` unless told
//! otherwise. Each particle is drawn as its domain (a square of its
//! current area) coloured by the chosen field on one colour scale for the
//! whole run, with a colour bar, the time, the walls acting at that time
//! (their line, the side behind it shaded) and the prescribed-velocity
//! regions, on one fixed frame that holds every snapshot's particles.
//!
//! The particles are rasterised straight into the image buffer; plotters
//! draws the axes, colour bar, walls and text around them. The GIF uses a
//! fixed palette (viridis, greys, the region colours), so frames need no
//! per-frame colour quantisation.

use crate::chart::register_font;
use crate::error::{Error, Result};
use crate::model::material::{self, StateColumn, state_columns};
use crate::output::vtk::{Vtu, read_pvd, read_vtu};
use crate::scene::Scene;
use plotters::prelude::*;
use plotters::style::colors::colormaps::{ColorMap, ViridisRGB};
use rayon::prelude::*;
use std::path::{Path, PathBuf};

/// What colours the particles: a field of every run, or a state column
/// of the registered materials (`Constitutive::STATE_COLUMNS`, by its
/// `column` name: ε̄p `eps_p`, p_c `p_c`, ...).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Field {
    /// |v| (m/s).
    Speed,
    /// von Mises equivalent stress of the Cauchy tensor, σzz included (Pa).
    Stress,
    /// Pressure −(σxx + σyy + σzz)/3 (Pa; positive in compression).
    Pressure,
    /// A material's state column, from its VTU array.
    State(StateColumn),
    /// |x − X|, the distance from the initial position (m).
    Displacement,
    /// Saturated soil: the pore pressure p (Pa; positive in compression).
    PorePressure,
}

impl clap::ValueEnum for Field {
    /// The run's fields, with every registered state column before
    /// `displacement`.
    fn value_variants<'a>() -> &'a [Self] {
        static ALL: std::sync::OnceLock<Vec<Field>> = std::sync::OnceLock::new();
        ALL.get_or_init(|| {
            let mut all = vec![Field::Speed, Field::Stress, Field::Pressure];
            all.extend(state_columns().into_iter().map(Field::State));
            all.push(Field::Displacement);
            all.push(Field::PorePressure);
            all
        })
    }

    fn to_possible_value(&self) -> Option<clap::builder::PossibleValue> {
        Some(clap::builder::PossibleValue::new(self.slug()).help(self.label()))
    }
}

impl Field {
    pub fn slug(self) -> &'static str {
        match self {
            Field::Speed => "speed",
            Field::Stress => "stress",
            Field::Pressure => "pressure",
            Field::State(c) => c.column,
            Field::Displacement => "displacement",
            Field::PorePressure => "pore_pressure",
        }
    }

    fn label(self) -> String {
        match self {
            Field::Speed => "speed (m/s)".into(),
            Field::Stress => "von Mises stress (Pa)".into(),
            Field::Pressure => "pressure (Pa)".into(),
            Field::State(c) => c.label(),
            Field::Displacement => "displacement (m)".into(),
            Field::PorePressure => "pore pressure (Pa)".into(),
        }
    }

    /// Its colour scale starts at its least value, not at 0.
    fn scale_at_least(self) -> bool {
        match self {
            Field::Pressure | Field::PorePressure => true,
            Field::State(c) => !c.from_zero,
            _ => false,
        }
    }
}

/// `lme-mpm render`'s options.
#[derive(Debug, Clone)]
pub struct RenderOptions {
    pub field: Field,
    /// Frames per second of the animation (default 10).
    pub fps: f64,
    /// Image width in pixels (default 800; the height follows the frame).
    pub width: u32,
    /// Output folder; default `DIR/render`.
    pub out: Option<PathBuf>,
    /// Every how many snapshots a frame (default 1; the last is always drawn).
    pub every: usize,
    /// Print the estimate of the output's size and time to stderr once the
    /// first frame is drawn (default true).
    pub say_estimate: bool,
}

impl Default for RenderOptions {
    fn default() -> Self {
        RenderOptions {
            field: Field::Speed,
            fps: 10.0,
            width: 800,
            out: None,
            every: 1,
            say_estimate: true,
        }
    }
}

/// The image widths `render` draws (pixels): below 320 the axes, colour
/// bar and title leave no room for the particles; above 4096 one frame
/// is over 60 MB of pixels, and plotters' buffer and the GIF's 16-bit
/// sizes end not far beyond.
pub const WIDTH: std::ops::RangeInclusive<u32> = 320..=4096;
/// Frames per second of the animation: a GIF's delay is a whole number
/// of hundredths of a second from 2 (50 frames/s) to 1000 (10 s a frame,
/// 0.1 frames/s).
pub const FPS: std::ops::RangeInclusive<f64> = 0.1..=50.0;

/// `--width`: a number of pixels in `WIDTH`.
pub fn parse_width(s: &str) -> std::result::Result<u32, String> {
    let v: u64 = s
        .trim()
        .parse()
        .map_err(|_| format!("`{s}` is not a width in pixels"))?;
    match u32::try_from(v) {
        Ok(w) if WIDTH.contains(&w) => Ok(w),
        _ => Err(format!(
            "{v} pixels: the width must be in {}..={} pixels",
            WIDTH.start(),
            WIDTH.end()
        )),
    }
}

/// `--fps`: a finite rate in `FPS`.
pub fn parse_fps(s: &str) -> std::result::Result<f64, String> {
    let v: f64 = s
        .trim()
        .parse()
        .map_err(|_| format!("`{s}` is not a number of frames per second"))?;
    if FPS.contains(&v) {
        Ok(v)
    } else {
        Err(format!(
            "{v} frames/s: the rate must be in {}..={} frames per second",
            FPS.start(),
            FPS.end()
        ))
    }
}

/// `--every`: a whole number, at least 1.
pub fn parse_every(s: &str) -> std::result::Result<usize, String> {
    match s.trim().parse::<usize>() {
        Ok(n) if n >= 1 => Ok(n),
        _ => Err(format!(
            "`{s}`: draw every N-th snapshot, N a whole number of at least 1"
        )),
    }
}

impl RenderOptions {
    /// The options' values against the ranges above, each failure naming
    /// its flag (exit 2).
    fn check(&self) -> Result<()> {
        let bad = |flag: &str, why: String| Err(Error::Usage(format!("--{flag}: {why}")));
        if !WIDTH.contains(&self.width) {
            return bad("width", parse_width(&self.width.to_string()).unwrap_err());
        }
        if !FPS.contains(&self.fps) {
            return bad("fps", parse_fps(&self.fps.to_string()).unwrap_err());
        }
        if self.every == 0 {
            return bad("every", parse_every("0").unwrap_err());
        }
        Ok(())
    }
}

/// What `render` wrote.
#[derive(Debug, Clone)]
pub struct Rendered {
    pub frames: Vec<PathBuf>,
    pub gif: PathBuf,
    /// Written when `ffmpeg` is on the PATH.
    pub mp4: Option<PathBuf>,
    /// Particles in the largest snapshot.
    pub particles: usize,
    /// The colour scale (field units).
    pub range: (f64, f64),
    /// Whether values above the scale's top were drawn at its colour.
    pub clipped: bool,
    /// What the first frame said of the whole render's size and time.
    pub estimate: Estimate,
}

/// One snapshot, reduced to what a frame draws.
struct Snapshot {
    t: f64,
    x: Vec<[f32; 2]>,
    value: Vec<f32>,
    /// Side of each particle's square (m).
    side: Vec<f32>,
}

/// Whether wall `w` acts at the snapshot time `t`: the rule of
/// `model::walls::Wall::active_at` (a gate is drawn until it goes).
fn acts(w: &crate::scene::schema::WallSpec, t: f64) -> bool {
    w.appear_at <= t && w.remove_at.is_none_or(|r| t < r)
}

fn folder_error(msg: String) -> Error {
    Error::Folder(msg)
}

/// A state column the snapshot lacks: which models have it, and the state
/// columns the snapshot holds instead.
fn no_column(v: &Vtu, c: &StateColumn, path: &Path) -> Error {
    let models = material::names_where(|e| e.state_columns.contains(c));
    let held: Vec<StateColumn> = state_columns()
        .into_iter()
        .filter(|d| v.get(d.array).is_some())
        .collect();
    let instead = if held.is_empty() {
        String::new()
    } else {
        let what: Vec<&str> = held.iter().map(|d| d.meaning).collect();
        let fields: Vec<String> = held
            .iter()
            .map(|d| format!("--field {}", d.column))
            .collect();
        format!(
            " (its materials carry {} instead: {})",
            material::name_list(&what, "and"),
            material::name_list(&fields.iter().map(String::as_str).collect::<Vec<_>>(), "or")
        )
    };
    folder_error(format!(
        "{}: no {}: --field {} needs a {} material{instead}",
        path.display(),
        c.meaning,
        c.column,
        material::name_list(&models, "or")
    ))
}

/// The field's value per particle, from the arrays `particles_vtu` writes.
fn values(v: &Vtu, field: Field, path: &Path) -> Result<Vec<f32>> {
    let n = v.n;
    let missing = |name: &str| {
        folder_error(format!(
            "{}: no `{name}` array (written by an older lme-mpm?): rerun the scene",
            path.display()
        ))
    };
    Ok(match field {
        Field::Speed => v.get("speed").ok_or_else(|| missing("speed"))?.0.to_vec(),
        Field::PorePressure => v
            .get("pore_pressure")
            .ok_or_else(|| {
                folder_error(format!(
                    "{}: no `pore_pressure` array: the scene has no saturated material",
                    path.display()
                ))
            })?
            .0
            .to_vec(),
        Field::Displacement => {
            let (d, _) = v
                .get("displacement")
                .ok_or_else(|| missing("displacement"))?;
            (0..n).map(|i| d[3 * i].hypot(d[3 * i + 1])).collect()
        }
        Field::State(c) => v
            .get(c.array)
            .ok_or_else(|| no_column(v, &c, path))?
            .0
            .to_vec(),
        Field::Stress | Field::Pressure => {
            let (s, _) = v.get("stress").ok_or_else(|| missing("stress"))?;
            (0..n)
                .map(|i| {
                    let [xx, yy, zz, xy] =
                        [s[6 * i], s[6 * i + 1], s[6 * i + 2], s[6 * i + 3]].map(f64::from);
                    if field == Field::Pressure {
                        (-(xx + yy + zz) / 3.0) as f32
                    } else {
                        (0.5 * ((xx - yy).powi(2) + (yy - zz).powi(2) + (zz - xx).powi(2))
                            + 3.0 * xy * xy)
                            .sqrt() as f32
                    }
                })
                .collect()
        }
    })
}

fn snapshot(path: &Path, t: f64, field: Field, fallback_side: f64) -> Result<Snapshot> {
    let bytes = std::fs::read(path).map_err(|e| Error::io("cannot read", path, e))?;
    let v = read_vtu(&bytes).map_err(|m| folder_error(format!("{}: {m}", path.display())))?;
    let (p, _) = v.get("position").expect("read_vtu checks it");
    let x = (0..v.n).map(|i| [p[3 * i], p[3 * i + 1]]).collect();
    let side = match v.get("volume") {
        Some((vol, _)) => vol.iter().map(|a| a.max(0.0).sqrt()).collect(),
        None => vec![fallback_side as f32; v.n],
    };
    Ok(Snapshot {
        t,
        x,
        value: values(&v, field, path)?,
        side,
    })
}

/// The frame in metres: [x0, y0, x1, y1].
type Frame = [f64; 4];

/// The image layout: sizes in pixels, the frame drawn.
#[derive(Debug, Clone, Copy)]
struct Layout {
    size: (u32, u32),
    frame: Frame,
}

/// The colour scale ends at this many times the 99th percentile's
/// distance from its bottom, when the largest value is farther.
const CLIP: f64 = 1.5;

const TITLE_H: u32 = 34;
const BAR_W: u32 = 120;
const LEFT_W: u32 = 72;
const BOTTOM_H: u32 = 46;
const MARGIN: u32 = 10;

fn layout(frame: Frame, width: u32) -> Layout {
    let width = width.max(*WIDTH.start());
    let plot_w = f64::from(width - LEFT_W - BAR_W - 2 * MARGIN);
    let [mut x0, mut y0, mut x1, mut y1] = frame;
    let mut scale = plot_w / (x1 - x0);
    let mut plot_h = (y1 - y0) * scale;
    let (min_h, max_h) = (0.25 * plot_w, 1.3 * plot_w);
    if plot_h > max_h {
        // Tall: fit the height, widen the frame to the width left.
        scale = max_h / (y1 - y0);
        plot_h = max_h;
        let extra = plot_w / scale - (x1 - x0);
        x0 -= 0.5 * extra;
        x1 += 0.5 * extra;
    } else if plot_h < min_h {
        let extra = min_h / scale - (y1 - y0);
        y0 -= 0.5 * extra;
        y1 += 0.5 * extra;
        plot_h = min_h;
    }
    let _ = scale;
    let height = (plot_h.round() as u32 + TITLE_H + BOTTOM_H + 2 * MARGIN).next_multiple_of(2);
    Layout {
        size: (width.next_multiple_of(2), height),
        frame: [x0, y0, x1, y1],
    }
}

/// The palette of the GIF: viridis, greys and the region colours.
struct Palette {
    rgb: Vec<[u8; 3]>,
    /// Nearest entry for each colour at 5 bits per channel.
    lut: Vec<u8>,
}

const VIRIDIS_LEVELS: usize = 184;
const GREYS: usize = 56;
const REGION_FILL: RGBColor = RGBColor(253, 224, 196);
const REGION_LINE: RGBColor = RGBColor(217, 95, 2);
const WALL_FILL: RGBColor = RGBColor(215, 215, 215);
const WALL_LINE: RGBColor = RGBColor(40, 40, 40);

impl Palette {
    fn new() -> Palette {
        let mut rgb: Vec<[u8; 3]> = (0..VIRIDIS_LEVELS)
            .map(|k| {
                let c: RGBColor = ViridisRGB.get_color(k as f32 / (VIRIDIS_LEVELS - 1) as f32);
                [c.0, c.1, c.2]
            })
            .collect();
        rgb.extend((0..GREYS).map(|k| {
            let g = (255 * k / (GREYS - 1)) as u8;
            [g, g, g]
        }));
        // The region colours and their blends with white and black (text
        // and edges are anti-aliased onto them).
        for c in [REGION_FILL, REGION_LINE] {
            for f in [1.0, 0.75, 0.5, 0.25] {
                rgb.push([c.0, c.1, c.2].map(|v| (f64::from(v) * f) as u8));
                rgb.push([c.0, c.1, c.2].map(|v| (f64::from(v) * f + 255.0 * (1.0 - f)) as u8));
            }
        }
        rgb.truncate(256);
        let lut = (0..32 * 32 * 32)
            .map(|k| {
                let q = [(k >> 10) & 31, (k >> 5) & 31, k & 31].map(|v| v * 255 / 31);
                rgb.iter()
                    .enumerate()
                    .min_by_key(|(_, c)| {
                        (0..3).map(|i| (i32::from(c[i]) - q[i]).pow(2)).sum::<i32>()
                    })
                    .map_or(0, |(i, _)| i as u8)
            })
            .collect();
        Palette { rgb, lut }
    }

    fn index(&self, rgb: &[u8]) -> Vec<u8> {
        rgb.chunks_exact(3)
            .map(|c| {
                let k = (usize::from(c[0] >> 3) << 10)
                    | (usize::from(c[1] >> 3) << 5)
                    | usize::from(c[2] >> 3);
                self.lut[k]
            })
            .collect()
    }
}

/// Three significant digits, plain between 0.001 and 9999.
fn num(v: f64) -> String {
    if v == 0.0 || !v.is_finite() {
        return format!("{v}");
    }
    let e = v.abs().log10().floor() as i32;
    if (-3..4).contains(&e) {
        let decimals = (2 - e).max(0) as usize;
        format!("{v:.decimals$}")
    } else {
        format!("{v:.2e}")
    }
}

/// The part of the frame behind a wall (x − p)·n < 0, as a polygon
/// (Sutherland–Hodgman against one half-plane).
fn behind(frame: Frame, point: [f64; 2], normal: [f64; 2]) -> Vec<(f64, f64)> {
    let [x0, y0, x1, y1] = frame;
    let corners = [(x0, y0), (x1, y0), (x1, y1), (x0, y1)];
    let d = |p: (f64, f64)| (p.0 - point[0]) * normal[0] + (p.1 - point[1]) * normal[1];
    let mut out = Vec::new();
    for k in 0..4 {
        let (a, b) = (corners[k], corners[(k + 1) % 4]);
        let (da, db) = (d(a), d(b));
        if da <= 0.0 {
            out.push(a);
        }
        if (da < 0.0) != (db < 0.0) && da != db {
            let s = da / (da - db);
            out.push((a.0 + s * (b.0 - a.0), a.1 + s * (b.1 - a.1)));
        }
    }
    out
}

/// The wall's line inside the frame, as its two ends.
fn wall_line(frame: Frame, point: [f64; 2], normal: [f64; 2]) -> Option<[(f64, f64); 2]> {
    let poly = behind(frame, point, normal);
    let d = |p: &(f64, f64)| (p.0 - point[0]) * normal[0] + (p.1 - point[1]) * normal[1];
    let scale = (frame[2] - frame[0]).max(frame[3] - frame[1]);
    let on: Vec<(f64, f64)> = poly
        .into_iter()
        .filter(|p| d(p).abs() <= 1e-9 * scale)
        .collect();
    (on.len() >= 2).then(|| [on[0], on[on.len() - 1]])
}

/// Draws what surrounds the particles at time `t` (`overlay` false: the
/// background, axes, shaded sides of the walls acting at `t`, regions and
/// colour bar; true: those walls' lines, region outlines and the title),
/// returning the plot area in pixels.
fn chrome(
    buf: &mut [u8],
    l: &Layout,
    scene: &Scene,
    t: f64,
    (range, clipped): ((f64, f64), bool),
    title: &str,
    overlay: bool,
) -> std::result::Result<[i32; 4], String> {
    let e = |e: &dyn std::fmt::Display| e.to_string();
    let root = BitMapBackend::with_buffer(buf, l.size).into_drawing_area();
    if !overlay {
        root.fill(&WHITE).map_err(|x| e(&x))?;
    }
    let (top, rest) = root.split_vertically(TITLE_H);
    let (plot, bar) = rest.split_horizontally(l.size.0 - BAR_W);
    let [x0, y0, x1, y1] = l.frame;
    let mut chart = ChartBuilder::on(&plot)
        .margin(MARGIN)
        .x_label_area_size(BOTTOM_H)
        .y_label_area_size(LEFT_W)
        .build_cartesian_2d(x0..x1, y0..y1)
        .map_err(|x| e(&x))?;
    let (px, py) = chart.plotting_area().get_pixel_range();
    let area = [px.start, py.start, px.end, py.end];
    if overlay {
        for w in scene.file.walls.values().filter(|w| acts(w, t)) {
            if let Some([a, b]) = wall_line(l.frame, w.point, w.normal) {
                chart
                    .draw_series(std::iter::once(PathElement::new(
                        vec![a, b],
                        WALL_LINE.stroke_width(3),
                    )))
                    .map_err(|x| e(&x))?;
            }
        }
        for c in scene.file.constraints.values() {
            let r = [
                (c.min[0].max(x0), c.min[1].max(y0)),
                (c.max[0].min(x1), c.max[1].min(y1)),
            ];
            if r[0].0 < r[1].0 && r[0].1 < r[1].1 {
                chart
                    .draw_series(std::iter::once(Rectangle::new(
                        r,
                        REGION_LINE.stroke_width(2),
                    )))
                    .map_err(|x| e(&x))?;
            }
        }
        // 18 px, smaller on narrow images so the time stays in.
        let size = (f64::from(l.size.0) / 34.0).clamp(11.0, 18.0);
        top.draw(&Text::new(
            title.to_string(),
            (MARGIN as i32, 8),
            ("sans-serif", size).into_font().color(&BLACK),
        ))
        .map_err(|x| e(&x))?;
        root.present().map_err(|x| e(&x))?;
        return Ok(area);
    }
    chart
        .configure_mesh()
        .x_desc("x (m)")
        .y_desc("y (m)")
        .label_style(("sans-serif", 13))
        .x_labels(7)
        .y_labels(7)
        .light_line_style(RGBColor(245, 245, 245))
        .draw()
        .map_err(|x| e(&x))?;
    for w in scene.file.walls.values().filter(|w| acts(w, t)) {
        let poly = behind(l.frame, w.point, w.normal);
        if poly.len() >= 3 {
            chart
                .draw_series(std::iter::once(Polygon::new(poly, WALL_FILL.filled())))
                .map_err(|x| e(&x))?;
        }
    }
    for (name, c) in &scene.file.constraints {
        let r = [
            (c.min[0].max(x0), c.min[1].max(y0)),
            (c.max[0].min(x1), c.max[1].min(y1)),
        ];
        if r[0].0 < r[1].0 && r[0].1 < r[1].1 {
            chart
                .draw_series(std::iter::once(Rectangle::new(r, REGION_FILL.filled())))
                .map_err(|x| e(&x))?;
            chart
                .draw_series(std::iter::once(Text::new(
                    name.clone(),
                    (r[0].0, r[1].1),
                    ("sans-serif", 12).into_font().color(&REGION_LINE),
                )))
                .map_err(|x| e(&x))?;
        }
    }
    // The colour bar, ticks at five values.
    let bar = bar.margin(MARGIN + 4, BOTTOM_H + MARGIN, 6, 10);
    let (_, bh) = bar.dim_in_pixel();
    let bh = bh as i32;
    for y in 0..bh {
        let f = 1.0 - f64::from(y) / f64::from((bh - 1).max(1));
        let c: RGBColor = ViridisRGB.get_color(f as f32);
        bar.draw(&Rectangle::new([(0, y), (16, y + 1)], c.filled()))
            .map_err(|x| e(&x))?;
    }
    let font = ("sans-serif", 12).into_font().color(&BLACK);
    for k in 0..5 {
        let f = f64::from(k) / 4.0;
        let v = range.0 + f * (range.1 - range.0);
        let y = ((1.0 - f) * f64::from(bh - 1)) as i32;
        bar.draw(&PathElement::new(vec![(16, y), (21, y)], BLACK))
            .map_err(|x| e(&x))?;
        let text = if k == 4 && clipped {
            format!("≥ {}", num(v))
        } else {
            num(v)
        };
        bar.draw(&Text::new(text, (24, y - 6), font.clone()))
            .map_err(|x| e(&x))?;
    }
    root.present().map_err(|x| e(&x))?;
    Ok(area)
}

/// Paints each particle's square into `buf` (RGB, `width` pixels a row),
/// clipped to the plot area.
fn paint(
    buf: &mut [u8],
    width: u32,
    area: [i32; 4],
    frame: Frame,
    s: &Snapshot,
    range: (f64, f64),
) {
    let [px0, py0, px1, py1] = area.map(f64::from);
    let sx = (px1 - px0) / (frame[2] - frame[0]);
    let sy = (py1 - py0) / (frame[3] - frame[1]);
    let colours: Vec<[u8; 3]> = (0..256)
        .map(|k| {
            let c: RGBColor = ViridisRGB.get_color(k as f32 / 255.0);
            [c.0, c.1, c.2]
        })
        .collect();
    let span = (range.1 - range.0).max(f64::MIN_POSITIVE);
    let w = width as usize;
    for i in 0..s.x.len() {
        let v = f64::from(s.value[i]);
        if !v.is_finite() {
            continue;
        }
        let c = colours[(((v - range.0) / span).clamp(0.0, 1.0) * 255.0).round() as usize];
        let cx = px0 + (f64::from(s.x[i][0]) - frame[0]) * sx;
        let cy = py1 - (f64::from(s.x[i][1]) - frame[1]) * sy;
        // At least one pixel; half a side each way, rounded outwards to
        // whole pixels so neighbours tile without gaps.
        let hx = (0.5 * f64::from(s.side[i]) * sx).max(0.5);
        let hy = (0.5 * f64::from(s.side[i]) * sy).max(0.5);
        let (a, b) = (
            ((cx - hx).floor().max(px0)) as i32,
            ((cx + hx).ceil().min(px1)) as i32,
        );
        let (c0, c1) = (
            ((cy - hy).floor().max(py0)) as i32,
            ((cy + hy).ceil().min(py1)) as i32,
        );
        for y in c0..c1 {
            let row = y as usize * w;
            for x in a..b {
                let k = 3 * (row + x as usize);
                buf[k..k + 3].copy_from_slice(&c);
            }
        }
    }
}

/// Renders the snapshots of the run in `dir`.
pub fn render(dir: &Path, opts: &RenderOptions) -> Result<Rendered> {
    opts.check()?;
    register_font();
    let scene_path = dir.join("scene.resolved.toml");
    let text = std::fs::read_to_string(&scene_path).map_err(|e| {
        folder_error(format!(
            "{}: {e} (is {} a run's output folder?)",
            scene_path.display(),
            dir.display()
        ))
    })?;
    let name = dir
        .file_name()
        .map_or("run".into(), |n| n.to_string_lossy().to_string());
    let scene = Scene::from_str(&text, &scene_path.display().to_string(), &name, &[])?;
    let pvd_path = dir.join("particles.pvd");
    let pvd = std::fs::read_to_string(&pvd_path).map_err(|_| {
        folder_error(format!(
            "{}: no snapshots to render; set output.vtk_interval (e.g. --set output.vtk_interval=0.04) \
             and run the scene again",
            pvd_path.display()
        ))
    })?;
    let all = read_pvd(&pvd);
    let every = opts.every;
    let entries: Vec<(f64, String)> = all
        .iter()
        .enumerate()
        .filter(|(k, _)| k % every == 0 || k + 1 == all.len())
        .map(|(_, e)| e.clone())
        .collect();
    if entries.is_empty() {
        return Err(folder_error(format!(
            "{}: lists no snapshot",
            pvd_path.display()
        )));
    }
    let fallback_side = scene.bodies().next().map_or(scene.file.grid.h, |(_, b)| {
        scene.file.grid.h / f64::from(b.ppc.max(1))
    });
    let snaps: Vec<Snapshot> = entries
        .par_iter()
        .map(|(t, f)| snapshot(&dir.join(f), *t, opts.field, fallback_side))
        .collect::<Result<_>>()?;
    // One frame and one colour scale for the whole run.
    let mut frame = [
        f64::INFINITY,
        f64::INFINITY,
        f64::NEG_INFINITY,
        f64::NEG_INFINITY,
    ];
    let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
    for s in &snaps {
        for i in 0..s.x.len() {
            let (x, y, r) = (
                f64::from(s.x[i][0]),
                f64::from(s.x[i][1]),
                0.5 * f64::from(s.side[i]),
            );
            if x.is_finite() && y.is_finite() {
                frame = [
                    frame[0].min(x - r),
                    frame[1].min(y - r),
                    frame[2].max(x + r),
                    frame[3].max(y + r),
                ];
            }
            let v = f64::from(s.value[i]);
            if v.is_finite() {
                lo = lo.min(v);
                hi = hi.max(v);
            }
        }
    }
    if !frame[0].is_finite() {
        return Err(folder_error(format!(
            "{}: the snapshots hold no particles",
            dir.display()
        )));
    }
    let pad = 0.06 * (frame[2] - frame[0]).max(frame[3] - frame[1]).max(1e-9);
    let frame = [
        frame[0] - pad,
        frame[1] - pad,
        frame[2] + pad,
        frame[3] + pad,
    ];
    if !lo.is_finite() {
        (lo, hi) = (0.0, 1.0);
    }
    // Magnitudes start at zero; p_c (about p′0 and up) and the pressure
    // keep their least value, so the scale spans what changes.
    if lo >= 0.0 && !opts.field.scale_at_least() {
        lo = 0.0;
    }
    // A few outliers (a shear band's tip, a particle flung off) would
    // leave the rest one colour: beyond CLIP times the 99th percentile
    // the scale stops there, and the bar says "≥".
    let mut sample: Vec<f64> = snaps
        .iter()
        .flat_map(|s| s.value.iter().step_by((s.value.len() / 20_000).max(1)))
        .map(|v| f64::from(*v))
        .filter(|v| v.is_finite())
        .collect();
    sample.sort_by(f64::total_cmp);
    let clipped = match sample.get(sample.len() * 99 / 100) {
        Some(&p99) if p99 > lo && hi - lo > CLIP * (p99 - lo) => {
            hi = lo + CLIP * (p99 - lo);
            true
        }
        _ => false,
    };
    if hi <= lo {
        hi = lo + lo.abs().max(1e-12);
    }
    let range = (lo, hi);
    let l = layout(frame, opts.width);
    let (w, h) = l.size;
    // One background per set of walls acting: a gate is drawn until its
    // removal time and not after.
    let mut backgrounds: std::collections::BTreeMap<Vec<bool>, (Vec<u8>, [i32; 4])> =
        Default::default();
    let acting = |t: f64| -> Vec<bool> { scene.file.walls.values().map(|w| acts(w, t)).collect() };
    for s in &snaps {
        if let std::collections::btree_map::Entry::Vacant(e) = backgrounds.entry(acting(s.t)) {
            let mut buf = vec![255u8; (w * h * 3) as usize];
            let area = chrome(&mut buf, &l, &scene, s.t, (range, clipped), "", false)
                .map_err(|e| Error::io("cannot draw", dir, std::io::Error::other(e)))?;
            e.insert((buf, area));
        }
    }
    let out = opts.out.clone().unwrap_or_else(|| dir.join("render"));
    std::fs::create_dir_all(&out).map_err(|e| Error::io("cannot create", &out, e))?;
    let palette = Palette::new();
    let slug = opts.field.slug();
    // Frame k: its PNG written, its size, and its palette indices for the GIF.
    let draw = |k: usize, s: &Snapshot| -> Result<(PathBuf, usize, Vec<u8>)> {
        let (background, area) = &backgrounds[&acting(s.t)];
        let mut buf = background.clone();
        paint(&mut buf, w, *area, l.frame, s, range);
        let title = format!("{}: {}, t = {} s", scene.name, opts.field.label(), num(s.t));
        chrome(&mut buf, &l, &scene, s.t, (range, clipped), &title, true)
            .map_err(|e| Error::io("cannot draw", dir, std::io::Error::other(e)))?;
        let path = out.join(format!("{slug}_{k:05}.png"));
        let png = crate::chart::png_bytes(&buf, l.size)?;
        crate::output::write_atomic(&path, &png)?;
        Ok((path, png.len(), palette.index(&buf)))
    };
    // The first frame alone: from its size and time, what the whole render
    // will write and take, said before the rest is drawn.
    let first_start = std::time::Instant::now();
    let first = draw(0, &snaps[0])?;
    let estimate = Estimate {
        frames: snaps.len(),
        size: l.size,
        first_png: first.1,
        first_seconds: first_start.elapsed().as_secs_f64(),
        threads: rayon::current_num_threads(),
    };
    if opts.say_estimate {
        eprintln!("render: {}", estimate.text());
    }
    let gif = out.join(format!("{slug}.gif"));
    let mut anim = Gif::new(&gif, &palette, l.size, opts.fps, snaps.len())?;
    let mut frames = vec![first.0];
    anim.push(first.2)?;
    // The rest a few frames at a time, in parallel, each batch handed to
    // the GIF in order: the frames' pixels are held a batch at a time,
    // never the whole run's.
    let batch = 2 * estimate.threads.max(1);
    for (c, chunk) in snaps[1..].chunks(batch).enumerate() {
        let drawn: Vec<_> = chunk
            .par_iter()
            .enumerate()
            .map(|(j, s)| draw(1 + c * batch + j, s))
            .collect::<Result<_>>()?;
        for (path, _, idx) in drawn {
            frames.push(path);
            anim.push(idx)?;
        }
    }
    anim.finish()?;
    let mp4 = mp4(&out, slug, opts.fps);
    Ok(Rendered {
        frames,
        gif,
        mp4,
        particles: snaps.iter().map(|s| s.x.len()).max().unwrap_or(0),
        range,
        clipped,
        estimate,
    })
}

/// What a render will write and take, from its first frame.
#[derive(Debug, Clone, Copy)]
pub struct Estimate {
    pub frames: usize,
    /// Pixels of each frame (width, height).
    pub size: (u32, u32),
    /// Bytes of the first frame's PNG.
    pub first_png: usize,
    /// Seconds the first frame took to draw and write.
    pub first_seconds: f64,
    pub threads: usize,
}

impl Estimate {
    /// Bytes of the PNG frames: frames × the first frame's.
    pub fn png_bytes(&self) -> f64 {
        self.frames as f64 * self.first_png as f64
    }

    /// The GIF's uncompressed size, one byte a pixel a frame: its LZW
    /// frames of what changed come out smaller.
    pub fn gif_bytes_at_most(&self) -> f64 {
        self.frames as f64 * f64::from(self.size.0) * f64::from(self.size.1)
    }

    pub fn text(&self) -> String {
        let (w, h) = self.size;
        let seconds = self.first_seconds * self.frames as f64 / self.threads.max(1) as f64;
        format!(
            "{} frames of {w} x {h} px: about {} of PNG frames ({} each) and a GIF under {}, \
             in about {:.0} s",
            self.frames,
            bytes(self.png_bytes()),
            bytes(self.first_png as f64),
            bytes(self.gif_bytes_at_most()),
            seconds.max(1.0)
        )
    }
}

/// A size in bytes, KB, MB or GB (powers of 1000).
fn bytes(b: f64) -> String {
    match b {
        b if b >= 1e9 => format!("{:.1} GB", b / 1e9),
        b if b >= 1e6 => format!("{:.1} MB", b / 1e6),
        b if b >= 1e3 => format!("{:.0} KB", b / 1e3),
        b => format!("{b:.0} B"),
    }
}

/// `lme-mpm render`: renders, says what it wrote and how long it took,
/// and gives the exit code (2 for a folder it cannot render).
pub fn command(
    dir: &Path,
    field: Field,
    fps: f64,
    width: u32,
    every: usize,
    out: Option<PathBuf>,
) -> std::process::ExitCode {
    let start = std::time::Instant::now();
    let opts = RenderOptions {
        field,
        fps,
        width,
        out,
        every,
        say_estimate: true,
    };
    match render(dir, &opts) {
        Ok(r) => {
            let folder = r.gif.parent().unwrap_or(Path::new("."));
            eprintln!(
                "render: {} frames of up to {} particles coloured by {} from {} to {} in {:.1} s",
                r.frames.len(),
                r.particles,
                field.label(),
                num(r.range.0),
                num(r.range.1),
                start.elapsed().as_secs_f64()
            );
            eprintln!(
                "outputs: {} ({}_00000.png ...), {}{}",
                folder.display(),
                field.slug(),
                r.gif.display(),
                r.mp4.as_ref().map_or(
                    " (no MP4: ffmpeg is not on the PATH)".to_string(),
                    |m| format!(", {}", m.display())
                )
            );
            std::process::ExitCode::SUCCESS
        }
        Err(e) => {
            eprintln!("error: {e}");
            std::process::ExitCode::from(e.exit_code() as u8)
        }
    }
}

/// The animated GIF, fed frame by frame (palette indices), holding only
/// the last frame's indices and the encoded bytes.
struct Gif<'a> {
    path: &'a Path,
    enc: gif::Encoder<Vec<u8>>,
    last: Option<Vec<u8>>,
    width: usize,
    delay: u16,
    frames: usize,
    pushed: usize,
}

impl<'a> Gif<'a> {
    fn new(
        path: &'a Path,
        palette: &Palette,
        size: (u32, u32),
        fps: f64,
        frames: usize,
    ) -> Result<Gif<'a>> {
        let flat: Vec<u8> = palette.rgb.iter().flatten().copied().collect();
        // `WIDTH` keeps both sizes within the GIF's 16 bits.
        let (w, h) = (
            u16::try_from(size.0).map_err(|_| gif_error(path, "too wide"))?,
            u16::try_from(size.1).map_err(|_| gif_error(path, "too tall"))?,
        );
        let mut enc = gif::Encoder::new(Vec::new(), w, h, &flat).map_err(|x| gif_error(path, x))?;
        enc.set_repeat(gif::Repeat::Infinite)
            .map_err(|x| gif_error(path, x))?;
        Ok(Gif {
            path,
            enc,
            last: None,
            width: size.0 as usize,
            // GIF delays are in hundredths of a second.
            delay: (100.0 / fps.max(0.1)).round().clamp(2.0, 65535.0) as u16,
            frames,
            pushed: 0,
        })
    }

    fn push(&mut self, idx: Vec<u8>) -> Result<()> {
        let w = self.width;
        // After the first frame, only the rectangle that changed (the rest
        // stays on screen: disposal `Keep`).
        let [x0, y0, x1, y1] = match &self.last {
            None => [0, 0, w, idx.len() / w],
            Some(last) => changed(last, &idx, w),
        };
        let sub: Vec<u8> = (y0..y1)
            .flat_map(|y| idx[y * w + x0..y * w + x1].iter().copied())
            .collect();
        let mut f = gif::Frame {
            left: x0 as u16,
            top: y0 as u16,
            width: (x1 - x0) as u16,
            height: (y1 - y0) as u16,
            buffer: std::borrow::Cow::Owned(sub),
            delay: self.delay,
            dispose: gif::DisposalMethod::Keep,
            ..Default::default()
        };
        self.pushed += 1;
        if self.pushed == self.frames {
            // Hold the last frame a second before the loop restarts.
            f.delay = self.delay.max(100);
        }
        self.enc
            .write_frame(&f)
            .map_err(|x| gif_error(self.path, x))?;
        self.last = Some(idx);
        Ok(())
    }

    fn finish(self) -> Result<()> {
        let path = self.path;
        let bytes = self.enc.into_inner().map_err(|x| gif_error(path, x))?;
        crate::output::write_atomic(path, &bytes)
    }
}

fn gif_error(path: &Path, e: impl std::fmt::Display) -> Error {
    Error::io("cannot write", path, std::io::Error::other(e.to_string()))
}

/// The smallest rectangle [x0, y0, x1, y1) holding every pixel where `a`
/// and `b` differ (rows of `w`); one pixel when none does.
fn changed(a: &[u8], b: &[u8], w: usize) -> [usize; 4] {
    let h = a.len() / w;
    let (mut x0, mut y0, mut x1, mut y1) = (w, h, 0, 0);
    for y in 0..h {
        let (ra, rb) = (&a[y * w..(y + 1) * w], &b[y * w..(y + 1) * w]);
        if ra == rb {
            continue;
        }
        let first = ra.iter().zip(rb).position(|(p, q)| p != q).unwrap_or(0);
        let last = w - ra
            .iter()
            .rev()
            .zip(rb.iter().rev())
            .position(|(p, q)| p != q)
            .unwrap_or(0);
        (x0, x1, y0, y1) = (x0.min(first), x1.max(last), y0.min(y), y + 1);
    }
    if x1 <= x0 {
        [0, 0, 1, 1]
    } else {
        [x0, y0, x1, y1]
    }
}

/// An MP4 of the PNG frames when `ffmpeg` is on the PATH (else None).
fn mp4(out: &Path, slug: &str, fps: f64) -> Option<PathBuf> {
    let path = out.join(format!("{slug}.mp4"));
    let status = std::process::Command::new("ffmpeg")
        .args(["-y", "-loglevel", "error", "-framerate"])
        .arg(format!("{fps}"))
        .arg("-i")
        .arg(out.join(format!("{slug}_%05d.png")))
        .args(["-pix_fmt", "yuv420p"])
        .arg(&path)
        .stdin(std::process::Stdio::null())
        .stdout(std::process::Stdio::null())
        .stderr(std::process::Stdio::null())
        .status()
        .ok()?;
    status.success().then_some(path)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_side_behind_a_wall_is_clipped_to_the_frame() {
        let f = [0.0, 0.0, 2.0, 1.0];
        // A floor at y = 0.5: the lower half.
        let p = behind(f, [0.0, 0.5], [0.0, 1.0]);
        let area: f64 = (0..p.len())
            .map(|k| {
                let (a, b) = (p[k], p[(k + 1) % p.len()]);
                0.5 * (a.0 * b.1 - b.0 * a.1)
            })
            .sum();
        assert!((area.abs() - 1.0).abs() < 1e-12, "{p:?}");
        let [a, b] = wall_line(f, [0.0, 0.5], [0.0, 1.0]).unwrap();
        assert!((a.1 - 0.5).abs() < 1e-12 && (b.1 - 0.5).abs() < 1e-12);
        // A wall outside the frame, material on the frame's side: nothing.
        assert!(behind(f, [0.0, -1.0], [0.0, 1.0]).is_empty());
    }

    #[test]
    fn the_palette_maps_viridis_and_grey_to_themselves() {
        let p = Palette::new();
        assert_eq!(p.rgb.len(), 256);
        for k in [0usize, 60, 183] {
            let c = p.rgb[k];
            let i = p.index(&c)[0] as usize;
            let d: i32 = (0..3)
                .map(|j| (i32::from(p.rgb[i][j]) - i32::from(c[j])).abs())
                .sum();
            // 5 bits a channel: within 3 × 8 of the colour.
            assert!(d <= 24, "{c:?} -> {:?}", p.rgb[i]);
        }
        assert_eq!(
            p.rgb[p.index(&[255, 255, 255])[0] as usize],
            [255, 255, 255]
        );
    }
}
