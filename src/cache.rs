//! Per-shape cache: placeholder.
