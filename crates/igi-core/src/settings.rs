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

    /// Every parameter within what the passes can honour: downsampling 1 to
    /// [`MAX_DOWNSAMPLE`], interleaving within [`check_interleave`], the upsampler's sigma
    /// and the depth threshold positive, the normal power not negative and the normal
    /// threshold a cosine. An idle modifier is not refused here (see
    /// [`RenderSettings::validate`]).
    pub fn validate(&self) -> Result<(), SettingsError> {
        if self.downsample == 0 || self.downsample > MAX_DOWNSAMPLE {
            return Err(SettingsError::Downsample(self.downsample));
        }
        let (n, m) = self.interleave;
        check_interleave(n, m).map_err(|_| SettingsError::Interleave { n, m })?;
        positive(self.upsample_sigma, SettingsError::UpsampleSigma)?;
        let k = self.upsample_normal_power;
        if !(k.is_finite() && k >= 0.0) {
            return Err(SettingsError::NormalPower(k));
        }
        positive(self.depth_threshold, SettingsError::DepthThreshold)?;
        if !(-1.0..=1.0).contains(&self.normal_threshold) {
            return Err(SettingsError::NormalThreshold(self.normal_threshold));
        }
        Ok(())
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

/// Most VPL subsets of interleaved sampling, n x m of [`Accelerations::interleave`]: the
/// passes keep one permutation entry and one mirror-list counter per subset in arrays of
/// this size (`MAX_SUBSETS` of the WGSL).
pub const MAX_SUBSETS: u32 = 64;

/// Largest downsampling factor of [`Accelerations::downsample`]: a bound that refuses a
/// mistyped factor (thousands) rather than computing the indirect light of a frame on a
/// handful of pixels; at 64 a 1920 x 1080 frame still has 30 x 17 of them.
pub const MAX_DOWNSAMPLE: u32 = 64;

/// Why settings were refused ([`RenderSettings::validate`]). The messages name the
/// command's options, which map one to one onto the fields, so that `igi render`, `igi
/// view`, `igi bench` and the renderer say the same thing of the same value.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum SettingsError {
    #[error("--exposure must be a positive number, got {0}")]
    Exposure(f32),
    #[error("--vpls must be at least 1")]
    NoVpls,
    #[error("--bounces must be at least 1")]
    NoBounces,
    #[error("--accumulate must be at least 1")]
    NoAccumulatedFrames,
    #[error("--mirror-depth must be at most {MAX_MIRROR_DEPTH}, got {0}")]
    MirrorDepth(u32),
    #[error("--min-dist must be a positive number, got {0}")]
    MinDist(f32),
    #[error("--downsample must be between 1 and {MAX_DOWNSAMPLE}, got {0}")]
    Downsample(u32),
    /// An interleave side of 0 ([`check_interleave`]: the option's own parser says it).
    #[error("{n}x{m}: each side must be at least 1")]
    InterleaveSide { n: u32, m: u32 },
    /// More than [`MAX_SUBSETS`] subsets ([`check_interleave`]).
    #[error("{n}x{m} is {subsets} subsets: N x M must be at most {MAX_SUBSETS}")]
    InterleaveSubsets { n: u32, m: u32, subsets: u64 },
    /// Either interleave refusal, of settings made elsewhere than by the option's parser.
    #[error("--interleave {n}x{m}: each side must be at least 1 and N x M at most {MAX_SUBSETS}")]
    Interleave { n: u32, m: u32 },
    #[error("--upsample-sigma must be a positive number, got {0}")]
    UpsampleSigma(f32),
    #[error("--normal-power must be a number >= 0, got {0}")]
    NormalPower(f32),
    #[error("--depth-threshold must be a positive number, got {0}")]
    DepthThreshold(f32),
    #[error("--normal-threshold must be between -1 and 1, got {0}")]
    NormalThreshold(f32),
    /// The irregular pattern without interleaving; `from_setup` names the set-up it came
    /// from, where it came from one.
    #[error(
        "{} lays out interleaved VPL subsets: it needs --interleave NxM (or il in --setup)",
        from_setup_named("--pattern irregular", from_setup)
    )]
    IrregularWithoutInterleave { from_setup: Option<String> },
    /// The fused filter with neither downsampling nor interleaving, which run no filter.
    #[error(
        "{} runs the filters of downsampling and interleaving in one pass: it needs --downsample S or --interleave NxM (or ds or il in --setup)",
        from_setup_named("--filter fused", from_setup)
    )]
    FusedWithoutFilter { from_setup: Option<String> },
    #[error("image size {width}x{height}: both must be at least 1")]
    ImageSize { width: u32, height: u32 },
    #[error("image size {width}x{height}: each side may be at most {MAX_IMAGE_SIDE} pixels (GPUs dispatch at most 65,535 workgroups along an axis, and the direct pass's workgroup covers 4 rows)")]
    ImageSide { width: u32, height: u32 },
}

/// The longest side of an image igi renders: 65,535 workgroups (the dispatch limit that
/// wgpu guarantees on every adapter) of the direct pass's tile, 8 x 4 pixels, along the
/// shorter axis of the tile. Larger images are refused before the GPU is touched.
pub const MAX_IMAGE_SIDE: u32 = 65_535 * 4;

fn from_setup_named(option: &str, setup: &Option<String>) -> String {
    match setup {
        Some(setup) => format!("{option} (from --setup {setup})"),
        None => option.to_string(),
    }
}

/// An exposure is a positive multiplier.
pub fn check_exposure(exposure: f32) -> Result<(), SettingsError> {
    positive(exposure, SettingsError::Exposure)
}

/// Interleaving over n x m subsets: each side at least 1, and at most [`MAX_SUBSETS`]
/// subsets, the product taken in 64 bits (two u32 sides can wrap around to a small
/// number in 32).
pub fn check_interleave(n: u32, m: u32) -> Result<(), SettingsError> {
    if n == 0 || m == 0 {
        return Err(SettingsError::InterleaveSide { n, m });
    }
    let subsets = u64::from(n) * u64::from(m);
    if subsets > u64::from(MAX_SUBSETS) {
        return Err(SettingsError::InterleaveSubsets { n, m, subsets });
    }
    Ok(())
}

/// `Ok` for a finite number above 0, else the error `refused` makes of it.
fn positive(v: f32, refused: fn(f32) -> SettingsError) -> Result<(), SettingsError> {
    if v.is_finite() && v > 0.0 {
        Ok(())
    } else {
        Err(refused(v))
    }
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

    /// The one check of settings, made by every command before it renders: the
    /// [`limits`](Self::validate_limits) but the image size, then no idle modifier (a
    /// pattern or filter mode that would label a frame with what it did not compute), then
    /// the image size. The first refusal is returned, in that order, which is the order of
    /// the command's options.
    pub fn validate(&self) -> Result<(), SettingsError> {
        self.validate_parameters()?;
        self.validate_size()
    }

    /// [`validate`](Self::validate) but for the image size: what a command can check
    /// before the scene, whose film gives the default size, is loaded.
    pub fn validate_parameters(&self) -> Result<(), SettingsError> {
        self.validate_frame_limits()?;
        match self.accelerations.idle_modifier() {
            Some("irregular") => {
                Err(SettingsError::IrregularWithoutInterleave { from_setup: None })
            }
            Some(_) => Err(SettingsError::FusedWithoutFilter { from_setup: None }),
            None => Ok(()),
        }
    }

    /// What any frame needs, idle modifiers allowed (the renderer ignores them, and the
    /// viewer's panel can leave one): the exposure positive; at least one VPL, bounce and
    /// accumulated frame; the mirror depth at most [`MAX_MIRROR_DEPTH`]; a given bounding
    /// distance positive; [`Accelerations::validate`]; and an image of at least 1 x 1.
    pub fn validate_limits(&self) -> Result<(), SettingsError> {
        self.validate_frame_limits()?;
        self.validate_size()
    }

    fn validate_frame_limits(&self) -> Result<(), SettingsError> {
        check_exposure(self.exposure)?;
        if self.vpls == 0 {
            return Err(SettingsError::NoVpls);
        }
        if self.bounces == 0 {
            return Err(SettingsError::NoBounces);
        }
        if self.accumulate == 0 {
            return Err(SettingsError::NoAccumulatedFrames);
        }
        if self.mirror_depth > MAX_MIRROR_DEPTH {
            return Err(SettingsError::MirrorDepth(self.mirror_depth));
        }
        if let Some(m) = self.min_dist {
            positive(m, SettingsError::MinDist)?;
        }
        self.accelerations.validate()
    }

    /// The image's size: each side at least 1 and at most [`MAX_IMAGE_SIDE`].
    pub fn validate_size(&self) -> Result<(), SettingsError> {
        if self.width == 0 || self.height == 0 {
            return Err(SettingsError::ImageSize {
                width: self.width,
                height: self.height,
            });
        }
        if self.width > MAX_IMAGE_SIDE || self.height > MAX_IMAGE_SIDE {
            return Err(SettingsError::ImageSide {
                width: self.width,
                height: self.height,
            });
        }
        Ok(())
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

    /// The message of `settings` changed by `change`, which must be refused.
    fn refusal(change: impl FnOnce(&mut RenderSettings)) -> String {
        let mut settings = RenderSettings::default();
        change(&mut settings);
        settings.validate().expect_err("refused").to_string()
    }

    #[test]
    fn defaults_and_the_papers_set_ups_are_valid() {
        assert_eq!(RenderSettings::default().validate(), Ok(()));
        for setup in [
            "canonical",
            "iv",
            "iv+ds",
            "iv+ds+il",
            "iv+ds+il+irregular+fused",
        ] {
            let settings = RenderSettings {
                accelerations: Accelerations::from_setup(setup).unwrap(),
                ..RenderSettings::default()
            };
            assert_eq!(settings.validate(), Ok(()), "{setup}");
        }
        // The largest of each.
        let mut settings = RenderSettings {
            mirror_depth: MAX_MIRROR_DEPTH,
            ..RenderSettings::default()
        };
        settings.accelerations.downsample = MAX_DOWNSAMPLE;
        settings.accelerations.interleave = (8, 8);
        settings.accelerations.normal_threshold = -1.0;
        settings.accelerations.upsample_normal_power = 0.0;
        assert_eq!(settings.validate(), Ok(()));
    }

    #[test]
    fn frame_parameters_out_of_range_are_refused() {
        for exposure in [0.0, -1.0, f32::NAN, f32::INFINITY] {
            let e = refusal(|s| s.exposure = exposure);
            assert_eq!(
                e,
                format!("--exposure must be a positive number, got {exposure}")
            );
        }
        assert_eq!(refusal(|s| s.vpls = 0), "--vpls must be at least 1");
        assert_eq!(refusal(|s| s.bounces = 0), "--bounces must be at least 1");
        assert_eq!(
            refusal(|s| s.accumulate = 0),
            "--accumulate must be at least 1"
        );
        // u32::MAX wrapped the VPL pass's path length (bounces + mirror depth) to 7.
        for depth in [MAX_MIRROR_DEPTH + 1, u32::MAX] {
            let e = refusal(|s| s.mirror_depth = depth);
            assert_eq!(
                e,
                format!("--mirror-depth must be at most 1024, got {depth}")
            );
        }
        for m in [0.0, -0.5, f32::NAN] {
            let e = refusal(|s| s.min_dist = Some(m));
            assert_eq!(e, format!("--min-dist must be a positive number, got {m}"));
        }
        let e = refusal(|s| s.width = 0);
        assert_eq!(e, "image size 0x600: both must be at least 1");
        let e = refusal(|s| s.height = 0);
        assert_eq!(e, "image size 800x0: both must be at least 1");
    }

    #[test]
    fn acceleration_parameters_out_of_range_are_refused() {
        for ds in [0, MAX_DOWNSAMPLE + 1] {
            let e = refusal(|s| s.accelerations.downsample = ds);
            assert_eq!(
                e,
                format!("--downsample must be between 1 and 64, got {ds}")
            );
        }
        // 65536 x 65536 is 0 in u32.
        for (n, m) in [(65_536, 65_536), (8, 9), (0, 4), (3, 0), (u32::MAX, 2)] {
            let e = refusal(|s| s.accelerations.interleave = (n, m));
            assert_eq!(
                e,
                format!("--interleave {n}x{m}: each side must be at least 1 and N x M at most 64")
            );
        }
        for sigma in [0.0, -1.0, f32::NAN, f32::INFINITY] {
            let e = refusal(|s| s.accelerations.upsample_sigma = sigma);
            assert_eq!(
                e,
                format!("--upsample-sigma must be a positive number, got {sigma}")
            );
        }
        for k in [-1.0, f32::NAN, f32::INFINITY] {
            let e = refusal(|s| s.accelerations.upsample_normal_power = k);
            assert_eq!(e, format!("--normal-power must be a number >= 0, got {k}"));
        }
        for t in [0.0, -0.1, f32::NAN] {
            let e = refusal(|s| s.accelerations.depth_threshold = t);
            assert_eq!(
                e,
                format!("--depth-threshold must be a positive number, got {t}")
            );
        }
        for c in [-1.5, 1.01, f32::NAN] {
            let e = refusal(|s| s.accelerations.normal_threshold = c);
            assert_eq!(
                e,
                format!("--normal-threshold must be between -1 and 1, got {c}")
            );
        }
    }

    #[test]
    fn interleave_sides_are_checked_in_64_bits() {
        assert_eq!(check_interleave(8, 8), Ok(()));
        assert_eq!(check_interleave(1, 64), Ok(()));
        let e = check_interleave(0, 3).unwrap_err().to_string();
        assert_eq!(e, "0x3: each side must be at least 1");
        let e = check_interleave(65_536, 65_536).unwrap_err().to_string();
        assert_eq!(
            e,
            "65536x65536 is 4294967296 subsets: N x M must be at most 64"
        );
        let e = check_interleave(8, 9).unwrap_err().to_string();
        assert_eq!(e, "8x9 is 72 subsets: N x M must be at most 64");
    }

    #[test]
    fn idle_modifiers_are_refused_but_within_the_limits() {
        let irregular: fn(&mut RenderSettings) =
            |s| s.accelerations.pattern = InterleavePattern::Irregular;
        let fused: fn(&mut RenderSettings) = |s| s.accelerations.filter = FilterMode::Fused;
        assert_eq!(
            refusal(irregular),
            "--pattern irregular lays out interleaved VPL subsets: it needs --interleave NxM (or il in --setup)"
        );
        assert_eq!(
            refusal(fused),
            "--filter fused runs the filters of downsampling and interleaving in one pass: it needs --downsample S or --interleave NxM (or ds or il in --setup)"
        );
        let e = SettingsError::IrregularWithoutInterleave {
            from_setup: Some("il+irregular".into()),
        };
        assert!(
            e.to_string()
                .starts_with("--pattern irregular (from --setup il+irregular) lays out"),
            "{e}"
        );
        // The viewer's panel can leave a modifier idle, and the renderer ignores it.
        for change in [irregular, fused] {
            let mut settings = RenderSettings::default();
            change(&mut settings);
            assert_eq!(settings.validate_limits(), Ok(()));
        }
    }

    #[test]
    fn the_image_size_is_checked_last_and_apart() {
        let settings = RenderSettings {
            width: 0,
            vpls: 0,
            ..RenderSettings::default()
        };
        // The options' order: the VPL count before the image size.
        assert_eq!(settings.validate(), Err(SettingsError::NoVpls));
        let settings = RenderSettings {
            width: 0,
            ..RenderSettings::default()
        };
        // Before the scene is loaded the size is not known yet.
        assert_eq!(settings.validate_parameters(), Ok(()));
        assert!(settings.validate_limits().is_err());
    }
}
