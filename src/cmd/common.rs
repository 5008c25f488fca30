//! What every command handler shares: loading a scene with `--set`
//! overrides, exit codes for errors, writing to stdout, the `--adapter`
//! check and the signal handlers. A leaf, so `main.rs` and the handlers in
//! `cmd/` name it and not each other.

use lme_mpm::scene::{Override, Scene};
use lme_mpm::{Error, SceneError};
use std::process::ExitCode;
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};

/// `--adapter` picks among GPU adapters: with `--backend cpu` it would be ignored.
pub fn adapter_without_gpu(adapter: &Option<String>, cpu: bool) -> Option<ExitCode> {
    (adapter.is_some() && cpu).then(|| {
        eprintln!(
            "error: --adapter names a GPU adapter, but --backend cpu runs no GPU: drop one of them"
        );
        ExitCode::from(2)
    })
}

pub fn load(path: &std::path::Path, set: &[String]) -> Result<Scene, SceneError> {
    let overrides = set
        .iter()
        .map(|s| Override::parse(s))
        .collect::<Result<Vec<_>, _>>()?;
    Scene::load(path, &overrides)
}

/// Writes `text` to stdout: a reader that closed the pipe took what it
/// wanted (exit 0); any other failure (a full disk) is an error (exit 1),
/// never a panic.
pub fn write_stdout(text: &str) -> ExitCode {
    use std::io::Write;
    let mut out = std::io::stdout().lock();
    match out.write_all(text.as_bytes()).and_then(|()| out.flush()) {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) if e.kind() == std::io::ErrorKind::BrokenPipe => ExitCode::SUCCESS,
        Err(e) => {
            lme_mpm::say!("error: cannot write to standard output: {e}");
            ExitCode::from(1)
        }
    }
}

pub fn fail(e: &Error) -> ExitCode {
    lme_mpm::say!("error: {e}");
    ExitCode::from(e.exit_code() as u8)
}

/// SIGINT, SIGTERM and SIGHUP raise `stop` (the run ends at the next step
/// boundary with every output and a checkpoint) and record which came
/// first. A repeat is ignored within `REPEAT_GRACE` of the first (GNU
/// `timeout` signals the process and then its group: two at once) and
/// while a run saves; later, it ends the process at once, each run folder
/// saying `interrupted` and holding no lock (`output::folder::abandon_all`).
pub struct Signals {
    pub stop: Arc<AtomicBool>,
    which: Arc<AtomicUsize>,
}

/// A repeated signal this soon after the first is the same request.
const REPEAT_GRACE: std::time::Duration = std::time::Duration::from_secs(2);

impl Signals {
    pub fn install() -> std::io::Result<Signals> {
        use signal_hook::consts::{SIGHUP, SIGINT, SIGTERM};
        let stop = Arc::new(AtomicBool::new(false));
        let which = Arc::new(AtomicUsize::new(0));
        let mut incoming = signal_hook::iterator::Signals::new([SIGINT, SIGTERM, SIGHUP])?;
        let (flag, first_sig) = (Arc::clone(&stop), Arc::clone(&which));
        std::thread::Builder::new()
            .name("signals".into())
            .spawn(move || {
                let mut first: Option<std::time::Instant> = None;
                for sig in incoming.forever() {
                    let Some(at) = first else {
                        first_sig.store(sig as usize, Ordering::SeqCst);
                        flag.store(true, Ordering::SeqCst);
                        first = Some(std::time::Instant::now());
                        continue;
                    };
                    if at.elapsed() < REPEAT_GRACE {
                        continue;
                    }
                    if lme_mpm::output::folder::abandon_all() {
                        lme_mpm::say!(
                            "error: signal {sig} again before the run reached a step boundary: \
                             ended at once; summary.json says interrupted"
                        );
                        let code = 128 + first_sig.load(Ordering::SeqCst).clamp(1, 127);
                        std::process::exit(code as i32);
                    }
                    lme_mpm::say!(
                        "signal {sig} again: still saving, the run ends when it is saved"
                    );
                }
            })?;
        Ok(Signals { stop, which })
    }

    pub fn install_or_say() -> Option<Signals> {
        Signals::install()
            .map_err(|e| {
                lme_mpm::say!("error: cannot install the SIGINT/SIGTERM/SIGHUP handlers: {e}")
            })
            .ok()
    }

    /// 128 + the first signal: 129 SIGHUP, 130 SIGINT, 143 SIGTERM.
    pub fn exit_code(&self) -> ExitCode {
        let sig = self.which.load(Ordering::SeqCst);
        ExitCode::from((128 + sig.clamp(1, 127)) as u8)
    }
}
