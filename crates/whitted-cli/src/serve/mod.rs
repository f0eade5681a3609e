//! `whitted serve`: a live preview in the browser. A small HTTP server on
//! the standard library's sockets, one thread per connection; the page
//! (embedded in the binary) gets its frames as server-sent events and
//! asks for views, ray trees and saves with plain requests. See
//! docs/serve.md; ARCHITECTURE.md says why this stack.

mod explaining;
mod http;
mod picture;
mod routes;
mod session;

use std::io::{self, BufReader, Read, Write};
use std::net::{IpAddr, Ipv4Addr, SocketAddr, TcpListener, TcpStream};
use std::sync::atomic::{AtomicUsize, Ordering};
use std::time::{Duration, Instant};

use clap::Args;

use crate::report::{note, results};
use crate::scene_arguments::SceneArgs;
use http::{REQUEST_DEADLINE, Refusal, Request, Response, read_request};
use session::Session;

/// The most requests read or answered at once (event streams aside).
const MAX_REQUESTS: usize = 256;

/// The most event streams (open pages) at once, besides the requests.
const MAX_EVENT_STREAMS: usize = 16;

/// How long a connection may wait to write.
const IO_TIMEOUT: Duration = Duration::from_secs(20);

/// How often an idle event stream sends a comment, to find closed pages.
const KEEP_ALIVE: Duration = Duration::from_secs(10);

/// How long a refused request's rest is waited for ([`linger`]).
const LINGER: Duration = Duration::from_secs(1);

/// The most bytes of a refused request's rest read and dropped.
const MAX_LINGER_BYTES: usize = 1 << 20;

/// Show a scene live in the browser: a progressive render that follows
/// the scene file, a camera moved with the mouse, the AOVs and
/// structures, each pixel's ray tree, and saves.
#[derive(Debug, Args)]
#[command(after_long_help = "Examples:
  whitted serve scenes/whitted.toml
  whitted serve ../shared/scenes/spd/balls3.nff --port 8080 --width 320 --height 240")]
pub struct ServeArgs {
    #[command(flatten)]
    scene: SceneArgs,

    /// The port to listen on (0: any free port, printed at the start).
    #[arg(long, value_name = "P", default_value_t = 7878)]
    port: u16,

    /// The address to listen on: 127.0.0.1 (the default) lets only this
    /// machine connect; 0.0.0.0 lets any.
    #[arg(long, value_name = "ADDR", default_value_t = IpAddr::V4(Ipv4Addr::LOCALHOST))]
    bind: IpAddr,
}

/// Runs the command: serves until stopped.
pub fn run(args: ServeArgs) -> Result<(), String> {
    args.scene.check()?;
    let listener = TcpListener::bind((args.bind, args.port))
        .map_err(|e| format!("cannot listen on {}:{}: {e}", args.bind, args.port))?;
    let address = listener.local_addr().map_err(|e| e.to_string())?;
    let who = if address.ip().is_loopback() {
        "only this machine can connect"
    } else {
        "other machines can connect"
    };
    results(&format!(
        "whitted serve: http://{address}/ ({who}; Ctrl-C stops)\n"
    ))?;
    let session = Session::new(args.scene);
    let slots = Slots::default();
    // Stamped before the render loop first reads the file, so that an edit
    // made right after that read is seen.
    let watched = session
        .file()
        .map(|path| (path.to_path_buf(), session::file_stamp(path)));
    std::thread::scope(|scope| {
        scope.spawn(|| session.render_loop());
        scope.spawn(|| session.explaining.run());
        if let Some((path, stamp)) = watched {
            let session = &session;
            scope.spawn(move || session.watch_file(path, stamp));
        }
        for stream in listener.incoming() {
            let Ok(stream) = stream else { continue };
            let (session, slots) = (&session, &slots);
            let Some(request_slot) = Slot::take(&slots.requests, MAX_REQUESTS) else {
                let refusal = Refusal::new(503, "too many requests at once; try again");
                let _ = Response::refused(&refusal).write(&mut &stream);
                continue;
            };
            scope.spawn(move || serve_connection(session, slots, request_slot, stream, address));
        }
    });
    Ok(())
}

/// The places of the connections served at once: requests being read or
/// answered, and event streams, each bounded on its own, so that open
/// pages cannot keep requests out nor requests pages.
#[derive(Default)]
struct Slots {
    requests: AtomicUsize,
    streams: AtomicUsize,
}

/// One place of a [`Slots`] count, given back when dropped.
struct Slot<'a>(&'a AtomicUsize);

impl<'a> Slot<'a> {
    /// A place in `count` if fewer than `most` are taken.
    fn take(count: &'a AtomicUsize, most: usize) -> Option<Self> {
        count
            .fetch_update(Ordering::SeqCst, Ordering::SeqCst, |n| {
                (n < most).then_some(n + 1)
            })
            .ok()
            .map(|_| Self(count))
    }
}

impl Drop for Slot<'_> {
    fn drop(&mut self) {
        self.0.fetch_sub(1, Ordering::SeqCst);
    }
}

/// A connection read until a deadline: each read waits at most until it,
/// and a read after it fails with [`io::ErrorKind::TimedOut`].
struct ReadBefore<'a> {
    stream: &'a TcpStream,
    deadline: Instant,
}

impl Read for ReadBefore<'_> {
    fn read(&mut self, buf: &mut [u8]) -> io::Result<usize> {
        let left = self.deadline.saturating_duration_since(Instant::now());
        if left.is_zero() {
            return Err(io::Error::new(
                io::ErrorKind::TimedOut,
                "the deadline has passed",
            ));
        }
        self.stream.set_read_timeout(Some(left))?;
        self.stream.read(buf)
    }
}

/// Reads one request from `stream` (within [`REQUEST_DEADLINE`]) and
/// answers it, holding `request_slot` meanwhile; an event stream trades
/// it for a place among the streams.
fn serve_connection(
    session: &Session,
    slots: &Slots,
    request_slot: Slot<'_>,
    stream: TcpStream,
    address: SocketAddr,
) {
    let _ = stream.set_write_timeout(Some(IO_TIMEOUT));
    let mut reader = BufReader::new(ReadBefore {
        stream: &stream,
        deadline: Instant::now() + REQUEST_DEADLINE,
    });
    let request = match read_request(&mut reader) {
        Ok(Some(request)) => request,
        Ok(None) => return,
        Err(refusal) => {
            let _ = Response::refused(&refusal).write(&mut &stream);
            linger(&stream, &mut reader);
            return;
        }
    };
    let peer = stream.peer_addr().ok();
    if let Err(refusal) = check_origin(&request, address, peer) {
        let _ = Response::refused(&refusal).write(&mut &stream);
        return;
    }
    if request.path == "/events" && request.method == "GET" {
        let Some(_stream_slot) = Slot::take(&slots.streams, MAX_EVENT_STREAMS) else {
            let refusal = Refusal::new(
                503,
                format!(
                    "too many pages are open ({MAX_EVENT_STREAMS}, the most this server \
                     follows at once): close one"
                ),
            );
            let _ = Response::refused(&refusal).write(&mut &stream);
            return;
        };
        drop(request_slot);
        let _ = stream.set_read_timeout(None);
        stream_events(session, &stream);
        return;
    }
    let response = routes::answer(session, &request).unwrap_or_else(|r| Response::refused(&r));
    if response.status >= 500 {
        note!("{} {}: {}", request.method, request.path, response.status);
    }
    let _ = if request.method == "HEAD" {
        response.write_head(&mut &stream)
    } else {
        response.write(&mut &stream)
    };
}

/// Closes a connection answered before its request was read whole (a head
/// too long, a body refused): the answer is sent, then what the client
/// still sends is read and dropped, within bounds, so that closing with
/// unread data does not reset the connection before the client reads the
/// answer.
fn linger(stream: &TcpStream, unread: &mut BufReader<ReadBefore<'_>>) {
    let _ = stream.shutdown(std::net::Shutdown::Write);
    unread.get_mut().deadline = Instant::now() + LINGER;
    let mut sink = [0u8; 4096];
    let mut left = MAX_LINGER_BYTES;
    while left > 0 {
        match unread.read(&mut sink) {
            Ok(0) | Err(_) => break,
            Ok(n) => left = left.saturating_sub(n),
        }
    }
}

/// Refuses, on a server bound to the loopback address, requests from
/// another machine, requests that name another host (a page of another
/// site reaching this server through a name it controls), and posts from
/// another site's page.
fn check_origin(
    request: &Request,
    address: SocketAddr,
    peer: Option<SocketAddr>,
) -> Result<(), Refusal> {
    if !address.ip().is_loopback() {
        return Ok(());
    }
    if peer.is_some_and(|p| !p.ip().is_loopback()) {
        return Err(Refusal::new(
            403,
            "requests from other machines are refused",
        ));
    }
    let port = address.port();
    // The names of the loopback interface, and the address the server is
    // bound to (another loopback address, such as 127.0.0.2).
    let hosts = [
        format!("127.0.0.1:{port}"),
        format!("localhost:{port}"),
        format!("[::1]:{port}"),
        address.to_string(),
    ];
    let host = request.header("host").unwrap_or("");
    if !hosts.iter().any(|h| h == host) {
        return Err(Refusal::new(
            403,
            format!("requests for host `{host}` are refused: this server is {address}"),
        ));
    }
    if let Some(origin) = request.header("origin")
        && request.method != "GET"
        && origin != format!("http://{host}")
    {
        return Err(Refusal::new(
            403,
            format!("posts from `{origin}` are refused"),
        ));
    }
    Ok(())
}

/// Sends the session's newest frame or error, then each newer one (those
/// still kept), until the page goes away.
fn stream_events(session: &Session, stream: &TcpStream) {
    let mut out = stream;
    if http::start_events(&mut out).is_err() {
        return;
    }
    let mut seen = 0;
    loop {
        let (now, events) = session.next_events(seen, KEEP_ALIVE);
        let sent = if events.is_empty() {
            out.write_all(b": still here\n\n")
                .and_then(|()| out.flush())
        } else {
            events
                .iter()
                .try_for_each(|e| http::send_event(&mut out, e.name, &e.data))
        };
        if sent.is_err() {
            return;
        }
        seen = now;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn with_headers(method: &str, headers: &[(&str, &str)]) -> Request {
        Request {
            method: method.to_string(),
            path: "/".to_string(),
            query: Vec::new(),
            headers: headers
                .iter()
                .map(|(n, v)| (n.to_string(), v.to_string()))
                .collect(),
            body: Vec::new(),
        }
    }

    #[test]
    fn other_hosts_and_sites_are_refused() {
        let address: SocketAddr = "127.0.0.1:7878".parse().unwrap();
        let local: SocketAddr = "127.0.0.1:50000".parse().unwrap();
        let check = |r: &Request, peer| check_origin(r, address, Some(peer)).map_err(|e| e.status);
        let ok = with_headers("GET", &[("host", "127.0.0.1:7878")]);
        assert_eq!(check(&ok, local), Ok(()));
        let named = with_headers("GET", &[("host", "localhost:7878")]);
        assert_eq!(check(&named, local), Ok(()));
        let far: SocketAddr = "10.0.0.2:50000".parse().unwrap();
        assert_eq!(check(&ok, far), Err(403));
        let rebound = with_headers("GET", &[("host", "evil.example:7878")]);
        assert_eq!(check(&rebound, local), Err(403));
        assert_eq!(check(&with_headers("GET", &[]), local), Err(403));
        let posted = with_headers(
            "POST",
            &[
                ("host", "127.0.0.1:7878"),
                ("origin", "http://evil.example"),
            ],
        );
        assert_eq!(check(&posted, local), Err(403));
        let own = with_headers(
            "POST",
            &[
                ("host", "127.0.0.1:7878"),
                ("origin", "http://127.0.0.1:7878"),
            ],
        );
        assert_eq!(check(&own, local), Ok(()));
        // A server bound to another loopback address answers that name.
        let other: SocketAddr = "127.0.0.2:7878".parse().unwrap();
        let named = with_headers("GET", &[("host", "127.0.0.2:7878")]);
        assert_eq!(
            check_origin(&named, other, Some(local)).map_err(|e| e.status),
            Ok(())
        );
        assert_eq!(check(&named, local), Err(403));
        let open: SocketAddr = "0.0.0.0:7878".parse().unwrap();
        assert_eq!(
            check_origin(&rebound, open, Some(far)).map_err(|e| e.status),
            Ok(())
        );
    }
}
