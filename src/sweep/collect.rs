//! A sweep folder's runs as records: each `runs/ID/summary.json` read back
//! (missing, killed and failed runs listed as such; a folder another plan
//! wrote, or an unreadable summary, as failed with the reason), then, where the runs
//! report no exact error, each run's error against its series' finest
//! completed run (`reference.rs`).

use super::entry::mismatch;
use super::plan::Plan;
use super::record::{Outcome, Record};
use super::reference;
use std::collections::BTreeMap;
use std::path::Path;

/// The records of every planned run, in plan order. `known` holds reasons
/// for runs that failed before writing their folder (a local sweep knows them).
pub fn records(plan: &Plan, dir: &Path, known: &BTreeMap<String, String>) -> Vec<Record> {
    let mut out: Vec<Record> = plan
        .runs
        .iter()
        .map(|run| {
            let keys = plan.keys_of(run);
            let folder = dir.join("runs").join(&run.id);
            let summary = folder.join("summary.json");
            let failed = |why: &str| {
                let mut r = Record::missing(&run.id, keys.clone(), why);
                r.outcome = Outcome::Failed;
                r
            };
            match std::fs::read(&summary) {
                Ok(bytes) => {
                    // Garbage or a cut file alike: unreadable, so failed.
                    let read = String::from_utf8(bytes)
                        .map_err(|_| "summary.json unreadable: not UTF-8 text".to_string())
                        .and_then(|text| Record::from_summary(&run.id, keys.clone(), &text));
                    match (read, mismatch(plan, run, &folder)) {
                        (Err(e), _) => failed(&e),
                        (Ok(_), Some(why)) => failed(&format!(
                            "not this plan's run: {why}; rerun its line, or collect the sweep \
                             that wrote it"
                        )),
                        (Ok(r), None) => r,
                    }
                }
                Err(e) if e.kind() != std::io::ErrorKind::NotFound => {
                    failed(&format!("summary.json unreadable: {e}"))
                }
                Err(_) => match known.get(&run.id) {
                    Some(reason) => {
                        let mut r = Record::missing(&run.id, keys, reason);
                        r.outcome = Outcome::Failed;
                        r
                    }
                    None => Record::missing(
                        &run.id,
                        keys,
                        "no summary.json: the run never started, or was refused before writing \
                         (see its job's log)",
                    ),
                },
            }
        })
        .collect();
    if !out.iter().any(|r| r.error_source == "exact") {
        add_reference_errors(plan, dir, &mut out);
    }
    out
}

/// The series of a run: its values of every axis but the resolution.
pub fn series_key(plan: &Plan, r: &Record) -> Vec<(String, String)> {
    r.keys
        .iter()
        .filter(|(k, _)| Some(k) != plan.resolution.as_ref())
        .cloned()
        .collect()
}

/// The resolution value of a run (smaller is finer).
pub fn resolution_of(plan: &Plan, r: &Record) -> Option<f64> {
    let key = plan.resolution.as_ref()?;
    r.key(key)?.parse().ok()
}

/// Errors against the finest completed run of each series, from the run
/// folders' probes.csv and particles.csv.
fn add_reference_errors(plan: &Plan, dir: &Path, records: &mut [Record]) {
    if plan.resolution.is_none() {
        return;
    }
    let mut series: BTreeMap<Vec<(String, String)>, Vec<usize>> = BTreeMap::new();
    for (i, r) in records.iter().enumerate() {
        series.entry(series_key(plan, r)).or_default().push(i);
    }
    let read = |id: &str, file: &str| std::fs::read_to_string(dir.join("runs").join(id).join(file));
    for members in series.values() {
        let Some(&finest) =
            members
                .iter()
                .filter(|&&i| records[i].completed())
                .min_by(|&&a, &&b| {
                    resolution_of(plan, &records[a])
                        .unwrap_or(f64::INFINITY)
                        .total_cmp(&resolution_of(plan, &records[b]).unwrap_or(f64::INFINITY))
                })
        else {
            continue;
        };
        let ref_id = records[finest].id.clone();
        let ref_probes = read(&ref_id, "probes.csv")
            .ok()
            .and_then(|t| reference::read_probes(&t).ok());
        let ref_particles = read(&ref_id, "particles.csv")
            .ok()
            .and_then(|t| reference::read_particles(&t).ok());
        let mut any = false;
        for &i in members {
            if i == finest || !records[i].completed() {
                continue;
            }
            let id = records[i].id.clone();
            let mut figures = Vec::new();
            if let (Some(rp), Ok(text)) = (&ref_probes, read(&id, "probes.csv")) {
                if let Some(f) = reference::read_probes(&text)
                    .ok()
                    .and_then(|p| reference::probe_errors(&p, rp))
                {
                    figures.extend(f);
                }
            }
            if let (Some(rp), Ok(text)) = (&ref_particles, read(&id, "particles.csv")) {
                if let Some(f) = reference::read_particles(&text)
                    .ok()
                    .and_then(|p| reference::particle_errors(&p, rp))
                {
                    figures.extend(f);
                }
            }
            if !figures.is_empty() {
                any = true;
                records[i].errors = figures;
                records[i].error_source = format!("finest run {ref_id}");
            }
        }
        if any {
            records[finest].error_source = "reference".into();
        }
    }
}
