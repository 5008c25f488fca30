//! Scenes: read a TOML file, apply `--set` overrides, check every value.
//! What comes out (`Scene`) is the file with defaults filled in and every
//! value known to be in range; `model::Model::new` turns it into particles
//! and a grid.

pub mod defaults;
pub mod overlap;
pub mod overrides;
pub mod schema;
pub mod seed;
mod validate;

pub use overrides::Override;
pub use schema::*;

use crate::error::SceneError;
use std::path::Path;

impl Scene {
    /// Reads `path`, applies `overrides` in order, and checks the result.
    pub fn load(path: &Path, overrides: &[Override]) -> Result<Scene, SceneError> {
        let text = read_capped(path, crate::limits::SCENE_FILE_MAX)?;
        let stem = path
            .file_stem()
            .map(|s| s.to_string_lossy().into_owned())
            .unwrap_or_else(|| "scene".to_string());
        Scene::from_str(&text, &path.display().to_string(), &stem, overrides)
    }

    /// Like `load`, from text already in memory. `origin` names the text in
    /// messages; `default_name` is used when the scene sets no `name`.
    pub fn from_str(
        text: &str,
        origin: &str,
        default_name: &str,
        overrides: &[Override],
    ) -> Result<Scene, SceneError> {
        let parse_err = |message: String| SceneError::Parse {
            path: origin.to_string(),
            message: message.trim_end().to_string(),
        };
        let mut dropped = Vec::new();
        let file: SceneFile = if overrides.is_empty() {
            // Straight from the text: messages carry line, column and a caret.
            toml::from_str(text).map_err(|e| parse_err(e.to_string()))?
        } else {
            let mut table: toml::Table = text
                .parse()
                .map_err(|e: toml::de::Error| parse_err(e.to_string()))?;
            for o in overrides {
                o.apply(&mut table)?;
            }
            dropped = drop_replaced_shape_keys(&mut table, overrides);
            // From the table: messages carry the full key path instead of a line.
            serde::Deserialize::deserialize(table)
                .map_err(|e: toml::de::Error| parse_err(e.to_string()))?
        };
        let mut scene = validate::check(file, default_name)?;
        scene.chosen.extend(dropped);
        Ok(scene)
    }
}

/// The scene file's keys of its own shape function that an override of
/// `solver.shape` (or `method`, `gmm_basis`) has made meaningless, removed from
/// `table`, one note per key: `--set solver.shape=linear` on an LME scene
/// runs it with linear shapes, and its `lme_gamma` was written for the
/// shape replaced. A key that an override sets itself stays (and is
/// refused where it does not apply); without such an override the file's
/// keys stay and `validate` refuses those its shape does not read.
fn drop_replaced_shape_keys(table: &mut toml::Table, overrides: &[Override]) -> Vec<String> {
    let set = |key: &str| overrides.iter().any(|o| o.path == ["solver", key]);
    if !(set("shape") || set("method") || set("gmm_basis")) {
        return Vec::new();
    }
    let Some(toml::Value::Table(solver)) = table.get_mut("solver") else {
        return Vec::new();
    };
    let text = |k: &str| solver.get(k).and_then(|v| v.as_str().map(str::to_string));
    let shape = text("shape").unwrap_or_else(|| "lme".to_string());
    let gmm = text("method").as_deref() == Some("gmm");
    let lme = shape == "lme" || (gmm && text("gmm_basis").as_deref().unwrap_or("lme") == "lme");
    let bspline = shape.starts_with("bspline");
    let mut notes = Vec::new();
    for (key, reads) in [
        ("lme_gamma", lme),
        ("lme_tol", lme),
        ("bspline_knots", bspline),
    ] {
        if !reads && !set(key) && solver.remove(key).is_some() {
            notes.push(format!(
                "solver.{key} of the scene file dropped: the override of the shape function ({shape}) does not read it"
            ));
        }
    }
    notes
}

/// Reads at most `cap` bytes of `path` as UTF-8; a longer file (or an
/// endless one such as /dev/zero) is refused after reading `cap + 1` bytes.
fn read_capped(path: &Path, cap: u64) -> Result<String, SceneError> {
    use std::io::Read;
    let err = |message: String| SceneError::Parse {
        path: path.display().to_string(),
        message,
    };
    let file = std::fs::File::open(path).map_err(|e| err(format!("cannot read the file: {e}")))?;
    let mut bytes = Vec::new();
    file.take(cap + 1)
        .read_to_end(&mut bytes)
        .map_err(|e| err(format!("cannot read the file: {e}")))?;
    if bytes.len() as u64 > cap {
        return Err(err(format!(
            "is larger than {} MiB: not a scene file",
            cap >> 20
        )));
    }
    String::from_utf8(bytes).map_err(|e| err(format!("is not UTF-8 text: {e}")))
}

/// The first key at which two scenes as TOML differ, in words, naming each
/// side by its label ("grid.h = 0.01 in the folder, 0.005 in the plan");
/// keys in `skip` (dotted) are passed over, on either side.
pub fn first_difference(
    got: &toml::Value,
    want: &toml::Value,
    skip: &[&str],
    labels: (&str, &str),
) -> Option<String> {
    difference_at(got, want, "", skip, labels)
}

fn difference_at(
    got: &toml::Value,
    want: &toml::Value,
    at: &str,
    skip: &[&str],
    (l1, l2): (&str, &str),
) -> Option<String> {
    let key = |k: &str| {
        if at.is_empty() {
            k.to_string()
        } else {
            format!("{at}.{k}")
        }
    };
    match (got, want) {
        (toml::Value::Table(a), toml::Value::Table(b)) => {
            let keys: std::collections::BTreeSet<&String> = a.keys().chain(b.keys()).collect();
            keys.into_iter().find_map(|k| {
                let dotted = key(k);
                if skip.contains(&dotted.as_str()) {
                    return None;
                }
                match (a.get(k), b.get(k)) {
                    (Some(x), Some(y)) => difference_at(x, y, &dotted, skip, (l1, l2)),
                    (Some(x), None) => Some(format!("{dotted} = {x} in {l1}, unset in {l2}")),
                    (None, Some(y)) => Some(format!("{dotted} unset in {l1}, {y} in {l2}")),
                    (None, None) => None,
                }
            })
        }
        (a, b) if a == b => None,
        (a, b) => Some(format!("{at} = {a} in {l1}, {b} in {l2}")),
    }
}
