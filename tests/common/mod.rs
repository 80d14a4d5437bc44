//! Shared test fixtures, one file per area.
#![allow(dead_code)]

pub mod mesh;
pub mod stable;
pub mod features;
//! Shared test fixtures, one module per area.
#![allow(dead_code)]

pub mod generate;
