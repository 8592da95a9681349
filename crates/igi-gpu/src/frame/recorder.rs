//! The recorder: the frame's passes, in the order the frame lists them, grouped into
//! stages and encoded. It owns the ordering: it decides which passes run side by side
//! from what each binds, so no pass needs to know its neighbours.
//!
//! **Why side by side.** Passes that depend on none of each other run best in one stage:
//! each ends on a few slow warps, and the next one's work fills the GPU meanwhile. In one
//! compute pass wgpu puts a barrier before a dispatch when one of its buffers changes
//! state, and also when it binds read-write a buffer that an earlier dispatch of the frame
//! bound read-write (whether or not either writes it); a barrier waits for every dispatch
//! before it. So a pass joins the stage before it only when, for every buffer it binds:
//! - no pass of the stage binds the buffer read-write;
//! - if the pass binds it read-write, nothing in the frame has bound it before (its
//!   outputs are new);
//! - if it only reads the buffer, no pass of the stage binds it differently; a buffer
//!   that an earlier stage wrote is put in its read state at the start of the stage
//!   ([`Stage::ready`]), where a barrier is due anyway.
//!
//! The scene's bind group binds the ray counters read-write in every pass; a pass beside
//! another gets a copy of the scene's bind group with counters of its own
//! (`SceneBuffers::beside_bind_groups`), each used once a frame, unless the frame counts
//! rays (then all count into one buffer, and wgpu serialises them).
//!
//! **Where stages go.** All in one compute pass, with the stages' timestamps written
//! inside it (one between two stages: `Profiler::set_chained`), where the device can (or
//! where nothing is timed); else one compute pass per stage, with a timestamp pair each.
//! wgpu makes command buffers of every compute pass, and each boundary leaves the GPU
//! idle for a moment.
//!
//! [`plan_stages`] is the rule alone, on any buffer keys, tested on the CPU below;
//! `tests/frame_stages.rs` checks the stages of each set-up on a device.

use crate::passes::bindings::{Access, Bound};
use crate::passes::{GatherRanges, Step, GATHER_RANGE_STRIDE};
use crate::profiler::Profiler;
use crate::scene_buffers::SceneBuffers;
use crate::switches::Switches;
use std::collections::HashMap;
use std::hash::Hash;

/// One pass of a frame as the frame lists it: its dispatches, in order, and its bind
/// groups beside the scene's.
pub(crate) struct FramePass<'a> {
    /// Its name in the stage timings (stages side by side join their names with " + ").
    pub name: &'static str,
    pub steps: Vec<Step<'a>>,
    /// Bind group 1: the pass's own buffers.
    pub group1: Bound<'a>,
    /// Bind group 2 of the gathers: every step runs once per VPL range.
    pub ranges: Option<GatherRanges<'a>>,
    /// Bind group 3, for the pipelines that have one.
    pub group3: Option<Bound<'a>>,
}

impl<'a> FramePass<'a> {
    /// A pass with bind group 1 alone.
    pub fn new(name: &'static str, steps: Vec<Step<'a>>, group1: Bound<'a>) -> FramePass<'a> {
        FramePass {
            name,
            steps,
            group1,
            ranges: None,
            group3: None,
        }
    }

    /// The same pass run once per range of `ranges`.
    pub fn over(mut self, ranges: GatherRanges<'a>) -> FramePass<'a> {
        self.ranges = Some(ranges);
        self
    }

    /// The same pass with bind group 3.
    pub fn with_group3(mut self, group3: Bound<'a>) -> FramePass<'a> {
        self.group3 = Some(group3);
        self
    }

    /// Every buffer the pass binds (the scene's aside), with its access.
    fn uses(&self) -> Vec<(&'a wgpu::Buffer, Access)> {
        let mut uses = self.group1.uses.clone();
        if let Some(g) = &self.group3 {
            uses.extend(g.uses.iter().copied());
        }
        uses
    }
}

/// A stage of the frame: passes `first..first + len` of the list, side by side, and the
/// buffers to put in a read state before it.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Stage<K> {
    pub first: usize,
    pub len: usize,
    /// Buffers that the stage's passes read and an earlier stage bound read-write, with
    /// the state they are read in (only for stages of more than one pass: a single pass's
    /// own dispatch moves them).
    pub ready: Vec<(K, Access)>,
}

/// Groups passes, each given by the buffers it binds with their access, into stages by
/// the rule of the module's documentation. `side_by_side` false puts each pass in a stage
/// of its own; at most `most_beside` passes of the frame join a stage after its first
/// (the spare ray counters).
pub fn plan_stages<K: Copy + Eq + Hash>(
    passes: &[Vec<(K, Access)>],
    side_by_side: bool,
    most_beside: usize,
) -> Vec<Stage<K>> {
    // How each buffer was last bound in the frame before the current stage.
    let mut frame_state: HashMap<K, Access> = HashMap::new();
    let mut stages = vec![];
    let mut beside = 0;
    let mut i = 0;
    while i < passes.len() {
        let first = i;
        let mut in_stage: HashMap<K, Access> = HashMap::new();
        let add = |uses: &[(K, Access)], in_stage: &mut HashMap<K, Access>| {
            for &(k, a) in uses {
                // Read-write wins: it is what the others must not meet.
                let e = in_stage.entry(k).or_insert(a);
                if a == Access::Write {
                    *e = a;
                }
            }
        };
        add(&passes[i], &mut in_stage);
        i += 1;
        while side_by_side && beside < most_beside && i < passes.len() {
            let joins = passes[i].iter().all(|&(k, a)| {
                let in_stage_as = in_stage.get(&k).copied();
                match a {
                    Access::Write => in_stage_as.is_none() && !frame_state.contains_key(&k),
                    _ => match in_stage_as {
                        Some(s) => s == a,
                        None => frame_state
                            .get(&k)
                            .is_none_or(|&s| s == a || s == Access::Write),
                    },
                }
            });
            if !joins {
                break;
            }
            add(&passes[i], &mut in_stage);
            beside += 1;
            i += 1;
        }
        let mut ready = vec![];
        if i - first > 1 {
            for uses in &passes[first..i] {
                for &(k, a) in uses {
                    if a.reads_only()
                        && frame_state.get(&k) == Some(&Access::Write)
                        && !ready.iter().any(|&(r, _)| r == k)
                    {
                        ready.push((k, a));
                    }
                }
            }
        }
        for uses in &passes[first..i] {
            for &(k, a) in uses {
                frame_state.insert(k, a);
            }
        }
        stages.push(Stage {
            first,
            len: i - first,
            ready,
        });
    }
    stages
}

/// A stage's name: its passes' names joined by " + ", kept for the life of the process
/// (the timings and the bench name stages by `&'static str`; a frame has a handful of
/// distinct combinations, so the set stays small).
pub fn stage_name(parts: &[&'static str]) -> &'static str {
    if let [one] = parts {
        return one;
    }
    static NAMES: std::sync::Mutex<Vec<&'static str>> = std::sync::Mutex::new(Vec::new());
    let joined = parts.join(" + ");
    let mut names = NAMES.lock().unwrap_or_else(|e| e.into_inner());
    if let Some(&name) = names.iter().find(|&&n| n == joined) {
        return name;
    }
    let name: &'static str = Box::leak(joined.into_boxed_str());
    names.push(name);
    name
}

/// The stages of a frame of `passes` (see [`plan_stages`]), by name, each with the names
/// of its passes.
pub(crate) fn stage_names(
    passes: &[FramePass],
    switches: &Switches,
) -> Vec<(&'static str, Vec<&'static str>)> {
    plan(passes, switches)
        .iter()
        .map(|s| {
            let parts: Vec<_> = passes[s.first..s.first + s.len]
                .iter()
                .map(|p| p.name)
                .collect();
            (stage_name(&parts), parts)
        })
        .collect()
}

fn plan<'a>(passes: &[FramePass<'a>], switches: &Switches) -> Vec<Stage<&'a wgpu::Buffer>> {
    let uses: Vec<_> = passes.iter().map(FramePass::uses).collect();
    plan_stages(
        &uses,
        switches.side_by_side,
        crate::scene_buffers::SPARE_COUNTERS,
    )
}

/// Encode `passes` into `encoder`, stage by stage, each between its timestamps; returns
/// the stages' names in order. `counting`: the frame counts rays (every pass binds the
/// scene's own counters).
pub(crate) fn record(
    encoder: &mut wgpu::CommandEncoder,
    profiler: &Profiler,
    scene: &SceneBuffers,
    passes: &[FramePass],
    switches: &Switches,
    counting: bool,
) -> Vec<&'static str> {
    let stages = plan(passes, switches);
    let one_pass = profiler.writes_inside_passes() && !switches.stage_passes;
    profiler.set_chained(one_pass);
    let mut frame_pass = one_pass.then(|| {
        encoder
            .begin_compute_pass(&wgpu::ComputePassDescriptor {
                label: Some("frame"),
                timestamp_writes: None,
            })
            .forget_lifetime()
    });
    let mut names = vec![];
    let mut spare = 0;
    for (index, stage) in stages.iter().enumerate() {
        let parts = &passes[stage.first..stage.first + stage.len];
        let name = stage_name(&parts.iter().map(|p| p.name).collect::<Vec<_>>());
        names.push(name);
        let index = index as u32;
        // The scene's bind group of each part: its own counters beside the first.
        let scenes: Vec<&wgpu::BindGroup> = (0..parts.len())
            .map(|k| {
                if k == 0 || counting {
                    &scene.bind_group
                } else {
                    spare += 1;
                    &scene.beside_bind_groups[spare - 1]
                }
            })
            .collect();
        match &mut frame_pass {
            Some(cpass) => {
                if !stage.ready.is_empty() {
                    cpass.transition_resources(
                        stage
                            .ready
                            .iter()
                            .map(|&(buffer, access)| wgpu::BufferTransition {
                                buffer,
                                state: read_state(access),
                            }),
                        std::iter::empty(),
                    );
                }
                // Stages follow each other: one's end is the next one's start.
                if index == 0 {
                    profiler.write_inside(cpass, 0);
                }
                cpass.push_debug_group(name);
                dispatch(cpass, parts, &scenes);
                cpass.pop_debug_group();
                profiler.write_inside(cpass, 2 * index + 1);
            }
            None => {
                let mut cpass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
                    label: Some(name),
                    timestamp_writes: profiler.pass_writes(index),
                });
                dispatch(&mut cpass, parts, &scenes);
            }
        }
    }
    names
}

/// The buffer state a read of `access` leaves.
fn read_state(access: Access) -> wgpu::BufferUses {
    match access {
        Access::Params => wgpu::BufferUses::UNIFORM,
        _ => wgpu::BufferUses::STORAGE_READ_ONLY,
    }
}

/// The dispatches of `parts`, in order, part k with the scene's bind group `scenes[k]`.
fn dispatch(cpass: &mut wgpu::ComputePass, parts: &[FramePass], scenes: &[&wgpu::BindGroup]) {
    for (part, scene) in parts.iter().zip(scenes) {
        cpass.set_bind_group(0, *scene, &[]);
        cpass.set_bind_group(1, &part.group1.group, &[]);
        if let Some(g) = &part.group3 {
            cpass.set_bind_group(3, &g.group, &[]);
        }
        for (pipeline, groups) in &part.steps {
            cpass.set_pipeline(pipeline);
            let run = |cpass: &mut wgpu::ComputePass| {
                cpass.dispatch_workgroups(groups[0], groups[1], groups[2])
            };
            match &part.ranges {
                None => run(cpass),
                Some(r) => {
                    for i in r.first..r.first + r.count {
                        let offset = (i as u64 * GATHER_RANGE_STRIDE) as u32;
                        cpass.set_bind_group(2, r.bind_group, &[offset]);
                        run(cpass);
                    }
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use Access::{Params, Read, Write};

    fn names(stages: &[Stage<&str>]) -> Vec<(usize, usize)> {
        stages.iter().map(|s| (s.first, s.len)).collect()
    }

    #[test]
    fn passes_that_share_no_written_buffer_run_side_by_side() {
        let passes = vec![
            vec![("params", Params), ("vpls", Write)],
            vec![("params", Params), ("gbuffer", Write)],
            // Reads what the first stage wrote: a new stage, the G-buffer made ready.
            vec![("vpls", Read), ("e", Write)],
            vec![("gbuffer", Read), ("mirror e", Write)],
        ];
        let stages = plan_stages(&passes, true, 4);
        assert_eq!(names(&stages), [(0, 2), (2, 2)]);
        assert_eq!(stages[1].ready, [("vpls", Read), ("gbuffer", Read)]);
        assert!(stages[0].ready.is_empty());
    }

    #[test]
    fn a_pass_that_reads_what_the_stage_writes_starts_a_stage() {
        let passes = vec![
            vec![("a", Write)],
            vec![("a", Read), ("b", Write)],
            vec![("b", Read), ("c", Write)],
        ];
        assert_eq!(
            names(&plan_stages(&passes, true, 4)),
            [(0, 1), (1, 1), (2, 1)]
        );
    }

    #[test]
    fn a_buffer_bound_read_write_twice_in_a_frame_keeps_passes_apart() {
        // Neither may write it, but wgpu puts a barrier between two read-write bindings.
        let passes = vec![
            vec![("a", Write)],
            vec![("a", Read), ("scratch", Write)],
            vec![("b", Read), ("scratch", Write)],
        ];
        assert_eq!(
            names(&plan_stages(&passes, true, 4)),
            [(0, 1), (1, 1), (2, 1)]
        );
        // A buffer read in the stage and then bound read-write changes state: apart too.
        let passes = vec![vec![("x", Write)], vec![("a", Read)], vec![("a", Write)]];
        assert_eq!(names(&plan_stages(&passes, true, 4)), [(0, 2), (2, 1)]);
        // So does one read in an earlier stage.
        let passes = vec![
            vec![("a", Read), ("x", Write)],
            vec![("x", Read)],
            vec![("a", Write)],
        ];
        assert_eq!(
            names(&plan_stages(&passes, true, 4)),
            [(0, 1), (1, 1), (2, 1)]
        );
    }

    #[test]
    fn one_buffer_read_in_two_states_keeps_passes_apart() {
        let passes = vec![vec![("x", Write)], vec![("p", Params)], vec![("p", Read)]];
        assert_eq!(names(&plan_stages(&passes, true, 4)), [(0, 2), (2, 1)]);
    }

    #[test]
    fn the_switch_and_the_spare_counters_bound_the_stages() {
        let passes = vec![vec![("a", Write)], vec![("b", Write)], vec![("c", Write)]];
        assert_eq!(names(&plan_stages(&passes, true, 4)), [(0, 3)]);
        assert_eq!(names(&plan_stages(&passes, true, 1)), [(0, 2), (2, 1)]);
        assert_eq!(
            names(&plan_stages(&passes, false, 4)),
            [(0, 1), (1, 1), (2, 1)]
        );
    }

    #[test]
    fn joined_names_are_kept_once() {
        let a = stage_name(&["indirect", "mirror indirect"]);
        let b = stage_name(&["indirect", "mirror indirect"]);
        assert_eq!(a, "indirect + mirror indirect");
        assert!(std::ptr::eq(a, b));
        assert_eq!(stage_name(&["compose"]), "compose");
    }
}
