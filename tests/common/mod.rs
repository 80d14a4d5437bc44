//! Shared test fixtures, one module per area.
#![allow(dead_code)]

pub mod generate;
