//! `igi bench`: measure like the paper (section 5), and report; `igi bench build` times
//! the BVH build.

pub mod build;
pub mod model;
pub mod report;
pub mod run;
