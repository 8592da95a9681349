//! The GPU's set-up (adapter, device and the passes' pipelines of the frame of Marques
//! and Santos, section 4) on a thread of its own, so that it runs while a command loads
//! its scenes, which keeps one core busy.

use anyhow::{bail, Context, Result};
use igi_gpu::{AdapterChoice, GpuContext, GpuError, Passes};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;
use std::thread::JoinHandle;

/// What the thread made: the context, and the passes unless it was asked for the context
/// alone.
type SetUp = (GpuContext, Option<Passes>);

/// The set-up under way. On the H200 it takes about 0.3 s with the driver's shader cache
/// warm (as long as loading the conference room), on lavapipe about 0.7 s. It is always
/// joined, also when the scene fails (exiting while the thread is inside the GPU driver
/// could crash there); then [`GpuSetUp::abandon`] spares it the pipelines, most of its
/// time.
pub struct GpuSetUp {
    thread: JoinHandle<Result<Option<SetUp>, GpuError>>,
    abandoned: Arc<AtomicBool>,
}

impl GpuSetUp {
    /// Starts the set-up for the adapter that `--adapter` names (`None`: the default): the
    /// adapter, the device and the frame's passes.
    pub fn start(adapter: Option<String>) -> Result<GpuSetUp> {
        Self::spawn(adapter, true)
    }

    /// Starts the set-up of the adapter and device alone, for a command that may render no
    /// frame (`igi bench rays` on ray sets that no frame makes): the passes' pipelines
    /// take longer than the device (2.8 s on the H200 with a cold shader cache).
    pub fn start_context(adapter: Option<String>) -> Result<GpuSetUp> {
        Self::spawn(adapter, false)
    }

    fn spawn(adapter: Option<String>, with_passes: bool) -> Result<GpuSetUp> {
        let abandoned = Arc::new(AtomicBool::new(false));
        let flag = abandoned.clone();
        let thread = std::thread::Builder::new()
            .name("gpu set-up".into())
            .spawn(move || {
                let ctx = GpuContext::new(&AdapterChoice::from_option(adapter.as_deref()))?;
                if flag.load(Ordering::Relaxed) {
                    return Ok(None);
                }
                let passes = with_passes.then(|| Passes::new(&ctx));
                Ok(Some((ctx, passes)))
            })
            .context("cannot start the GPU set-up thread")?;
        Ok(GpuSetUp { thread, abandoned })
    }

    /// Waits for the set-up: the context and the passes (made now where the set-up was
    /// started without them), or the set-up's error.
    pub fn join(self) -> Result<(GpuContext, Passes)> {
        let (ctx, passes) = self.join_inner()?;
        let passes = passes.unwrap_or_else(|| Passes::new(&ctx));
        Ok((ctx, passes))
    }

    /// Waits for the set-up and keeps the context alone (passes it made are dropped).
    pub fn join_context(self) -> Result<GpuContext> {
        Ok(self.join_inner()?.0)
    }

    fn join_inner(self) -> Result<SetUp> {
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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_context_alone_makes_no_passes_until_they_are_asked_for() {
        if let Err(e) = GpuContext::new(&AdapterChoice::Best) {
            crate::note!("skipped: no adapter ({e})");
            return;
        }
        let (full, bare) = (
            GpuSetUp::start(None).unwrap(),
            GpuSetUp::start_context(None).unwrap(),
        );
        assert!(full.join_inner().unwrap().1.is_some(), "passes made");
        assert!(bare.join_inner().unwrap().1.is_none(), "no passes made");
        // Joined for the passes, a context-only set-up makes them then.
        let (ctx, passes) = GpuSetUp::start_context(None).unwrap().join().unwrap();
        let scene = igi_core::scene::builtin::builtin_scene("cornell-box").unwrap();
        let bvh = igi_core::bvh::Bvh::build(&scene.triangles);
        assert!(igi_gpu::Renderer::with_passes(&ctx, passes, &scene, &bvh).is_ok());
    }
}
