//! Study `contact`: contact between bodies (issue 24), each benchmark
//! beside the single shared velocity field the scene has without its
//! `[contact]` pair.
//!
//! - Block on a slab (`cases/contact_block.toml`), μ = 0, 0.2, 0.4, 0.7:
//!   the block's velocity relative to the slab against
//!   g (sin θ − μ cos θ) R(t) while it slides, at rest for μ > tan θ.
//! - Two disks colliding (`cases/contact_disks.toml`, seeded on rings),
//!   head-on and off-centre, frictionless: contact onset against the time
//!   the surfaces meet, the largest overlap, the spin (none, exactly), the
//!   tangential velocity (kept), momentum; in the full study also the
//!   off-centre pair at R/h = 16 and with lattice-seeded disks at R/h = 8
//!   and 16, whose staircase edges spin them.
//! - A disk rolling on an elastic slab (`cases/contact_rolling.toml`) at
//!   R/h = 10, 20 (and 40 in the full study): the centre's displacement
//!   against ½ (2/3) g sin θ t².
//! - A rigid strip footing pressed into a Tresca soil (`cases/footing.toml`,
//!   full study, CPU), smooth and rough, h = 0.1, 0.05 and 0.025 m: the
//!   peak pressure against Prandtl's (2 + π) c, and the load–settlement
//!   curves.
//!
//! Everything is measured from particle snapshots (`BodyMotion`), so the
//! figures do not depend on the run's own score.

use super::runner::{Job, JobResult};
use super::spec::Study;
use super::{backend_slug, image, sig, table};
use crate::cases::{CONTACT_BLOCK, CONTACT_DISKS, CONTACT_ROLLING, FOOTING};
use crate::chart::{LineChart, Series};
use crate::error::Result;
use crate::exact::sliding::SlidingBlock;
use crate::model::Particles;
use crate::simulation::BackendChoice;
use std::fmt::Write;
use std::path::{Path, PathBuf};

pub use crate::exact::bodies::{BodyMotion, body_motion};

/// How far body 0's particle domains reach past body 1's along the line
/// from 0's centre to 1's (m; negative: apart). Domains are squares of
/// half-width ½ sqrt(V), read along the line as their half-width.
pub fn overlap(p: &Particles, b: &[BodyMotion]) -> f64 {
    let d = [
        b[1].centre[0] - b[0].centre[0],
        b[1].centre[1] - b[0].centre[1],
    ];
    let len = d[0].hypot(d[1]).max(f64::MIN_POSITIVE);
    let u = [d[0] / len, d[1] / len];
    let (mut reach0, mut reach1) = (f64::NEG_INFINITY, f64::INFINITY);
    for i in 0..p.len() {
        let l = 0.5 * (p.mass[i] / p.rho[i]).sqrt();
        let s = p.x[i][0] * u[0] + p.x[i][1] * u[1];
        match p.body[i] {
            0 => reach0 = reach0.max(s + l),
            1 => reach1 = reach1.min(s - l),
            _ => {}
        }
    }
    reach0 - reach1
}

/// A case's text without its `[contact.<name>]` table: one shared field.
/// Its `exact` line goes too: the pair's reference (`contact_sliding`,
/// `disk_impact`, ...) needs the pair.
pub fn one_field(case: &str, table_name: &str) -> String {
    let head = format!("[contact.{table_name}]");
    let start = case
        .find(&head)
        .unwrap_or_else(|| panic!("the case has no {head}"));
    let end = start + case[start..].find("\n\n").unwrap_or(case.len() - start);
    format!("{}{}", &case[..start], &case[end..])
        .lines()
        .filter(|l| !l.starts_with("exact = "))
        .map(|l| format!("{l}\n"))
        .collect()
}

/// The block case's incline: 30°, gravity 9.81 m/s² ramped by eq. 45 over
/// T = 0.2 s (as `cases/contact_block.toml` says).
fn block_exact(mu: f64) -> SlidingBlock {
    let th = 30f64.to_radians();
    SlidingBlock {
        tangent: [1.0, 0.0],
        normal: [0.0, 1.0],
        g_tangential: 9.81 * th.sin(),
        g_normal: 9.81 * th.cos(),
        mu,
        ramp_period: 0.2,
    }
}

/// The block's friction coefficients: sliding (0, 0.2, 0.4) and at rest
/// (0.7 > tan 30° = 0.577).
const BLOCK_MU: [f64; 4] = [0.0, 0.2, 0.4, 0.7];
/// The off-centre disks' line of centres at impact (30° off x) and its
/// tangent; impact speed 1 m/s each, radius 0.2 m.
const LINE: [f64; 2] = [0.866_025_403_784_438_6, 0.5];
const TANGENT: [f64; 2] = [-0.5, 0.866_025_403_784_438_6];
const DISK_R: f64 = 0.2;
/// When the disks' surfaces meet: 0.05 m apart, closing at 2 m/s (s).
const DISKS_MEET: f64 = 0.025;
/// The disks' cell in `cases/contact_disks.toml` (m): R/h = 8.
const DISKS_H: f64 = 0.025;
/// The head-on variant: the right disk on the left one's line.
const HEAD_ON: &str = "bodies.right.disks=[[0.75, 0.5, 0.2]]";
/// The rolling disk's radius (m) and the cell sizes of its grid study.
const ROLL_R: f64 = 0.5;

fn every(dt: f64, t_end: f64) -> Vec<f64> {
    let n = (t_end / dt).round() as usize;
    (1..=n).map(|k| k as f64 * dt).collect()
}

/// `lme-mpm study contact`.
pub const STUDY: Study = Study {
    slug: "contact",
    help: "Contact between bodies: block on a slab (μ = 0–0.7), two disks colliding head-on and \
         off-centre, a disk rolling on an elastic slab (R/h = 10–40), each beside the single \
         shared field; a strip footing on a Tresca soil against Prandtl's 5.14 c, smooth and \
         rough, three grids (full run only) (CPU; about 15 minutes, --quick about 1)",
    jobs: |quick, backends| Ok(jobs(quick, backends)),
    report,
};

pub fn jobs(quick: bool, backends: &[BackendChoice]) -> Vec<Job> {
    let mut out = Vec::new();
    for &b in backends {
        let s = backend_slug(b);
        // The block runs 26k steps (the stiff slab); `tests/contact.rs`
        // checks it, so the quick sweep leaves it out.
        let mus: Vec<f64> = if quick { Vec::new() } else { BLOCK_MU.to_vec() };
        for mu in mus {
            let mut j = Job::new(format!("{s}-block-mu{mu}"), CONTACT_BLOCK, "contact_block")
                .set(format!("contact.interface.friction={mu}"))
                .on(b)
                .tag("case", "block")
                .tag("fields", "pair")
                .tag("mu", mu);
            j.snapshot_times = every(0.025, 0.5);
            out.push(j);
        }
        let mut j = Job::new(
            format!("{s}-block-one-field"),
            one_field(CONTACT_BLOCK, "interface"),
            "contact_block",
        )
        .on(b)
        .tag("case", "block")
        .tag("fields", "one")
        .tag("mu", "-");
        j.snapshot_times = every(0.025, 0.5);
        if !quick {
            out.push(j);
        }
        // (geometry, fields, disks' seeding, cell): the case on both
        // geometries, then the off-centre pair on a finer grid and with
        // lattice-seeded disks.
        let disks: &[(&str, &str, &str, f64)] = if quick {
            &[
                ("off-centre", "pair", "rings", DISKS_H),
                ("off-centre", "one", "rings", DISKS_H),
            ]
        } else {
            &[
                ("head-on", "pair", "rings", DISKS_H),
                ("head-on", "one", "rings", DISKS_H),
                ("off-centre", "pair", "rings", DISKS_H),
                ("off-centre", "one", "rings", DISKS_H),
                ("off-centre", "pair", "rings", DISKS_H / 2.0),
                ("off-centre", "pair", "lattice", DISKS_H),
                ("off-centre", "pair", "lattice", DISKS_H / 2.0),
            ]
        };
        for &(geometry, fields, seeding, h) in disks {
            let text = if fields == "pair" {
                CONTACT_DISKS.to_string()
            } else {
                one_field(CONTACT_DISKS, "impact")
            };
            let mut j = Job::new(
                format!("{s}-disks-{geometry}-{fields}-{seeding}-h{h}"),
                text,
                "contact_disks",
            )
            .set("output.sample_interval=0.0005")
            .set(format!("grid.h={h}"))
            .set(format!("bodies.left.disk_layout=\"{seeding}\""))
            .set(format!("bodies.right.disk_layout=\"{seeding}\""))
            .on(b)
            .tag("case", "disks")
            .tag("geometry", geometry)
            .tag("fields", fields)
            .tag("seeding", seeding)
            .tag("h", h);
            if geometry == "head-on" {
                j = j.set(HEAD_ON);
            }
            j.snapshot_times = every(0.0025, 0.1);
            out.push(j);
        }
        let hs: &[f64] = if quick {
            &[0.05]
        } else {
            &[0.05, 0.025, 0.0125]
        };
        for &h in hs {
            for fields in ["pair", "one"] {
                if fields == "one" && h != hs[0] {
                    continue;
                }
                let text = if fields == "pair" {
                    CONTACT_ROLLING.to_string()
                } else {
                    one_field(CONTACT_ROLLING, "rolling")
                };
                let mut j = Job::new(
                    format!("{s}-rolling-h{h}-{fields}"),
                    text,
                    "contact_rolling",
                )
                .set(format!("grid.h={h}"))
                .on(b)
                .tag("case", "rolling")
                .tag("h", h)
                .tag("fields", fields);
                j.snapshot_times = every(0.025, 0.5);
                out.push(j);
            }
        }
    }
    if !quick {
        out.extend(footing_jobs());
    }
    out
}

/// The footing's grids (m): 10, 20 and 40 cells under its 1 m width.
pub const FOOTING_H: [f64; 3] = [0.1, 0.05, 0.025];
/// The footing's speed (m/s), as in `cases/footing.toml`: settlement = v t.
const FOOTING_V: f64 = 0.02;
/// The soil's cohesion (Pa) and the footing's width (m), as in the case.
const FOOTING_C: f64 = 1e4;
const FOOTING_B: f64 = 1.0;
/// Prandtl's limit pressure over c, (2 + π).
pub const PRANDTL: f64 = 2.0 + std::f64::consts::PI;

/// The footing's runs (full study, on the f64 CPU path whatever the study's
/// backends; `run_parity::footing_gpu_matches_cpu` holds the GPU to it):
/// smooth and rough on every grid with the cell-averaged volumetric strain
/// rate (the case's), and smooth with each particle's own on the two
/// coarser grids, to show the locking it removes.
fn footing_jobs() -> Vec<Job> {
    let mut out = Vec::new();
    for law in ["slip", "stick"] {
        for &h in &FOOTING_H {
            for vol in ["cell_average", "particle"] {
                if vol == "particle" && (law != "slip" || h < 0.05) {
                    continue;
                }
                out.push(
                    Job::new(format!("cpu-footing-{law}-{vol}-h{h}"), FOOTING, "footing")
                        .set(format!("grid.h={h}"))
                        .set(format!("contact.interface.law={law}"))
                        .set(format!("solver.volumetric_strain={vol}"))
                        .on(BackendChoice::Cpu)
                        .tag("case", "footing")
                        .tag("law", law)
                        .tag("volumetric", vol)
                        .tag("h", h),
                );
            }
        }
    }
    out
}

/// A footing run's (settlement in mm, q/c) at its samples: the pair's
/// vertical reaction (the last reaction of a sample) over B c.
pub fn footing_curve(r: &JobResult) -> Vec<(f64, f64)> {
    r.data().map_or(Vec::new(), |d| {
        d.samples
            .iter()
            .filter_map(|s| {
                let q = s.reactions.last()?[1] / (FOOTING_B * FOOTING_C);
                Some((1e3 * FOOTING_V * s.t, q))
            })
            .collect()
    })
}

/// (t, motion of each body) at a job's snapshots.
pub fn history(r: &JobResult) -> Vec<(f64, Vec<BodyMotion>)> {
    let Some(d) = r.data() else {
        return Vec::new();
    };
    d.snapshots
        .iter()
        .map(|(t, p)| {
            let n = p.body.iter().map(|&b| b as usize + 1).max().unwrap_or(0);
            (*t, body_motion(p, n))
        })
        .collect()
}

fn tagged<'a>(mine: &[&'a JobResult], tags: &[(&str, &str)]) -> Vec<&'a JobResult> {
    mine.iter()
        .copied()
        .filter(|r| tags.iter().all(|&(k, v)| r.job.tag_value(k) == Some(v)))
        .collect()
}

pub fn report(results: &[JobResult], dir: &Path, quick: bool) -> Result<(String, Vec<PathBuf>)> {
    let main = super::main_backend(results);
    let mine = super::on_backend(results, &main);
    let mut md = String::new();
    let mut charts = Vec::new();
    // A case with no run here (the quick sweep leaves the long ones out)
    // gets a line saying so, not an empty table and chart.
    let mut left_out = Vec::new();
    if tagged(&mine, &[("case", "block")]).is_empty() {
        left_out.push(
            "the block on a slab (`cases/contact_block.toml`, 26k steps; `tests/contact.rs` runs it)",
        );
    } else {
        charts.extend(block_section(&mine, dir, &mut md)?);
    }
    if tagged(&mine, &[("case", "disks")]).is_empty() {
        left_out.push("the colliding disks (`cases/contact_disks.toml`)");
    } else {
        charts.extend(disks_section(&mine, dir, &mut md)?);
    }
    if tagged(&mine, &[("case", "rolling")]).is_empty() {
        left_out.push("the disk rolling on a slab (`cases/contact_rolling.toml`)");
    } else {
        charts.extend(rolling_section(&mine, dir, &mut md)?);
    }
    let footing: Vec<&JobResult> = results
        .iter()
        .filter(|r| r.job.tag_value("case") == Some("footing"))
        .collect();
    if footing.is_empty() {
        left_out.push("the strip footing against Prandtl (`cases/footing.toml`)");
    } else {
        charts.extend(footing_section(&footing, dir, &mut md)?);
    }
    if !left_out.is_empty() {
        let _ = writeln!(
            md,
            "Not run {}: {}; `lme-mpm study contact` runs every case.\n",
            if quick { "by the quick sweep" } else { "here" },
            left_out.join(", ")
        );
    }
    Ok((md, charts))
}

/// The footing: peak q/c against Prandtl's, and the load–settlement chart.
fn footing_section(runs: &[&JobResult], dir: &Path, md: &mut String) -> Result<Vec<PathBuf>> {
    let _ = writeln!(
        md,
        "**Strip footing on a Tresca soil** (`cases/footing.toml`, CPU): a rigid footing 1 m wide \
         pressed at {FOOTING_V} m/s into a weightless soil 5 m × 2 m (E = 10 MPa, ν = 0.3, c = 10 kPa, \
         φ = ψ = 0), rollers on the sides, fixed base, linear shapes, NPC, 2 × 2 particles per cell; the \
         pair `interface` smooth (`slip`) or rough (`stick`). q is the pair's vertical reaction over the \
         width, settlement = {FOOTING_V} m/s × t. Prandtl's limit for both: (2 + π) c = {} c. \
         `volumetric`: the strain rate's volumetric part, the particle's own or its cell's mean \
         (`solver.volumetric_strain`, [methods](methods.md#cell-averaged-volumetric-strain-rate)).\n",
        sig(PRANDTL)
    );
    let header: Vec<String> = [
        "interface",
        "volumetric",
        "h (m)",
        "cells under the footing",
        "status",
        "peak q/c",
        "at settlement (mm)",
        "error against 5.14",
    ]
    .map(String::from)
    .to_vec();
    let mut rows = Vec::new();
    let mut c = LineChart::new(
        "Strip footing on a Tresca soil: load against settlement",
        "settlement (mm)",
        "q / c",
    );
    let mut top = 0.0f64;
    for (k, r) in runs.iter().enumerate() {
        let law = r.job.tag_value("law").unwrap_or("");
        let vol = r.job.tag_value("volumetric").unwrap_or("");
        let h: f64 = r
            .job
            .tag_value("h")
            .and_then(|v| v.parse().ok())
            .unwrap_or(0.0);
        let curve = footing_curve(r);
        let peak = curve
            .iter()
            .copied()
            .fold(None, |m: Option<(f64, f64)>, x| match m {
                Some(m) if m.1 >= x.1 => Some(m),
                _ => Some(x),
            });
        let interface = if law == "slip" { "smooth" } else { "rough" };
        rows.push(vec![
            interface.to_string(),
            vol.replace('_', " "),
            format!("{h}"),
            format!("{:.0}", FOOTING_B / h),
            if r.completed() {
                "completed".to_string()
            } else {
                super::failure_text(r)
            },
            peak.map_or("-".into(), |p| sig(p.1)),
            peak.map_or("-".into(), |p| sig(p.0)),
            peak.map_or("-".into(), |p| {
                format!("{:+.1} %", 100.0 * (p.1 / PRANDTL - 1.0))
            }),
        ]);
        top = curve.iter().map(|p| p.0).fold(top, f64::max);
        let mut series = Series::line(
            format!("{interface}, {}, h = {h}", vol.replace('_', " ")),
            curve,
            k,
        );
        if vol == "particle" {
            series = series.dashed();
        }
        c.series.push(series);
    }
    c.series
        .push(Series::line("Prandtl (2 + π) c", vec![(0.0, PRANDTL), (top, PRANDTL)], 7).dashed());
    md.push_str(&table(&header, &rows));
    md.push('\n');
    md.push_str(&image(
        "footing load against settlement",
        "study-contact-footing.png",
    ));
    md.push('\n');
    save(&mut c, dir, "study-contact-footing")
}

fn save(c: &mut LineChart, dir: &Path, stem: &str) -> Result<Vec<PathBuf>> {
    c.size = (900, 480);
    c.place_legend();
    c.save(&dir.join(stem))?;
    Ok([format!("{stem}.png"), format!("{stem}.svg")]
        .map(|f| dir.join(f))
        .to_vec())
}

/// The block on the slab: relative velocity against Coulomb's.
fn block_section(mine: &[&JobResult], dir: &Path, md: &mut String) -> Result<Vec<PathBuf>> {
    let _ = writeln!(
        md,
        "**Block on a slab** (`cases/contact_block.toml`): an elastic block (1 m × 0.5 m, E = 10 MPa) on a \
         stiffer slab (E = 100 MPa) held by a stick floor, gravity 9.81 m/s² tilted by 30° and ramped in over \
         0.1 s, h = 0.05 m, linear shapes, NPC; the pair `interface` with Coulomb friction μ. Exact: the \
         block slides relative to the slab at g (sin θ − μ cos θ) R(t) and rests for μ > tan 30° = 0.577. \
         The relative velocity is the difference of the bodies' mass-weighted mean velocities along x.\n"
    );
    let header: Vec<String> = [
        "fields",
        "μ",
        "status",
        "relative v at 0.5 s (m/s)",
        "exact (m/s)",
        "error",
    ]
    .map(String::from)
    .to_vec();
    let mut rows = Vec::new();
    let mut c = LineChart::new(
        "Block on a slab: velocity relative to the slab",
        "t (s)",
        "relative velocity (m/s)",
    );
    for (k, r) in tagged(mine, &[("case", "block")]).into_iter().enumerate() {
        let fields = r.job.tag_value("fields").unwrap_or("");
        let mu_tag = r.job.tag_value("mu").unwrap_or("-");
        let mu: f64 = mu_tag.parse().unwrap_or(0.2);
        let exact = block_exact(mu);
        let h = history(r);
        let pts: Vec<(f64, f64)> = h
            .iter()
            .filter(|(_, b)| b.len() >= 2)
            .map(|(t, b)| (*t, b[0].v[0] - b[1].v[0]))
            .collect();
        let label = if fields == "pair" {
            format!("μ = {mu_tag}")
        } else {
            "one field (μ = 0.2 declared, no pair)".into()
        };
        let last = pts.last().copied();
        let status = if r.completed() {
            "completed".to_string()
        } else {
            super::failure_text(r)
        };
        let (v, e, err) = match last {
            Some((t, v)) => {
                let e = exact.velocity(t);
                let err = if e > 0.0 {
                    format!("{} %", sig(100.0 * (v / e - 1.0)))
                } else {
                    format!(
                        "{} of g sin θ R(t)",
                        sig(v.abs() / block_exact(0.0).velocity(t))
                    )
                };
                (sig(v), sig(e), err)
            }
            None => ("-".into(), "-".into(), "-".into()),
        };
        rows.push(vec![
            fields.to_string(),
            mu_tag.to_string(),
            status,
            v,
            e,
            err,
        ]);
        c.series.push(Series::line(label, pts, k));
        if fields == "pair" {
            let ts = every(0.005, 0.5);
            c.series.push(
                Series::line(
                    format!("exact, μ = {mu_tag}"),
                    ts.iter().map(|&t| (t, exact.velocity(t))).collect(),
                    k,
                )
                .dashed(),
            );
        }
    }
    md.push_str(&table(&header, &rows));
    md.push('\n');
    md.push_str(&image("block relative velocity", "study-contact-block.png"));
    md.push('\n');
    save(&mut c, dir, "study-contact-block")
}

/// One collision's figures.
#[derive(Debug, Clone)]
pub struct Collision {
    /// First sample time with a non-zero pair reaction (s); None without a pair.
    pub onset: Option<f64>,
    /// Largest `overlap` over the snapshots (m).
    pub max_overlap: f64,
    /// Largest change of the total momentum from the first snapshot, over
    /// one disk's momentum.
    pub momentum_drift: f64,
    /// The bodies at the last snapshot.
    pub end: Vec<BodyMotion>,
}

/// A disks job's collision figures (None when it produced no snapshots).
pub fn collision(r: &JobResult) -> Option<Collision> {
    let d = r.data()?;
    let h = history(r);
    // Momentum before contact (the first snapshot, 2.5 ms): no other
    // force acts, and the seeded disks' masses differ by their lattice.
    let (_, b0) = h.first()?;
    let m = b0[0].mass;
    let p0 = [
        b0[0].mass * b0[0].v[0] + b0[1].mass * b0[1].v[0],
        b0[0].mass * b0[0].v[1] + b0[1].mass * b0[1].v[1],
    ];
    let onset = if r.job.tag_value("fields") == Some("pair") {
        // The pair's reaction is the last one (no constraints or walls).
        d.samples
            .iter()
            .find(|s| s.reactions.last().is_some_and(|f| f != &[0.0, 0.0]))
            .map(|s| s.t)
    } else {
        None
    };
    let mut max_overlap = f64::NEG_INFINITY;
    let mut drift = 0.0f64;
    for ((_, p), (_, b)) in d.snapshots.iter().zip(&h) {
        max_overlap = max_overlap.max(overlap(p, b));
        let px = b[0].mass * b[0].v[0] + b[1].mass * b[1].v[0];
        let py = b[0].mass * b[0].v[1] + b[1].mass * b[1].v[1];
        drift = drift.max((px - p0[0]).abs().max((py - p0[1]).abs()) / m);
    }
    Some(Collision {
        onset,
        max_overlap,
        momentum_drift: drift,
        end: h.last()?.1.clone(),
    })
}

/// The two disks: spin, tangential velocity, onset, overlap, momentum.
fn disks_section(mine: &[&JobResult], dir: &Path, md: &mut String) -> Result<Vec<PathBuf>> {
    let _ = writeln!(
        md,
        "**Two disks colliding** (`cases/contact_disks.toml`): elastic disks (R = 0.2 m, E = 10 MPa, \
         ρ = 1000 kg/m³) approach at 1 m/s each, 0.05 m apart, so their surfaces meet at {DISKS_MEET} s; \
         linear, NPC; frictionless pair `impact`. Off-centre, the line of centres at impact is \
         30° off x. Exact (frictionless): the forces pass through the centres, so neither disk spins \
         (ω R = 0) and each keeps its velocity along the contact tangent (v·t = ∓0.5 m/s off-centre, for \
         rigid disks; deformable ones slide on while the line of centres turns); total \
         momentum is kept. The case seeds its disks on rings (`disk_layout = \"rings\"`, round at the \
         particle scale); `lattice` is the cell's points inside the disk, whose edge is a staircase. \
         Onset: the first sample (every 0.5 ms) with a non-zero pair reaction. \
         Overlap: how far one body's particle domains reach into the other's along the line of centres \
         (snapshots every 2.5 ms), in cells of the run. Momentum drift: the largest change of Σ m v from the first snapshot, over one disk's momentum.\n"
    );
    let header: Vec<String> = [
        "geometry",
        "fields",
        "disks",
        "R/h",
        "onset (s)",
        "largest overlap (cells)",
        "ω R left / right (m/s)",
        "v·t left / right (m/s)",
        "separating v·u (m/s)",
        "momentum drift",
    ]
    .map(String::from)
    .to_vec();
    let dot = |a: [f64; 2], b: [f64; 2]| a[0] * b[0] + a[1] * b[1];
    let mut rows = Vec::new();
    let mut c = LineChart::new(
        "Off-centre disks: spin of the right disk",
        "t (s)",
        "ω R of the right disk (m/s)",
    );
    for (k, r) in tagged(mine, &[("case", "disks")]).into_iter().enumerate() {
        let geometry = r.job.tag_value("geometry").unwrap_or("");
        let fields = r.job.tag_value("fields").unwrap_or("");
        let seeding = r.job.tag_value("seeding").unwrap_or("");
        let h = r
            .job
            .tag_value("h")
            .and_then(|h| h.parse::<f64>().ok())
            .unwrap_or(DISKS_H);
        let (u, t) = if geometry == "head-on" {
            ([1.0, 0.0], [0.0, 1.0])
        } else {
            (LINE, TANGENT)
        };
        let mut row = vec![
            geometry.to_string(),
            fields.to_string(),
            seeding.to_string(),
            format!("{}", (DISK_R / h).round()),
        ];
        match collision(r) {
            Some(col) if col.end.len() >= 2 => {
                let [l, rt] = [col.end[0], col.end[1]];
                row.extend([
                    col.onset.map_or("-".into(), sig),
                    sig(col.max_overlap / h),
                    format!("{} / {}", sig(l.omega * DISK_R), sig(rt.omega * DISK_R)),
                    format!("{} / {}", sig(dot(l.v, t)), sig(dot(rt.v, t))),
                    sig(dot(rt.v, u) - dot(l.v, u)),
                    format!("{:.1e}", col.momentum_drift),
                ]);
            }
            _ => {
                row.push(super::failure_text(r));
                row.extend(std::iter::repeat_n("-".to_string(), 5));
            }
        }
        rows.push(row);
        if geometry == "off-centre" {
            let pts = history(r)
                .iter()
                .map(|(t, b)| (*t, b[1].omega * DISK_R))
                .collect();
            let label = if fields == "pair" {
                format!("pair, {seeding}, R/h {}", (DISK_R / h).round())
            } else {
                format!("one shared field, {seeding}")
            };
            c.series.push(Series::line(&label, pts, k));
        }
    }
    c.series
        .push(Series::line("exact (no spin)", vec![(0.0, 0.0), (0.1, 0.0)], 7).dashed());
    md.push_str(&table(&header, &rows));
    md.push('\n');
    md.push_str(&image("off-centre disks' spin", "study-contact-disks.png"));
    md.push('\n');
    save(&mut c, dir, "study-contact-disks")
}

/// The disk rolling on the slab: distance against (2/3) g sin θ.
fn rolling_section(mine: &[&JobResult], dir: &Path, md: &mut String) -> Result<Vec<PathBuf>> {
    let a = 2.0 / 3.0 * 9.81 * 30f64.to_radians().sin();
    let _ = writeln!(
        md,
        "**A disk rolling on an elastic body** (`cases/contact_rolling.toml`): the implicit-MPM paper's \
         hyperelastic disk (R = {ROLL_R} m, ρ = 7800 kg/m³, E = 200 MPa, seeded on rings) on a linear-elastic slab 0.25 m thick \
         (the same E and ρ) held by a stick floor, gravity 9.81 m/s² tilted by 30° at once, pair `rolling` \
         with μ = 0.5 (rolling without slip needs μ ≥ tan 30° / 3 = 0.19), linear, NPC, CFL 0.3. Exact: the \
         centre moves ½ a t² with a = (2/3) g sin 30° = {} m/s² ({} m at 0.5 s).\n",
        sig(a),
        sig(0.5 * a * 0.25)
    );
    let header: Vec<String> = [
        "h (m)",
        "R/h",
        "fields",
        "status",
        "u at 0.5 s (m)",
        "error",
        "slip at the contact, v_x + ω R (m/s)",
    ]
    .map(String::from)
    .to_vec();
    let mut rows = Vec::new();
    let mut c = LineChart::new(
        "Disk rolling on an elastic slab: centre displacement",
        "t (s)",
        "u_x of the disk's centre (m)",
    );
    for (k, r) in tagged(mine, &[("case", "rolling")]).into_iter().enumerate() {
        let h: f64 = r
            .job
            .tag_value("h")
            .and_then(|v| v.parse().ok())
            .unwrap_or(0.0);
        let fields = r.job.tag_value("fields").unwrap_or("");
        let hist = history(r);
        let pts: Vec<(f64, f64)> = hist
            .iter()
            .map(|(t, b)| (*t, b[0].displacement[0]))
            .collect();
        let status = if r.completed() {
            "completed".to_string()
        } else {
            super::failure_text(r)
        };
        let (u, err, slip) = match hist.last() {
            Some((t, b)) => {
                let exact = 0.5 * a * t * t;
                (
                    sig(b[0].displacement[0]),
                    format!("{} %", sig(100.0 * (b[0].displacement[0] / exact - 1.0))),
                    sig(b[0].v[0] + b[0].omega * ROLL_R),
                )
            }
            None => ("-".into(), "-".into(), "-".into()),
        };
        rows.push(vec![
            sig(h),
            sig(ROLL_R / h),
            fields.to_string(),
            status,
            u,
            err,
            slip,
        ]);
        c.series.push(Series::line(
            format!(
                "R/h = {}, {}",
                sig(ROLL_R / h),
                if fields == "pair" {
                    "pair"
                } else {
                    "one field"
                }
            ),
            pts,
            k,
        ));
    }
    let ts = every(0.005, 0.5);
    c.series.push(
        Series::line(
            "exact ½ (2/3) g sin θ t²",
            ts.iter().map(|&t| (t, 0.5 * a * t * t)).collect(),
            7,
        )
        .dashed(),
    );
    md.push_str(&table(&header, &rows));
    md.push('\n');
    md.push_str(&image(
        "rolling disk's centre displacement",
        "study-contact-rolling.png",
    ));
    md.push('\n');
    save(&mut c, dir, "study-contact-rolling")
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The footing's runs: smooth and rough on the three grids with the
    /// cell average, smooth with the particles' own rate on the two
    /// coarser ones; every scene valid, on the CPU, only in the full study.
    #[test]
    fn the_footing_runs_are_valid_cpu_scenes_of_the_full_study() {
        let runs = footing_jobs();
        assert_eq!(runs.len(), 8);
        for j in &runs {
            let scene = j.scene().unwrap();
            assert_eq!(j.backend, BackendChoice::Cpu);
            let h = j.tag_value("h").unwrap().parse::<f64>().unwrap();
            assert_eq!(scene.file.grid.h, h);
        }
        let footing = |quick| {
            super::jobs(quick, &[BackendChoice::Cpu])
                .iter()
                .filter(|j| j.tag_value("case") == Some("footing"))
                .count()
        };
        assert_eq!((footing(true), footing(false)), (0, 8));
    }

    /// The footing's section from two short runs (h = 0.1 m, 0.2 s: the
    /// load still rising): a row per run with its peak, and the chart.
    #[test]
    fn the_footing_section_reports_each_runs_peak() {
        let runs: Vec<Job> = footing_jobs()
            .into_iter()
            .filter(|j| j.tag_value("h") == Some("0.1") && j.tag_value("law") == Some("slip"))
            .map(|j| j.set("solver.t_end=0.2"))
            .collect();
        assert_eq!(runs.len(), 2);
        let results = super::super::runner::run_jobs(runs, 2, false, None);
        let dir = std::env::temp_dir().join(format!("lme-footing-report-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let refs: Vec<&JobResult> = results.iter().collect();
        let mut md = String::new();
        let charts = footing_section(&refs, &dir, &mut md).unwrap();
        for r in &results {
            let curve = footing_curve(r);
            assert!(
                curve.len() >= 10,
                "{}: {} samples",
                r.job.label,
                curve.len()
            );
            // Loading: the pressure grows with settlement (4 mm at 0.2 s).
            let (s, q) = *curve.last().unwrap();
            assert!(
                (s - 4.0).abs() < 0.1 && q > 1.0 && q < PRANDTL,
                "{s} mm, q/c {q}"
            );
        }
        assert!(
            md.contains("| smooth | cell average | 0.1 | 10 | completed |"),
            "{md}"
        );
        assert!(
            md.contains("| smooth | particle | 0.1 | 10 | completed |"),
            "{md}"
        );
        assert!(charts.iter().all(|c| c.exists()));
        let _ = std::fs::remove_dir_all(&dir);
    }
}
