//! `coseg studio`: the labelling session ([`coseg::studio::Studio`]) served to a browser page on
//! the loopback. This file only translates HTTP to library calls and guards the door: the
//! server binds 127.0.0.1, every request must carry the session's token (the printed
//! address's `?token=`, then a cookie or the `X-Coseg-Token` header), requests whose `Host`
//! or `Origin` is not this server are refused, and bad requests get a JSON error and change
//! nothing.

use super::pipeline_args::PipelineArgs;
use anyhow::{Context, Result};
use clap::Args;
use coseg::studio::{PropagateReport, Studio, StudioError, StudioOptions};
use serde::Deserialize;
use serde_json::{Value, json};
use std::io::{Read, Write};
use std::path::PathBuf;
use std::process::ExitCode;
use std::sync::{Arc, LazyLock, Mutex, RwLock};
use tiny_http::{Header, Method, Request, Response, Server};

/// The page: plain JavaScript and WebGL, embedded in the binary; its WebGL helpers and shaded
/// program are the viewer page's (`coseg::output::write_viewer`), from the same files.
static PAGE: LazyLock<String> = LazyLock::new(|| {
    include_str!("studio.html")
        .replace(
            "__GL_FUNCTIONS__\n",
            include_str!("../output/gl_functions.js"),
        )
        .replace("__GL_PROGRAM__\n", include_str!("../output/gl_program.js"))
});

/// Largest request body read (a brush stroke over a whole large shape fits many times).
const MAX_BODY: usize = 16 << 20;

/// Request threads: a click is never queued behind a picture being drawn.
const WORKERS: usize = 4;

#[derive(Debug, Args)]
pub struct StudioArgs {
    /// Folder of meshes (.obj, .off, .ply) to label.
    folder: PathBuf,
    /// Folder the session is saved to and resumed from (default: FOLDER/labels).
    #[arg(long)]
    labels: Option<PathBuf>,
    /// Port on 127.0.0.1 (default 0: any free port; the address is printed).
    #[arg(long)]
    port: Option<u16>,
    /// Open the address in the system's browser.
    #[arg(long)]
    open: bool,
    /// Per-shape cache folder (default: `<LABELS>/.cache`).
    #[arg(long)]
    cache: Option<PathBuf>,
    #[command(flatten)]
    pipeline: PipelineArgs,
}

/// State of the propagation running in the background.
#[derive(Default)]
struct Progress {
    running: bool,
    done: usize,
    total: usize,
    error: Option<String>,
    report: Option<PropagateReport>,
}

struct App {
    /// Requests that only look take it shared (the grid's pictures load in parallel); edits
    /// and the propagation take it alone.
    studio: RwLock<Studio>,
    progress: Mutex<Progress>,
    token: String,
    port: u16,
}

pub fn run(args: StudioArgs) -> Result<ExitCode> {
    let mut options = StudioOptions::default();
    options.propagate.pipeline = args.pipeline.options()?;
    let labels = args
        .labels
        .clone()
        .unwrap_or_else(|| args.folder.join("labels"));
    options.labels_dir = Some(labels.clone());
    options.propagate.cache_dir = Some(args.cache.clone().unwrap_or_else(|| labels.join(".cache")));
    let spinner = super::spinner("opening the folder");
    let studio = Studio::open(&args.folder, &options)
        .with_context(|| format!("coseg studio {}", args.folder.display()))?;
    if let Some(s) = spinner {
        s.finish_and_clear();
    }
    for w in studio.warnings() {
        super::warn(w);
    }
    // Loopback only: another machine cannot reach the server at all.
    // No port: 0, the operating system's "any free port".
    let server = Server::http(("127.0.0.1", args.port.unwrap_or(0))).map_err(|e| {
        anyhow::anyhow!("cannot listen on 127.0.0.1:{}: {e}", args.port.unwrap_or(0))
    })?;
    let port = server
        .server_addr()
        .to_ip()
        .map(|a| a.port())
        .context("the server has no IP address")?;
    let token = format!("{:032x}", rand::random::<u128>());
    let url = format!("http://127.0.0.1:{port}/?token={token}");
    println!(
        "coseg studio: {} shapes of {}",
        studio.len(),
        studio.folder().display()
    );
    println!("open {url}");
    println!(
        "(saves into {}; Ctrl+C stops)",
        studio.labels_dir().display()
    );
    std::io::stdout().flush().ok();
    if args.open {
        open_browser(&url);
    }
    let app = Arc::new(App {
        studio: RwLock::new(studio),
        progress: Mutex::new(Progress::default()),
        token,
        port,
    });
    // The progress bar's poll is answered by the thread that accepts requests (it only reads
    // a counter), so that it is never queued behind requests waiting for a propagation.
    let (queue, inbox) = std::sync::mpsc::channel::<Request>();
    let inbox = Arc::new(Mutex::new(inbox));
    let workers: Vec<_> = (0..WORKERS)
        .map(|_| {
            let (inbox, app) = (inbox.clone(), app.clone());
            std::thread::spawn(move || {
                loop {
                    let next = inbox.lock().unwrap_or_else(|e| e.into_inner()).recv();
                    match next {
                        Ok(rq) => handle(&app, rq),
                        Err(_) => break,
                    }
                }
            })
        })
        .collect();
    for rq in server.incoming_requests() {
        let path = rq.url().split('?').next().unwrap_or("");
        if *rq.method() == Method::Get && path == "/api/progress" {
            handle(&app, rq);
        } else if queue.send(rq).is_err() {
            break;
        }
    }
    drop(queue);
    for w in workers {
        w.join().ok();
    }
    Ok(ExitCode::SUCCESS)
}

fn open_browser(url: &str) {
    let program = if cfg!(target_os = "macos") {
        "open"
    } else if cfg!(windows) {
        "explorer"
    } else {
        "xdg-open"
    };
    if let Err(e) = std::process::Command::new(program).arg(url).spawn() {
        super::warn(format!(
            "could not open a browser ({program}: {e}); open the address above"
        ));
    }
}

type Reply = Response<std::io::Cursor<Vec<u8>>>;

fn header(name: &str, value: &str) -> Header {
    Header::from_bytes(name.as_bytes(), value.as_bytes()).expect("valid header")
}

/// A reply with the headers every reply carries: no caching by others, no framing, no
/// sniffing, nothing fetched from elsewhere.
fn reply(status: u16, content_type: &str, body: Vec<u8>) -> Reply {
    Response::from_data(body)
        .with_status_code(status)
        .with_header(header("Content-Type", content_type))
        .with_header(header("Cache-Control", "no-store"))
        .with_header(header("X-Content-Type-Options", "nosniff"))
        .with_header(header("X-Frame-Options", "DENY"))
        .with_header(header("Referrer-Policy", "no-referrer"))
        .with_header(header(
            "Content-Security-Policy",
            "default-src 'self'; script-src 'unsafe-inline'; style-src 'unsafe-inline'; \
             img-src 'self'; connect-src 'self'; frame-ancestors 'none'",
        ))
}

fn json_reply(status: u16, value: &Value) -> Reply {
    reply(status, "application/json", value.to_string().into_bytes())
}

fn error(status: u16, message: impl std::fmt::Display) -> Reply {
    json_reply(status, &json!({ "error": message.to_string() }))
}

fn handle(app: &Arc<App>, mut rq: Request) {
    let response = match authorise(app, &rq) {
        Err(r) => r,
        Ok(()) => route(app, &mut rq),
    };
    rq.respond(response).ok();
}

fn header_value<'a>(rq: &'a Request, name: &str) -> Option<&'a str> {
    rq.headers()
        .iter()
        .find(|h| h.field.as_str().as_str().eq_ignore_ascii_case(name))
        .map(|h| h.value.as_str())
}

/// Compares in time independent of where the strings differ (the token is a secret).
fn same_secret(a: &str, b: &str) -> bool {
    a.len() == b.len()
        && a.bytes()
            .zip(b.bytes())
            .fold(0u8, |acc, (x, y)| acc | (x ^ y))
            == 0
}

fn query_param<'a>(url: &'a str, name: &str) -> Option<&'a str> {
    let query = url.split_once('?')?.1;
    query
        .split('&')
        .filter_map(|kv| kv.split_once('='))
        .find(|(k, _)| *k == name)
        .map(|(_, v)| v)
}

/// The door: `Host` must name this server (no DNS rebinding), an `Origin`, when sent, must be
/// this server's (no other page drives it), and the token must match.
fn authorise(app: &App, rq: &Request) -> Result<(), Reply> {
    let hosts = [
        format!("127.0.0.1:{}", app.port),
        format!("localhost:{}", app.port),
    ];
    match header_value(rq, "Host") {
        Some(h) if hosts.iter().any(|x| x == h) => {}
        h => {
            return Err(error(
                403,
                format!(
                    "Host {h:?} refused: coseg studio answers only to 127.0.0.1:{}",
                    app.port
                ),
            ));
        }
    }
    if let Some(origin) = header_value(rq, "Origin")
        && !hosts.iter().any(|h| origin == format!("http://{h}"))
    {
        return Err(error(
            403,
            format!("Origin {origin:?} refused: requests must come from the studio's own page"),
        ));
    }
    let from_cookie = header_value(rq, "Cookie").and_then(|c| {
        c.split(';')
            .filter_map(|kv| kv.trim().split_once('='))
            .find(|(k, _)| *k == "coseg_token")
            .map(|(_, v)| v)
    });
    let given = header_value(rq, "X-Coseg-Token")
        .or(from_cookie)
        .or_else(|| query_param(rq.url(), "token"));
    match given {
        Some(t) if same_secret(t, &app.token) => Ok(()),
        Some(_) => Err(error(
            401,
            "wrong token: open the address `coseg studio` printed",
        )),
        None => Err(error(
            401,
            "missing token: open the address `coseg studio` printed",
        )),
    }
}

fn read_body(rq: &mut Request) -> Result<Value, Reply> {
    if rq.body_length().is_some_and(|n| n > MAX_BODY) {
        return Err(error(413, format!("request body over {MAX_BODY} bytes")));
    }
    let mut body = Vec::new();
    rq.as_reader()
        .take(MAX_BODY as u64 + 1)
        .read_to_end(&mut body)
        .map_err(|e| error(400, format!("unreadable body: {e}")))?;
    if body.len() > MAX_BODY {
        return Err(error(413, format!("request body over {MAX_BODY} bytes")));
    }
    if body.is_empty() {
        return Ok(json!({}));
    }
    serde_json::from_slice(&body).map_err(|e| error(400, format!("body is not JSON: {e}")))
}

fn parse<T: for<'de> Deserialize<'de>>(body: Value) -> Result<T, Reply> {
    serde_json::from_value(body).map_err(|e| error(400, format!("bad request: {e}")))
}

fn studio_error(e: StudioError) -> Reply {
    let status = match e {
        StudioError::BadRequest(_) => 400,
        StudioError::OutsideFolder { .. } => 403,
        _ => 500,
    };
    error(status, e)
}

fn shape_param(url: &str) -> Result<usize, Reply> {
    query_param(url, "i")
        .and_then(|v| v.parse().ok())
        .ok_or_else(|| error(400, "expected ?i=<shape index>"))
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct LabelRequest {
    shape: usize,
    label: i32,
    patch: Option<u32>,
    vertices: Option<Vec<u32>>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields, tag = "op", rename_all = "lowercase")]
enum PartRequest {
    Add { name: String },
    Rename { label: i32, name: String },
    Recolor { label: i32, color: String },
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct ExportRequest {
    dir: String,
}

fn route(app: &Arc<App>, rq: &mut Request) -> Reply {
    let path = rq.url().split('?').next().unwrap_or("").to_string();
    let url = rq.url().to_string();
    let method = rq.method().clone();
    if method == Method::Get && path == "/" {
        return reply(200, "text/html; charset=utf-8", PAGE.as_bytes().to_vec()).with_header(
            header(
                "Set-Cookie",
                &format!(
                    "coseg_token={}; HttpOnly; SameSite=Strict; Path=/",
                    app.token
                ),
            ),
        );
    }
    // Browsers ask for an icon; there is none, and a 404 would be a console error.
    if method == Method::Get && path == "/favicon.ico" {
        return reply(204, "image/x-icon", Vec::new());
    }
    if method == Method::Get && path == "/api/progress" {
        let p = app.progress.lock().unwrap_or_else(|e| e.into_inner());
        return json_reply(
            200,
            &json!({"running": p.running, "done": p.done, "total": p.total,
                    "error": p.error, "report": p.report}),
        );
    }
    let body = if method == Method::Post {
        match read_body(rq) {
            Ok(b) => b,
            Err(r) => return r,
        }
    } else {
        Value::Null
    };
    if method == Method::Post && path == "/api/propagate" {
        return start_propagation(app);
    }
    // Looking waits for a running edit; an edit while a propagation holds the session is
    // refused rather than left hanging the page.
    if method == Method::Get {
        let studio = app.studio.read().unwrap_or_else(|e| e.into_inner());
        return look(&studio, &path, &url).unwrap_or_else(|r| r);
    }
    if app
        .progress
        .lock()
        .unwrap_or_else(|e| e.into_inner())
        .running
    {
        return error(409, "busy: a propagation is running");
    }
    let mut studio = app.studio.write().unwrap_or_else(|e| e.into_inner());
    let result: Result<Reply, Reply> = (|| {
        Ok(match (method, path.as_str()) {
            (Method::Post, "/api/label") => {
                let r: LabelRequest = parse(body)?;
                let edit = match (r.patch, r.vertices) {
                    (Some(p), None) => studio.label_patch(r.shape, p, r.label),
                    (None, Some(v)) => studio.brush(r.shape, &v, r.label),
                    _ => return Err(error(400, "give either `patch` or `vertices`")),
                }
                .map_err(studio_error)?;
                let mut out = labels_json(&studio, r.shape)?;
                out["changed"] = json!(edit.changed);
                json_reply(200, &out)
            }
            (Method::Post, "/api/undo") | (Method::Post, "/api/redo") => {
                let shape = if path == "/api/undo" {
                    studio.undo()
                } else {
                    studio.redo()
                };
                match shape {
                    Some(i) => json_reply(200, &labels_json(&studio, i)?),
                    None => json_reply(200, &json!({ "shape": null })),
                }
            }
            (Method::Post, "/api/parts") => {
                let r: PartRequest = parse(body)?;
                let label = match r {
                    PartRequest::Add { name } => studio.add_part(&name),
                    PartRequest::Rename { label, name } => {
                        studio.rename_part(label, &name).map(|_| label)
                    }
                    PartRequest::Recolor { label, color } => {
                        let c = parse_color(&color)?;
                        studio.recolor_part(label, c).map(|_| label)
                    }
                }
                .map_err(studio_error)?;
                json_reply(
                    200,
                    &json!({ "label": label, "parts": studio.palette().parts() }),
                )
            }
            (Method::Post, "/api/save") => {
                let files = studio.save().map_err(studio_error)?;
                json_reply(
                    200,
                    &json!({"files": files.len(), "dir": studio.labels_dir().display().to_string()}),
                )
            }
            (Method::Post, "/api/export") => {
                let r: ExportRequest = parse(body)?;
                let files = studio.export(&r.dir).map_err(studio_error)?;
                let dir = studio.folder().join(&r.dir);
                json_reply(
                    200,
                    &json!({ "files": files.len(), "dir": dir.display().to_string() }),
                )
            }
            (m, p) => return Err(error(404, format!("no such request: {m} {p}"))),
        })
    })();
    result.unwrap_or_else(|r| r)
}

/// The requests that only read the session.
fn look(studio: &Studio, path: &str, url: &str) -> Result<Reply, Reply> {
    Ok(match path {
        "/api/state" => json_reply(200, &state(studio)),
        "/api/shape" => {
            let i = shape_param(url)?;
            let positions = studio.view_positions(i).map_err(studio_error)?;
            let mesh = studio.mesh(i).map_err(studio_error)?;
            json_reply(
                200,
                &json!({
                    "index": i,
                    "positions": positions.concat(),
                    "faces": mesh.faces().concat(),
                    "patches": studio.patches(i).map_err(studio_error)?,
                    "labels": studio.labels(i).map_err(studio_error)?,
                }),
            )
        }
        "/api/labels" => {
            let i = shape_param(url)?;
            json_reply(200, &labels_json(studio, i)?)
        }
        "/api/thumb" => {
            let i = shape_param(url)?;
            let size = query_param(url, "size")
                .map(|s| {
                    s.parse::<u32>()
                        .map_err(|_| error(400, "size: not a number"))
                })
                .transpose()?
                .unwrap_or(160);
            let png = studio.thumbnail(i, size).map_err(studio_error)?;
            reply(200, "image/png", png)
        }
        p => return Err(error(404, format!("no such request: GET {p}"))),
    })
}

fn parse_color(text: &str) -> Result<[u8; 3], Reply> {
    let hex = text.strip_prefix('#').unwrap_or("");
    if hex.len() != 6 || !hex.bytes().all(|b| b.is_ascii_hexdigit()) {
        return Err(error(400, format!("colour {text:?}: expected #rrggbb")));
    }
    let byte = |k: usize| u8::from_str_radix(&hex[k..k + 2], 16).expect("checked hex");
    Ok([byte(0), byte(2), byte(4)])
}

fn labels_json(studio: &Studio, i: usize) -> Result<Value, Reply> {
    let labels = studio.labels(i).map_err(studio_error)?;
    let info = &studio.shapes()[i];
    Ok(json!({ "shape": i, "labels": labels, "version": info.version, "source": info.source }))
}

fn state(studio: &Studio) -> Value {
    let (undo, redo) = studio.history();
    json!({
        "folder": studio.folder().display().to_string(),
        "labels_dir": studio.labels_dir().display().to_string(),
        "shapes": studio.shapes(),
        "order": studio.grid_order(),
        "parts": studio.palette().parts(),
        "undo": undo,
        "redo": redo,
        "pending": studio.pending(),
        "warnings": studio.warnings(),
    })
}

fn start_propagation(app: &Arc<App>) -> Reply {
    {
        let mut p = app.progress.lock().unwrap_or_else(|e| e.into_inner());
        if p.running {
            return error(409, "a propagation is already running");
        }
        *p = Progress {
            running: true,
            ..Progress::default()
        };
    }
    // The caller holds no lock; the worker owns the session until it is done.
    let app_ptr = app.clone();
    std::thread::spawn(move || {
        let result = {
            let mut studio = app_ptr.studio.write().unwrap_or_else(|e| e.into_inner());
            studio.propagate(|step| {
                let mut p = app_ptr.progress.lock().unwrap_or_else(|e| e.into_inner());
                p.done = step.done;
                p.total = step.total;
            })
        };
        let mut p = app_ptr.progress.lock().unwrap_or_else(|e| e.into_inner());
        p.running = false;
        match result {
            Ok(r) => p.report = Some(r),
            Err(e) => p.error = Some(e.to_string()),
        }
    });
    json_reply(202, &json!({ "started": true }))
}
