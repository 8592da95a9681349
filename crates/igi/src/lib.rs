//! The igi command's library part: what `igi bench` measures and how it is reported.

pub mod bench;
pub mod view;
