//! The driver stops at once when its observer fails (an output that cannot
//! be written): the run does not compute on to t_end before reporting it.

use lme_mpm::backend::{Backend, Sample};
use lme_mpm::scene::Scene;
use lme_mpm::simulation::{BackendSpec, Simulation};
use lme_mpm::solver::Observer;

/// Fails on its third sample.
struct FailsOnThird {
    seen: usize,
}

impl Observer for FailsOnThird {
    fn sample(&mut self, _s: &Sample) -> lme_mpm::Result<()> {
        self.seen += 1;
        if self.seen == 3 {
            return Err(lme_mpm::Error::Gpu("disk full (test)".into()));
        }
        Ok(())
    }
    fn snapshot(&mut self, _b: &mut dyn Backend) -> lme_mpm::Result<()> {
        Ok(())
    }
}

#[test]
fn an_observer_error_stops_the_run_at_once() {
    let path = std::path::PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("cases/dyka_bar.toml");
    let scene = Scene::load(&path, &[]).unwrap();
    let mut sim = Simulation::new(&scene, &BackendSpec::cpu()).unwrap();
    let interval = sim.schedule().sample_interval;
    let mut obs = FailsOnThird { seen: 0 };
    let err = sim
        .drive(&mut obs)
        .expect_err("the observer's error must end the run");
    assert!(err.to_string().contains("disk full"), "{err}");
    let t = sim.backend_ref().time();
    let t_end = sim.backend_ref().model().t_end;
    // Samples at 0, one interval, two intervals: the third failed, so the
    // run stopped at the first step end past 2 intervals, far from t_end.
    assert!(
        t < 3.0 * interval && t < 0.1 * t_end,
        "stopped at t = {t} s (interval {interval} s, t_end {t_end} s)"
    );
}
