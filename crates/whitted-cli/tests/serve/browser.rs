//! The page in a real browser: Debian's headless chromium driven by
//! chromedriver, spoken to in the W3C WebDriver protocol (JSON over HTTP,
//! a few requests, so no client crate). It waits for the full picture,
//! clicks a pixel and compares the tree shown with `explain --json`,
//! switches to the depth view, edits the scene file and sees the new
//! picture, drags the camera, and takes a screenshot. It prints the
//! page's timings (first frame, first full frame, frames per second while
//! dragging) and asserts none.
//!
//! Without chromium or chromedriver it prints SKIPPED and passes, unless
//! `WHITTED_REQUIRE_TOOLS` is set (as `.ci/run` sets it).

use std::io::{BufRead, BufReader, Read, Write};
use std::net::{TcpListener, TcpStream};
use std::path::PathBuf;
use std::process::{Child, Command, Stdio};
use std::time::{Duration, Instant};

use serde_json::{Value, json};

use crate::support::{PATIENCE, Server, scene_text, whitted};

/// An executable on the `PATH`.
fn on_path(name: &str) -> Option<PathBuf> {
    std::env::split_paths(&std::env::var_os("PATH")?)
        .map(|dir| dir.join(name))
        .find(|path| path.is_file())
}

/// The WebDriver's key of an element reference.
const ELEMENT: &str = "element-6066-11e4-a52e-4f735466cecf";

/// chromedriver with one browser session, both ended when dropped.
struct Browser {
    driver: Child,
    port: u16,
    session: String,
}

impl Browser {
    fn start(driver: &PathBuf, chromium: &PathBuf) -> Browser {
        let port = TcpListener::bind("127.0.0.1:0")
            .unwrap()
            .local_addr()
            .unwrap()
            .port();
        let driver = Command::new(driver)
            .arg(format!("--port={port}"))
            .stdout(Stdio::null())
            .stderr(Stdio::null())
            .spawn()
            .unwrap();
        let mut browser = Browser {
            driver,
            port,
            session: String::new(),
        };
        let start = Instant::now();
        while TcpStream::connect(("127.0.0.1", port)).is_err() {
            assert!(start.elapsed() < PATIENCE, "chromedriver did not start");
            std::thread::sleep(Duration::from_millis(50));
        }
        let created = browser.call(
            "POST",
            "/session",
            &json!({ "capabilities": { "alwaysMatch": {
                "browserName": "chrome",
                "goog:chromeOptions": {
                    "binary": chromium,
                    "args": ["--headless=new", "--no-sandbox", "--disable-gpu",
                             "--disable-dev-shm-usage", "--window-size=1200,900"],
                },
            }}}),
        );
        browser.session = created["sessionId"]
            .as_str()
            .unwrap_or_else(|| panic!("no session: {created}"))
            .to_string();
        browser
    }

    /// One WebDriver command; its `value`.
    fn call(&self, method: &str, path: &str, body: &Value) -> Value {
        let body = body.to_string();
        let mut stream = TcpStream::connect(("127.0.0.1", self.port)).unwrap();
        stream.set_read_timeout(Some(PATIENCE)).unwrap();
        write!(
            stream,
            "{method} {path} HTTP/1.1\r\nHost: 127.0.0.1:{}\r\nContent-Type: application/json\r\n\
             Content-Length: {}\r\nConnection: close\r\n\r\n{body}",
            self.port,
            body.len()
        )
        .unwrap();
        // chromedriver keeps the connection open: read what its head says.
        let mut reader = BufReader::new(stream);
        let mut length = None;
        let mut line = String::new();
        while reader.read_line(&mut line).unwrap() > 0 && line != "\r\n" {
            let lower = line.to_ascii_lowercase();
            if let Some(n) = lower.strip_prefix("content-length:") {
                length = Some(n.trim().parse::<usize>().unwrap());
            }
            line.clear();
        }
        let mut body = vec![0; length.expect("chromedriver's answer has a Content-Length")];
        reader.read_exact(&mut body).unwrap();
        let value: Value = serde_json::from_slice(&body)
            .unwrap_or_else(|e| panic!("{e}: {}", String::from_utf8_lossy(&body)));
        assert!(
            value["value"].get("error").is_none(),
            "{method} {path}: {value}"
        );
        value["value"].clone()
    }

    fn command(&self, method: &str, what: &str, body: &Value) -> Value {
        self.call(method, &format!("/session/{}{what}", self.session), body)
    }

    /// Runs `script` (a function body) in the page; what it returns.
    fn run(&self, script: &str) -> Value {
        self.command(
            "POST",
            "/execute/sync",
            &json!({ "script": script, "args": [] }),
        )
    }

    /// Runs `script` until it returns something true (within PATIENCE).
    fn wait_for(&self, what: &str, script: &str) -> Value {
        let start = Instant::now();
        loop {
            let value = self.run(script);
            if !value.is_null() && value != json!(false) {
                return value;
            }
            assert!(start.elapsed() < PATIENCE, "waited too long for {what}");
            std::thread::sleep(Duration::from_millis(20));
        }
    }

    fn element(&self, css: &str) -> Value {
        let found = self.command(
            "POST",
            "/element",
            &json!({ "using": "css selector", "value": css }),
        );
        found[ELEMENT].clone()
    }

    /// Mouse actions over `element` (offsets from its centre).
    fn mouse(&self, element: &Value, steps: Vec<Value>) {
        let mut actions = vec![json!({
            "type": "pointerMove", "origin": { (ELEMENT): element }, "x": 0, "y": 0
        })];
        for step in steps {
            let mut step = step;
            if step["type"] == "pointerMove" {
                step["origin"] = json!({ (ELEMENT): element });
            }
            actions.push(step);
        }
        self.command(
            "POST",
            "/actions",
            &json!({ "actions": [{
                "type": "pointer", "id": "mouse",
                "parameters": { "pointerType": "mouse" }, "actions": actions,
            }]}),
        );
    }
}

impl Drop for Browser {
    fn drop(&mut self) {
        if !self.session.is_empty() {
            let _ = std::panic::catch_unwind(|| self.command("DELETE", "", &json!({})));
        }
        let _ = self.driver.kill();
        let _ = self.driver.wait();
    }
}

/// A script's expression: the newest frame's request once it is a full
/// frame and shown, else false.
const FULL_FRAME: &str = "(window.whitted && window.whitted.frame \
    && window.whitted.frame.pass === 'full' \
    && document.getElementById('picture').dataset.pass === 'full' \
    && document.getElementById('picture').dataset.request == window.whitted.frame.request \
    && window.whitted.frame.request)";

#[test]
fn the_page_in_headless_chromium_shows_the_picture_trees_views_and_edits() {
    let (driver, chromium) = (on_path("chromedriver"), on_path("chromium"));
    let (Some(driver), Some(chromium)) = (driver, chromium) else {
        let why = "SKIPPED: the browser test of whitted serve needs chromium and chromedriver \
                   on the PATH (apt-get install chromium chromium-driver)";
        assert!(
            std::env::var_os("WHITTED_REQUIRE_TOOLS").is_none(),
            "{why} (WHITTED_REQUIRE_TOOLS is set, as .ci/run sets it: the tools must be there)"
        );
        eprintln!("{why}");
        return;
    };
    let server = Server::start(&scene_text(), &["--width", "320", "--height", "240"]);
    let browser = Browser::start(&driver, &chromium);
    browser.command("POST", "/url", &json!({ "url": server.url("/") }));
    browser.wait_for("the full picture", &format!("return {FULL_FRAME};"));
    let timings = browser.run("return window.whitted.timings;");
    eprintln!(
        "page timings (ms from navigation start): first frame {}, first full frame {}",
        timings["firstFrame"], timings["firstFull"]
    );

    // Click a pixel: the tree shown is explain --json's.
    let picture = browser.element("#picture");
    browser.mouse(
        &picture,
        vec![
            json!({ "type": "pointerMove", "x": -60, "y": 30 }),
            json!({ "type": "pointerDown", "button": 0 }),
            json!({ "type": "pointerUp", "button": 0 }),
        ],
    );
    let tree = browser.wait_for(
        "the ray tree",
        "const p = window.whitted; \
         return p.lastTree && !document.getElementById('rays').hidden \
             && document.getElementById('tree').textContent.includes('camera ray') \
             && [p.lastTree, p.explained];",
    );
    let (shown, pixel) = (&tree[0], &tree[1]);
    assert_eq!((&pixel["x"], &pixel["y"]), (&json!(100), &json!(150)));
    let pixel = "100,150";
    let printed: Value = serde_json::from_slice(&whitted(
        &[
            "explain",
            "scene.toml",
            "--pixel",
            pixel,
            "--json",
            "--width",
            "320",
            "--height",
            "240",
        ],
        server.dir.path(),
    ))
    .unwrap();
    assert_eq!(
        as_floats(shown),
        as_floats(&printed),
        "the tree shown is explain --json's"
    );

    // The depth view.
    browser.command(
        "POST",
        &format!(
            "/element/{}/click",
            browser
                .element("#aov option[value=depth]")
                .as_str()
                .unwrap()
        ),
        &json!({}),
    );
    let depth = browser.wait_for(
        "the depth view",
        &format!("return window.whitted.frame.aov === 'depth' && {FULL_FRAME};"),
    );

    // An edit of the scene file is seen (a narrower view: the depth changes).
    let before = browser.run("return document.getElementById('picture').src;");
    std::fs::write(server.scene(), scene_text().replace("fov = 45", "fov = 35")).unwrap();
    browser.wait_for(
        "the edited scene",
        &format!("return {FULL_FRAME} && window.whitted.frame.request > {depth};"),
    );
    let after = browser.run("return document.getElementById('picture').src;");
    assert_ne!(before, after, "the picture changed");

    // Drag the camera for a while, counting the frames shown.
    let before = browser
        .run("return [window.whitted.frames, performance.now(), window.whitted.state.flags];");
    let mut steps = vec![json!({ "type": "pointerDown", "button": 0 })];
    for i in 1..=40 {
        steps.push(json!({ "type": "pointerMove", "x": 2 * i, "y": i / 2, "duration": 50 }));
    }
    steps.push(json!({ "type": "pointerUp", "button": 0 }));
    browser.mouse(&picture, steps);
    let after = browser.run("return [window.whitted.frames, performance.now()];");
    let frames = after[0].as_f64().unwrap() - before[0].as_f64().unwrap();
    let seconds = (after[1].as_f64().unwrap() - before[1].as_f64().unwrap()) / 1e3;
    eprintln!(
        "dragging at 320x240: {frames} frames in {seconds:.2} s, {:.1} frames per second",
        frames / seconds
    );
    let moved = browser.wait_for(
        "the moved camera's flags",
        &format!(
            "const f = window.whitted.state.flags; return f !== {} && f;",
            before[2]
        ),
    );
    assert!(moved.as_str().unwrap().starts_with("--eye "), "{moved}");
    browser.wait_for(
        "the picture after the drag",
        &format!("return {FULL_FRAME};"),
    );

    let screenshot = browser.command("GET", "/screenshot", &json!({}));
    let png = decode_base64(screenshot.as_str().unwrap());
    assert!(png.starts_with(b"\x89PNG"));
    let path = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join("serve-browser.png");
    std::fs::write(&path, &png).unwrap();
    eprintln!("screenshot: {}", path.display());
}

/// `value` with every number a float (JavaScript writes 1.0 as 1).
fn as_floats(value: &Value) -> Value {
    match value {
        Value::Number(n) => json!(n.as_f64()),
        Value::Array(items) => Value::Array(items.iter().map(as_floats).collect()),
        Value::Object(map) => {
            Value::Object(map.iter().map(|(k, v)| (k.clone(), as_floats(v))).collect())
        }
        other => other.clone(),
    }
}

/// Standard base64 to bytes.
fn decode_base64(text: &str) -> Vec<u8> {
    let value = |c: u8| match c {
        b'A'..=b'Z' => c - b'A',
        b'a'..=b'z' => c - b'a' + 26,
        b'0'..=b'9' => c - b'0' + 52,
        b'+' => 62,
        _ => 63,
    };
    let digits: Vec<u8> = text.bytes().filter(|&c| c != b'=').map(value).collect();
    digits
        .chunks(4)
        .flat_map(|c| {
            let n = c
                .iter()
                .enumerate()
                .fold(0u32, |n, (i, &d)| n | u32::from(d) << (18 - 6 * i));
            let bytes = [(n >> 16) as u8, (n >> 8) as u8, n as u8];
            bytes.into_iter().take(c.len() - 1)
        })
        .collect()
}
