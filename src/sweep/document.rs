//! A sweep's results for people: `sweep.csv`, the three charts (error
//! against wall time with the Pareto front, error against the resolution
//! with fitted orders, the stability grid) and `sweep.md`, which holds the
//! table and the charts so the sweep reads without a plotting tool.

use super::collect::{resolution_of, series_key};
use super::plan::Plan;
use super::record::Record;
use super::report::{self, Curve, sig, table};
use crate::error::Result;
use std::fmt::Write;
use std::path::{Path, PathBuf};

/// What `write` produced.
#[derive(Debug, Clone)]
pub struct Written {
    pub records: Vec<Record>,
    /// The figure the charts use (none when no run reports an error).
    pub metric: Option<String>,
    /// Every file written (sweep.csv, sweep.md, charts).
    pub files: Vec<PathBuf>,
}

/// One series of a sweep: its label and its runs (indices into records).
struct Group {
    label: String,
    members: Vec<usize>,
}

fn groups(
    plan: &Plan,
    records: &[Record],
    row_key: impl Fn(&Record) -> Vec<(String, String)>,
) -> Vec<Group> {
    let mut out: Vec<(Vec<(String, String)>, Group)> = Vec::new();
    for (i, r) in records.iter().enumerate() {
        let key = row_key(r);
        match out.iter_mut().find(|(k, _)| *k == key) {
            Some((_, g)) => g.members.push(i),
            None => {
                let label = if key.is_empty() {
                    plan.scene_name.clone()
                } else {
                    key.iter()
                        .map(|(k, v)| {
                            let short = plan
                                .axes
                                .iter()
                                .find(|a| &a.key == k)
                                .map_or(k.clone(), |a| a.short_name(&plan.axes));
                            format!("{short}={v}")
                        })
                        .collect::<Vec<_>>()
                        .join(", ")
                };
                out.push((
                    key,
                    Group {
                        label,
                        members: vec![i],
                    },
                ))
            }
        }
    }
    out.into_iter().map(|(_, g)| g).collect()
}

/// Unit of a resolution key, for axis labels.
fn unit(key: &str) -> &'static str {
    match key {
        "grid.h" => " (m)",
        "solver.dt" => " (s)",
        _ => "",
    }
}

/// The unit of an error figure, from its name (summary.json's and the
/// sweep's `ref_*` figures): relative ones are fractions of the field's
/// scale; absolute ones in m, m/s or Pa.
pub fn metric_label(name: &str) -> String {
    let unit = if name.ends_with("_relative") || name.contains("rel_error") {
        "relative to the field's scale, 1 = 100 %"
    } else if name.contains("velocity") || name.contains("_v_") || name.starts_with("v_") {
        "m/s"
    } else if name.contains("stress") || name.contains("sigma") {
        "Pa"
    } else if name.contains("displacement")
        || name.contains("settlement")
        || name.contains("deflection")
        || name.contains("_u_")
        || name.starts_with("u_")
    {
        "m"
    } else {
        ""
    };
    if unit.is_empty() {
        name.to_string()
    } else {
        format!("{name} ({unit})")
    }
}

/// Writes sweep.csv, the charts and sweep.md into `dir`.
pub fn write(
    plan: &Plan,
    dir: &Path,
    records: Vec<Record>,
    metric: Option<String>,
) -> Result<Written> {
    let mut files = Vec::new();
    let csv_path = dir.join("sweep.csv");
    crate::output::write_atomic(&csv_path, report::csv(&records).as_bytes())?;
    files.push(csv_path);
    let metric = metric.or_else(|| report::default_metric(&records));
    let doc = Doc {
        plan,
        dir,
        records: &records,
        metric: metric.as_deref(),
    };
    let mut md = doc.intro();
    md.push_str(&doc.runs_table());
    if let Some(m) = doc.metric {
        let series = groups(plan, &records, |r| series_key(plan, r));
        md.push_str(&doc.front(m, &series, &mut files)?);
        md.push_str(&doc.convergence(m, &series, &mut files)?);
    }
    md.push_str(&doc.stability(&mut files)?);
    let md_path = dir.join("sweep.md");
    crate::output::write_atomic(&md_path, md.as_bytes())?;
    files.push(md_path);
    Ok(Written {
        records,
        metric,
        files,
    })
}

/// What every part of sweep.md reads.
struct Doc<'a> {
    plan: &'a Plan,
    dir: &'a Path,
    records: &'a [Record],
    /// The charted figure, if any run reports one.
    metric: Option<&'a str>,
}

impl Doc<'_> {
    /// The charted figure of a completed run, when finite and positive.
    fn value(&self, r: &Record) -> Option<f64> {
        self.metric
            .and_then(|m| r.figure(m))
            .filter(|e| r.completed() && e.is_finite() && *e > 0.0)
    }

    /// Title, what was varied, how many runs completed, and what the errors
    /// are measured against.
    fn intro(&self) -> String {
        let (plan, records) = (self.plan, self.records);
        let mut md = String::new();
        let n = records.len();
        let completed = records.iter().filter(|r| r.completed()).count();
        let axes_text: Vec<String> = plan
            .axes
            .iter()
            .map(|a| format!("`{}` = {}", a.key, a.values.join(", ")))
            .collect();
        let _ = writeln!(
            md,
            "# Sweep of {}\n\nScene `{}`{}; varied: {}; backend `{}`. {n} runs: {completed} completed, {} not.\n",
            plan.scene_name,
            plan.scene.display(),
            if plan.sets.is_empty() {
                String::new()
            } else {
                format!(" with `--set {}`", plan.sets.join(" --set "))
            },
            axes_text.join("; "),
            plan.backend,
            n - completed
        );
        let source = if records.iter().any(|r| r.error_source == "exact") {
            "Errors: against the scene's exact solution, as each run's `summary.json` reports them."
                .to_string()
        } else if records.iter().any(|r| r.error_source.starts_with("finest")) {
            format!(
                "Errors: **no exact solution**, so each run is measured against the finest completed run of its \
                 series (same values of every key but `{}`; the table says which): RMS difference of the probe \
                 histories (displacement from the first sample, velocity, stress), the reference interpolated \
                 linearly in time, and of the final particle fields where both runs hold the same particles. \
                 Orders fitted against the finest run overstate the true order near it.",
                plan.resolution.as_deref().unwrap_or("")
            )
        } else {
            "Errors: none. The scene has no exact solution and no run could be compared with a finer one \
             (vary a resolution key such as `grid.h`, `solver.dt` or `solver.cfl`, with `[output.probes]` in the \
             scene or the same particles in every run)."
                .to_string()
        };
        let _ = writeln!(
            md,
            "{source}{}\n",
            self.metric
                .map_or(String::new(), |m| format!(" Charted figure: `{m}`."))
        );
        md
    }

    /// One row per run: its keys, how it ended, its cost and its error.
    fn runs_table(&self) -> String {
        let mut header = vec!["run".to_string()];
        header.extend(self.plan.axes.iter().map(|a| a.short_name(&self.plan.axes)));
        header.extend(
            [
                "status",
                "t (s)",
                "steps",
                "wall (s)",
                "particle-steps/s",
                "particles",
                "B/particle",
            ]
            .map(String::from),
        );
        header.push(self.metric.unwrap_or("error").to_string());
        header.push("measured against".into());
        let rows: Vec<Vec<String>> = self
            .records
            .iter()
            .map(|r| {
                let mut row = vec![format!("`{}`", r.id)];
                row.extend(r.keys.iter().map(|(_, v)| v.clone()));
                row.push(r.status_text().replace('|', "/"));
                row.push(r.t.map_or("-".into(), sig));
                row.push(r.steps.map_or("-".into(), |s| s.to_string()));
                row.push(r.wall_seconds.map_or("-".into(), sig));
                row.push(r.particle_steps_per_second.map_or("-".into(), sig));
                row.push(r.particles.map_or("-".into(), |p| p.to_string()));
                row.push(
                    r.bytes_per_particle
                        .map_or("-".into(), |b| format!("{b:.0}")),
                );
                row.push(
                    self.metric
                        .and_then(|m| r.figure(m))
                        .map_or("-".into(), sig),
                );
                row.push(match r.error_source.as_str() {
                    "" => "-".into(),
                    s => s.to_string(),
                });
                row
            })
            .collect();
        table(&header, &rows) + "\n"
    }

    /// One curve per series of (x, metric) over its runs that have both,
    /// and which run each point is.
    fn curves(
        &self,
        series: &[Group],
        x: &dyn Fn(&Record) -> Option<f64>,
    ) -> (Vec<Curve>, Vec<Vec<usize>>) {
        let records = self.records;
        series
            .iter()
            .enumerate()
            .map(|(k, g)| {
                let (points, runs): (Vec<(f64, f64)>, Vec<usize>) = g
                    .members
                    .iter()
                    .filter_map(|&i| Some(((x(&records[i])?, self.value(&records[i])?), i)))
                    .unzip();
                let curve = Curve {
                    label: g.label.clone(),
                    points,
                    color: k,
                    dashed: false,
                };
                (curve, runs)
            })
            .unzip()
    }

    /// Error against wall time, with the Pareto front named run by run.
    fn front(&self, m: &str, series: &[Group], files: &mut Vec<PathBuf>) -> Result<String> {
        let (curves, index) = self.curves(series, &|r| r.wall_seconds);
        if curves.iter().all(|c| c.points.is_empty()) {
            return Ok(String::new());
        }
        let (f, front) = report::front_chart(
            &format!("{}: {m} against wall time", self.plan.scene_name),
            &metric_label(m),
            &curves,
            &self.dir.join("sweep-front"),
        )?;
        files.extend(f);
        let front_runs: Vec<String> = front
            .iter()
            .map(|&(c, p)| {
                let r = &self.records[index[c][p]];
                format!(
                    "`{}` ({} s, {})",
                    r.id,
                    sig(r.wall_seconds.unwrap_or(f64::NAN)),
                    sig(self.value(r).unwrap_or(f64::NAN))
                )
            })
            .collect();
        Ok(format!(
            "![{m} against wall time](sweep-front.png)\n\n**Speed against accuracy.** Each point is one \
             completed run, one line per series; down and left is better. The Pareto front (no run is both \
             cheaper and more accurate), cheapest first: {}.\n\n",
            front_runs.join(", ")
        ))
    }

    /// Error against the resolution key, with the fitted order per series.
    fn convergence(&self, m: &str, series: &[Group], files: &mut Vec<PathBuf>) -> Result<String> {
        let plan = self.plan;
        let Some(res) = &plan.resolution else {
            return Ok(String::new());
        };
        let (curves, _) = self.curves(series, &|r| resolution_of(plan, r));
        if curves.iter().all(|c| c.points.is_empty()) {
            return Ok(String::new());
        }
        let (f, orders) = report::convergence_chart(
            &format!("{}: {m} against {res}", plan.scene_name),
            &format!("{res}{}", unit(res)),
            &metric_label(m),
            &curves,
            &self.dir.join("sweep-convergence"),
        )?;
        files.extend(f);
        let fitted: Vec<String> = curves
            .iter()
            .zip(&orders)
            .map(|(c, p)| {
                format!(
                    "{}: {}",
                    c.label,
                    p.map_or("- (fewer than two points)".into(), |p| format!("{p:.2}"))
                )
            })
            .collect();
        Ok(format!(
            "![{m} against {res}](sweep-convergence.png)\n\n**Order.** Least-squares slope of \
             ln({m}) against ln({res}) per series: {}.\n\n",
            fitted.join("; ")
        ))
    }

    /// The stability grid: one row per series, one column per value of the
    /// resolution key (or the last axis), completed or not, when and why.
    fn stability(&self, files: &mut Vec<PathBuf>) -> Result<String> {
        let (plan, records) = (self.plan, self.records);
        let col_key = plan
            .resolution
            .clone()
            .or_else(|| plan.axes.last().map(|a| a.key.clone()))
            .unwrap_or_default();
        let col_axis = plan.axes.iter().find(|a| a.key == col_key);
        let cols: Vec<String> = col_axis.map_or(Vec::new(), |a| a.values.clone());
        let rows = groups(plan, records, |r| {
            r.keys
                .iter()
                .filter(|(k, _)| *k != col_key)
                .cloned()
                .collect()
        });
        let mut cells = Vec::new();
        let mut md_rows = Vec::new();
        for g in &rows {
            let mut line = Vec::new();
            let mut md_line = vec![g.label.clone()];
            for c in &cols {
                let r = g
                    .members
                    .iter()
                    .map(|&i| &records[i])
                    .find(|r| r.key(&col_key) == Some(c.as_str()));
                let fig = r.and_then(|r| self.value(r)).map(sig);
                let (status, text, md_text) = report::status_cell(r, fig);
                line.push((status, text));
                md_line.push(md_text.replace('|', "/"));
            }
            cells.push(line);
            md_rows.push(md_line);
        }
        let short = col_axis.map_or(col_key.clone(), |a| a.short_name(&plan.axes));
        files.extend(report::stability_chart(
            &format!("{}: completed or unstable, when and why", plan.scene_name),
            rows.iter().map(|g| g.label.clone()).collect(),
            cols.iter().map(|c| format!("{short} =\n{c}")).collect(),
            cells,
            &self.dir.join("sweep-stability"),
        )?);
        let mut header = vec!["series".to_string()];
        header.extend(cols.iter().map(|c| format!("{short} = {c}")));
        Ok(format!(
            "![stability grid](sweep-stability.png)\n\n**Stability.** Completed (with the charted error) or not, \
             when and why:\n\n{}\n",
            table(&header, &md_rows)
        ))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn error_figures_carry_their_units() {
        assert_eq!(metric_label("rms_velocity"), "rms_velocity (m/s)");
        assert!(metric_label("rms_velocity_relative").contains("relative"));
        assert_eq!(metric_label("ref_probe_u_rms"), "ref_probe_u_rms (m)");
        assert_eq!(
            metric_label("ref_probe_stress_rms"),
            "ref_probe_stress_rms (Pa)"
        );
        assert_eq!(metric_label("settlement_top"), "settlement_top (m)");
    }
}
