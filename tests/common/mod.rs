//! Shared test fixtures, one file per area.
#![allow(dead_code)]

pub mod adversarial;
pub mod features;
pub mod generate;
pub mod graph;
pub mod mesh;
pub mod shapes;
pub mod stable;
