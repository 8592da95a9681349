//! Timing of the BVH build, for `igi bench build` and the `bvh_build` example: the
//! build that replaces OptiX's acceleration structure in Marques and Santos' system, run
//! several times in one process, with what a reader needs to compare two figures (the
//! phases, the threads, the page faults of the first build, a hash of the tree). The
//! build figures of the lab log (docs/lab/PERFORMANCE.md) are measured with it
//! (`scripts/build-bench.sh`).

use std::fmt;
use std::time::Instant;

use super::{Bvh, BvhBuilder, BvhNode};
use crate::scene::Triangle;

/// What [`time_builds`] measured.
pub struct BuildTiming {
    pub builder: BvhBuilder,
    /// Threads of the pool the build ran on.
    pub threads: usize,
    /// Wall time of each build in milliseconds, sorted.
    pub times_ms: Vec<f64>,
    /// The median of each phase over the builds (see [`super::BuildStats::phases`]).
    pub phase_medians: Vec<(&'static str, f64)>,
    /// CPU time of one build, all threads (Linux; ticks of 10 ms, so meaningful over
    /// several builds), less sensitive than wall time to other processes.
    pub cpu_ms_per_build: Option<f64>,
    /// Minor page faults of the first build (Linux): what a build in a new process pays
    /// for fresh memory, a large share of its time.
    pub first_build_faults: Option<u64>,
    /// The last build's tree.
    pub bvh: Bvh,
}

impl BuildTiming {
    /// The median build time (the upper of the two middle builds for an even count, as
    /// `igi bench rays` takes its median run).
    pub fn median_ms(&self) -> f64 {
        self.times_ms[self.times_ms.len() / 2]
    }
}

/// Builds a BVH over `triangles` `runs` times (at least once) in this process, calling
/// `progress(k)` after build k (1-based).
pub fn time_builds(
    triangles: &[Triangle],
    builder: BvhBuilder,
    runs: usize,
    mut progress: impl FnMut(usize),
) -> BuildTiming {
    let runs = runs.max(1);
    let mut times_ms = Vec::with_capacity(runs);
    let mut phases: Vec<(&'static str, Vec<f64>)> = vec![];
    let cpu_start = process_cpu_seconds();
    let mut first_build_faults = None;
    let mut last = None;
    for k in 0..runs {
        let faults = minor_faults();
        let t = Instant::now();
        let bvh = Bvh::build_with(triangles, builder);
        times_ms.push(t.elapsed().as_secs_f64() * 1e3);
        if k == 0 {
            first_build_faults = minor_faults().zip(faults).map(|(b, a)| b - a);
        }
        for (i, &(name, ms)) in bvh.build_stats.phases.iter().enumerate() {
            if i == phases.len() {
                phases.push((name, vec![]));
            }
            phases[i].1.push(ms);
        }
        last = Some(bvh);
        progress(k + 1);
    }
    let cpu_ms_per_build = process_cpu_seconds()
        .zip(cpu_start)
        .map(|(b, a)| (b - a) * 1e3 / runs as f64);
    times_ms.sort_by(f64::total_cmp);
    let phase_medians = phases
        .into_iter()
        .map(|(name, mut ms)| {
            ms.sort_by(f64::total_cmp);
            (name, ms[ms.len() / 2])
        })
        .collect();
    BuildTiming {
        builder,
        threads: rayon_core::current_num_threads(),
        times_ms,
        phase_medians,
        cpu_ms_per_build,
        first_build_faults,
        bvh: last.expect("at least one build"),
    }
}

/// FNV-1a over the nodes, the rows and the slot order: equal hashes, the same tree (for
/// checking that a change to the builder keeps it).
pub fn tree_hash(bvh: &Bvh) -> u64 {
    crate::fingerprint::fnv1a(
        bytemuck::cast_slice::<_, u8>(&bvh.nodes)
            .iter()
            .chain(bytemuck::cast_slice::<_, u8>(&bvh.tri_rows))
            .chain(bytemuck::cast_slice::<_, u8>(&bvh.tri_order))
            .map(|&byte| u64::from(byte)),
    )
}

/// The report, one figure a line; `scripts/build-bench.sh` reads the line that begins
/// with "build: median".
impl fmt::Display for BuildTiming {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let runs = self.times_ms.len();
        writeln!(f, "builder: {}", self.builder.name())?;
        writeln!(f, "threads: {}", self.threads)?;
        if let Some(cpu) = self.cpu_ms_per_build {
            writeln!(f, "CPU time per build, all threads: {cpu:.0} ms")?;
        }
        writeln!(
            f,
            "build: median {:.1} ms of {runs} (min {:.1}, max {:.1})",
            self.median_ms(),
            self.times_ms[0],
            self.times_ms[runs - 1]
        )?;
        let phases: Vec<String> = self
            .phase_medians
            .iter()
            .map(|(name, ms)| format!("{name} {ms:.1}"))
            .collect();
        writeln!(f, "phases, median ms: {}", phases.join(", "))?;
        if let Some(faults) = self.first_build_faults {
            writeln!(f, "minor page faults of the first build: {faults}")?;
        }
        let s = &self.bvh.build_stats;
        writeln!(
            f,
            "tree hash (FNV-1a of nodes, rows and slot order): {:016x}",
            tree_hash(&self.bvh)
        )?;
        write!(
            f,
            "references {}, nodes {} ({} KiB), leaves {}, max depth {}, max leaf {}, oversized leaves {}, SAH cost {:.2}",
            s.references,
            s.nodes,
            s.nodes * std::mem::size_of::<BvhNode>() / 1024,
            s.leaves,
            s.max_depth,
            s.max_leaf_size,
            s.oversized_leaves,
            s.sah_cost
        )
    }
}

/// Fields of /proc/self/stat after the command name (which ends with ')'), numbered
/// from 0 (the state); None where there is no such file (not Linux).
fn proc_stat_fields() -> Option<Vec<u64>> {
    let stat = std::fs::read_to_string("/proc/self/stat").ok()?;
    let rest = &stat[stat.rfind(')')? + 2..];
    // The state is a letter; the fields wanted here are numbers.
    Some(
        rest.split_whitespace()
            .map(|f| f.parse().unwrap_or(0))
            .collect(),
    )
}

/// Minor page faults of the process so far (minflt, field 7).
fn minor_faults() -> Option<u64> {
    proc_stat_fields()?.get(7).copied()
}

/// CPU time of the process so far, all threads, finished ones included (utime and
/// stime, fields 11 and 12, in ticks of 1/100 s).
fn process_cpu_seconds() -> Option<f64> {
    let fields = proc_stat_fields()?;
    Some((fields.get(11)? + fields.get(12)?) as f64 / 100.0)
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::Vec3;

    fn quad_grid(n: usize) -> Vec<Triangle> {
        let mut tris = vec![];
        for i in 0..n {
            for j in 0..n {
                let p = |x: usize, y: usize| Vec3::new(x as f32, y as f32, (x * y % 3) as f32);
                for v in [
                    [p(i, j), p(i + 1, j), p(i + 1, j + 1)],
                    [p(i, j), p(i + 1, j + 1), p(i, j + 1)],
                ] {
                    tris.push(Triangle {
                        v,
                        n: [Vec3::Z; 3],
                        material: 0,
                    });
                }
            }
        }
        tris
    }

    #[test]
    fn timing_reports_every_build_and_the_same_tree_as_a_build() {
        let tris = quad_grid(12);
        let mut calls = vec![];
        let timing = time_builds(&tris, BvhBuilder::Split, 3, |k| calls.push(k));
        assert_eq!(calls, [1, 2, 3]);
        assert_eq!(timing.times_ms.len(), 3);
        assert!(timing.times_ms.windows(2).all(|w| w[0] <= w[1]));
        let names: Vec<&str> = timing.phase_medians.iter().map(|p| p.0).collect();
        let built = Bvh::build_with(&tris, BvhBuilder::Split);
        let expected: Vec<&str> = built.build_stats.phases.iter().map(|p| p.0).collect();
        assert_eq!(names, expected);
        assert_eq!(tree_hash(&timing.bvh), tree_hash(&built));
        let report = timing.to_string();
        for line in [
            "builder: split",
            "build: median",
            "phases, median ms: references",
        ] {
            assert!(report.contains(line), "no {line:?} in\n{report}");
        }
        // At least one build, whatever is asked.
        assert_eq!(
            time_builds(&tris, BvhBuilder::Binned, 0, |_| {})
                .times_ms
                .len(),
            1
        );
    }

    #[test]
    fn the_hash_tells_trees_apart() {
        let tris = quad_grid(6);
        let a = Bvh::build_with(&tris, BvhBuilder::Split);
        let b = Bvh::build_with(&tris[1..], BvhBuilder::Split);
        assert_eq!(
            tree_hash(&a),
            tree_hash(&Bvh::build_with(&tris, BvhBuilder::Split))
        );
        assert_ne!(tree_hash(&a), tree_hash(&b));
    }
}
