//! `igi bench`: measure like the paper (section 5), and report.

pub mod model;
pub mod report;
pub mod run;
