//! The per-shape cache and the output files under faults: two processes writing one entry at
//! once, writes that fail half way (an injected writer error, a read-only folder, a full disk),
//! truncated and tampered entries. Each is detected, recomputed or reported — never trusted,
//! never left half-written.
//!
//! The read-only and disk-full cases mount a small tmpfs when the tests run as root (CI does);
//! otherwise the read-only case uses file permissions and the disk-full case prints that it
//! was skipped (the injected writer error covers the same code path).

mod common;

use common::adversarial::sphere_mesh as sphere;
use common::features::small_pipeline;
use coseg::cache::{CacheOutcome, cache_path};
use coseg::mesh::{write_atomic, write_mesh};
use coseg::pipeline::{
    ShapePipelineOptions, compute_shape_data, decode_shape_entry, encode_shape_entry,
    load_or_compute, load_or_compute_bands, shape_key,
};
use std::io::Write;
use std::path::{Path, PathBuf};
use std::process::Command;

/// The per-shape flags of the binary's runs here: [`options`] as flags.
#[rustfmt::skip]
const PIPE: [&str; 10] = [
    "--eigenpairs", "30", "--hks", "8", "--wks", "8", "--curvature", "8", "--bands", "6",
];

fn scratch(name: &str) -> PathBuf {
    let dir = PathBuf::from(env!("CARGO_TARGET_TMPDIR"))
        .join("faults")
        .join(name);
    if dir.exists() {
        let _ = std::fs::remove_dir_all(&dir);
    }
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

fn options() -> ShapePipelineOptions {
    let mut o = small_pipeline(30, 8);
    o.bands.bands = 6;
    o
}

/// Files in `dir` whose names say they are temporary files of [`write_atomic`].
fn temporaries(dir: &Path) -> Vec<String> {
    std::fs::read_dir(dir)
        .map(|r| {
            r.filter_map(|e| e.ok())
                .map(|e| e.file_name().to_string_lossy().into_owned())
                .filter(|n| n.ends_with(".tmp"))
                .collect()
        })
        .unwrap_or_default()
}

/// A small tmpfs at `dir` (`size` bytes, read-only if asked), unmounted on drop; `None` when
/// mounting is not allowed (not root).
struct Tmpfs(PathBuf);

impl Tmpfs {
    fn mount(dir: &Path, size: usize, read_only: bool) -> Option<Self> {
        std::fs::create_dir_all(dir).ok()?;
        let mut opts = format!("size={size}");
        if read_only {
            opts.push_str(",ro");
        }
        let ok = Command::new("mount")
            .args(["-t", "tmpfs", "-o", &opts, "tmpfs"])
            .arg(dir)
            .output()
            .is_ok_and(|o| o.status.success());
        ok.then(|| Tmpfs(dir.to_path_buf()))
    }
}

impl Drop for Tmpfs {
    fn drop(&mut self) {
        let _ = Command::new("umount").arg(&self.0).output();
    }
}

#[test]
fn a_writer_failing_half_way_leaves_the_old_file_and_no_temporary() {
    let dir = scratch("injected");
    let path = dir.join("entry.bin");
    write_atomic(&path, |w| w.write_all(b"complete old content")).unwrap();
    let err = write_atomic(&path, |w| {
        w.write_all(&[7u8; 100_000])?; // past the buffer: bytes reach the temporary file
        Err(std::io::Error::from(std::io::ErrorKind::StorageFull))
    })
    .unwrap_err();
    assert_eq!(err.kind(), std::io::ErrorKind::StorageFull);
    assert_eq!(std::fs::read(&path).unwrap(), b"complete old content");
    assert!(temporaries(&dir).is_empty(), "{:?}", temporaries(&dir));
}

#[test]
fn truncated_and_tampered_entries_are_never_trusted() {
    let dir = scratch("tampered");
    let mesh = sphere(1);
    let o = options();
    let fresh = load_or_compute(&mesh, &o, &dir).unwrap();
    assert_eq!(fresh.outcome, CacheOutcome::Miss);
    let good = std::fs::read(&fresh.path).unwrap();
    let key = shape_key(&mesh, &o);
    // A tampered payload with a recomputed checksum: the frame is valid, the content is not.
    let nan_entry = {
        let mut data = fresh.data.clone();
        // (The full entry stores the spectrum, not the descriptors: cache format 4.)
        data.spectrum.eigenvalues[3] = f64::NAN;
        encode_shape_entry(&data)
    };
    let cases: Vec<(&str, Vec<u8>, &str)> = vec![
        ("empty", Vec::new(), "truncated header"),
        ("truncated header", good[..40].to_vec(), "truncated header"),
        (
            "truncated payload",
            good[..good.len() / 2].to_vec(),
            "truncated",
        ),
        (
            "flipped payload bit",
            {
                let mut b = good.clone();
                let n = b.len();
                b[n - 10] ^= 0x10;
                b
            },
            "checksum",
        ),
        (
            "other key",
            {
                let mut b = good.clone();
                b[20] ^= 1;
                b
            },
            "key",
        ),
        (
            "other version",
            {
                let mut b = good.clone();
                b[8] = b[8].wrapping_add(1);
                b
            },
            "version",
        ),
        (
            "bad magic",
            {
                let mut b = good.clone();
                b[0] = b'X';
                b
            },
            "magic",
        ),
        (
            "padded",
            {
                let mut b = good.clone();
                b.extend_from_slice(&[0; 16]);
                b
            },
            "truncated or padded",
        ),
        ("NaN behind a valid checksum", nan_entry, "non-finite"),
    ];
    for (what, bytes, reason) in cases {
        let err = decode_shape_entry(&bytes, &key, mesh.vertex_count()).unwrap_err();
        assert!(err.contains(reason), "{what}: {err}");
        std::fs::write(&fresh.path, &bytes).unwrap();
        let r = load_or_compute(&mesh, &o, &dir).unwrap();
        match &r.outcome {
            CacheOutcome::Recomputed { reason: why } => {
                assert!(why.contains(reason), "{what}: {why}")
            }
            other => panic!("{what}: trusted ({other:?})"),
        }
        assert_eq!(r.data, fresh.data, "{what}: recomputed data differ");
        assert_eq!(
            std::fs::read(&fresh.path).unwrap(),
            good,
            "{what}: not rewritten"
        );
        let again = load_or_compute(&mesh, &o, &dir).unwrap();
        assert_eq!(again.outcome, CacheOutcome::Hit, "{what}");
    }
    // The compact entry: truncated, it is rebuilt with a warning.
    let b = load_or_compute_bands(&mesh, &o, &dir).unwrap();
    let bands = dir.join(format!("{}.coseg-bands", key.to_hex()));
    let bytes = std::fs::read(&bands).unwrap();
    std::fs::write(&bands, &bytes[..bytes.len() - 1]).unwrap();
    let rebuilt = load_or_compute_bands(&mesh, &o, &dir).unwrap();
    assert!(
        rebuilt.warnings.iter().any(|w| w.contains("truncated")),
        "{:?}",
        rebuilt.warnings
    );
    assert_eq!(rebuilt.data, b.data);
    assert_eq!(std::fs::read(&bands).unwrap(), bytes);
}

#[test]
fn an_unwritable_cache_costs_a_warning_not_the_shape() {
    let dir = scratch("unwritable");
    let mesh = sphere(2);
    let o = options();
    // The cache "folder" is a file: nothing can be created in it.
    let not_a_dir = dir.join("cache");
    std::fs::write(&not_a_dir, b"a file").unwrap();
    let r = load_or_compute(&mesh, &o, &not_a_dir).unwrap();
    assert_eq!(r.data, compute_shape_data(&mesh, &o).unwrap());
    assert!(
        r.write_error
            .as_deref()
            .is_some_and(|e| e.contains("not written"))
    );
    let b = load_or_compute_bands(&mesh, &o, &not_a_dir).unwrap();
    assert!(
        b.warnings.iter().any(|w| w.contains("not written")),
        "{:?}",
        b.warnings
    );

    // A read-only folder: a read-only tmpfs as root, permissions otherwise.
    let ro = dir.join("read_only");
    let _mount = Tmpfs::mount(&ro, 1 << 20, true);
    if _mount.is_none() {
        use std::os::unix::fs::PermissionsExt;
        std::fs::create_dir_all(&ro).unwrap();
        std::fs::set_permissions(&ro, std::fs::Permissions::from_mode(0o555)).unwrap();
    }
    let r = load_or_compute(&mesh, &o, &ro).unwrap();
    assert_eq!(r.outcome, CacheOutcome::Miss);
    assert!(
        r.write_error
            .as_deref()
            .is_some_and(|e| e.contains("not written")),
        "{:?} (mounted: {})",
        r.write_error,
        _mount.is_some()
    );
    assert!(!cache_path(&ro, &r.data.key).exists());
    assert!(temporaries(&ro).is_empty());
}

#[test]
fn a_full_disk_leaves_no_half_written_cache_entry_or_output() {
    let dir = scratch("full");
    let full = dir.join("tiny");
    let Some(_mount) = Tmpfs::mount(&full, 16 * 1024, false) else {
        println!(
            "skipped: mounting a tmpfs needs root (the injected writer failure test covers write_atomic)"
        );
        return;
    };
    let mesh = sphere(3);
    let o = options();
    let r = load_or_compute(&mesh, &o, &full).unwrap();
    assert_eq!(r.data, compute_shape_data(&mesh, &o).unwrap());
    let e = r.write_error.expect("a 16 KiB disk cannot hold the entry");
    assert!(e.contains("not written"), "{e}");
    assert!(
        !r.path.exists(),
        "a half-written entry was left under its name"
    );
    assert!(temporaries(&full).is_empty(), "{:?}", temporaries(&full));

    // Outputs: `coseg pair` into the full disk fails naming a file, and every file it did
    // leave is complete (identical to the same run on a roomy disk).
    let input = dir.join("in");
    std::fs::create_dir_all(&input).unwrap();
    for (seed, name) in [(4, "a.off"), (5, "b.off")] {
        write_mesh(input.join(name), &sphere(seed), &[]).unwrap();
    }
    let pair = |out: &Path| {
        Command::new(env!("CARGO_BIN_EXE_coseg"))
            .arg("pair")
            .args([input.join("a.off"), input.join("b.off")])
            .arg("-o")
            .arg(out)
            .args(PIPE)
            .args(["--map-size", "30"])
            .output()
            .unwrap()
    };
    let roomy = dir.join("roomy");
    assert!(pair(&roomy).status.success());
    let o = pair(&full);
    let stderr = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(1), "{stderr}");
    assert!(stderr.contains(&full.display().to_string()), "{stderr}");
    assert!(!stderr.contains("panicked"), "{stderr}");
    for entry in std::fs::read_dir(&full).unwrap() {
        let p = entry.unwrap().path();
        let name = p.file_name().unwrap().to_owned();
        assert!(!name.to_string_lossy().ends_with(".tmp"), "{}", p.display());
        if p.is_file() {
            assert_eq!(
                std::fs::read(&p).unwrap(),
                std::fs::read(roomy.join(&name)).unwrap(),
                "{} is not complete",
                p.display()
            );
        }
    }
}

#[test]
fn two_processes_writing_one_cache_entry_leave_one_valid_entry() {
    let dir = scratch("concurrent");
    let mesh_path = dir.join("m.off");
    let mesh = sphere(6);
    write_mesh(&mesh_path, &mesh, &[]).unwrap();
    let cache = dir.join("cache");
    let o = options();
    for round in 0..3 {
        let _ = std::fs::remove_dir_all(&cache);
        let spawn = |i: usize| {
            Command::new(env!("CARGO_BIN_EXE_coseg"))
                .arg("features")
                .arg(&mesh_path)
                .arg("-o")
                .arg(dir.join(format!("out{round}_{i}")))
                .arg("--cache")
                .arg(&cache)
                .args(PIPE)
                .stdout(std::process::Stdio::null())
                .stderr(std::process::Stdio::null())
                .spawn()
                .unwrap()
        };
        let (mut a, mut b) = (spawn(0), spawn(1));
        assert!(a.wait().unwrap().success());
        assert!(b.wait().unwrap().success());
        let entries: Vec<_> = std::fs::read_dir(&cache).unwrap().collect();
        assert_eq!(entries.len(), 1, "round {round}: {entries:?}");
        let r = load_or_compute(&mesh, &o, &cache).unwrap();
        assert_eq!(r.outcome, CacheOutcome::Hit, "round {round}");
        assert_eq!(r.data, compute_shape_data(&mesh, &o).unwrap());
        assert_eq!(
            std::fs::read(dir.join(format!("out{round}_0/descriptors.npy"))).unwrap(),
            std::fs::read(dir.join(format!("out{round}_1/descriptors.npy"))).unwrap()
        );
    }
}
