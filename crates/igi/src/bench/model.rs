//! What `igi bench` measures (paper section 5, Figs. 4 and 5, plus image error): one
//! [`BenchRun`] per scene x set-up x VPL count, with everything needed to redo the table.
//! Serialised as `results.json`; `report.rs` turns it into CSV, Markdown and charts.

use serde::{Deserialize, Serialize};

/// A whole `igi bench` invocation.
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
pub struct BenchResults {
    pub meta: BenchMeta,
    pub runs: Vec<BenchRun>,
}

/// Where and how the numbers were taken.
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
pub struct BenchMeta {
    /// Adapter name, e.g. "NVIDIA H200".
    pub adapter: String,
    /// wgpu backend, e.g. "Vulkan".
    pub backend: String,
    /// Driver name and version as wgpu reports them.
    pub driver: String,
    /// `git rev-parse --short HEAD` of the igi that measured, or "unknown".
    pub git_commit: String,
    /// UTC date and time of the run, RFC 3339.
    pub date: String,
    /// The command line, as typed.
    pub command: String,
    /// igi's version (Cargo).
    pub igi_version: String,
    /// Timed frames per combination, after `warmup` untimed ones.
    pub frames: u32,
    pub warmup: u32,
}

/// Median, minimum and maximum of a GPU time over the timed frames, in milliseconds.
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
pub struct TimeStats {
    pub median_ms: f64,
    pub min_ms: f64,
    pub max_ms: f64,
}

/// One stage of the frame (VPL shooting, direct + specular, indirect, each filter,
/// compose) and its share of the frame's median time.
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
pub struct StageStats {
    pub name: String,
    pub time: TimeStats,
    /// median of this stage / median of the frame (0..1).
    pub share: f64,
}

/// Rays traced in one frame, by kind (counted on the GPU in an extra, untimed frame).
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq, Default)]
pub struct RayCounts {
    /// Primary (camera) rays: closest hit.
    pub primary: u64,
    /// Mirror-reflected rays of the Whitted tree: closest hit.
    pub mirror: u64,
    /// Shadow rays towards point lights: any hit.
    pub light_shadow: u64,
    /// Shadow rays towards VPLs (the bulk of IGI): any hit.
    pub vpl_shadow: u64,
    /// Closest-hit rays of the light paths of VPL shooting.
    pub particle: u64,
}

impl RayCounts {
    pub fn total(&self) -> u64 {
        self.primary + self.mirror + self.light_shadow + self.vpl_shadow + self.particle
    }
}

/// Image error against a reference.
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
pub struct ImageErrors {
    /// The reference EXR.
    pub reference: String,
    /// Relative MSE on linear radiance (igi_core::image::rel_mse).
    pub rel_mse: f64,
    /// Mean FLIP error of the tone-mapped images (0 = identical, 1 = maximal).
    pub flip: f64,
}

fn binned() -> String {
    igi_core::bvh::BvhBuilder::Binned.name().to_string()
}

/// One scene x set-up x VPL count.
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
pub struct BenchRun {
    /// Scene name (file stem or builtin name) and the path given.
    pub scene: String,
    pub scene_path: String,
    pub triangles: u64,
    /// BVH build time on the CPU of the benchmarking machine.
    pub bvh_build_ms: f64,
    /// The BVH builder (`--bvh`): "binned" or "split" (results written before it existed
    /// were all "binned").
    #[serde(default = "binned")]
    pub bvh: String,
    pub width: u32,
    pub height: u32,
    /// Set-up name as given to --setups, e.g. "canonical", "iv", "iv+ds", "iv+ds+il".
    pub setup: String,
    /// VPLs asked for, and reached.
    pub vpls_asked: u32,
    pub vpl_count: u32,
    pub light_paths: u32,
    /// Whole frame (first stage start to last stage end) and each stage, in frame order.
    pub frame: TimeStats,
    pub stages: Vec<StageStats>,
    /// 1000 / median frame time.
    pub fps: f64,
    pub rays: RayCounts,
    /// rays.total() / median frame time.
    pub rays_per_s: f64,
    /// Bytes held on the GPU by the scene (BVH, triangles, materials, lights) and by the
    /// frame's buffers.
    pub scene_bytes: u64,
    pub frame_bytes: u64,
    /// Present when a reference was given or found.
    pub error: Option<ImageErrors>,
    /// Files written for this run, relative to the output directory.
    pub image_exr: String,
    pub image_png: String,
}
