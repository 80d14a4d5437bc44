//! `OUT/index.html` opened in a real headless Chromium (Debian's `chromium`; `.ci/run` installs
//! it). Skipped, with a message, when no Chromium is installed.

mod common;

use common::cli::{FAST_PIPELINE, arg, coseg, text};
use common::features::{blob, similarity};
use coseg::mesh::write_mesh;
use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn chromium() -> Option<PathBuf> {
    ["chromium", "chromium-browser", "google-chrome"]
        .iter()
        .find_map(|name| {
            std::env::var_os("PATH")?
                .to_str()?
                .split(':')
                .map(|d| Path::new(d).join(name))
                .find(|p| p.is_file())
        })
}

/// Chromium headless on `page` with a fresh profile; `extra` selects the output.
fn browse(browser: &Path, profile: &Path, page: &Path, extra: &[String]) -> Output {
    Command::new(browser)
        .args([
            "--headless",
            "--no-sandbox",
            "--disable-gpu",
            "--disable-quic",
            "--no-first-run",
            "--disable-background-networking",
            "--disable-component-update",
            "--disable-sync",
            // WebGL without a GPU: the SwiftShader software renderer.
            "--use-angle=swiftshader",
            "--enable-unsafe-swiftshader",
            "--enable-logging=stderr",
            "--virtual-time-budget=10000",
        ])
        .arg(format!("--user-data-dir={}", profile.display()))
        .args(extra)
        .arg(format!("file://{}", page.display()))
        .output()
        .expect("run chromium")
}

#[test]
fn viewer_page_renders_in_headless_chromium_without_console_errors() {
    let Some(browser) = chromium() else {
        eprintln!("skipped: no chromium on PATH (apt-get install chromium)");
        return;
    };
    let dir = tempfile::tempdir().unwrap();
    let input = dir.path().join("in");
    std::fs::create_dir(&input).unwrap();
    for i in 0..2 {
        let mesh = similarity(&blob(3), 1.0 + 0.2 * i as f64);
        write_mesh(input.join(format!("blob{i}.obj")), &mesh, &[]).unwrap();
    }
    let out = dir.path().join("out");
    let mut args = vec!["segment", arg(&input), "-o", arg(&out), "--regions", "3"];
    args.extend(FAST_PIPELINE);
    let run = coseg(&args);
    assert_eq!(run.status.code(), Some(0), "{}", text(&run.stderr));
    let page = out.join("index.html");
    let html = std::fs::read_to_string(&page).unwrap();
    assert!(
        !html.contains("http:") && !html.contains("https:"),
        "the page must not fetch anything"
    );

    let dom = browse(
        &browser,
        &dir.path().join("profile1"),
        &page,
        &["--dump-dom".into()],
    );
    let (dom_text, log) = (
        String::from_utf8_lossy(&dom.stdout).into_owned(),
        String::from_utf8_lossy(&dom.stderr).into_owned(),
    );
    assert!(
        dom_text.contains(r#"<div id="status" class="ok">ok: 2 shapes</div>"#),
        "status not ok:\n{}\n{log}",
        dom_text
            .lines()
            .filter(|l| l.contains("status"))
            .collect::<Vec<_>>()
            .join("\n")
    );
    assert!(dom_text.contains("blob0") && dom_text.contains("blob1"));
    // Console messages other than the driver's performance notes are errors of the page.
    let console: Vec<&str> = log
        .lines()
        .filter(|l| l.contains(":CONSOLE") && !l.contains("GL Driver Message"))
        .collect();
    assert!(
        console.is_empty(),
        "console output:\n{}",
        console.join("\n")
    );

    let shot = dir.path().join("shot.png");
    let run = browse(
        &browser,
        &dir.path().join("profile2"),
        &page,
        &[
            "--window-size=800,600".into(),
            format!("--screenshot={}", shot.display()),
        ],
    );
    assert!(
        shot.is_file(),
        "no screenshot: {}",
        String::from_utf8_lossy(&run.stderr)
    );
    let dec = png::Decoder::new(std::io::BufReader::new(std::fs::File::open(&shot).unwrap()));
    let mut reader = dec.read_info().unwrap();
    let mut buf = vec![0; reader.output_buffer_size().unwrap()];
    let info = reader.next_frame(&mut buf).unwrap();
    let channels = info.color_type.samples();
    // Pixels of the 3D view (right of the 240-pixel side panel) that are strongly coloured:
    // the shape's part colours, not the grey background or black text.
    let mut coloured = 0usize;
    for y in 0..info.height as usize {
        for x in 260..info.width as usize {
            let i = (y * info.width as usize + x) * channels;
            let (r, g, b) = (buf[i] as i32, buf[i + 1] as i32, buf[i + 2] as i32);
            if r.max(g).max(b) - r.min(g).min(b) > 60 {
                coloured += 1;
            }
        }
    }
    assert!(
        coloured > 5000,
        "only {coloured} coloured pixels: the 3D view looks blank"
    );
}
