//! GPU time per stage from timestamp queries (paper section 5 reports the share of each
//! stage): a begin/end timestamp pair per stage, or, where the stages follow each other
//! inside one compute pass, one timestamp between two stages, the end of one and the
//! start of the next, so that the stage times add up to the frame time (what falls
//! between two stages, the barrier and the start of the next dispatch, counts for the
//! next).

use std::cell::Cell;
use std::time::Instant;

use crate::context::{GpuContext, GpuError};

/// Least wall time of untimed work before timed GPU work: an idle GPU clocks down within
/// a second, and a few short warm-up runs (3 frames, or 3 traces of 10 ms) do not bring
/// its clocks back up: without it the bench's medians measured the clocking, not the
/// work, and so did a trace of rays right after another program had used the GPU.
pub const WARMUP_SECONDS: f64 = 0.5;

/// The untimed runs before timed ones: at least `runs` of them, and while there are any,
/// at least [`WARMUP_SECONDS`] of them. `while warm_up.more() { run() }`.
pub struct WarmUp {
    runs: u32,
    done: u32,
    start: Instant,
}

impl WarmUp {
    /// A warm-up of at least `runs` runs (none at all for 0), started now.
    pub fn new(runs: u32) -> WarmUp {
        WarmUp {
            runs,
            done: 0,
            start: Instant::now(),
        }
    }

    /// Whether to make one more untimed run (counted as made).
    pub fn more(&mut self) -> bool {
        let more = self.more_after(self.start.elapsed().as_secs_f64());
        self.done += u32::from(more);
        more
    }

    /// Whether a run is still due after `seconds` of warm-up with `done` runs made.
    fn more_after(&self, seconds: f64) -> bool {
        self.done < self.runs || (self.runs > 0 && seconds < WARMUP_SECONDS)
    }
}

/// GPU time of one stage of a frame.
#[derive(Clone, Debug, PartialEq)]
pub struct StageTime {
    pub name: &'static str,
    pub ms: f64,
}

pub struct Profiler {
    query_set: Option<wgpu::QuerySet>,
    resolve: Option<wgpu::Buffer>,
    capacity: u32,
    /// Whether timestamps can be written inside a compute pass (between its dispatches).
    inside_passes: bool,
    /// Whether the last frame's stages were timed back to back (see [`Self::set_chained`]).
    chained: Cell<bool>,
}

impl Profiler {
    /// Room for `stages` begin/end pairs; inert when the device has no timestamps.
    pub fn new(ctx: &GpuContext, stages: u32) -> Profiler {
        if !ctx.timestamps {
            return Profiler {
                query_set: None,
                resolve: None,
                capacity: stages,
                inside_passes: true,
                chained: Cell::new(false),
            };
        }
        let count = 2 * stages;
        let query_set = ctx.device.create_query_set(&wgpu::QuerySetDescriptor {
            label: Some("stage timestamps"),
            ty: wgpu::QueryType::Timestamp,
            count,
        });
        let resolve = ctx.device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("timestamp resolve"),
            size: 8 * count as u64,
            usage: wgpu::BufferUsages::QUERY_RESOLVE | wgpu::BufferUsages::COPY_SRC,
            mapped_at_creation: false,
        });
        Profiler {
            query_set: Some(query_set),
            resolve: Some(resolve),
            capacity: stages,
            inside_passes: ctx
                .device
                .features()
                .contains(wgpu::Features::TIMESTAMP_QUERY_INSIDE_PASSES),
            chained: Cell::new(false),
        }
    }

    /// How the frame being recorded writes its timestamps: `true` when its stages follow
    /// each other in one compute pass and only stage 0 writes a start (index 0), every
    /// stage i its end (index 2 i + 1), which is also stage i + 1's start; `false` for a
    /// begin/end pair per stage. [`Self::read`] reads them the same way.
    pub fn set_chained(&self, chained: bool) {
        self.chained.set(chained);
    }

    /// Whether stages can share one compute pass and still be timed one by one (also
    /// true when nothing is timed).
    pub fn writes_inside_passes(&self) -> bool {
        self.inside_passes
    }

    /// Write timestamp `index` between two dispatches of `cpass`.
    pub fn write_inside(&self, cpass: &mut wgpu::ComputePass, index: u32) {
        assert!(
            index < 2 * self.capacity,
            "profiler has room for {} stages",
            self.capacity
        );
        if let Some(qs) = &self.query_set {
            cpass.write_timestamp(qs, index);
        }
    }

    pub fn enabled(&self) -> bool {
        self.query_set.is_some()
    }

    /// The timestamp writes for the compute pass of stage `stage`.
    pub fn pass_writes(&self, stage: u32) -> Option<wgpu::ComputePassTimestampWrites<'_>> {
        assert!(
            stage < self.capacity,
            "profiler has room for {} stages",
            self.capacity
        );
        self.query_set
            .as_ref()
            .map(|qs| wgpu::ComputePassTimestampWrites {
                query_set: qs,
                beginning_of_pass_write_index: Some(2 * stage),
                end_of_pass_write_index: Some(2 * stage + 1),
            })
    }

    /// Copy the timestamps of the first `stages` stages into the resolve buffer.
    pub fn resolve(&self, encoder: &mut wgpu::CommandEncoder, stages: u32) {
        if let (Some(qs), Some(buf)) = (&self.query_set, &self.resolve) {
            encoder.resolve_query_set(qs, 0..2 * stages, buf, 0);
        }
    }

    /// Read the stage times back (after the frame's submission), with the span from the
    /// first stage's start to the last one's end; `None` without timestamps.
    pub fn read(
        &self,
        ctx: &GpuContext,
        names: &[&'static str],
    ) -> Result<Option<(Vec<StageTime>, f64)>, GpuError> {
        let Some(buf) = &self.resolve else {
            return Ok(None);
        };
        let ticks: Vec<u64> = ctx.read_buffer(buf)?;
        let ms = |from: u64, to: u64| {
            to.saturating_sub(from) as f64 * ctx.queue.get_timestamp_period() as f64 * 1e-6
        };
        let start = |i: usize| {
            if self.chained.get() && i > 0 {
                ticks[2 * i - 1]
            } else {
                ticks[2 * i]
            }
        };
        let stages = names
            .iter()
            .enumerate()
            .map(|(i, &name)| StageTime {
                name,
                ms: ms(start(i), ticks[2 * i + 1]),
            })
            .collect();
        let span = ms(ticks[0], ticks[2 * names.len() - 1]);
        Ok(Some((stages, span)))
    }
}

impl Profiler {
    /// A profiler that records nothing (for work outside the timed frame).
    pub fn disabled() -> Profiler {
        Profiler {
            query_set: None,
            resolve: None,
            capacity: u32::MAX / 2,
            inside_passes: true,
            chained: Cell::new(false),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn warm_up_runs_the_runs_asked_and_for_at_least_its_time() {
        let at = |runs: u32, done: u32, seconds: f64| {
            WarmUp {
                runs,
                done,
                start: Instant::now(),
            }
            .more_after(seconds)
        };
        // No warm-up asked: none, however early.
        assert!(!at(0, 0, 0.0));
        // The runs asked, however late.
        assert!(at(3, 0, 10.0) && at(3, 2, 10.0));
        // Past them, runs until WARMUP_SECONDS and not after.
        assert!(at(3, 3, 0.0) && at(3, 50, WARMUP_SECONDS - 0.01));
        assert!(!at(3, 3, WARMUP_SECONDS) && !at(3, 50, 1.0));
        // `more` counts what it allows: a warm-up of 1 run says yes at least once.
        let mut w = WarmUp::new(1);
        assert!(w.more());
        assert_eq!(w.done, 1);
    }
}
