//! What a sweep will run: the `--vary KEY=V1,V2,…` axes, their Cartesian
//! product as runs with ids, every run's scene checked (and its cost
//! estimated by the preflight) before anything runs, and the plan file
//! `sweep-plan.json` that `--collect` reads back.

use crate::error::SceneError;
use crate::scene::{Override, Scene};
use crate::simulation::BackendChoice;
use serde::{Deserialize, Serialize};
use std::path::{Path, PathBuf};

/// The plan file in a sweep folder.
pub const PLAN_FILE: &str = "sweep-plan.json";
/// Keys that, when varied, are a sweep's resolution (smaller is finer), in
/// order of preference when `--resolution` is not given.
pub const RESOLUTION_KEYS: [&str; 3] = ["grid.h", "solver.dt", "solver.cfl"];
/// Longest run id (characters); longer ones are cut (the index keeps them unique).
const ID_MAX: usize = 80;

/// One `--vary` argument.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
pub struct Axis {
    /// Dotted scene key, e.g. `solver.shape`.
    pub key: String,
    /// Values as written (TOML values, or bare words).
    pub values: Vec<String>,
}

impl Axis {
    /// Parses `KEY=V1,V2,…`. Commas inside `[…]`, `{…}` or quotes belong to
    /// the value, so `bodies.a.velocity=[-5, 0],[-10, 0]` is two values.
    pub fn parse(arg: &str) -> Result<Axis, SceneError> {
        let err = |message: String| SceneError::Sweep {
            arg: format!("--vary {arg}"),
            message,
        };
        let (key, list) = arg
            .split_once('=')
            .ok_or_else(|| err("expected KEY=V1,V2,…, e.g. grid.h=0.01,0.005".into()))?;
        let key = key.trim();
        if key.is_empty() {
            return Err(err("the key before '=' is empty".into()));
        }
        let values = split_values(list);
        if values.iter().all(|v| v.is_empty()) {
            return Err(err(format!("`{key}` has an empty list of values")));
        }
        if let Some(k) = values.iter().position(String::is_empty) {
            return Err(err(format!(
                "value {} of `{key}` is empty (two commas in a row, or a trailing comma)",
                k + 1
            )));
        }
        for (i, v) in values.iter().enumerate() {
            if values[..i].contains(v) {
                return Err(err(format!("`{key}` lists the value `{v}` twice")));
            }
        }
        // The key's syntax, as `--set` checks it.
        Override::parse(&format!("{key}={}", values[0])).map_err(|e| err(e.to_string()))?;
        Ok(Axis {
            key: key.to_string(),
            values,
        })
    }

    /// The key's last part when that names it alone among `axes`, else the key.
    pub fn short_name(&self, axes: &[Axis]) -> String {
        let last = self.key.rsplit('.').next().unwrap_or(&self.key);
        let clash = axes
            .iter()
            .filter(|a| a.key.rsplit('.').next() == Some(last))
            .count()
            > 1;
        if clash {
            self.key.clone()
        } else {
            last.to_string()
        }
    }
}

/// Splits at commas outside brackets, braces and quotes; trims each value.
fn split_values(list: &str) -> Vec<String> {
    let (mut out, mut cur, mut depth, mut quote) = (Vec::new(), String::new(), 0i32, None);
    for c in list.chars() {
        match (quote, c) {
            (Some(q), c) if c == q => quote = None,
            (Some(_), _) => {}
            (None, '"' | '\'') => quote = Some(c),
            (None, '[' | '{') => depth += 1,
            (None, ']' | '}') => depth -= 1,
            (None, ',') if depth <= 0 => {
                out.push(cur.trim().to_string());
                cur.clear();
                continue;
            }
            _ => {}
        }
        cur.push(c);
    }
    out.push(cur.trim().to_string());
    out
}

/// One run of the plan.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
pub struct PlannedRun {
    /// Folder name under `runs/`: index, then the values.
    pub id: String,
    /// This run's value of each axis, in axis order.
    pub values: Vec<String>,
    /// Its peak memory as the preflight estimates it (bytes; 0 in plans
    /// written before it was kept): what `run_local` sums over the runs
    /// it runs at once.
    #[serde(default)]
    pub memory_bytes: u64,
}

/// A whole sweep, as written to `sweep-plan.json`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Plan {
    /// The scene file (absolute path).
    pub scene: PathBuf,
    /// Its name (the scene's `name`, or the file stem).
    pub scene_name: String,
    /// `--set` overrides every run gets, before the varied keys.
    pub sets: Vec<String>,
    pub axes: Vec<Axis>,
    /// The axis whose finest (smallest) value is a series' reference and
    /// the x of the convergence chart; none when no resolution key is varied.
    pub resolution: Option<String>,
    /// `--backend` of every run.
    pub backend: String,
    pub runs: Vec<PlannedRun>,
}

impl Plan {
    /// The product of `axes` on `scene`, every run's scene checked and its
    /// cost estimated (the preflight `run` does) before anything runs.
    /// Errors name the key and value (exit 2).
    pub fn new(
        scene: &Path,
        sets: &[String],
        axes: Vec<Axis>,
        resolution: Option<String>,
        backend: BackendChoice,
    ) -> Result<Plan, SceneError> {
        for (i, a) in axes.iter().enumerate() {
            if axes[..i].iter().any(|b| b.key == a.key) {
                return Err(SceneError::Sweep {
                    arg: format!("--vary {}=…", a.key),
                    message: "the key is varied twice; give all its values in one --vary".into(),
                });
            }
            if sets
                .iter()
                .any(|s| s.split('=').next().map(str::trim) == Some(&a.key))
            {
                return Err(SceneError::Sweep {
                    arg: format!("--vary {}=…", a.key),
                    message: "the key is also given by --set; drop one of them".into(),
                });
            }
        }
        if axes.is_empty() {
            return Err(SceneError::Sweep {
                arg: "--vary".into(),
                message: "a sweep needs at least one --vary KEY=V1,V2,…".into(),
            });
        }
        let resolution = match resolution {
            Some(r) => {
                let Some(axis) = axes.iter().find(|a| a.key == r) else {
                    return Err(SceneError::Sweep {
                        arg: format!("--resolution {r}"),
                        message: "not one of the varied keys".into(),
                    });
                };
                if let Some(v) = axis.values.iter().find(|v| v.parse::<f64>().is_err()) {
                    return Err(SceneError::Sweep {
                        arg: format!("--resolution {r}"),
                        message: format!("its value `{v}` is not a number"),
                    });
                }
                Some(r)
            }
            None => RESOLUTION_KEYS
                .iter()
                .find(|k| axes.iter().any(|a| a.key == **k))
                .map(|k| k.to_string()),
        };
        let base: Vec<Override> = sets
            .iter()
            .map(|s| Override::parse(s))
            .collect::<Result<_, _>>()?;
        let scene_file = scene.canonicalize().map_err(|e| SceneError::Parse {
            path: scene.display().to_string(),
            message: format!("cannot read the file: {e}"),
        })?;
        let base_scene = Scene::load(&scene_file, &base)?;
        // Each value alone first, so an error names the value that causes it.
        for a in &axes {
            for v in &a.values {
                let mut o = base.clone();
                o.push(Override::parse(&format!("{}={v}", a.key))?);
                Scene::load(&scene_file, &o).map_err(|e| SceneError::Sweep {
                    arg: format!("--vary {}={v}", a.key),
                    message: e.to_string(),
                })?;
            }
        }
        let runs = product(&axes);
        let digits = runs.len().saturating_sub(1).to_string().len().max(2);
        let mut planned = Vec::with_capacity(runs.len());
        let limits = crate::preflight::Limits::default();
        for (i, values) in runs.into_iter().enumerate() {
            let id = run_id(i, digits, &values);
            let o = overrides(&base, &axes, &values)?;
            let described = || {
                axes.iter()
                    .zip(&values)
                    .map(|(a, v)| format!("{}={v}", a.key))
                    .collect::<Vec<_>>()
                    .join(" ")
            };
            let s = Scene::load(&scene_file, &o).map_err(|e| SceneError::Sweep {
                arg: format!("run {id} ({})", described()),
                message: e.to_string(),
            })?;
            let checked = crate::preflight::plan(&s, &limits, rayon::current_num_threads())
                .map_err(|e| SceneError::Sweep {
                    arg: format!("run {id} ({})", described()),
                    message: e.to_string(),
                })?;
            planned.push(PlannedRun {
                id,
                values,
                memory_bytes: checked.estimate.memory_bytes.round() as u64,
            });
        }
        Ok(Plan {
            scene: scene_file,
            scene_name: base_scene.name,
            sets: sets.to_vec(),
            axes,
            resolution,
            backend: match backend {
                BackendChoice::Cpu => "cpu",
                BackendChoice::Gpu => "gpu",
                BackendChoice::Auto => "auto",
            }
            .to_string(),
            runs: planned,
        })
    }

    /// The `--set` arguments of one run: the fixed ones, then the varied keys.
    pub fn sets_of(&self, run: &PlannedRun) -> Vec<String> {
        self.sets
            .iter()
            .cloned()
            .chain(
                self.axes
                    .iter()
                    .zip(&run.values)
                    .map(|(a, v)| format!("{}={v}", a.key)),
            )
            .collect()
    }

    /// A run's keys and values, as the table shows them.
    pub fn keys_of(&self, run: &PlannedRun) -> Vec<(String, String)> {
        self.axes
            .iter()
            .zip(&run.values)
            .map(|(a, v)| (a.key.clone(), v.clone()))
            .collect()
    }

    pub fn backend_choice(&self) -> BackendChoice {
        match self.backend.as_str() {
            "cpu" => BackendChoice::Cpu,
            "gpu" => BackendChoice::Gpu,
            _ => BackendChoice::Auto,
        }
    }

    /// One self-contained shell line per run: `EXE run SCENE --backend B
    /// --out DIR/runs/ID --set …`, every word quoted for `sh`.
    pub fn shell_lines(&self, exe: &str, dir: &Path) -> Vec<String> {
        self.runs
            .iter()
            .map(|r| {
                let mut words = vec![
                    exe.to_string(),
                    "run".into(),
                    self.scene.display().to_string(),
                    "--backend".into(),
                    self.backend.clone(),
                    "--out".into(),
                    dir.join("runs").join(&r.id).display().to_string(),
                ];
                for s in self.sets_of(r) {
                    words.push("--set".into());
                    words.push(s);
                }
                words
                    .iter()
                    .map(|w| shell_quote(w))
                    .collect::<Vec<_>>()
                    .join(" ")
            })
            .collect()
    }

    /// Reads `DIR/sweep-plan.json`.
    pub fn read(dir: &Path) -> crate::Result<Plan> {
        let p = dir.join(PLAN_FILE);
        let text = std::fs::read_to_string(&p).map_err(|e| {
            crate::Error::Folder(format!(
                "{}: cannot read the sweep plan ({e}); is this a folder that `lme-mpm sweep` \
                 (or `sweep --emit-jobs`) wrote?",
                dir.display()
            ))
        })?;
        serde_json::from_str(&text)
            .map_err(|e| crate::Error::Folder(format!("{}: not a sweep plan: {e}", p.display())))
    }

    /// Whether `other` plans the same runs (the memory estimates aside,
    /// which depend on the machine that planned).
    pub fn same_runs(&self, other: &Plan) -> bool {
        let ids = |p: &Plan| -> Vec<(String, Vec<String>)> {
            p.runs
                .iter()
                .map(|r| (r.id.clone(), r.values.clone()))
                .collect()
        };
        self.scene == other.scene
            && self.sets == other.sets
            && self.axes == other.axes
            && self.backend == other.backend
            && ids(self) == ids(other)
    }

    /// Writes `DIR/sweep-plan.json`.
    pub fn write(&self, dir: &Path) -> crate::Result<()> {
        let json = serde_json::to_string_pretty(self).expect("a plan serialises");
        crate::output::write_atomic(&dir.join(PLAN_FILE), json.as_bytes())
    }
}

/// Every combination of the axes' values, the last axis varying fastest.
fn product(axes: &[Axis]) -> Vec<Vec<String>> {
    let mut out: Vec<Vec<String>> = vec![Vec::new()];
    for a in axes {
        out = out
            .into_iter()
            .flat_map(|prefix| {
                a.values.iter().map(move |v| {
                    let mut p = prefix.clone();
                    p.push(v.clone());
                    p
                })
            })
            .collect();
    }
    out
}

fn overrides(
    base: &[Override],
    axes: &[Axis],
    values: &[String],
) -> Result<Vec<Override>, SceneError> {
    let mut o = base.to_vec();
    for (a, v) in axes.iter().zip(values) {
        o.push(Override::parse(&format!("{}={v}", a.key))?);
    }
    Ok(o)
}

/// `007-lme_0.005`: the index, then the values with anything but letters,
/// digits, `.`, `+`, `-` dropped (a folder name safe in any shell).
fn run_id(i: usize, digits: usize, values: &[String]) -> String {
    let vals: Vec<String> = values
        .iter()
        .map(|v| {
            v.chars()
                .filter(|c| c.is_ascii_alphanumeric() || matches!(c, '.' | '+' | '-'))
                .collect()
        })
        .collect();
    let mut id = format!("{i:0digits$}-{}", vals.join("_"));
    id.truncate(ID_MAX);
    id
}

/// `word` quoted for POSIX sh (single quotes; a quote inside as `'\''`).
pub fn shell_quote(word: &str) -> String {
    if !word.is_empty()
        && word
            .chars()
            .all(|c| c.is_ascii_alphanumeric() || "/._-+=:,".contains(c))
    {
        return word.to_string();
    }
    format!("'{}'", word.replace('\'', "'\\''"))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn values_split_at_top_level_commas() {
        let a = Axis::parse("bodies.a.velocity=[-5, 0],[-10, 0]").unwrap();
        assert_eq!(a.values, ["[-5, 0]", "[-10, 0]"]);
        let a = Axis::parse("name=\"a,b\",c").unwrap();
        assert_eq!(a.values, ["\"a,b\"", "c"]);
        let a = Axis::parse(" grid.h = 0.01, 0.005 ").unwrap();
        assert_eq!((a.key.as_str(), a.values.len()), ("grid.h", 2));
    }

    #[test]
    fn empty_and_repeated_values_are_refused() {
        for bad in [
            "grid.h=",
            "grid.h=0.1,,0.2",
            "grid.h=0.1,",
            "grid.h",
            "=1,2",
        ] {
            let e = Axis::parse(bad).unwrap_err().to_string();
            assert!(e.contains("--vary"), "{bad}: {e}");
        }
        let e = Axis::parse("grid.h=0.1,0.1").unwrap_err().to_string();
        assert!(e.contains("twice") && e.contains("0.1"), "{e}");
    }

    #[test]
    fn product_varies_the_last_axis_fastest() {
        let axes = [
            Axis::parse("a=1,2").unwrap(),
            Axis::parse("b=x,y,z").unwrap(),
        ];
        let p = product(&axes);
        assert_eq!(p.len(), 6);
        assert_eq!(p[1], ["1", "y"]);
        assert_eq!(p[3], ["2", "x"]);
    }

    #[test]
    fn ids_are_folder_safe_and_quoting_survives_sh() {
        assert_eq!(
            run_id(3, 2, &["lme".into(), "[-5, 0]".into()]),
            "03-lme_-50"
        );
        assert_eq!(shell_quote("grid.h=0.01"), "grid.h=0.01");
        assert_eq!(shell_quote("a b"), "'a b'");
        assert_eq!(shell_quote("it's"), "'it'\\''s'");
    }
}
