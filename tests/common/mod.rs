//! Shared test fixtures, one file per area.
#![allow(dead_code)]

pub mod graph;
pub mod stable;
