//! Any bytes as a per-vertex label file: labels or an error naming the line, never a panic.
#![no_main]

use coseg::evaluate::parse_labels;
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    if let Ok(labels) = parse_labels(data, "fuzz.labels.txt") {
        assert!(labels.len() <= data.len());
    }
});
