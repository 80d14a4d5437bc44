//! `coseg studio` in a real browser: Debian's headless `chromium` driven through
//! `chromedriver` (the W3C WebDriver protocol, as JSON over HTTP on the loopback). On a copy of
//! the shipped goblets it adds parts, labels one shape by clicks on patches, tries the brush,
//! undo and redo (keys and buttons) and erase, propagates, checks the grid (order, sources,
//! confidences) and the other shapes against what `coseg propagate` gives from the same labels,
//! corrects the least confident shape, propagates again (the incremental update), saves,
//! steps through shapes by keys, exports, and compares the saved files with what was
//! labelled. Skipped, with a message, when chromium or chromedriver is missing (`.ci/run`
//! installs both). With `COSEG_STUDIO_SCREENSHOTS=DIR` it also writes the pictures of
//! docs/STUDIO.md and the README.

mod common;

use common::cli::{arg, coseg_ok};
use common::generate::{collections_dir, read_labels};
use common::studio::{PIPELINE, request, start, try_request};
use serde_json::{Value, json};
use std::collections::BTreeMap;
use std::f64::consts::{FRAC_PI_2, PI};
use std::net::{TcpListener, TcpStream};
use std::path::{Path, PathBuf};
use std::process::{Child, Command, Stdio};
use std::time::{Duration, Instant};

/// The W3C name of an element reference in WebDriver JSON.
const ELEMENT: &str = "element-6066-11e4-a52e-4f735466cecf";

/// Parts the test creates, in order (their labels are 0, 1, 2: the goblets' ground truth).
const PARTS: [&str; 3] = ["bowl", "stem", "base"];

/// Patches smaller than this share of a shape's vertices (a handful of vertices) are left to
/// the propagation: a person labelling would not chase them either. Bigger ones are all
/// clicked, the thin goblet stems' included.
const MIN_PATCH_SHARE: f64 = 0.001;

/// How far under `coseg propagate`'s accuracy the studio may fall (the incremental update is
/// an approximation of a full solve).
const FLOOR_MARGIN: f64 = 0.05;

/// True once every picture of the grid has loaded.
const ALL_PICTURES: &str = "Array.prototype.every.call(document.querySelectorAll('#grid img'), \
     function (i) { return i.complete && i.naturalWidth > 0; })";

fn on_path(name: &str) -> Option<PathBuf> {
    std::env::var_os("PATH")?
        .to_str()?
        .split(':')
        .map(|d| Path::new(d).join(name))
        .find(|p| p.is_file())
}

/// A chromedriver process and one browser session; both end on drop.
struct Browser {
    driver: Child,
    port: u16,
    session: String,
}

impl Drop for Browser {
    fn drop(&mut self) {
        if !self.session.is_empty() {
            let path = format!("/session/{}", self.session);
            try_request(self.port, "DELETE", &path, &[], "").ok();
        }
        self.driver.kill().ok();
        self.driver.wait().ok();
    }
}

impl Browser {
    fn start(chromedriver: &Path, chromium: &Path, profile: &Path) -> Browser {
        let port = TcpListener::bind("127.0.0.1:0")
            .unwrap()
            .local_addr()
            .unwrap()
            .port();
        let mut driver = Command::new(chromedriver)
            .arg(format!("--port={port}"))
            .stdout(Stdio::null())
            // Its own complaints, if it fails, are the diagnosis.
            .stderr(Stdio::inherit())
            .spawn()
            .unwrap_or_else(|e| panic!("{} does not start: {e}", chromedriver.display()));
        let t0 = Instant::now();
        while TcpStream::connect(("127.0.0.1", port)).is_err() {
            if let Ok(Some(status)) = driver.try_wait() {
                panic!(
                    "{} stopped before listening on port {port} ({status})",
                    chromedriver.display()
                );
            }
            if t0.elapsed() > Duration::from_secs(30) {
                driver.kill().ok();
                driver.wait().ok();
                panic!(
                    "{} did not listen on port {port} within 30 s",
                    chromedriver.display()
                );
            }
            std::thread::sleep(Duration::from_millis(50));
        }
        let mut browser = Browser {
            driver,
            port,
            session: String::new(),
        };
        let caps = json!({"capabilities": {"alwaysMatch": {
            "browserName": "chrome",
            "goog:loggingPrefs": {"browser": "ALL"},
            "goog:chromeOptions": {
                "binary": chromium,
                "args": [
                    "--headless", "--no-sandbox", "--disable-dev-shm-usage",
                    // WebGL without a GPU: the SwiftShader software renderer.
                    "--use-angle=swiftshader", "--enable-unsafe-swiftshader",
                    "--window-size=1200,800", "--force-device-scale-factor=1",
                    "--no-first-run", "--disable-background-networking",
                    "--disable-component-update", "--disable-sync",
                    format!("--user-data-dir={}", profile.display()),
                ]
            }
        }}});
        let reply = browser.raw("POST", "/session", &caps);
        browser.session = reply["sessionId"]
            .as_str()
            .unwrap_or_else(|| {
                panic!(
                    "chromedriver started no {} session: {reply}",
                    chromium.display()
                )
            })
            .to_string();
        browser
    }

    /// One WebDriver command on the driver itself; its `value`.
    fn raw(&self, method: &str, path: &str, body: &Value) -> Value {
        let text = if body.is_null() {
            String::new()
        } else {
            body.to_string()
        };
        let (code, reply) = request(
            self.port,
            method,
            path,
            &[("Content-Type", "application/json")],
            &text,
        );
        let v: Value = serde_json::from_str(&reply)
            .unwrap_or_else(|e| panic!("{method} {path}: {e}: {reply}"));
        assert_eq!(code, 200, "{method} {path}: {v}");
        v["value"].clone()
    }

    /// One WebDriver command of the session.
    fn call(&self, method: &str, path: &str, body: Value) -> Value {
        self.raw(method, &format!("/session/{}{path}", self.session), &body)
    }

    fn js(&self, script: &str, args: Value) -> Value {
        self.call(
            "POST",
            "/execute/sync",
            json!({"script": script, "args": args}),
        )
    }

    /// Waits (polling the page) until the expression is truthy; returns its value.
    fn wait(&self, expression: &str, what: &str) -> Value {
        self.wait_or_show(expression, what, "null")
    }

    /// [`Browser::wait`] that shows the value of `detail` (an expression) if it times out.
    fn wait_or_show(&self, expression: &str, what: &str, detail: &str) -> Value {
        let t0 = Instant::now();
        loop {
            let v = self.js(&format!("return {expression};"), json!([]));
            if !(v.is_null() || v == json!(false) || v == json!(0)) {
                return v;
            }
            if t0.elapsed() > Duration::from_secs(120) {
                let status = self.status();
                let detail = self.js(&format!("return {detail};"), json!([]));
                panic!("waited 120 s for {what} ({expression}); page status: {status}; {detail}");
            }
            std::thread::sleep(Duration::from_millis(20));
        }
    }

    fn element(&self, css: &str) -> String {
        let v = self.call(
            "POST",
            "/element",
            json!({"using": "css selector", "value": css}),
        );
        v[ELEMENT].as_str().unwrap().to_string()
    }

    fn click(&self, css: &str) {
        let e = self.element(css);
        self.call("POST", &format!("/element/{e}/click"), json!({}));
    }

    fn type_into(&self, css: &str, text: &str) {
        let e = self.element(css);
        self.call(
            "POST",
            &format!("/element/{e}/value"),
            json!({"text": text}),
        );
    }

    /// A mouse click at a point of the viewport (CSS pixels).
    fn click_at(&self, x: i64, y: i64) {
        let actions = json!({"actions": [{"type": "pointer", "id": "mouse",
            "parameters": {"pointerType": "mouse"}, "actions": [
                {"type": "pointerMove", "duration": 0, "origin": "viewport", "x": x, "y": y},
                {"type": "pointerDown", "button": 0},
                {"type": "pointerUp", "button": 0}]}]});
        self.call("POST", "/actions", actions);
    }

    /// Presses keys together (`"\u{E009}"` is Control, `"\u{E008}"` Shift) and releases them.
    fn keys(&self, keys: &[&str]) {
        let mut seq: Vec<Value> = keys
            .iter()
            .map(|k| json!({"type": "keyDown", "value": k}))
            .collect();
        seq.extend(
            keys.iter()
                .rev()
                .map(|k| json!({"type": "keyUp", "value": k})),
        );
        let actions = json!({"actions": [{"type": "key", "id": "keyboard", "actions": seq}]});
        self.call("POST", "/actions", actions);
    }

    fn screenshot(&self, path: &Path) {
        let b64 = self.call("GET", "/screenshot", Value::Null);
        std::fs::write(path, base64_decode(b64.as_str().unwrap())).unwrap();
    }

    /// The page's console messages since the last call.
    fn console(&self) -> Vec<Value> {
        self.call("POST", "/se/log", json!({"type": "browser"}))
            .as_array()
            .cloned()
            .unwrap_or_default()
    }

    fn status(&self) -> String {
        self.js(
            "return document.getElementById('status').textContent;",
            json!([]),
        )
        .as_str()
        .unwrap()
        .to_string()
    }

    /// The labels the editor shows.
    fn shown_labels(&self) -> Vec<i32> {
        serde_json::from_value(self.js("return window.studioTest.mesh().labels;", json!([])))
            .unwrap()
    }

    fn edits(&self) -> u64 {
        self.js("return window.studioTest.edits;", json!([]))
            .as_u64()
            .unwrap()
    }
}

fn base64_decode(text: &str) -> Vec<u8> {
    let value = |c: u8| match c {
        b'A'..=b'Z' => c - b'A',
        b'a'..=b'z' => c - b'a' + 26,
        b'0'..=b'9' => c - b'0' + 52,
        b'+' => 62,
        b'/' => 63,
        _ => panic!("not base64: {c}"),
    } as u32;
    let bytes: Vec<u8> = text.bytes().filter(|&c| c != b'=').collect();
    let mut out = Vec::with_capacity(bytes.len() * 3 / 4);
    for chunk in bytes.chunks(4) {
        let n = chunk
            .iter()
            .enumerate()
            .fold(0u32, |acc, (k, &c)| acc | value(c) << (18 - 6 * k));
        out.extend_from_slice(&n.to_be_bytes()[1..chunk.len()]);
    }
    out
}

/// The views the labelling tries, in order (yaw, pitch): front, sides, back, above, below.
const VIEWS: [(f64, f64); 10] = [
    (0.0, 0.0),
    (FRAC_PI_2, 0.0),
    (-FRAC_PI_2, 0.0),
    (PI, 0.0),
    (0.0, 1.2),
    (0.0, -1.2),
    (FRAC_PI_2, 0.8),
    (-FRAC_PI_2, 0.8),
    (FRAC_PI_2, -0.8),
    (-FRAC_PI_2, -0.8),
];

/// Labels, in the open editor, every patch of `targets` (patch → part label) the views show,
/// by a key press choosing the part (`1`…`9`) and a click on the patch. Returns the patches
/// labelled.
fn label_patches(b: &Browser, targets: &BTreeMap<u32, i32>) -> Vec<u32> {
    let patches: Vec<u32> =
        serde_json::from_value(b.js("return window.studioTest.mesh().patches;", json!([])))
            .unwrap();
    let mut done = Vec::new();
    let mut part = None;
    for (yaw, pitch) in VIEWS {
        b.js(
            "window.studioTest.setView(arguments[0], arguments[1]);",
            json!([yaw, pitch]),
        );
        let todo: Vec<u32> = targets
            .keys()
            .copied()
            .filter(|p| !done.contains(p))
            .collect();
        // Where each remaining patch can be clicked in this view (viewport pixels).
        let points = b.js(
            "var T = window.studioTest, r = document.getElementById('canvas').getBoundingClientRect();
             return arguments[0].map(function (p) {
               var q = T.visiblePatchPoint(p);
               return q && [p, Math.round(q.x + r.left), Math.round(q.y + r.top)];
             }).filter(function (q) { return q; });",
            json!([todo]),
        );
        for point in points.as_array().unwrap() {
            let (p, x, y) = (
                point[0].as_u64().unwrap() as u32,
                point[1].as_i64().unwrap(),
                point[2].as_i64().unwrap(),
            );
            let label = targets[&p];
            if part != Some(label) {
                // Parts are keyed 1… in palette order, which is label order here.
                b.keys(&[&(label + 1).to_string()]);
                part = Some(label);
            }
            let before = b.edits();
            b.click_at(x, y);
            b.wait(
                &format!("window.studioTest.edits > {before}"),
                "the click's edit",
            );
            let shown = b.shown_labels();
            assert!(
                (0..patches.len()).all(|v| patches[v] != p || shown[v] == label),
                "the click at ({x}, {y}) did not give patch {p} part {label}"
            );
            done.push(p);
        }
    }
    done
}

/// Patch → the ground-truth part most of its vertices carry, for the patches of at least
/// [`MIN_PATCH_SHARE`] of the vertices, biggest first in the iteration of the caller.
fn patch_majorities(patches: &[u32], truth: &[u32]) -> BTreeMap<u32, (i32, usize)> {
    let mut counts: BTreeMap<u32, BTreeMap<u32, usize>> = BTreeMap::new();
    for (v, &p) in patches.iter().enumerate() {
        *counts.entry(p).or_default().entry(truth[v]).or_default() += 1;
    }
    counts
        .into_iter()
        .filter_map(|(p, c)| {
            let size: usize = c.values().sum();
            let (&label, _) = c.iter().max_by_key(|&(l, n)| (*n, std::cmp::Reverse(*l)))?;
            (size as f64 >= MIN_PATCH_SHARE * patches.len() as f64)
                .then_some((p, (label as i32, size)))
        })
        .collect()
}

fn accuracy(labels: &[i32], truth: &[u32]) -> f64 {
    assert_eq!(labels.len(), truth.len());
    labels
        .iter()
        .zip(truth)
        .filter(|(l, t)| **l == **t as i32)
        .count() as f64
        / truth.len() as f64
}

fn read_saved(path: &Path) -> Vec<i32> {
    std::fs::read_to_string(path)
        .unwrap_or_else(|e| panic!("{}: {e}", path.display()))
        .lines()
        .map(|l| l.trim().parse().unwrap())
        .collect()
}

/// Mean accuracy over the shapes that are not in `sources`, of the label files in `dir`.
fn mean_accuracy(dir: &Path, truth: &[Vec<u32>], sources: &[usize]) -> f64 {
    let others: Vec<usize> = (0..truth.len()).filter(|i| !sources.contains(i)).collect();
    others
        .iter()
        .map(|&i| {
            let saved = read_saved(&dir.join(format!("goblets_{i:02}.labels.txt")));
            accuracy(&saved, &truth[i])
        })
        .sum::<f64>()
        / others.len() as f64
}

/// The studio's propagation scores (mean accuracy `studio` over the shapes not in `sources`)
/// at least what `coseg propagate` scores from the same sources (its output in `cli_dir`), less
/// [`FLOOR_MARGIN`]; both are printed with the time since `t0`.
fn studio_at_least_cli(
    which: &str,
    studio: f64,
    cli_dir: &Path,
    truth: &[Vec<u32>],
    sources: &[usize],
    t0: Instant,
) {
    let cli = mean_accuracy(cli_dir, truth, sources);
    eprintln!(
        "{which} propagation: studio {studio:.3}, coseg propagate {cli:.3} \
         (mean vertex accuracy of the {} other shapes), {:.1} s",
        truth.len() - sources.len(),
        t0.elapsed().as_secs_f64()
    );
    assert!(
        studio >= cli - FLOOR_MARGIN,
        "studio {studio:.3} vs coseg propagate {cli:.3}"
    );
}

/// `coseg propagate` from the given label files, with the studio's pipeline and cache.
fn cli_propagate(folder: &Path, cache: &Path, labels: &[PathBuf], out: &Path) {
    let list: Vec<String> = labels.iter().map(|p| p.display().to_string()).collect();
    let list = list.join(",");
    let mut args = vec!["propagate", arg(folder), "--labels", &list, "-o", arg(out)];
    args.extend(["--cache", arg(cache), "--no-pictures"]);
    args.extend(PIPELINE);
    coseg_ok(&args);
}

#[test]
fn a_labelling_session_in_a_real_browser_labels_propagates_corrects_and_saves() {
    let (Some(chromium), Some(chromedriver)) = (
        on_path("chromium").or_else(|| on_path("chromium-browser")),
        on_path("chromedriver"),
    ) else {
        eprintln!(
            "skipped: chromium or chromedriver missing (apt-get install chromium chromium-driver)"
        );
        return;
    };
    let shots = std::env::var_os("COSEG_STUDIO_SCREENSHOTS").map(PathBuf::from);
    if let Some(d) = &shots {
        std::fs::create_dir_all(d).unwrap();
    }
    let t0 = Instant::now();
    let dir = tempfile::tempdir().unwrap();
    let folder = dir.path().join("goblets");
    std::fs::create_dir(&folder).unwrap();
    let n = 6;
    let truth: Vec<Vec<u32>> = (0..n)
        .map(|i| {
            let src = collections_dir().join("goblets");
            let name = format!("goblets_{i:02}");
            std::fs::copy(
                src.join(format!("{name}.obj")),
                folder.join(format!("{name}.obj")),
            )
            .unwrap();
            read_labels(&src.join(format!("{name}.labels.txt")))
        })
        .collect();
    let cache = dir.path().join("cache");
    let server = start(&folder, &cache);
    let url = format!("http://127.0.0.1:{}/?token={}", server.port, server.token);
    let b = Browser::start(&chromedriver, &chromium, &dir.path().join("profile"));
    b.call("POST", "/url", json!({ "url": url }));
    b.wait(
        "window.studioTest && window.studioTest.ready",
        "the page to load",
    );
    eprintln!(
        "studio open in the browser: {:.1} s",
        t0.elapsed().as_secs_f64()
    );

    // The palette, through its text field and button.
    for (k, name) in PARTS.iter().enumerate() {
        b.type_into("#newpart", name);
        b.click("#addpart");
        b.wait(
            &format!(
                "document.querySelectorAll('#parts .part').length === {}",
                k + 1
            ),
            "the new part",
        );
    }
    let parts = b.js("return window.studioTest.state().parts;", json!([]));
    for (k, name) in PARTS.iter().enumerate() {
        assert_eq!(parts[k]["label"], json!(k), "{parts}");
        assert_eq!(parts[k]["name"], json!(name), "{parts}");
    }

    // Shape 0: open it from the grid, click its patches.
    b.click("#card-0");
    b.wait(
        "window.studioTest.mesh() && window.studioTest.mesh().shape === 0",
        "the editor",
    );
    let patches: Vec<u32> =
        serde_json::from_value(b.js("return window.studioTest.mesh().patches;", json!([])))
            .unwrap();
    let majorities = patch_majorities(&patches, &truth[0]);
    let targets: BTreeMap<u32, i32> = majorities.iter().map(|(&p, &(l, _))| (p, l)).collect();
    let clicked = label_patches(&b, &targets);
    let covered: usize = clicked.iter().map(|p| majorities[p].1).sum();
    assert!(
        covered as f64 >= 0.95 * patches.len() as f64,
        "the clicks labelled {covered} of {} vertices",
        patches.len()
    );
    let labelled0 = b.shown_labels();
    eprintln!(
        "shape 0: {} clicks on patches, {:.3} of the vertices right, {:.1} s",
        clicked.len(),
        accuracy(&labelled0, &truth[0]),
        t0.elapsed().as_secs_f64()
    );

    // The brush (key B) paints around a click; Ctrl+Z (the keyboard) takes it back.
    b.keys(&["b"]);
    b.keys(&["2"]);
    b.js("window.studioTest.setView(0, 0);", json!([]));
    let centre = b.js(
        "var r = document.getElementById('canvas').getBoundingClientRect();
         return [Math.round(r.left + r.width / 2), Math.round(r.top + r.height / 2)];",
        json!([]),
    );
    let before = b.edits();
    b.click_at(centre[0].as_i64().unwrap(), centre[1].as_i64().unwrap());
    b.wait(
        &format!("window.studioTest.edits > {before}"),
        "the brush stroke",
    );
    let brushed = b.shown_labels();
    assert_ne!(brushed, labelled0, "the brush changed nothing");
    b.keys(&["\u{E009}", "z"]);
    b.wait("window.studioTest.steps === 1", "the undo (Ctrl+Z)");
    assert_eq!(b.shown_labels(), labelled0, "Ctrl+Z did not undo the brush");
    b.keys(&["\u{E009}", "\u{E008}", "z"]);
    b.wait("window.studioTest.steps === 2", "the redo (Ctrl+Shift+Z)");
    assert_eq!(
        b.shown_labels(),
        brushed,
        "Ctrl+Shift+Z did not redo the brush"
    );
    b.click("#undo");
    b.wait("window.studioTest.steps === 3", "the undo (button)");
    assert_eq!(b.shown_labels(), labelled0, "the undo button did not undo");
    // Erase (key E) on a patch gives it -1; the redo button is then disabled (a new edit
    // drops what was undone), and the undo button takes the erase back.
    b.keys(&["p"]);
    b.keys(&["e"]);
    let erased = clicked[0];
    let point = b.js(
        "var q = window.studioTest.visiblePatchPoint(arguments[0]), \
         r = document.getElementById('canvas').getBoundingClientRect(); \
         return q && [Math.round(q.x + r.left), Math.round(q.y + r.top)];",
        json!([erased]),
    );
    let before = b.edits();
    b.click_at(point[0].as_i64().unwrap(), point[1].as_i64().unwrap());
    b.wait(&format!("window.studioTest.edits > {before}"), "the erase");
    let shown = b.shown_labels();
    assert!(
        (0..patches.len()).all(|v| if patches[v] == erased {
            shown[v] == -1
        } else {
            shown[v] == labelled0[v]
        }),
        "the erase did not give exactly patch {erased} the label -1"
    );
    assert_eq!(
        b.js(
            "return document.getElementById('redo').disabled;",
            json!([])
        ),
        json!(true)
    );
    b.click("#undo");
    b.wait("window.studioTest.steps === 4", "the undo of the erase");
    assert_eq!(b.shown_labels(), labelled0, "the erase was not undone");
    b.keys(&["e"]);
    // [ and ] resize the brush: down to the slider's minimum, and up again from there.
    let radius = || {
        b.js(
            "return +document.getElementById('radius').value;",
            json!([]),
        )
        .as_f64()
        .unwrap()
    };
    for _ in 0..12 {
        b.keys(&["["]);
    }
    assert_eq!(radius(), 0.01, "[ did not reach the smallest brush");
    b.keys(&["]"]);
    assert!(radius() > 0.01, "] did not grow the smallest brush");
    b.keys(&["p"]);
    if let Some(d) = &shots {
        b.js("window.studioTest.setView(0.35, 0.3);", json!([]));
        b.screenshot(&d.join("studio_label.png"));
    }

    // Propagate (the button), then look at the grid.
    b.click("#propagate");
    b.wait(
        "window.studioTest.propagations === 1 && !window.studioTest.busy()",
        "the first propagation",
    );
    assert!(b.status().contains("full run"), "{}", b.status());
    b.click("#gridbtn");
    b.wait_or_show(
        ALL_PICTURES,
        "the grid's pictures",
        "Array.prototype.map.call(document.querySelectorAll('#grid img'), \
         function (i) { return [i.getAttribute('src'), i.complete, i.naturalWidth]; })",
    );
    // The grid: least confident first, the source last and marked as such, each card with
    // its confidence.
    let cards = b.js(
        "return Array.prototype.map.call(document.querySelectorAll('#grid .card'), function (c) {
           return [+c.dataset.index, c.classList.contains('source'),
                   c.querySelector('.cap').lastChild.textContent];
         });",
        json!([]),
    );
    let state = b.js("return window.studioTest.state();", json!([]));
    let shown_order: Vec<u64> = cards
        .as_array()
        .unwrap()
        .iter()
        .map(|c| c[0].as_u64().unwrap())
        .collect();
    assert_eq!(
        json!(shown_order),
        state["order"],
        "the grid is not in the order of the state"
    );
    let mut last = f64::NEG_INFINITY;
    for card in cards.as_array().unwrap() {
        let i = card[0].as_u64().unwrap() as usize;
        let text = card[2].as_str().unwrap();
        if i == 0 {
            assert_eq!(card[1], json!(true), "the source is not marked: {cards}");
            assert_eq!(text, "source", "{cards}");
            assert_eq!(
                shown_order.last(),
                Some(&0),
                "the source is not last: {cards}"
            );
            continue;
        }
        assert_eq!(card[1], json!(false), "shape {i} marked a source: {cards}");
        let confidence = state["shapes"][i]["confidence"].as_f64().unwrap();
        assert_eq!(text, format!("{:.0} %", 100.0 * confidence), "{cards}");
        assert!(
            confidence >= last,
            "the grid is not least confident first: {state}"
        );
        last = confidence;
    }
    b.click("#save");
    b.wait("window.studioTest.saves === 1", "the save");
    let labels_dir = folder.join("labels");
    assert_eq!(
        read_saved(&labels_dir.join("goblets_00.labels.txt")),
        labelled0
    );
    let studio_first = mean_accuracy(&labels_dir, &truth, &[0]);
    let cli_first_dir = dir.path().join("cli1");
    let saved0 = dir.path().join("goblets_00.labels.txt");
    std::fs::copy(labels_dir.join("goblets_00.labels.txt"), &saved0).unwrap();
    cli_propagate(
        &folder,
        &cache,
        std::slice::from_ref(&saved0),
        &cli_first_dir,
    );
    studio_at_least_cli("first", studio_first, &cli_first_dir, &truth, &[0], t0);

    // Correct the least confident shape: its patches the propagation got wrong, among the
    // parts known so far (so the next run is the incremental update).
    let worst = b.js("return window.studioTest.state().order[0];", json!([]));
    let worst = worst.as_u64().unwrap() as usize;
    assert_ne!(worst, 0, "a source is never first in the grid");
    b.click(&format!("#card-{worst}"));
    b.wait(
        &format!("window.studioTest.mesh() && window.studioTest.mesh().shape === {worst}"),
        "the editor",
    );
    let patches: Vec<u32> =
        serde_json::from_value(b.js("return window.studioTest.mesh().patches;", json!([])))
            .unwrap();
    let shown = b.shown_labels();
    let wrong: BTreeMap<u32, i32> = patch_majorities(&patches, &truth[worst])
        .into_iter()
        .filter(|&(p, (label, _))| {
            (label as usize) < PARTS.len()
                && (0..patches.len()).any(|v| patches[v] == p && shown[v] != label)
        })
        .map(|(p, (label, _))| (p, label))
        .collect();
    let before_fix = accuracy(&shown, &truth[worst]);
    let fixed = label_patches(&b, &wrong);
    assert!(!fixed.is_empty(), "shape {worst}: nothing to correct");
    let labelled_worst = b.shown_labels();
    let after_fix = accuracy(&labelled_worst, &truth[worst]);
    assert!(after_fix > before_fix, "{before_fix} → {after_fix}");
    b.keys(&["\u{E009}", "\u{E007}"]); // Ctrl+Enter: propagate
    b.wait(
        "window.studioTest.propagations === 2 && !window.studioTest.busy()",
        "the second propagation",
    );
    assert!(
        b.status().contains("1 changed shape(s)"),
        "not the incremental update: {}",
        b.status()
    );
    b.keys(&["\u{E009}", "s"]); // Ctrl+S: save
    b.wait("window.studioTest.saves === 2", "the second save");
    eprintln!(
        "shape {worst} corrected ({} clicks, {before_fix:.3} → {after_fix:.3}), propagated, \
         saved: {:.1} s",
        fixed.len(),
        t0.elapsed().as_secs_f64()
    );

    // N opens the next shape of the grid, Shift+N the previous one, G goes back to the grid.
    let order: Vec<usize> =
        serde_json::from_value(b.js("return window.studioTest.state().order;", json!([]))).unwrap();
    let next = order[(order.iter().position(|&i| i == worst).unwrap() + 1) % order.len()];
    b.keys(&["n"]);
    b.wait(
        &format!("window.studioTest.mesh() && window.studioTest.mesh().shape === {next}"),
        "the next shape (N)",
    );
    b.keys(&["\u{E008}", "n"]);
    b.wait(
        &format!("window.studioTest.mesh() && window.studioTest.mesh().shape === {worst}"),
        "the previous shape (Shift+N)",
    );
    b.keys(&["g"]);
    b.wait(
        "!window.studioTest.mesh() && document.getElementById('grid').style.display === 'flex'",
        "the grid (G)",
    );
    if let Some(d) = &shots {
        b.wait(ALL_PICTURES, "the grid's pictures");
        b.screenshot(&d.join("studio_grid.png"));
    }

    // Export: a path out of the folder is refused and writes nothing; a folder inside it
    // gets the same files as the save.
    let export_dir = b.element("#exportdir");
    b.call("POST", &format!("/element/{export_dir}/clear"), json!({}));
    b.type_into("#exportdir", "../outside");
    b.click("#export");
    b.wait(
        "document.getElementById('status').className === 'error'",
        "the refused export",
    );
    assert!(b.status().starts_with("export: "), "{}", b.status());
    // The refusal is a 403 the browser logs; it is the one console error expected.
    let logged = b.console();
    assert!(
        logged.iter().any(|m| m["message"]
            .as_str()
            .is_some_and(|t| t.contains("/api/export"))),
        "{logged:?}"
    );
    assert!(!dir.path().join("outside").exists());
    b.call("POST", &format!("/element/{export_dir}/clear"), json!({}));
    b.type_into("#exportdir", "export");
    b.click("#export");
    b.wait("window.studioTest.exports === 1", "the export");
    let exported = folder.join("export");
    for i in 0..n {
        for ext in ["seg", "labels.txt"] {
            let name = format!("goblets_{i:02}.{ext}");
            assert_eq!(
                std::fs::read(exported.join(&name)).unwrap(),
                std::fs::read(folder.join("labels").join(&name)).unwrap(),
                "{name}: export and save differ"
            );
        }
    }

    // The saved files are what was labelled; the others reach the floor again.
    assert_eq!(
        read_saved(&labels_dir.join("goblets_00.labels.txt")),
        labelled0
    );
    let worst_file = labels_dir.join(format!("goblets_{worst:02}.labels.txt"));
    assert_eq!(read_saved(&worst_file), labelled_worst);
    for i in 0..n {
        let seg = read_saved(&labels_dir.join(format!("goblets_{i:02}.seg")));
        let faces = std::fs::read_to_string(folder.join(format!("goblets_{i:02}.obj")))
            .unwrap()
            .lines()
            .filter(|l| l.starts_with("f "))
            .count();
        assert_eq!(seg.len(), faces, "goblets_{i:02}.seg");
    }
    let summary: Value =
        serde_json::from_str(&std::fs::read_to_string(labels_dir.join("summary.json")).unwrap())
            .unwrap();
    assert_eq!(
        summary["sources"],
        json!(["goblets_00", format!("goblets_{worst:02}")])
    );
    let names: Value =
        serde_json::from_str(&std::fs::read_to_string(labels_dir.join("parts.json")).unwrap())
            .unwrap();
    assert_eq!(names, json!({"0": "bowl", "1": "stem", "2": "base"}));
    let studio_second = mean_accuracy(&labels_dir, &truth, &[0, worst]);
    let cli_second_dir = dir.path().join("cli2");
    let saved_worst = dir.path().join(format!("goblets_{worst:02}.labels.txt"));
    std::fs::copy(&worst_file, &saved_worst).unwrap();
    cli_propagate(&folder, &cache, &[saved0, saved_worst], &cli_second_dir);
    let sources = [0, worst];
    studio_at_least_cli(
        "second",
        studio_second,
        &cli_second_dir,
        &truth,
        &sources,
        t0,
    );

    let errors: Vec<Value> = b
        .console()
        .into_iter()
        .filter(|m| m["level"] == json!("SEVERE"))
        .collect();
    assert!(errors.is_empty(), "console errors: {errors:?}");
}
