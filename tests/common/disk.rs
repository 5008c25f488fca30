//! The rolling disk (`cases/rolling_disk.toml`) run in memory with the
//! centre of mass sampled every 0.01 s, as `study disk` and `study
//! implicit` sample it: eq. 67 and the final displacement's error.

use lme_mpm::backend::{Backend, NewtonStats, Sample};
use lme_mpm::exact::rolling::RollingDisk;
use lme_mpm::simulation::{BackendSpec, Simulation};
use lme_mpm::solver::{Observer, RunStatus};
use std::time::Instant;

/// Centre-of-mass displacement along x at each snapshot: eq. 67's samples.
#[derive(Default)]
pub struct CentreHistory(pub Vec<(f64, f64)>);

impl Observer for CentreHistory {
    fn sample(&mut self, _: &Sample) -> lme_mpm::error::Result<()> {
        Ok(())
    }
    fn snapshot(&mut self, b: &mut dyn Backend) -> lme_mpm::error::Result<()> {
        let t = b.time();
        if t > 0.0 {
            let (u, _) = RollingDisk::centre(b.particles()?);
            self.0.push((t, u[0]));
        }
        Ok(())
    }
}

/// A rolling disk run: its end, eq. 67 (percent), the final centre
/// displacement's relative error, Newton's figures, wall time (s).
pub struct DiskRun {
    pub status: RunStatus,
    pub error_percent: f64,
    pub final_rel: f64,
    pub newton: NewtonStats,
    pub wall: f64,
}

/// Runs `cases/rolling_disk.toml` with `sets` (an implicit integrator
/// among them), sampling the centre every 0.01 s.
pub fn disk_run(sets: &[&str]) -> DiskRun {
    disk_run_text(lme_mpm::cases::ROLLING_DISK, sets)
}

/// `disk_run` on a variant of the case's text (e.g. its stick wall).
pub fn disk_run_text(text: &str, sets: &[&str]) -> DiskRun {
    let o: Vec<lme_mpm::scene::Override> = sets
        .iter()
        .map(|s| lme_mpm::scene::Override::parse(s).unwrap())
        .collect();
    let scene = lme_mpm::scene::Scene::from_str(text, "rolling_disk", "rolling_disk", &o)
        .unwrap_or_else(|e| panic!("{sets:?}: {e}"));
    let exact = RollingDisk::from_scene(&scene);
    let t_end = scene.file.solver.t_end;
    let mut sim = Simulation::new(&scene, &BackendSpec::cpu()).unwrap();
    let n = (t_end / 0.01).round() as usize;
    let schedule = lme_mpm::solver::Schedule {
        vtk_interval: None,
        snapshot_times: (1..=n).map(|k| k as f64 * 0.01).collect(),
        ..sim.schedule()
    };
    let mut history = CentreHistory::default();
    let start = Instant::now();
    let status = sim.drive_with(schedule, &mut history).unwrap();
    let wall = start.elapsed().as_secs_f64();
    let (error_percent, final_rel) = match history.0.last() {
        Some(&(t, u)) => (
            exact.history_error_percent(&history.0),
            (u - exact.displacement(t)[0]).abs() / exact.displacement(t)[0],
        ),
        None => (f64::NAN, f64::NAN),
    };
    DiskRun {
        status,
        error_percent,
        final_rel,
        newton: sim.backend_ref().newton().unwrap().clone(),
        wall,
    }
}
