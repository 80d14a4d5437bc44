//! The rigid route's pairs and the collection alignment on disk
//! (`src/propagate/rigid_pair_store.rs`), through the `coseg` binary: a warm run reads every
//! pair's registration and nearest points (and the map route's point maps) from the cache
//! folder and writes the cold run's files byte for byte; corrupt entries are recomputed
//! without an error and rewritten with the same bytes.

mod common;

use common::cli::{FAST_PIPELINE, arg as s, coseg, text};
use common::outputs::{cache_entries as entries, output_files as files, same_files as same};
use std::path::Path;

/// Bare `coseg propagate` on the shipped chairs from two sources (so the held-out runs
/// register the sources onto each other too), cold, warm, then with every pair, alignment
/// and point-map entry corrupted: the three runs write the same files, and the corrupted
/// entries are rewritten as the cold run wrote them.
#[test]
fn a_warm_run_reads_the_pairs_and_writes_the_cold_runs_bytes() {
    let dir = tempfile::tempdir().unwrap();
    let chairs = Path::new(env!("CARGO_MANIFEST_DIR")).join("collections/chairs");
    let labels = format!(
        "{},{}",
        chairs.join("chairs_00.labels.txt").display(),
        chairs.join("chairs_03.labels.txt").display()
    );
    let cache = dir.path().join("cache");
    let run = |out: &Path| {
        let mut args = vec![
            "propagate",
            s(&chairs),
            "--labels",
            &labels,
            "-o",
            s(out),
            "--cache",
            s(&cache),
            "--no-pictures",
            "-q",
        ];
        args.extend(FAST_PIPELINE);
        let o = coseg(&args);
        assert!(o.status.success(), "{}", text(&o.stderr));
        files(out)
    };
    let cold = run(&dir.path().join("cold"));
    let kinds = ["coseg-pair", "coseg-align", "coseg-map"];
    let written: Vec<_> = kinds.iter().map(|k| entries(&cache, k)).collect();
    // 4 targets onto 2 sources, and each source onto the other in the held-out runs.
    assert!(written[0].len() >= 10, "{} pairs", written[0].len());
    assert_eq!(written[1].len(), 1, "one collection alignment");
    assert!(!written[2].is_empty(), "point maps");
    let warm = run(&dir.path().join("warm"));
    same(&cold, &warm, "warm");
    for (k, w) in kinds.iter().zip(&written) {
        assert_eq!(&entries(&cache, k), w, "{k}: a warm run rewrites nothing");
    }
    for (k, (path, bytes)) in written.iter().flatten().enumerate() {
        // Every other entry truncated, the others with a flipped payload byte.
        let mut b = bytes.clone();
        if k % 2 == 0 {
            b.truncate(b.len() / 2);
        } else {
            let last = b.len() - 1;
            b[last] ^= 0x5a;
        }
        std::fs::write(path, b).unwrap();
    }
    let repaired = run(&dir.path().join("repaired"));
    same(&cold, &repaired, "corrupt entries");
    for (k, w) in kinds.iter().zip(&written) {
        assert_eq!(
            &entries(&cache, k),
            w,
            "{k}: rewritten as the cold run wrote it"
        );
    }
}
