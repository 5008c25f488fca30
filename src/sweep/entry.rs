//! `runs/ID/sweep-run.json`: the plan entry of the run a sweep put in a
//! folder (its scene, `--set` list and backend), written before the run
//! starts (locally, or by `--emit-jobs`); and the check `collect` makes
//! before it tables a folder: the entry is this plan's, and the folder's
//! `scene.resolved.toml` is the scene this plan gives the run. A folder
//! that another plan (other `--set`, another value) wrote is flagged, not
//! tabled as this plan's run.

use super::plan::{Plan, PlannedRun};
use crate::error::{Error, Result};
use crate::output::folder::SWEEP_ENTRY;
use crate::scene::{Override, Scene};
use serde::{Deserialize, Serialize};
use std::path::{Path, PathBuf};

/// What a sweep planned for one run folder.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
pub struct Entry {
    /// The run's id (its folder name under `runs/`).
    pub id: String,
    /// The scene file (absolute path).
    pub scene: PathBuf,
    /// Every `--set` of the run: the sweep's fixed ones, then the varied keys.
    pub sets: Vec<String>,
    /// `--backend` of the run.
    pub backend: String,
}

impl Entry {
    /// The entry `plan` gives `run`.
    pub fn of(plan: &Plan, run: &PlannedRun) -> Entry {
        Entry {
            id: run.id.clone(),
            scene: plan.scene.clone(),
            sets: plan.sets_of(run),
            backend: plan.backend.clone(),
        }
    }

    /// Writes the entry into the run folder `dir` (made if missing).
    pub fn write(&self, dir: &Path) -> Result<()> {
        std::fs::create_dir_all(dir).map_err(|e| Error::io("cannot create", dir, e))?;
        let json = serde_json::to_string_pretty(self).expect("an entry serialises");
        crate::output::write_atomic(&dir.join(SWEEP_ENTRY), json.as_bytes())
    }
}

/// Why the run folder `dir` does not hold `plan`'s `run`, or None when it
/// does (or holds nothing to compare: no entry and no resolved scene).
pub fn mismatch(plan: &Plan, run: &PlannedRun, dir: &Path) -> Option<String> {
    let want = Entry::of(plan, run);
    match std::fs::read_to_string(dir.join(SWEEP_ENTRY)) {
        Ok(text) => match serde_json::from_str::<Entry>(&text) {
            Ok(got) if got == want => {}
            Ok(got) => {
                return Some(format!(
                    "its {SWEEP_ENTRY} plans `{}` with --set {}, this plan `{}` with --set {}",
                    got.scene.display(),
                    got.sets.join(" --set "),
                    want.scene.display(),
                    want.sets.join(" --set ")
                ));
            }
            Err(e) => return Some(format!("its {SWEEP_ENTRY} is unreadable: {e}")),
        },
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => {}
        Err(e) => return Some(format!("its {SWEEP_ENTRY} is unreadable: {e}")),
    }
    let text = std::fs::read_to_string(dir.join("scene.resolved.toml")).ok()?;
    let got = match text.parse::<toml::Table>() {
        Ok(t) => toml::Value::Table(t),
        Err(e) => return Some(format!("its scene.resolved.toml is unreadable: {e}")),
    };
    let expected = match resolved(plan, run) {
        Ok(v) => v,
        Err(e) => return Some(format!("the plan's scene for it no longer loads: {e}")),
    };
    // A resumed run writes the default sample interval it ran with: the
    // folder may set it where the plan does not.
    let planned = expected
        .get("output")
        .and_then(|o| o.get("sample_interval"));
    let skip: &[&str] = if planned.is_none() {
        &["output.sample_interval"]
    } else {
        &[]
    };
    crate::scene::first_difference(&got, &expected, skip, ("the folder", "the plan"))
        .map(|d| format!("its scene.resolved.toml differs: {d}"))
}

/// The resolved scene `plan` gives `run`, as `lme-mpm run` writes it to
/// `scene.resolved.toml` (after the preflight's clamping of intervals).
fn resolved(plan: &Plan, run: &PlannedRun) -> Result<toml::Value> {
    let overrides = plan
        .sets_of(run)
        .iter()
        .map(|s| Override::parse(s))
        .collect::<std::result::Result<Vec<_>, _>>()?;
    let scene = Scene::load(&plan.scene, &overrides)?;
    // No limit refuses here: only the clamping matters.
    let limits = crate::preflight::Limits {
        max_memory: Some(u64::MAX),
        max_steps: u64::MAX,
        max_hours: None,
        allow_many_snapshots: true,
    };
    let checked = crate::preflight::plan(&scene, &limits, rayon::current_num_threads())?;
    let text = toml::to_string(&checked.scene.file).expect("a scene file serialises to TOML");
    let table = text
        .parse::<toml::Table>()
        .expect("TOML lme-mpm wrote parses");
    Ok(toml::Value::Table(table))
}

#[cfg(test)]
mod tests {
    use crate::scene::first_difference;

    #[test]
    fn the_first_difference_is_named_by_its_dotted_key() {
        let a: toml::Table = "[grid]\nh = 0.01\n[solver]\nshape = \"lme\"\n"
            .parse()
            .unwrap();
        let b: toml::Table = "[grid]\nh = 0.005\n[solver]\nshape = \"lme\"\n"
            .parse()
            .unwrap();
        let (a, b) = (toml::Value::Table(a), toml::Value::Table(b));
        let labels = ("the folder", "the plan");
        assert_eq!(first_difference(&a, &a, &[], labels), None);
        let d = first_difference(&a, &b, &[], labels).unwrap();
        assert!(d.starts_with("grid.h = 0.01 in the folder, 0.005"), "{d}");
    }
}
