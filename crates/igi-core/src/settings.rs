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
    /// Shading normals of the primary hits as 0.5 + 0.5 n (black where no surface).
    Normals,
    /// Distance from the camera to the primary hit over the scene's diagonal.
    Depth,
}

/// How interleaved sampling assigns VPL subsets to the pixels of a tile (paper section 4.3
/// and its future work).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum InterleavePattern {
    /// Pixel (x, y) of every tile gathers subset (x mod n) + n (y mod m), as in the paper.
    #[default]
    Regular,
    /// Each tile permutes the subsets (a seeded permutation per tile), against the visible
    /// repetition of the regular pattern.
    Irregular,
}

/// How the interleaved, downsampled indirect term is filtered back to full resolution.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum FilterMode {
    /// Discontinuity buffer at the indirect resolution, then joint bilateral upsampling.
    #[default]
    TwoPass,
    /// One pass doing both (the paper's future work).
    Fused,
}

/// The paper's accelerations (sections 4.1 to 4.3) and their filter parameters.
#[derive(Clone, Debug, PartialEq)]
pub struct Accelerations {
    /// VPL shadow rays test triangle bounding boxes instead of triangles (section 4.1).
    pub imperfect_visibility: bool,
    /// Indirect light at 1/downsample of the resolution per axis (section 4.2); 1 = off.
    pub downsample: u32,
    /// Interleaved sampling over n x m VPL subsets (section 4.3); (1, 1) = off.
    pub interleave: (u32, u32),
    pub pattern: InterleavePattern,
    pub filter: FilterMode,
    /// Standard deviation of the upsampler's spatial Gaussian, in low-resolution pixels.
    pub upsample_sigma: f32,
    /// Exponent of the upsampler's normal weight (N_p . N_q)^k; the paper's plain cosine is 1.
    pub upsample_normal_power: f32,
    /// Whether depth joins the upsampler's range weight (not in the paper).
    pub upsample_depth: bool,
    /// Relative depth difference beyond which a neighbour is discontinuous (filters).
    pub depth_threshold: f32,
    /// Smallest normal dot product for a neighbour to count as continuous (filters).
    pub normal_threshold: f32,
}

impl Default for Accelerations {
    fn default() -> Self {
        Accelerations {
            imperfect_visibility: false,
            downsample: 1,
            interleave: (1, 1),
            pattern: InterleavePattern::Regular,
            filter: FilterMode::TwoPass,
            upsample_sigma: 1.0,
            upsample_normal_power: 1.0,
            upsample_depth: true,
            depth_threshold: 0.1,
            normal_threshold: 0.9,
        }
    }
}

/// What [`Accelerations::from_setup`] accepts, for its error messages.
pub const SETUP_NAMES: &str =
    "the set-ups are canonical, or iv, ds, il, irregular, fused joined by '+', e.g. iv+ds+il";

impl Accelerations {
    /// The paper's four set-ups by name: "canonical", and any of "iv", "ds", "il" joined
    /// by '+' (e.g. "iv+ds+il"), with the paper's parameters (downsample 4, interleave
    /// 3x3); "irregular" and "fused" switch the pattern and the filter.
    pub fn from_setup(name: &str) -> Result<Accelerations, String> {
        let mut a = Accelerations::default();
        if name == "canonical" {
            return Ok(a);
        }
        // The callers put the option's name in front; the name itself is repeated only
        // where it says more than the part (a set-up of several parts).
        if name.is_empty() {
            return Err(format!("an empty set-up name ({SETUP_NAMES})"));
        }
        for part in name.split('+') {
            match part {
                "iv" => a.imperfect_visibility = true,
                "ds" => a.downsample = 4,
                "il" => a.interleave = (3, 3),
                "irregular" => a.pattern = InterleavePattern::Irregular,
                "fused" => a.filter = FilterMode::Fused,
                "" => return Err(format!("an empty part in set-up '{name}' ({SETUP_NAMES})")),
                other if other == name => {
                    return Err(format!("unknown set-up '{name}' ({SETUP_NAMES})"))
                }
                other => {
                    return Err(format!(
                        "unknown part '{other}' in set-up '{name}' ({SETUP_NAMES})"
                    ))
                }
            }
        }
        // The renderer ignores a pattern without subsets and a filter mode without a
        // filter, so such a name would label a table row with what was not measured.
        if let Some(idle) = a.idle_modifier() {
            let (needs, example) = match idle {
                "irregular" => ("il", "iv+ds+il+irregular"),
                _ => ("ds or il", "iv+ds+il+fused"),
            };
            return Err(format!(
                "set-up '{name}': {idle} modifies {needs}, which it lacks (e.g. {example})"
            ));
        }
        Ok(a)
    }

    /// The modifier in force that has nothing to modify, by its set-up name: "irregular"
    /// (the pattern of interleaved subsets) without interleaving, or "fused" (the filter
    /// passes in one) with neither downsampling nor interleaving, which run no filter.
    pub fn idle_modifier(&self) -> Option<&'static str> {
        if self.pattern == InterleavePattern::Irregular && self.interleave == (1, 1) {
            Some("irregular")
        } else if self.filter == FilterMode::Fused && !self.filtered() {
            Some("fused")
        } else {
            None
        }
    }

    /// Whether the indirect term goes through a filter at all.
    pub fn filtered(&self) -> bool {
        self.downsample > 1 || self.interleave != (1, 1)
    }
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
    /// Depth limit of the Whitted mirror tree (reflections after the primary hit); at
    /// most [`MAX_MIRROR_DEPTH`].
    pub mirror_depth: u32,
    pub seed: u32,
    /// Frame number within an accumulation sequence: picks a fresh window of the Halton
    /// sequence, so frames 0..K together form one K-times-larger VPL set.
    pub frame: u32,
    pub exposure: f32,
    pub output: OutputBuffer,
    pub accelerations: Accelerations,
    /// Frames averaged into the image, each with a fresh VPL set (1 = one frame).
    pub accumulate: u32,
}

/// Most mirror reflections a walk follows ([`RenderSettings::mirror_depth`]). The passes
/// count a walk's reflections, and a light path's segments (bounces + mirror depth), in
/// u32: without a bound `--mirror-depth 4294967295` wrapped the path length of the VPL
/// pass to 7 segments. It also bounds the work of a pixel that sees a hall of mirrors
/// (one closest-hit ray per reflection); the viewer's slider stops at 16.
pub const MAX_MIRROR_DEPTH: u32 = 1024;

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
            accelerations: Accelerations::default(),
            accumulate: 1,
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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn setup_names_and_their_errors() {
        let a = Accelerations::from_setup("iv+ds+il+irregular+fused").unwrap();
        assert!(a.imperfect_visibility && a.downsample == 4 && a.interleave == (3, 3));
        assert_eq!(a.pattern, InterleavePattern::Irregular);
        assert_eq!(a.filter, FilterMode::Fused);
        assert_eq!(
            Accelerations::from_setup("canonical").unwrap(),
            Accelerations::default()
        );
        // A one-part name is said once; every error lists the valid names.
        let e = Accelerations::from_setup("foo").unwrap_err();
        assert_eq!(e.matches("foo").count(), 1, "{e}");
        assert!(
            e.contains("unknown set-up 'foo'") && e.contains("iv, ds, il"),
            "{e}"
        );
        let e = Accelerations::from_setup("iv+foo").unwrap_err();
        assert!(e.contains("unknown part 'foo' in set-up 'iv+foo'"), "{e}");
        // Empty names and parts (a trailing ',' or '+') get their own words.
        let e = Accelerations::from_setup("").unwrap_err();
        assert!(
            e.starts_with("an empty set-up name") && e.contains("canonical"),
            "{e}"
        );
        let e = Accelerations::from_setup("iv+").unwrap_err();
        assert!(e.starts_with("an empty part in set-up 'iv+'"), "{e}");
        // A modifier without what it modifies is refused, not ignored.
        let e = Accelerations::from_setup("iv+irregular").unwrap_err();
        assert!(e.contains("irregular modifies il, which it lacks"), "{e}");
        let e = Accelerations::from_setup("fused").unwrap_err();
        assert!(e.contains("fused modifies ds or il"), "{e}");
        assert!(Accelerations::from_setup("ds+fused").is_ok());
        assert!(Accelerations::from_setup("il+irregular").is_ok());
    }
}
