//! Starting `whitted serve` on a free port, and speaking HTTP and
//! server-sent events to it with the standard library.

use std::io::{BufRead, BufReader, Read, Write};
use std::net::TcpStream;
use std::path::{Path, PathBuf};
use std::process::{Child, Command, Stdio};
use std::time::{Duration, Instant};

use serde_json::Value;

/// The longest a test waits for a frame.
pub const PATIENCE: Duration = Duration::from_secs(60);

/// The scene the tests serve: the built-in scene's file.
pub fn scene_text() -> String {
    let path: PathBuf = [
        env!("CARGO_MANIFEST_DIR"),
        "..",
        "..",
        "scenes",
        "whitted.toml",
    ]
    .iter()
    .collect();
    std::fs::read_to_string(path).unwrap()
}

/// The `whitted` binary the tests run: the one `WHITTED_BIN` names (a
/// release build, to measure the page's speed), else the one cargo built.
pub fn binary() -> PathBuf {
    std::env::var_os("WHITTED_BIN").map_or_else(
        || PathBuf::from(env!("CARGO_BIN_EXE_whitted")),
        PathBuf::from,
    )
}

/// A running `whitted serve`, stopped when dropped.
pub struct Server {
    child: Child,
    /// Its port.
    pub port: u16,
    /// The folder of its scene file.
    pub dir: tempfile::TempDir,
}

impl Server {
    /// Writes `scene` to `scene.toml` in a new folder and serves it with
    /// `args` on a port the system picks.
    pub fn start(scene: &str, args: &[&str]) -> Server {
        let dir = tempfile::tempdir().unwrap();
        std::fs::write(dir.path().join("scene.toml"), scene).unwrap();
        let mut child = Command::new(binary())
            .arg("serve")
            .arg("scene.toml")
            .args(["--port", "0"])
            .args(args)
            .current_dir(dir.path())
            .stdout(Stdio::piped())
            .stderr(Stdio::inherit())
            .spawn()
            .unwrap();
        let mut line = String::new();
        BufReader::new(child.stdout.take().unwrap())
            .read_line(&mut line)
            .unwrap();
        let port = line
            .split("http://127.0.0.1:")
            .nth(1)
            .and_then(|rest| rest.split('/').next())
            .and_then(|port| port.parse().ok())
            .unwrap_or_else(|| panic!("no URL in `{line}`"));
        assert!(line.contains("only this machine can connect"), "{line}");
        eprintln!("whitted serve started: {}", line.trim());
        Server { child, port, dir }
    }

    /// The scene file.
    pub fn scene(&self) -> PathBuf {
        self.dir.path().join("scene.toml")
    }

    /// The server's address.
    pub fn url(&self, path: &str) -> String {
        format!("http://127.0.0.1:{}{path}", self.port)
    }

    /// Sends `head` (the request line and headers, without the blank
    /// line) and `body`; the status and body of the answer.
    pub fn raw(&self, head: &str, body: &[u8]) -> (u16, Vec<u8>) {
        let (status, _, body) = self.exchange(head, body);
        (status, body)
    }

    /// [`Self::raw`], with the answer's head (its status line and
    /// headers) as text.
    pub fn exchange(&self, head: &str, body: &[u8]) -> (u16, String, Vec<u8>) {
        let mut stream = TcpStream::connect(("127.0.0.1", self.port)).unwrap();
        stream.set_read_timeout(Some(PATIENCE)).unwrap();
        let mut request = format!("{head}\r\n");
        if !body.is_empty() {
            request.push_str(&format!("Content-Length: {}\r\n", body.len()));
        }
        request.push_str("\r\n");
        stream.write_all(request.as_bytes()).unwrap();
        stream.write_all(body).unwrap();
        let mut answer = Vec::new();
        stream.read_to_end(&mut answer).unwrap();
        let end = answer
            .windows(4)
            .position(|w| w == b"\r\n\r\n")
            .unwrap_or_else(|| panic!("no head in {:?}", String::from_utf8_lossy(&answer)));
        let head = String::from_utf8_lossy(&answer[..end]).into_owned();
        let status = head.split(' ').nth(1).unwrap().parse().unwrap();
        (status, head, answer[end + 4..].to_vec())
    }

    /// `GET path`.
    pub fn get(&self, path: &str) -> (u16, Vec<u8>) {
        self.raw(
            &format!("GET {path} HTTP/1.1\r\nHost: 127.0.0.1:{}", self.port),
            b"",
        )
    }

    /// `GET path`: the status, the head and the body.
    pub fn get_with_head(&self, path: &str) -> (u16, String, Vec<u8>) {
        self.exchange(
            &format!("GET {path} HTTP/1.1\r\nHost: 127.0.0.1:{}", self.port),
            b"",
        )
    }

    /// `GET path`, which must answer 200 with JSON.
    pub fn get_json(&self, path: &str) -> Value {
        let (status, body) = self.get(path);
        assert_eq!(status, 200, "{}", String::from_utf8_lossy(&body));
        serde_json::from_slice(&body).unwrap()
    }

    /// `POST /api/view` with `form`; the status and body.
    pub fn view(&self, form: &str) -> (u16, String) {
        let (status, body) = self.raw(
            &format!(
                "POST /api/view HTTP/1.1\r\nHost: 127.0.0.1:{}\r\n\
                 Content-Type: application/x-www-form-urlencoded",
                self.port
            ),
            form.as_bytes(),
        );
        (status, String::from_utf8_lossy(&body).into_owned())
    }

    /// Opens the event stream.
    pub fn events(&self) -> Events {
        let mut stream = TcpStream::connect(("127.0.0.1", self.port)).unwrap();
        stream.set_read_timeout(Some(PATIENCE)).unwrap();
        write!(
            stream,
            "GET /events HTTP/1.1\r\nHost: 127.0.0.1:{}\r\n\r\n",
            self.port
        )
        .unwrap();
        let mut reader = BufReader::new(stream);
        let mut line = String::new();
        reader.read_line(&mut line).unwrap();
        assert!(line.starts_with("HTTP/1.1 200"), "{line}");
        loop {
            line.clear();
            reader.read_line(&mut line).unwrap();
            if line == "\r\n" {
                break;
            }
        }
        Events { reader }
    }

    /// Whether the process is still running.
    pub fn alive(&mut self) -> bool {
        self.child.try_wait().unwrap().is_none()
    }
}

impl Drop for Server {
    fn drop(&mut self) {
        let _ = self.child.kill();
        let _ = self.child.wait();
    }
}

/// A stream of server-sent events.
pub struct Events {
    reader: BufReader<TcpStream>,
}

impl Events {
    /// The next event: its name and data.
    pub fn next(&mut self) -> (String, Value) {
        let (mut name, mut data) = (String::new(), String::new());
        loop {
            let mut line = String::new();
            let n = self.reader.read_line(&mut line).unwrap();
            assert!(n > 0, "the event stream ended");
            let line = line.trim_end_matches('\n');
            if let Some(rest) = line.strip_prefix("event: ") {
                name = rest.to_string();
            } else if let Some(rest) = line.strip_prefix("data: ") {
                data.push_str(rest);
            } else if line.is_empty() && !name.is_empty() {
                return (name, serde_json::from_str(&data).unwrap());
            }
        }
    }

    /// Events until one `accept`s (within [`PATIENCE`]); all of them, the
    /// accepted last.
    pub fn until(&mut self, accept: impl Fn(&str, &Value) -> bool) -> Vec<(String, Value)> {
        let start = Instant::now();
        let mut seen = Vec::new();
        loop {
            assert!(start.elapsed() < PATIENCE, "no such event in {seen:?}");
            let (name, data) = self.next();
            let done = accept(&name, &data);
            seen.push((name, data));
            if done {
                return seen;
            }
        }
    }

    /// Events until a full frame; that frame.
    pub fn full_frame(&mut self) -> Value {
        let events = self.until(|name, data| name == "frame" && data["pass"] == "full");
        events.last().unwrap().1.clone()
    }
}

/// Runs `whitted ARGS` in `dir`; its standard output (it must succeed).
pub fn whitted(args: &[&str], dir: &Path) -> Vec<u8> {
    let output = Command::new(binary())
        .args(args)
        .current_dir(dir)
        .output()
        .unwrap();
    assert!(
        output.status.success(),
        "{}",
        String::from_utf8_lossy(&output.stderr)
    );
    output.stdout
}
