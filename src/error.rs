//! The crate's error type: every variant says what went wrong and what the
//! user can do about it. The binary maps each to an exit code (`exit_code`).

use std::path::PathBuf;

/// Errors from loading a scene, running it, or writing its outputs.
///
/// An unstable run is *not* an error: it is a result (`RunStatus::Unstable`).
#[derive(Debug, thiserror::Error)]
pub enum Error {
    /// The scene file or a `--set` override is invalid. Nothing was written.
    #[error("invalid scene: {0}")]
    Scene(#[from] SceneError),

    /// A file could not be read or written.
    #[error("{action} {path}: {source}")]
    Io {
        action: &'static str,
        path: PathBuf,
        #[source]
        source: std::io::Error,
    },

    /// `--backend gpu` was asked for but no usable adapter exists.
    #[error("no GPU adapter: {0}")]
    NoAdapter(String),

    /// A checkpoint cannot be resumed: missing, corrupted, from another
    /// version, or not matching its scene.
    #[error("checkpoint {0}")]
    Checkpoint(String),

    /// The output folder cannot be used: not an lme-mpm folder, or another
    /// run holds it.
    #[error("output folder {0}")]
    Folder(String),

    /// The GPU device reported an error (validation, out of memory, lost device).
    #[error("GPU error: {0}")]
    Gpu(String),

    /// A command's flag has a value outside what it allows; the message
    /// names the flag, the value and the range.
    #[error("{0}")]
    Usage(String),

    /// `bench --peer`: the peer's command failed or printed no measurement.
    #[error("bench: {0}")]
    Bench(String),
}

impl Error {
    /// Exit code of the `lme-mpm` binary for this error: 2 for invalid input,
    /// 1 for anything else (0 = completed and 3 = unstable are run results).
    pub fn exit_code(&self) -> i32 {
        match self {
            Error::Scene(_) | Error::Checkpoint(_) | Error::Folder(_) | Error::Usage(_) => 2,
            _ => 1,
        }
    }

    pub(crate) fn io(
        action: &'static str,
        path: impl Into<PathBuf>,
        source: std::io::Error,
    ) -> Self {
        Error::Io {
            action,
            path: path.into(),
            source,
        }
    }
}

/// A scene that cannot be run as written: names the key and what is allowed.
#[derive(Debug, thiserror::Error)]
pub enum SceneError {
    /// The file is not valid TOML or does not match the schema (unknown key,
    /// wrong type, unknown enum value). The message comes from the parser and
    /// names the key and line.
    #[error("{path}: {message}")]
    Parse { path: String, message: String },

    /// A key has a value outside what is allowed.
    #[error("`{key}` {message}")]
    Invalid { key: String, message: String },

    /// A `--set dotted.key=value` argument could not be applied.
    #[error("--set {arg}: {message}")]
    Override { arg: String, message: String },

    /// A `lme-mpm sweep` argument (`--vary KEY=V1,V2`, `--resolution`, a
    /// run of the product) cannot be used; `arg` names it with its value.
    #[error("{arg}: {message}")]
    Sweep { arg: String, message: String },
}

impl SceneError {
    pub(crate) fn invalid(key: impl Into<String>, message: impl Into<String>) -> Self {
        SceneError::Invalid {
            key: key.into(),
            message: message.into(),
        }
    }
}

pub type Result<T, E = Error> = std::result::Result<T, E>;
