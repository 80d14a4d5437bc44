//! `coseg studio`'s door, against the binary: requests without the token or with a wrong one,
//! from another `Origin` or `Host`, or naming a path outside the folder are refused and change
//! nothing; bad requests get a JSON error; the server is not reachable on a non-loopback
//! address. The page itself is driven in a real browser by tests/e2e_studio.rs.

mod common;

use common::generate::goblets;
use common::studio::{Server, request, start};
use std::net::{SocketAddr, TcpStream, UdpSocket};
use std::path::Path;
use std::time::Duration;

fn state(s: &Server) -> serde_json::Value {
    let (code, body) = request(
        s.port,
        "GET",
        "/api/state",
        &[("X-Coseg-Token", &s.token)],
        "",
    );
    assert_eq!(code, 200, "{body}");
    serde_json::from_str(&body).unwrap()
}

/// Method, path, headers, body and the expected status.
type Case<'a> = (&'a str, &'a str, Vec<(&'a str, &'a str)>, &'a str, u16);

#[test]
fn studio_refuses_requests_without_the_token_from_elsewhere_or_outside_the_folder() {
    let dir = tempfile::tempdir().unwrap();
    let folder = goblets(dir.path(), 3);
    let s = start(&folder, &dir.path().join("cache"));
    let before = state(&s);
    let add = r#"{"op":"add","name":"bowl"}"#;
    let token = s.token.as_str();
    let wrong = "0".repeat(token.len());
    let origin_ok = format!("http://127.0.0.1:{}", s.port);
    let refused: Vec<Case> = vec![
        // No token, a wrong token, a token in a cookie of the wrong name.
        ("POST", "/api/parts", vec![], add, 401),
        (
            "POST",
            "/api/parts",
            vec![("X-Coseg-Token", &wrong)],
            add,
            401,
        ),
        ("GET", "/api/state", vec![("Cookie", "token=x")], "", 401),
        ("GET", "/", vec![], "", 401),
        // The right token from another page's origin, or through another host name (DNS
        // rebinding).
        (
            "POST",
            "/api/parts",
            vec![("X-Coseg-Token", token), ("Origin", "http://evil.example")],
            add,
            403,
        ),
        (
            "POST",
            "/api/parts",
            vec![("X-Coseg-Token", token), ("Origin", "null")],
            add,
            403,
        ),
        (
            "POST",
            "/api/parts",
            vec![("X-Coseg-Token", token), ("Host", "evil.example:80")],
            add,
            403,
        ),
        // Paths out of the folder.
        (
            "POST",
            "/api/export",
            vec![("X-Coseg-Token", token)],
            r#"{"dir":"../escape"}"#,
            403,
        ),
        (
            "POST",
            "/api/export",
            vec![("X-Coseg-Token", token)],
            r#"{"dir":"/tmp/escape"}"#,
            403,
        ),
        (
            "POST",
            "/api/export",
            vec![("X-Coseg-Token", token), ("Origin", &origin_ok)],
            r#"{"dir":"a/../../escape"}"#,
            403,
        ),
        // Bad requests.
        (
            "POST",
            "/api/label",
            vec![("X-Coseg-Token", token)],
            r#"{"shape":0,"patch":0,"label":5}"#,
            400,
        ),
        (
            "POST",
            "/api/label",
            vec![("X-Coseg-Token", token)],
            r#"{"shape":99,"patch":0,"label":-1}"#,
            400,
        ),
        (
            "POST",
            "/api/label",
            vec![("X-Coseg-Token", token)],
            r#"{"shape":0,"label":-1}"#,
            400,
        ),
        (
            "POST",
            "/api/label",
            vec![("X-Coseg-Token", token)],
            "{not json",
            400,
        ),
        (
            "POST",
            "/api/parts",
            vec![("X-Coseg-Token", token)],
            r#"{"op":"recolor","label":0,"color":"red"}"#,
            400,
        ),
        (
            "GET",
            "/api/shape?i=99",
            vec![("X-Coseg-Token", token)],
            "",
            400,
        ),
        (
            "GET",
            "/api/thumb?i=0&size=999999",
            vec![("X-Coseg-Token", token)],
            "",
            400,
        ),
        (
            "GET",
            "/../../etc/passwd",
            vec![("X-Coseg-Token", token)],
            "",
            404,
        ),
        (
            "POST",
            "/api/propagate",
            vec![("X-Coseg-Token", token)],
            "",
            202,
        ),
    ];
    for (method, path, headers, body, expected) in &refused {
        let (code, text) = request(s.port, method, path, headers, body);
        assert_eq!(code, *expected, "{method} {path} {headers:?}: {text}");
        if *expected != 202 {
            let v: serde_json::Value = serde_json::from_str(&text).unwrap();
            assert!(v["error"].as_str().is_some_and(|e| !e.is_empty()), "{text}");
        }
    }
    // The propagation had nothing to carry: it failed with a message and changed nothing.
    let progress = loop {
        let (_, p) = request(
            s.port,
            "GET",
            "/api/progress",
            &[("X-Coseg-Token", token)],
            "",
        );
        let p: serde_json::Value = serde_json::from_str(&p).unwrap();
        if !p["running"].as_bool().unwrap() {
            break p;
        }
        std::thread::sleep(Duration::from_millis(50));
    };
    assert!(
        progress["error"]
            .as_str()
            .unwrap()
            .contains("nothing to propagate")
    );
    assert_eq!(state(&s), before, "a refused request changed the session");
    assert!(!dir.path().join("escape").exists() && !Path::new("/tmp/escape").exists());
    // The page itself, with the token, sets the cookie later requests may use instead.
    let (code, page) = request(s.port, "GET", &format!("/?token={token}"), &[], "");
    assert_eq!(code, 200);
    assert!(page.contains("coseg studio"));
    // The WebGL helpers and program shared with the viewer page are filled in.
    assert!(
        !page.contains("__GL_"),
        "a placeholder of the page was left"
    );
    assert!(page.contains("function normals(pos, idx)") && page.contains("var loc = {"));
    let cookie = format!("coseg_token={token}");
    let (code, _) = request(s.port, "GET", "/api/state", &[("Cookie", &cookie)], "");
    assert_eq!(code, 200);
    // A good request through the same door works.
    let (code, body) = request(
        s.port,
        "POST",
        "/api/parts",
        &[("X-Coseg-Token", token), ("Origin", &origin_ok)],
        add,
    );
    assert_eq!(code, 200, "{body}");
}

#[test]
fn studio_is_not_reachable_on_a_non_loopback_address() {
    // This machine's address toward the outside (connecting a UDP socket sends nothing).
    let local = UdpSocket::bind("0.0.0.0:0")
        .and_then(|u| u.connect("192.0.2.1:9").map(|_| u))
        .and_then(|u| u.local_addr())
        .map(|a| a.ip());
    let ip = match local {
        Ok(ip) if !ip.is_loopback() && !ip.is_unspecified() => ip,
        _ => {
            eprintln!("skipped: this machine has no non-loopback address");
            return;
        }
    };
    let dir = tempfile::tempdir().unwrap();
    let folder = goblets(dir.path(), 3);
    let s = start(&folder, &dir.path().join("cache"));
    assert_eq!(
        request(s.port, "GET", "/api/state", &[], "").0,
        401,
        "the server runs"
    );
    let outside = SocketAddr::new(ip, s.port);
    assert!(
        TcpStream::connect_timeout(&outside, Duration::from_secs(2)).is_err(),
        "coseg studio answered on {outside}"
    );
}
