//! Build script: `COSEG_SOURCE_HASH`, a hash of the library's sources and of the locked
//! dependencies. The part-tree cache entries ([`coseg::parts::part_tree_key`]) depend on every
//! algorithm of the collection stage, which no option names: with this hash in their key, a
//! build whose code differs reads none of another build's entries.

use std::path::{Path, PathBuf};

fn files(dir: &Path, out: &mut Vec<PathBuf>) {
    let Ok(entries) = std::fs::read_dir(dir) else {
        return;
    };
    for e in entries.flatten() {
        let p = e.path();
        if p.is_dir() {
            files(&p, out);
        } else {
            out.push(p);
        }
    }
}

fn main() {
    println!("cargo:rerun-if-changed=src");
    println!("cargo:rerun-if-changed=Cargo.lock");
    let mut all = Vec::new();
    files(Path::new("src"), &mut all);
    all.sort();
    all.push(PathBuf::from("Cargo.lock"));
    // FNV-1a (64 bits) over each file's path and bytes: an identity for the sources, not a
    // defence against anything.
    let mut h: u64 = 0xcbf2_9ce4_8422_2325;
    let mut eat = |bytes: &[u8]| {
        for &b in bytes {
            h ^= u64::from(b);
            h = h.wrapping_mul(0x0000_0100_0000_01b3);
        }
    };
    for f in &all {
        let bytes = std::fs::read(f).unwrap_or_default();
        eat(f.to_string_lossy().as_bytes());
        eat(&(bytes.len() as u64).to_le_bytes());
        eat(&bytes);
    }
    println!("cargo:rustc-env=COSEG_SOURCE_HASH={h:016x}");
}
