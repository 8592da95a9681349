//! The environment switches of the renderer, read once when its passes are made
//! ([`Switches::from_env`]) and documented here only. They exist to measure and to look
//! for bugs; none changes an image, and the tests check that (`tests/lanes.rs`,
//! `tests/stage_passes.rs`).
//!
//! | variable | value | effect |
//! |---|---|---|
//! | `IGI_VPL_LANES` | 1, 4, 8 or 16 | lanes per pixel of the indirect gather, instead of the choice by image size ([`crate::passes::lanes_for`]) |
//! | `IGI_MIRROR_LANES` | 1, 2, 4, 8, 16 or 32 | lanes per pixel of the gather at the mirrored hits ([`crate::passes::mirror_lanes`]) |
//! | `IGI_STAGE_PASSES` | 1 | a compute pass per stage instead of one for the whole frame |
//! | `IGI_SIDE_BY_SIDE` | 0 | every pass of the frame in a stage of its own: nothing side by side |
//! | `IGI_SHADER_CHECKS` | 1 | wgpu's run-time index and loop checks in the shaders ([`crate::passes::TRUSTED_CHECKS`]) |
//!
//! Values outside those listed are ignored (the default holds).

/// The switches' values (see the module's table).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Switches {
    pub vpl_lanes: Option<u32>,
    pub mirror_lanes: Option<u32>,
    pub stage_passes: bool,
    pub side_by_side: bool,
    pub shader_checks: bool,
}

impl Default for Switches {
    /// No variable set.
    fn default() -> Switches {
        Switches {
            vpl_lanes: None,
            mirror_lanes: None,
            stage_passes: false,
            side_by_side: true,
            shader_checks: false,
        }
    }
}

impl Switches {
    /// The switches as the environment sets them now.
    pub fn from_env() -> Switches {
        Switches::from_lookup(|name| std::env::var(name).ok())
    }

    /// The switches from `lookup(name)`, the value of each variable if set.
    pub fn from_lookup(lookup: impl Fn(&str) -> Option<String>) -> Switches {
        let lanes = |name: &str, allowed: &[u32]| {
            lookup(name)
                .and_then(|v| v.parse::<u32>().ok())
                .filter(|l| allowed.contains(l))
        };
        Switches {
            vpl_lanes: lanes("IGI_VPL_LANES", &crate::passes::LANE_CHOICES),
            mirror_lanes: lanes("IGI_MIRROR_LANES", &[1, 2, 4, 8, 16, 32]),
            stage_passes: lookup("IGI_STAGE_PASSES").as_deref() == Some("1"),
            side_by_side: lookup("IGI_SIDE_BY_SIDE").as_deref() != Some("0"),
            shader_checks: lookup("IGI_SHADER_CHECKS").as_deref() == Some("1"),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn values_outside_the_listed_ones_keep_the_default() {
        let none = Switches::from_lookup(|_| None);
        assert_eq!(none, Switches::default());
        let set = Switches::from_lookup(|name| {
            Some(
                match name {
                    "IGI_VPL_LANES" => "8",
                    "IGI_MIRROR_LANES" => "32",
                    "IGI_STAGE_PASSES" => "1",
                    "IGI_SIDE_BY_SIDE" => "0",
                    _ => "1",
                }
                .to_string(),
            )
        });
        assert_eq!(
            set,
            Switches {
                vpl_lanes: Some(8),
                mirror_lanes: Some(32),
                stage_passes: true,
                side_by_side: false,
                shader_checks: true,
            }
        );
        let wrong = Switches::from_lookup(|name| {
            Some(if name == "IGI_VPL_LANES" { "2" } else { "yes" }.to_string())
        });
        assert_eq!(wrong, Switches::default());
    }
}
