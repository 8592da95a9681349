//! Render settings: one struct shared by `igi render`, `igi bench` and the viewer, so that
//! every command means the same thing by the same option (paper section 4, the frame's
//! parameters: VPL count N, bounces B, the bounding distance of G).

use crate::scene::Scene;

/// How the singularity of the geometry term G = cos cos / d^2 is bounded.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum GeometryBound {
    /// The paper's bounding: G times smoothstep(0.8 m, 1.2 m, d) (0 below 0.8 m).
    #[default]
    Smoothstep,
    /// The classic clamp: cos cos / max(d^2, m^2).
    Clamp,
}

/// Which buffer of the frame ends up in the output image.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum OutputBuffer {
    /// direct + specular + (rho / pi) E: the composed frame.
    #[default]
    Final,
    /// The direct + specular pass alone (Whitted, with indirect light at mirrored hits).
    Direct,
    /// (rho / pi) E at primary hits: the indirect diffuse light alone.
    Indirect,
    /// E, the incident indirect term without the albedo.
    Irradiance,
}

/// Everything that decides what a frame computes (not where it goes).
#[derive(Clone, Debug, PartialEq)]
pub struct RenderSettings {
    pub width: u32,
    pub height: u32,
    /// The number of VPLs asked for (the paper's N: 30, 90, 180). The number of light
    /// paths is chosen so that the expected VPL count is N; the actual count is reported.
    pub vpls: u32,
    /// Maximum number of diffuse bounces of a light path, i.e. VPLs per path (B >= 1).
    pub bounces: u32,
    /// Bounding distance m of the geometry term; `None` = [`default_min_dist`].
    pub min_dist: Option<f32>,
    pub geometry_bound: GeometryBound,
    /// Depth limit of the Whitted mirror tree (reflections after the primary hit).
    pub mirror_depth: u32,
    pub seed: u32,
    /// Frame number within an accumulation sequence: picks a fresh window of the Halton
    /// sequence, so frames 0..K together form one K-times-larger VPL set.
    pub frame: u32,
    pub exposure: f32,
    pub output: OutputBuffer,
}

impl Default for RenderSettings {
    fn default() -> Self {
        RenderSettings {
            width: 800,
            height: 600,
            vpls: 180,
            bounces: 8,
            min_dist: None,
            geometry_bound: GeometryBound::Smoothstep,
            mirror_depth: 6,
            seed: 0,
            frame: 0,
            exposure: 1.0,
            output: OutputBuffer::Final,
        }
    }
}

/// Fraction of the scene's bounding-box diagonal used as the default bounding distance.
pub const DEFAULT_MIN_DIST_FRACTION: f32 = 0.05;

/// The default bounding distance m of G for a scene: 5% of its bounding-box diagonal.
pub fn default_min_dist(scene: &Scene) -> f32 {
    DEFAULT_MIN_DIST_FRACTION * scene.diagonal()
}

impl RenderSettings {
    /// Settings with the scene's film size.
    pub fn for_scene(scene: &Scene) -> Self {
        RenderSettings {
            width: scene.film.width,
            height: scene.film.height,
            ..Default::default()
        }
    }

    /// The bounding distance in force for `scene`.
    pub fn min_dist_for(&self, scene: &Scene) -> f32 {
        self.min_dist.unwrap_or_else(|| default_min_dist(scene))
    }
}
