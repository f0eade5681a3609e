//! The little HTTP/1.1 that `whitted serve` speaks: one request per
//! connection (`Connection: close`), its head and body bounded, answered
//! whole or as a stream of server-sent events. Anything it cannot read is
//! a 4xx, never a panic.

use std::io::{self, BufRead, Read, Write};
use std::time::Duration;

/// The most bytes of a request's line and headers.
const MAX_HEAD: usize = 16 << 10;

/// The most bytes of a request's body (the page only posts short forms).
const MAX_BODY: usize = 64 << 10;

/// A request as read.
#[derive(Debug, PartialEq)]
pub struct Request {
    /// `GET`, `POST`, ...
    pub method: String,
    /// The path, without its query.
    pub path: String,
    /// The query's pairs, decoded.
    pub query: Vec<(String, String)>,
    /// Header names (lower case) and values.
    pub headers: Vec<(String, String)>,
    /// The body.
    pub body: Vec<u8>,
}

impl Request {
    /// The value of header `name` (lower case).
    pub fn header(&self, name: &str) -> Option<&str> {
        self.headers
            .iter()
            .find(|(n, _)| n == name)
            .map(|(_, v)| v.as_str())
    }

    /// The value of the query's pair `name`.
    pub fn query(&self, name: &str) -> Option<&str> {
        self.query
            .iter()
            .find(|(n, _)| n == name)
            .map(|(_, v)| v.as_str())
    }
}

/// A request that cannot be answered, with the status that says why.
#[derive(Debug, PartialEq)]
pub struct Refusal {
    /// The HTTP status (4xx or 5xx).
    pub status: u16,
    /// What is wrong, in words.
    pub message: String,
}

impl Refusal {
    /// A refusal with `status`; `message` is shown as every report is
    /// ([`crate::report::bounded`]: what it quotes of a request at length
    /// is cut).
    pub fn new(status: u16, message: impl Into<String>) -> Self {
        let message = message.into();
        Self {
            status,
            message: crate::report::bounded(&message).into_owned(),
        }
    }
}

/// How long a client has to send a whole request, head and body: a client
/// sending a byte now and then cannot hold a request's place for longer.
/// The reader given to [`read_request`] keeps it.
pub const REQUEST_DEADLINE: Duration = Duration::from_secs(10);

/// The refusal of a request whose `what` could not be read: 408 when it
/// did not come before [`REQUEST_DEADLINE`], else 400.
fn unreadable(what: &str, e: &io::Error) -> Refusal {
    match e.kind() {
        io::ErrorKind::TimedOut | io::ErrorKind::WouldBlock => Refusal::new(
            408,
            format!(
                "{what} did not arrive in time: a request's head and body must come within {} s",
                REQUEST_DEADLINE.as_secs()
            ),
        ),
        _ => Refusal::new(400, format!("{what} could not be read: {e}")),
    }
}

/// Reads one request. `Ok(None)`: the peer closed before sending one.
pub fn read_request(input: &mut impl BufRead) -> Result<Option<Request>, Refusal> {
    let mut head = Read::take(&mut *input, MAX_HEAD as u64);
    let mut line = String::new();
    let mut read_line = |line: &mut String| -> Result<usize, Refusal> {
        line.clear();
        let n = head
            .read_line(line)
            .map_err(|e| unreadable("the request", &e))?;
        if n > 0 && !line.ends_with('\n') {
            return Err(Refusal::new(431, "the request's head is too long"));
        }
        Ok(n)
    };
    if read_line(&mut line)? == 0 {
        return Ok(None);
    }
    let mut parts = line.trim_end().split(' ');
    let (Some(method), Some(target), Some(version), None) =
        (parts.next(), parts.next(), parts.next(), parts.next())
    else {
        return Err(Refusal::new(
            400,
            "the request line is not `METHOD PATH HTTP/1.1`",
        ));
    };
    if !version.starts_with("HTTP/1.") || method.is_empty() || !target.starts_with('/') {
        return Err(Refusal::new(
            400,
            "the request line is not `METHOD PATH HTTP/1.1`",
        ));
    }
    let (method, target) = (method.to_string(), target.to_string());
    let mut headers = Vec::new();
    loop {
        if read_line(&mut line)? == 0 {
            return Err(Refusal::new(400, "the request's head ends early"));
        }
        let text = line.trim_end_matches(['\r', '\n']);
        if text.is_empty() {
            break;
        }
        let Some((name, value)) = text.split_once(':') else {
            return Err(Refusal::new(400, format!("`{text}` is not a header")));
        };
        let name = name.trim().to_ascii_lowercase();
        if name == "host" && headers.iter().any(|(n, _)| n == "host") {
            return Err(Refusal::new(
                400,
                "the request has more than one Host header",
            ));
        }
        headers.push((name, value.trim().to_string()));
    }
    let (path, query) = target.split_once('?').unwrap_or((&target, ""));
    let mut request = Request {
        method,
        path: decode(path)?,
        query: form_pairs(query)?,
        headers,
        body: Vec::new(),
    };
    let length = match request.header("content-length") {
        None => 0,
        Some(text) => text
            .parse::<usize>()
            .map_err(|_| Refusal::new(400, format!("Content-Length `{text}` is not a number")))?,
    };
    if length > MAX_BODY {
        return Err(Refusal::new(413, "the request's body is too long"));
    }
    if request.header("transfer-encoding").is_some() {
        return Err(Refusal::new(
            411,
            "a body must come with its Content-Length",
        ));
    }
    request.body = vec![0; length];
    input
        .read_exact(&mut request.body)
        .map_err(|e| unreadable("the request's body", &e))?;
    Ok(Some(request))
}

/// The pairs of a query or a form body (`a=1&b=x%2Cy`), decoded.
pub fn form_pairs(text: &str) -> Result<Vec<(String, String)>, Refusal> {
    text.split('&')
        .filter(|pair| !pair.is_empty())
        .map(|pair| {
            let (name, value) = pair.split_once('=').unwrap_or((pair, ""));
            Ok((decode(name)?, decode(value)?))
        })
        .collect()
}

/// Percent-decoding (`+` is a space), to UTF-8.
fn decode(text: &str) -> Result<String, Refusal> {
    let bad = || Refusal::new(400, format!("`{text}` is not properly percent-encoded"));
    let bytes = text.as_bytes();
    let mut out = Vec::with_capacity(bytes.len());
    let mut i = 0;
    while i < bytes.len() {
        match bytes[i] {
            b'%' => {
                let hex = bytes.get(i + 1..i + 3).ok_or_else(bad)?;
                let hex = std::str::from_utf8(hex).map_err(|_| bad())?;
                out.push(u8::from_str_radix(hex, 16).map_err(|_| bad())?);
                i += 3;
            }
            b'+' => {
                out.push(b' ');
                i += 1;
            }
            b => {
                out.push(b);
                i += 1;
            }
        }
    }
    String::from_utf8(out).map_err(|_| bad())
}

/// The reason phrase of a status.
fn reason(status: u16) -> &'static str {
    match status {
        200 => "OK",
        400 => "Bad Request",
        403 => "Forbidden",
        404 => "Not Found",
        405 => "Method Not Allowed",
        409 => "Conflict",
        411 => "Length Required",
        413 => "Content Too Large",
        431 => "Request Header Fields Too Large",
        500 => "Internal Server Error",
        503 => "Service Unavailable",
        _ => "",
    }
}

/// A whole response.
#[derive(Debug)]
pub struct Response {
    /// The status.
    pub status: u16,
    /// Its `Content-Type`.
    pub content_type: &'static str,
    /// More headers.
    pub headers: Vec<(&'static str, String)>,
    /// The body.
    pub body: Vec<u8>,
}

impl Response {
    /// 200 with `body` of `content_type`.
    pub fn ok(content_type: &'static str, body: impl Into<Vec<u8>>) -> Self {
        Self {
            status: 200,
            content_type,
            headers: Vec::new(),
            body: body.into(),
        }
    }

    /// 200 with a JSON body.
    pub fn json(value: &serde_json::Value) -> Self {
        Self::ok("application/json", value.to_string())
    }

    /// The refusal as a plain-text response.
    pub fn refused(refusal: &Refusal) -> Self {
        Self {
            status: refusal.status,
            content_type: "text/plain; charset=utf-8",
            headers: Vec::new(),
            body: format!("{}\n", refusal.message).into_bytes(),
        }
    }

    /// Writes the response.
    pub fn write(&self, out: &mut impl Write) -> io::Result<()> {
        self.write_head(out)?;
        out.write_all(&self.body)?;
        out.flush()
    }

    /// Writes the response's status and headers only, as the answer to a
    /// `HEAD` request (the length is the body's).
    pub fn write_head(&self, out: &mut impl Write) -> io::Result<()> {
        let mut head = format!(
            "HTTP/1.1 {} {}\r\nContent-Type: {}\r\nContent-Length: {}\r\nConnection: close\r\n\
             Cache-Control: no-store\r\nX-Content-Type-Options: nosniff\r\n",
            self.status,
            reason(self.status),
            self.content_type,
            self.body.len()
        );
        for (name, value) in &self.headers {
            head.push_str(&format!("{name}: {value}\r\n"));
        }
        head.push_str("\r\n");
        out.write_all(head.as_bytes())?;
        out.flush()
    }
}

/// Starts a stream of server-sent events.
pub fn start_events(out: &mut impl Write) -> io::Result<()> {
    out.write_all(
        b"HTTP/1.1 200 OK\r\nContent-Type: text/event-stream\r\nCache-Control: no-store\r\n\
          Connection: close\r\nX-Content-Type-Options: nosniff\r\n\r\n",
    )?;
    out.flush()
}

/// Sends one event `name` with `data` (one line: JSON has no raw line
/// breaks).
pub fn send_event(out: &mut impl Write, name: &str, data: &str) -> io::Result<()> {
    write!(out, "event: {name}\ndata: {data}\n\n")?;
    out.flush()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn read(text: &str) -> Result<Option<Request>, Refusal> {
        read_request(&mut text.as_bytes())
    }

    #[test]
    fn a_request_is_read_with_its_query_headers_and_body() {
        let request = read(
            "POST /api/view?x=1&name=a%20b+c HTTP/1.1\r\nHost: 127.0.0.1\r\n\
             Content-Length: 11\r\n\r\neye=1%2C2,3",
        )
        .unwrap()
        .unwrap();
        assert_eq!(request.method, "POST");
        assert_eq!(request.path, "/api/view");
        assert_eq!(request.query("x"), Some("1"));
        assert_eq!(request.query("name"), Some("a b c"));
        assert_eq!(request.header("host"), Some("127.0.0.1"));
        assert_eq!(
            form_pairs(std::str::from_utf8(&request.body).unwrap()).unwrap(),
            vec![("eye".to_string(), "1,2,3".to_string())]
        );
        assert_eq!(read(""), Ok(None));
    }

    #[test]
    fn bad_requests_are_refused_with_a_4xx() {
        let status = |text: &str| read(text).unwrap_err().status;
        assert_eq!(status("GARBAGE\r\n\r\n"), 400);
        assert_eq!(status("GET / HTTP/1.1\r\nno colon\r\n\r\n"), 400);
        assert_eq!(status("GET / HTTP/1.1\r\nHost: x\r\n"), 400);
        assert_eq!(status("GET /%zz HTTP/1.1\r\n\r\n"), 400);
        assert_eq!(status("GET /%ff HTTP/1.1\r\n\r\n"), 400);
        assert_eq!(status("GET relative HTTP/1.1\r\n\r\n"), 400);
        assert_eq!(
            status("POST / HTTP/1.1\r\nContent-Length: 999999999\r\n\r\n"),
            413
        );
        assert_eq!(
            status("POST / HTTP/1.1\r\nTransfer-Encoding: chunked\r\n\r\n"),
            411
        );
        let long = format!("GET /{} HTTP/1.1\r\n\r\n", "a".repeat(MAX_HEAD));
        assert_eq!(status(&long), 431);
        assert_eq!(
            status("POST / HTTP/1.1\r\nContent-Length: 5\r\n\r\nab"),
            400
        );
    }
}
