//! The GPU's set-up (adapter, device and the passes' pipelines of the frame of Marques
//! and Santos, section 4) on a thread of its own, so that it runs while a command loads
//! its scenes, which keeps one core busy.

use anyhow::{bail, Context, Result};
use igi_gpu::{AdapterChoice, GpuContext, GpuError, Passes};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;
use std::thread::JoinHandle;

/// The set-up under way. On the H200 it takes about 0.3 s with the driver's shader cache
/// warm (as long as loading the conference room), on lavapipe about 0.7 s. It is always
/// joined, also when the scene fails (exiting while the thread is inside the GPU driver
/// could crash there); then [`GpuSetUp::abandon`] spares it the pipelines, most of its
/// time.
pub struct GpuSetUp {
    thread: JoinHandle<Result<Option<(GpuContext, Passes)>, GpuError>>,
    abandoned: Arc<AtomicBool>,
}

impl GpuSetUp {
    /// Starts the set-up for the adapter that `--adapter` names (`None`: the default).
    pub fn start(adapter: Option<String>) -> Result<GpuSetUp> {
        let abandoned = Arc::new(AtomicBool::new(false));
        let flag = abandoned.clone();
        let thread = std::thread::Builder::new()
            .name("gpu set-up".into())
            .spawn(move || {
                let ctx = GpuContext::new(&AdapterChoice::from_option(adapter.as_deref()))?;
                if flag.load(Ordering::Relaxed) {
                    return Ok(None);
                }
                let passes = Passes::new(&ctx);
                Ok(Some((ctx, passes)))
            })
            .context("cannot start the GPU set-up thread")?;
        Ok(GpuSetUp { thread, abandoned })
    }

    /// Waits for the set-up: the context and the passes, or the set-up's error.
    pub fn join(self) -> Result<(GpuContext, Passes)> {
        match self.thread.join() {
            Ok(Ok(Some(set_up))) => Ok(set_up),
            // Only `abandon` sets the flag, and it consumes the set-up.
            Ok(Ok(None)) => bail!("the GPU set-up was abandoned"),
            Ok(Err(e)) => Err(e.into()),
            Err(_) => bail!("the GPU set-up failed (its thread panicked)"),
        }
    }

    /// Waits for the thread after telling it to skip what it has not begun.
    pub fn abandon(self) {
        self.abandoned.store(true, Ordering::Relaxed);
        let _ = self.thread.join();
    }
}
