//! Tables and charts of a set of runs, shared by `lme-mpm sweep` and the
//! papers' studies: the CSV (one row per run), markdown tables, error
//! against wall time with the Pareto front marked, error against cell size
//! with the fitted order per series, and the stability grid (completed or
//! unstable, when and why). Writes PNG and SVG beside each other.

use super::record::{Outcome, Record};
use crate::chart::{LineChart, Series, Status, StatusGrid};
use crate::error::Result;
use std::fmt::Write;
use std::path::{Path, PathBuf};

pub use super::number::sig;

/// A markdown table.
pub fn table(header: &[String], rows: &[Vec<String>]) -> String {
    let mut s = String::new();
    let _ = writeln!(s, "| {} |", header.join(" | "));
    let _ = writeln!(s, "|{}", "---|".repeat(header.len()));
    for r in rows {
        let _ = writeln!(s, "| {} |", r.join(" | "));
    }
    s
}

/// Markdown image line for a chart in `charts/` beside the document.
pub fn image(alt: &str, file: &str) -> String {
    format!("![{alt}](charts/{file})\n")
}

/// A CSV field: quoted when it holds a comma, quote or line break.
fn field(s: &str) -> String {
    if s.contains([',', '"', '\n']) {
        format!("\"{}\"", s.replace('"', "\"\""))
    } else {
        s.to_string()
    }
}

fn num<T: ToString>(v: Option<T>) -> String {
    v.map_or(String::new(), |v| v.to_string())
}

/// Every error figure's name among `records`, in order of first appearance.
pub fn figure_names(records: &[Record]) -> Vec<String> {
    let mut names: Vec<String> = Vec::new();
    for r in records {
        for (k, _) in &r.errors {
            if !names.contains(k) {
                names.push(k.clone());
            }
        }
    }
    names
}

/// Whether a figure is an error (not a value reported beside one, such
/// as a settlement): its name starts `rms`/`max` or says `error` or `_rms`.
pub fn is_error_name(name: &str) -> bool {
    name.starts_with("rms")
        || name.starts_with("max")
        || name.contains("error")
        || name.contains("_rms")
}

/// The figure charts use by default: the first error the runs report.
pub fn default_metric(records: &[Record]) -> Option<String> {
    figure_names(records).into_iter().find(|n| is_error_name(n))
}

/// One row per run: `run`, the keys, `status`, `reason` (always quoted),
/// `reason_code`, `t`, `t_end`, `steps`, `wall_seconds`,
/// `particle_steps_per_second`, `particles`, `bytes_per_particle`, `backend`,
/// `h`, `error_source`, then every error figure.
pub fn csv(records: &[Record]) -> String {
    let mut keys: Vec<&str> = Vec::new();
    for r in records {
        for (k, _) in &r.keys {
            if !keys.contains(&k.as_str()) {
                keys.push(k);
            }
        }
    }
    let figures = figure_names(records);
    let mut s = String::from("run");
    for k in &keys {
        let _ = write!(s, ",{}", field(k));
    }
    s.push_str(",status,reason,reason_code,t,t_end,steps,wall_seconds,particle_steps_per_second,particles,bytes_per_particle,backend,h,error_source");
    for f in &figures {
        let _ = write!(s, ",{}", field(f));
    }
    s.push('\n');
    for r in records {
        s.push_str(&field(&r.id));
        for k in &keys {
            let _ = write!(s, ",{}", field(r.key(k).unwrap_or("")));
        }
        let _ = write!(
            s,
            ",{},\"{}\",{},{},{},{},{},{},{},{},{},{},{}",
            r.outcome.as_str(),
            r.reason.replace('"', "\"\""),
            field(&r.reason_code),
            num(r.t),
            num(r.t_end),
            num(r.steps),
            num(r.wall_seconds),
            num(r.particle_steps_per_second),
            num(r.particles),
            num(r.bytes_per_particle),
            field(&r.backend),
            num(r.h),
            field(&r.error_source)
        );
        for f in &figures {
            let _ = write!(s, ",{}", num(r.figure(f)));
        }
        s.push('\n');
    }
    s
}

/// Indices of the points no other point beats on both x (cost) and y
/// (error), cheapest first. Points with a non-finite coordinate are skipped.
pub fn pareto(points: &[(f64, f64)]) -> Vec<usize> {
    let mut order: Vec<usize> = (0..points.len())
        .filter(|&i| points[i].0.is_finite() && points[i].1.is_finite())
        .collect();
    order.sort_by(|&a, &b| {
        points[a]
            .0
            .total_cmp(&points[b].0)
            .then(points[a].1.total_cmp(&points[b].1))
    });
    let mut best = f64::INFINITY;
    order
        .into_iter()
        .filter(|&i| {
            let keep = points[i].1 < best;
            if keep {
                best = points[i].1;
            }
            keep
        })
        .collect()
}

/// Least-squares slope of ln y against ln x: the order p of y ≈ C x^p.
/// None with fewer than two distinct positive x.
pub fn fitted_order(points: &[(f64, f64)]) -> Option<f64> {
    let pts: Vec<(f64, f64)> = points
        .iter()
        .filter(|p| p.0 > 0.0 && p.1 > 0.0 && p.0.is_finite() && p.1.is_finite())
        .map(|p| (p.0.ln(), p.1.ln()))
        .collect();
    let n = pts.len() as f64;
    let (mx, my) = (
        pts.iter().map(|p| p.0).sum::<f64>() / n,
        pts.iter().map(|p| p.1).sum::<f64>() / n,
    );
    let sxx: f64 = pts.iter().map(|p| (p.0 - mx).powi(2)).sum();
    let sxy: f64 = pts.iter().map(|p| (p.0 - mx) * (p.1 - my)).sum();
    (pts.len() >= 2 && sxx > 1e-24).then(|| sxy / sxx)
}

/// A series of points with its look.
#[derive(Debug, Clone)]
pub struct Curve {
    pub label: String,
    /// (x, y); need not be sorted.
    pub points: Vec<(f64, f64)>,
    /// Index into the chart palette.
    pub color: usize,
    pub dashed: bool,
}

fn stems(stem: &Path) -> Vec<PathBuf> {
    vec![stem.with_extension("png"), stem.with_extension("svg")]
}

/// A point on the Pareto front: (curve index, point index in that curve).
pub type OnFront = (usize, usize);

/// Error against wall time (log-log), one line per curve, and the Pareto
/// front over all their points as a dashed grey line. Returns the files
/// written and the front as (curve index, point index), cheapest first.
pub fn front_chart(
    title: &str,
    y_label: &str,
    curves: &[Curve],
    stem: &Path,
) -> Result<(Vec<PathBuf>, Vec<OnFront>)> {
    let mut c = LineChart::new(title, "wall time of the run (s)", y_label).log_log();
    let mut all = Vec::new();
    for (ci, cv) in curves.iter().enumerate() {
        let mut pts = cv.points.clone();
        pts.sort_by(|a, b| a.0.total_cmp(&b.0));
        let s = Series::line(cv.label.clone(), pts, cv.color).markers();
        c.series.push(if cv.dashed { s.dashed() } else { s });
        all.extend(
            cv.points
                .iter()
                .enumerate()
                .filter(|(_, p)| p.0 > 0.0 && p.1 > 0.0)
                .map(|(pi, p)| ((ci, pi), *p)),
        );
    }
    let pts: Vec<(f64, f64)> = all.iter().map(|a| a.1).collect();
    let front: Vec<(usize, usize)> = pareto(&pts).into_iter().map(|i| all[i].0).collect();
    if !front.is_empty() {
        let line: Vec<(f64, f64)> = front
            .iter()
            .map(|&(ci, pi)| curves[ci].points[pi])
            .collect();
        c.series
            .push(Series::line("Pareto front", line, 7).dashed().markers());
    }
    c.size = (900, 560);
    c.legend = plotters::chart::SeriesLabelPosition::LowerLeft;
    c.save(stem)?;
    Ok((stems(stem), front))
}

/// Error against cell size (log-log), one line per curve, its fitted order
/// in the legend ("… p = 1.98"). Returns the files and the orders.
pub fn convergence_chart(
    title: &str,
    x_label: &str,
    y_label: &str,
    curves: &[Curve],
    stem: &Path,
) -> Result<(Vec<PathBuf>, Vec<Option<f64>>)> {
    let mut c = LineChart::new(title, x_label, y_label).log_log();
    let mut orders = Vec::new();
    for cv in curves {
        let mut pts = cv.points.clone();
        pts.sort_by(|a, b| a.0.total_cmp(&b.0));
        let p = fitted_order(&pts);
        orders.push(p);
        let label = match p {
            Some(p) => format!("{}, p = {:.2}", cv.label, p),
            None => cv.label.clone(),
        };
        let s = Series::line(label, pts, cv.color).markers();
        c.series.push(if cv.dashed { s.dashed() } else { s });
    }
    c.size = (900, 560);
    c.legend = plotters::chart::SeriesLabelPosition::LowerRight;
    c.save(stem)?;
    Ok((stems(stem), orders))
}

/// A cell of the stability grid: its colour, its text in the image (a few
/// short lines) and in markdown. `figure` is the error shown when completed.
pub fn status_cell(r: Option<&Record>, figure: Option<String>) -> (Status, String, String) {
    let Some(r) = r else {
        return (Status::Missing, "-".into(), "-".into());
    };
    let t = r.t.map_or("?".into(), sig);
    match r.outcome {
        Outcome::Completed => (
            Status::Ok,
            format!(
                "ok{}",
                figure.as_ref().map_or(String::new(), |e| format!("\n{e}"))
            ),
            format!("ok{}", figure.map_or(String::new(), |e| format!(" ({e})"))),
        ),
        Outcome::Unstable => (
            Status::Failed,
            format!("t = {t} s\n{}", r.reason_code),
            format!("**unstable** at {t} s: {}", r.reason),
        ),
        Outcome::Interrupted => (
            Status::Error,
            format!("t = {t} s\ninterrupted"),
            format!("interrupted at {t} s"),
        ),
        Outcome::Missing => (
            Status::Missing,
            "missing".into(),
            format!("missing: {}", r.reason),
        ),
        o => (
            Status::Error,
            o.as_str().into(),
            format!("{}: {}", o.as_str(), r.reason),
        ),
    }
}

/// The stability grid (`stem`.png/.svg): rows × columns of cells.
pub fn stability_chart(
    title: &str,
    rows: Vec<String>,
    cols: Vec<String>,
    cells: Vec<Vec<(Status, String)>>,
    stem: &Path,
) -> Result<Vec<PathBuf>> {
    StatusGrid {
        title: title.to_string(),
        rows,
        cols,
        cells,
    }
    .save(stem)?;
    Ok(stems(stem))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_pareto_front_keeps_what_nothing_beats() {
        // (cost, error): b is beaten by a (cheaper and more accurate), d by c.
        let pts = [
            (1.0, 5.0),
            (2.0, 6.0),
            (3.0, 2.0),
            (4.0, 2.5),
            (5.0, 1.0),
            (0.5, f64::NAN),
        ];
        assert_eq!(pareto(&pts), vec![0, 2, 4]);
    }

    #[test]
    fn the_fitted_order_is_the_slope_in_log_log() {
        let pts: Vec<(f64, f64)> = [0.1, 0.05, 0.025]
            .iter()
            .map(|&h| (h, 3.0 * h * h))
            .collect();
        assert!((fitted_order(&pts).unwrap() - 2.0).abs() < 1e-12);
        assert_eq!(fitted_order(&pts[..1]), None);
        assert_eq!(fitted_order(&[(0.1, 1.0), (0.1, 2.0)]), None);
    }

    #[test]
    fn csv_quotes_what_needs_it_and_always_the_reason() {
        let mut r = Record::missing("a", vec![("k".into(), "x,y".into())], "why, \"so\"");
        r.errors = vec![("rms".into(), 0.5)];
        let text = csv(&[r]);
        let row = text.lines().nth(1).unwrap();
        assert!(
            row.starts_with("a,\"x,y\",missing,\"why, \"\"so\"\"\","),
            "{row}"
        );
        assert!(row.ends_with(",0.5"), "{row}");
        assert_eq!(default_metric(&[]), None);
    }
}
