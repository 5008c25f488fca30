//! The run driver: advances a backend from output time to output time
//! (`drive`), checks the energy, and hands samples, snapshots and
//! checkpoints to an `Observer`. What one step runs is the step plan
//! (`crate::step`), which the backends execute.

use crate::backend::{Backend, Halt, Sample};
use crate::error::Result;
use crate::model::energy::Energy;
use crate::model::fault::{Fault, FaultKind};
use std::sync::Arc;
use std::sync::atomic::AtomicBool;

/// A run stops as unstable when kinetic + strain energy exceeds this many
/// times the energy the run could have received (initial energy plus the
/// bound on gravity's work, plus a manufactured field's peak energy). Stable elastic runs stay at or below 1 (energy
/// is conserved or dissipated); 10 leaves room for round-off and for the
/// bound's slack without missing an exponential blow-up.
pub const ENERGY_RUNAWAY: f64 = 10.0;

/// How a run ended.
#[derive(Debug, Clone, PartialEq)]
pub enum RunStatus {
    Completed,
    Unstable {
        fault: Fault,
        t: f64,
        step: u64,
    },
    /// `Schedule::stop` was raised (a signal): stopped at a step boundary.
    Interrupted {
        t: f64,
        step: u64,
    },
}

/// Receives a run's samples as they happen (the output writer, or a test).
/// An error from either call ends the run at once (`drive` returns it).
pub trait Observer {
    fn sample(&mut self, sample: &Sample) -> Result<()>;
    /// A snapshot of all particles is due (VTK).
    fn snapshot(&mut self, backend: &mut dyn Backend) -> Result<()>;
    /// Progress: time reached, t_end (s), steps taken.
    fn progress(&mut self, _t: f64, _t_end: f64, _steps: u64) {}
    /// A checkpoint is due (every `Schedule::checkpoint_interval`, when
    /// interrupted, and at t_end with `Schedule::final_checkpoint`):
    /// `cursor` is what `drive_from` needs to continue.
    fn checkpoint(&mut self, _backend: &mut dyn Backend, _cursor: &Cursor) -> Result<()> {
        Ok(())
    }
}

/// Observer that keeps every sample in memory.
#[derive(Debug, Default)]
pub struct Recorder {
    pub samples: Vec<Sample>,
}

impl Observer for Recorder {
    fn sample(&mut self, sample: &Sample) -> Result<()> {
        self.samples.push(sample.clone());
        Ok(())
    }
    fn snapshot(&mut self, _backend: &mut dyn Backend) -> Result<()> {
        Ok(())
    }
}

/// When to sample and snapshot (s).
#[derive(Debug, Clone, Default)]
pub struct Schedule {
    pub sample_interval: f64,
    /// Snapshots every this often (plus one at t = 0).
    pub vtk_interval: Option<f64>,
    /// Snapshots at these times too, each taken at the first step end at or after it.
    pub snapshot_times: Vec<f64>,
    /// Checkpoints every this often (s). Default: none.
    pub checkpoint_interval: Option<f64>,
    /// A checkpoint at t_end too, so a completed run can be extended
    /// (`lme-mpm resume DIR --set solver.t_end=LATER`). Default: false.
    pub final_checkpoint: bool,
    /// Raised to stop at the next step boundary (`RunStatus::Interrupted`).
    pub stop: Option<Arc<AtomicBool>>,
}

/// Where `drive` stands between steps: its sample, snapshot and checkpoint
/// counters and the energy reference of the runaway check. A checkpoint
/// keeps it so a resumed run samples exactly as an uninterrupted one.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Cursor {
    /// Index of the next sample time (k · sample_interval).
    pub k_sample: u64,
    /// Index of the next periodic snapshot.
    pub k_vtk: u64,
    /// Index of the next checkpoint.
    pub k_checkpoint: u64,
    /// Energy at t = 0 (J/m).
    pub e0: Energy,
    /// Peak energy a manufactured field supplies (J/m).
    pub supplied: f64,
    /// Energies below this are round-off (J/m).
    pub floor: f64,
}

impl Schedule {
    /// The next snapshot due after time `t` (`k_vtk` counts periodic ones).
    fn next_snapshot(&self, k_vtk: u64, t: f64) -> f64 {
        let periodic = self
            .vtk_interval
            .map_or(f64::INFINITY, |i| k_vtk as f64 * i);
        let listed = self
            .snapshot_times
            .iter()
            .copied()
            .filter(|&s| s > t)
            .fold(f64::INFINITY, f64::min);
        periodic.min(listed)
    }
}

/// Runs `backend` to the model's t_end, sampling on `schedule`. Returns how
/// the run ended; an unstable run stops at the step that found the fault.
/// Errors are failures of the backend itself (a lost GPU device) or of the
/// observer (an output that cannot be written); either stops the run at once.
pub fn drive(
    backend: &mut dyn Backend,
    schedule: Schedule,
    obs: &mut dyn Observer,
) -> Result<RunStatus> {
    drive_from(backend, schedule, obs, None)
}

/// `drive`, continuing from `cursor` (a resumed run: the backend holds the
/// checkpoint's state; no sample or snapshot is taken at the start) or from
/// t = 0 when `cursor` is None.
pub fn drive_from(
    backend: &mut dyn Backend,
    schedule: Schedule,
    obs: &mut dyn Observer,
    cursor: Option<Cursor>,
) -> Result<RunStatus> {
    let t_end = backend.model().t_end;
    let never = AtomicBool::new(false);
    let stop = schedule.stop.as_deref().unwrap_or(&never);
    let mut c = match cursor {
        Some(c) => c,
        None => {
            let first = backend.sample()?;
            let floor = energy_floor(backend);
            // A manufactured body force supplies (and takes back) the exact field's energy.
            // A constraint that drives the material (a prescribed velocity)
            // or a loaded platen (its work is not tracked) can supply any
            // energy: no bound, so no runaway check.
            let supplied = {
                let m = backend.model();
                let driven = m
                    .constraints
                    .groups
                    .iter()
                    .any(|g| g.velocity != [0.0, 0.0])
                    || m.constraints.platens.iter().any(|p| p.force != 0.0);
                if driven {
                    f64::INFINITY
                } else {
                    m.manufactured
                        .as_ref()
                        .map_or(0.0, |mms| mms.peak_energy(&m.particles))
                }
            };
            obs.sample(&first)?;
            if schedule.vtk_interval.is_some() {
                obs.snapshot(backend)?;
            }
            Cursor {
                k_sample: 1,
                k_vtk: 1,
                k_checkpoint: 1,
                e0: first.energy,
                supplied,
                floor,
            }
        }
    };
    loop {
        let t = backend.time();
        if t >= t_end {
            if schedule.final_checkpoint {
                obs.checkpoint(backend, &c)?;
            }
            return Ok(RunStatus::Completed);
        }
        if crate::backend::stop_requested(stop) {
            obs.checkpoint(backend, &c)?;
            return Ok(RunStatus::Interrupted {
                t,
                step: backend.steps(),
            });
        }
        let next_sample = c.k_sample as f64 * schedule.sample_interval;
        let next_vtk = schedule.next_snapshot(c.k_vtk, t);
        let next_checkpoint = schedule
            .checkpoint_interval
            .map_or(f64::INFINITY, |i| c.k_checkpoint as f64 * i);
        let target = next_sample.min(next_vtk).min(next_checkpoint).min(t_end);
        match backend.advance(target, stop) {
            Ok(()) => {}
            Err(Halt::Failed(e)) => return Err(e),
            Err(Halt::Unstable(fault)) => {
                let s = backend.sample()?;
                obs.sample(&s)?;
                return Ok(RunStatus::Unstable {
                    fault,
                    t: backend.time(),
                    step: backend.steps(),
                });
            }
        }
        let t = backend.time();
        obs.progress(t, t_end, backend.steps());
        if t >= next_sample || t >= t_end {
            let s = backend.sample()?;
            obs.sample(&s)?;
            c.k_sample = next_multiple(c.k_sample, schedule.sample_interval, t);
            if let Some(fault) = runaway(&c.e0, &s.energy, c.supplied, c.floor) {
                return Ok(RunStatus::Unstable {
                    fault,
                    t,
                    step: backend.steps(),
                });
            }
        }
        if t >= next_vtk {
            obs.snapshot(backend)?;
            if let Some(iv) = schedule.vtk_interval {
                c.k_vtk = next_multiple(c.k_vtk, iv, t);
            }
        }
        if t >= next_checkpoint && t < t_end {
            if let Some(iv) = schedule.checkpoint_interval {
                c.k_checkpoint = next_multiple(c.k_checkpoint, iv, t);
            }
            obs.checkpoint(backend, &c)?;
        }
    }
}

/// The smallest k ≥ `k` with k · `interval` > `t`: the index of the next
/// sample or snapshot time. Jumps straight there (a tiny interval must not
/// cost one loop turn per interval passed), then settles the rounding.
fn next_multiple(k: u64, interval: f64, t: f64) -> u64 {
    let mut k = k.max((t / interval).floor().min(u64::MAX as f64 / 2.0) as u64);
    while k as f64 * interval <= t {
        k += 1;
    }
    k
}

/// Energies below this (J/m) are round-off: 1e-12 of Σ m c², the energy
/// scale of elastic waves in the scene.
fn energy_floor(backend: &mut dyn Backend) -> f64 {
    let m = backend.model();
    let p = &m.particles;
    let mc2: f64 = (0..p.len())
        .map(|i| {
            let q = p.plastic.get(i).unwrap_or(&[0.0; 4]);
            p.mass[i]
                * m.material_of(i)
                    .wave_speed(p.rho[i], &p.stress[i], q)
                    .powi(2)
        })
        .sum();
    1e-12 * mc2
}

fn runaway(e0: &Energy, e: &Energy, supplied: f64, floor: f64) -> Option<Fault> {
    let available = e0.kinetic + e0.strain + e.gravity_work_bound + supplied;
    let now = e.kinetic + e.strain;
    (now > floor && now > ENERGY_RUNAWAY * available).then(|| Fault {
        particle: None,
        kind: FaultKind::EnergyRunaway {
            ratio: now / available.max(floor),
        },
    })
}
