//! `whitted serve` over HTTP: the page, the progressive frames, the ray
//! tree of a pixel against the picture and `explain --json`, edits of the
//! scene file (a bad one shown, the server alive), the camera and its
//! flags, the views, and bad requests.

use crate::pfm::read_pfm;
use std::time::{Duration, Instant};

use crate::support::{Server, scene_text, whitted};

const SIZE: [&str; 4] = ["--width", "64", "--height", "48"];

#[test]
fn the_page_is_served_and_frames_come_coarse_first_then_full() {
    let server = Server::start(&scene_text(), &SIZE);
    let (status, page) = server.get("/");
    assert_eq!(status, 200);
    let page = String::from_utf8(page).unwrap();
    assert!(page.contains("<script src=\"/page.js\">"), "{page}");
    assert_eq!(server.get("/page.js").0, 200);
    assert_eq!(server.get("/page.css").0, 200);
    let mut events = server.events();
    let first = events.full_frame();
    assert_eq!(
        (&first["width"], &first["height"]),
        (&64.into(), &48.into())
    );
    assert!(
        first["png"]
            .as_str()
            .unwrap()
            .starts_with("data:image/png;base64,iVBOR")
    );
    assert!(first["rays_per_second"].as_f64().unwrap() > 0.0);
    assert!(first["build_seconds"].as_f64().unwrap() >= 0.0);
    // A new request: every pass of it is seen, the coarse one first.
    let (status, _) = server.view("accel=kdtree");
    assert_eq!(status, 200);
    let passes: Vec<_> = events
        .until(|_, data| data["pass"] == "full" && data["accel"] == "kdtree")
        .into_iter()
        .filter(|(_, data)| data["accel"] == "kdtree")
        .map(|(_, data)| (data["pass"].clone(), data["width"].clone()))
        .collect();
    assert_eq!(
        passes,
        [
            ("coarse".into(), 8.into()),
            ("refining".into(), 32.into()),
            ("full".into(), 64.into())
        ]
    );
}

#[test]
fn a_camera_move_renders_through_the_kept_world_and_a_new_structure_builds_one() {
    let server = Server::start(&scene_text(), &SIZE);
    let mut events = server.events();
    let first = events.full_frame()["request"].as_u64().unwrap();
    // Every frame of requests after `after`, up to the full one of the
    // newest: (request, pass, build_seconds).
    let frames_after = |events: &mut crate::support::Events, after: u64| {
        events
            .until(|_, data| data["pass"] == "full" && data["request"].as_u64() > Some(after))
            .into_iter()
            .filter(|(_, data)| data["request"].as_u64() > Some(after))
            .map(|(name, data)| {
                assert_eq!(name, "frame", "{data}");
                (
                    data["request"].as_u64().unwrap(),
                    data["pass"].as_str().unwrap().to_string(),
                    data["build_seconds"].as_f64().unwrap(),
                )
            })
            .collect::<Vec<_>>()
    };
    assert_eq!(server.view("eye=1.5,2,-4.5&fov=50").0, 200);
    let moved = frames_after(&mut events, first);
    assert!(!moved.is_empty());
    for (_, pass, build) in &moved {
        assert_eq!(
            *build, 0.0,
            "the {pass} pass after a camera move built the world"
        );
    }
    let last = moved.last().unwrap().0;
    assert_eq!(server.view("accel=kdtree").0, 200);
    let rebuilt = frames_after(&mut events, last);
    let (_, pass, build) = &rebuilt[0];
    assert!(
        *build > 0.0,
        "the {pass} pass of a new structure reused the old world"
    );
    assert!(
        rebuilt[1..].iter().all(|(_, _, build)| *build == 0.0),
        "{rebuilt:?}"
    );
}

#[test]
fn a_pixels_ray_tree_is_explain_json_and_its_root_is_the_rendered_pixel() {
    let server = Server::start(&scene_text(), &SIZE);
    server.events().full_frame();
    let (status, pfm) = server.get("/api/save.pfm");
    assert_eq!(status, 200);
    let (width, pixels) = read_pfm(&pfm);
    assert_eq!((width, pixels.len()), (64, 64 * 48));
    for (x, y) in [(0, 0), (20, 30), (40, 12), (63, 47)] {
        let tree = server.get_json(&format!("/api/explain?x={x}&y={y}"));
        let value: Vec<f32> = tree["pixel"]["value"]
            .as_array()
            .unwrap()
            .iter()
            .map(|v| v.as_f64().unwrap() as f32)
            .collect();
        assert_eq!(value, pixels[y * 64 + x], "pixel {x},{y}");
        let root: Vec<f32> = tree["tree"]["color"]
            .as_array()
            .unwrap()
            .iter()
            .map(|v| v.as_f64().unwrap() as f32)
            .collect();
        assert_eq!(root, value, "one sample per pixel: the root is the pixel");
        let pixel = format!("{x},{y}");
        let mut args = vec!["explain", "scene.toml", "--pixel", &pixel, "--json"];
        args.extend(SIZE);
        let printed: serde_json::Value =
            serde_json::from_slice(&whitted(&args, server.dir.path())).unwrap();
        assert_eq!(tree, printed, "the page's tree is explain --json's");
    }
    let (status, svg) = server.get("/api/explain.svg?x=20&y=30");
    assert_eq!(status, 200);
    assert!(String::from_utf8(svg).unwrap().starts_with("<svg"));
    assert_eq!(server.get("/api/explain?x=64&y=0").0, 400);
    assert_eq!(server.get("/api/explain?x=a&y=0").0, 400);
}

/// Milliseconds the server says it spent on `name` (`Server-Timing`).
fn server_timing(head: &str, name: &str) -> f64 {
    let line = head
        .lines()
        .find_map(|l| l.strip_prefix("Server-Timing: "))
        .unwrap_or_else(|| panic!("no Server-Timing in {head}"));
    let entry = line
        .split(", ")
        .find(|e| e.starts_with(&format!("{name};")))
        .unwrap_or_else(|| panic!("no {name} in {line}"));
    entry.split("dur=").nth(1).unwrap().parse().unwrap()
}

#[test]
fn the_world_is_built_once_for_many_clicks_and_again_for_another_structure() {
    let server = Server::start(&scene_text(), &SIZE);
    let mut events = server.events();
    events.full_frame();
    let click = |x: u32, y: u32| {
        let (status, head, body) = server.get_with_head(&format!("/api/explain?x={x}&y={y}"));
        assert_eq!(status, 200, "{}", String::from_utf8_lossy(&body));
        let tree: serde_json::Value = serde_json::from_slice(&body).unwrap();
        (server_timing(&head, "world"), tree)
    };
    let (first, _) = click(10, 10);
    assert!(first > 0.0, "the first click builds the world");
    assert_eq!(click(20, 30).0, 0.0, "the second keeps it");
    // A moved camera keeps the world, and explains through the camera.
    let (status, state) = server.view("eye=1.5,2,-4.5&fov=50");
    assert_eq!(status, 200, "{state}");
    events.until(|_, data| data["pass"] == "full" && data["state"]["camera"]["fov"] == 50.0);
    let (kept, tree) = click(20, 30);
    assert_eq!(kept, 0.0, "the camera is not part of the world");
    let mut args = vec!["explain", "scene.toml", "--pixel", "20,30", "--json"];
    args.extend(SIZE);
    args.extend("--eye 1.5,2,-4.5 --look-at 0.2,0.9,0.5 --up 0,1,0 --fov 50".split(' '));
    let printed: serde_json::Value =
        serde_json::from_slice(&whitted(&args, server.dir.path())).unwrap();
    assert_eq!(tree, printed, "the moved camera's tree");
    // Another structure: built again, and the tree's costs are its.
    assert_eq!(server.view("accel=kdtree").0, 200);
    events.until(|_, data| data["pass"] == "full" && data["accel"] == "kdtree");
    let (rebuilt, tree) = click(20, 30);
    assert!(rebuilt > 0.0, "another structure builds the world again");
    assert_eq!(tree["accel"], "kdtree");
}

#[test]
fn a_bad_edit_is_shown_located_and_a_good_one_renders_again() {
    let mut server = Server::start(&scene_text(), &SIZE);
    let mut events = server.events();
    events.full_frame();
    let (_, before) = server.get("/api/save.pfm");
    let text = scene_text();
    std::fs::write(server.scene(), text.replace("fov = 45", "fov = \"wide\"")).unwrap();
    let error = events.until(|name, _| name == "error").pop().unwrap().1;
    let message = error["message"].as_str().unwrap();
    assert!(message.contains("scene.toml:"), "{message}");
    assert!(message.contains(":17:"), "the line of the error: {message}");
    assert!(server.alive());
    assert_eq!(server.get("/").0, 200);
    assert_eq!(server.get("/api/explain?x=1&y=1").0, 409);
    std::fs::write(
        server.scene(),
        text.replace("[0.25, 0.45, 0.85]", "[0.85, 0.45, 0.25]"),
    )
    .unwrap();
    events.full_frame();
    let (_, after) = server.get("/api/save.pfm");
    let (before, after) = (read_pfm(&before).1, read_pfm(&after).1);
    assert_ne!(before[0], after[0], "the sky's colour changed");
}

#[test]
fn a_moved_camera_gives_flags_that_render_the_same_picture() {
    let server = Server::start(&scene_text(), &SIZE);
    let mut events = server.events();
    events.full_frame();
    let (status, state) = server.view("eye=1.5,2,-4.5&fov=50");
    assert_eq!(status, 200, "{state}");
    let state: serde_json::Value = serde_json::from_str(&state).unwrap();
    let flags = state["flags"].as_str().unwrap().to_string();
    assert_eq!(
        flags,
        "--eye 1.5,2,-4.5 --look-at 0.2,0.9,0.5 --up 0,1,0 --fov 50"
    );
    events.until(|name, data| {
        name == "frame" && data["pass"] == "full" && data["state"]["flags"] == flags.as_str()
    });
    let (_, served) = server.get("/api/save.pfm");
    let mut args = vec!["render", "scene.toml", "-o", "flags.pfm", "--quiet"];
    args.extend(SIZE);
    args.extend(flags.split(' '));
    whitted(&args, server.dir.path());
    let rendered = std::fs::read(server.dir.path().join("flags.pfm")).unwrap();
    assert!(served == rendered, "the flags render the picture shown");
    // Back to the scene's camera.
    let (_, state) = server.view("camera=scene");
    assert!(state.contains("--eye 0,1.8,-5.5 "), "{state}");
    assert_eq!(server.view("eye=0.2,0.9,0.5").0, 400, "eye at look_at");
}

#[test]
fn views_switch_between_aovs_and_saves_use_the_writers() {
    let server = Server::start(&scene_text(), &SIZE);
    let mut events = server.events();
    events.full_frame();
    for aov in ["depth", "normal", "id", "cost"] {
        assert_eq!(server.view(&format!("aov={aov}")).0, 200);
        events.until(|_, data| data["pass"] == "full" && data["aov"] == aov);
        let (status, png) = server.get("/api/save.png");
        assert_eq!(status, 200);
        assert!(png.starts_with(b"\x89PNG"), "{aov}");
    }
    let (status, exr) = server.get("/api/save.exr");
    assert_eq!(status, 200);
    assert!(
        exr.starts_with(&[0x76, 0x2f, 0x31, 0x01]),
        "an OpenEXR file"
    );
    assert_eq!(server.view("aov=color").0, 200);
}

#[test]
fn bad_and_foreign_requests_are_refused_and_the_server_stays_up() {
    let mut server = Server::start(&scene_text(), &SIZE);
    let port = server.port;
    assert_eq!(server.raw("GARBAGE", b"").0, 400);
    assert_eq!(
        server.raw("GET / HTTP/1.1\r\nHost: evil.example", b"").0,
        403
    );
    assert_eq!(server.get("/../scene.toml").0, 404);
    assert_eq!(server.get("/scene.toml").0, 404);
    assert_eq!(server.get("/%2e%2e/etc/passwd").0, 404);
    let foreign =
        format!("POST /api/view HTTP/1.1\r\nHost: 127.0.0.1:{port}\r\nOrigin: http://evil.example");
    assert_eq!(server.raw(&foreign, b"aov=depth").0, 403);
    assert_eq!(server.view("aov=nothing").0, 400);
    assert_eq!(server.view("fov=0").0, 400);
    // HEAD answers the head alone, with the body's length.
    let (status, head, body) =
        server.exchange(&format!("HEAD / HTTP/1.1\r\nHost: 127.0.0.1:{port}"), b"");
    assert_eq!(status, 200);
    assert!(body.is_empty(), "{} bytes of body", body.len());
    let (_, page) = server.get("/");
    assert!(
        head.contains(&format!("Content-Length: {}", page.len())),
        "{head}"
    );
    // A second Host header is refused.
    let twice = format!("GET / HTTP/1.1\r\nHost: 127.0.0.1:{port}\r\nHost: evil.example");
    assert_eq!(server.raw(&twice, b"").0, 400);
    // A head past 16 KiB is answered 431, not reset.
    let long = format!(
        "GET / HTTP/1.1\r\nHost: 127.0.0.1:{port}\r\nX-Padding: {}",
        "a".repeat(40 << 10)
    );
    assert_eq!(server.raw(&long, b"").0, 431);
    assert!(server.alive());
    assert_eq!(server.get("/").0, 200);
}

/// Issue 50, item 4: a newer scene cancels the pass under way within a
/// pixel's work. The glass ball in mirrors at 64 samples costs some 0.15 s
/// a pixel in a debug build, so a tile of its full pass takes some 40 s:
/// a render cancelled only between tiles kept the next scene waiting
/// that long.
#[test]
fn a_newer_scene_cancels_the_pass_under_way_within_a_pixel() {
    let slow = std::fs::read_to_string(
        std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("../whitted/tests/hostile_scenes/glass_in_mirrors.toml"),
    )
    .unwrap()
    .replace("height = 8\n", "height = 8\nsamples = 64\n");
    assert!(slow.contains("samples = 64"));
    let server = Server::start(&slow, &SIZE);
    let mut events = server.events();
    events.until(|name, data| name == "frame" && data["pass"] == "refining");
    // Into the full pass.
    std::thread::sleep(Duration::from_millis(500));
    let start = Instant::now();
    std::fs::write(server.scene(), scene_text()).unwrap();
    let (name, frame) = events.until(|name, _| name == "frame").pop().unwrap();
    let waited = start.elapsed();
    eprintln!("the new scene's first frame came {waited:?} after it was saved");
    assert_eq!(name, "frame", "{frame}");
    assert_eq!(
        frame["pass"], "coarse",
        "the new scene's first frame: {frame}"
    );
    assert!(waited < Duration::from_secs(5), "{waited:?}");
}

/// Issue 50, item 20: 70 clients sending a request a byte at a time, and
/// 16 open pages, neither keep out the page's requests; a request must
/// come whole within 10 s (408 after), and a 17th page is refused by name.
#[test]
fn slow_clients_and_open_pages_do_not_lock_out_requests() {
    use std::io::{Read, Write};
    let server = Server::start(&scene_text(), &SIZE);
    let port = server.port;
    let started = Instant::now();
    let mut slow: Vec<std::net::TcpStream> = (0..70)
        .map(|_| {
            let mut stream = std::net::TcpStream::connect(("127.0.0.1", port)).unwrap();
            stream.write_all(b"GET / HT").unwrap();
            stream
        })
        .collect();
    let pages: Vec<_> = (0..16).map(|_| server.events()).collect();
    assert_eq!(server.get("/").0, 200, "a request beside them");
    let (status, refused) = server.get("/events");
    assert_eq!(status, 503);
    assert_eq!(
        String::from_utf8_lossy(&refused),
        "too many pages are open (16, the most this server follows at once): close one\n"
    );
    // Each slow client is answered 408 once its 10 s are up.
    let first = &mut slow[0];
    first
        .set_read_timeout(Some(Duration::from_secs(30)))
        .unwrap();
    let mut answer = String::new();
    first.read_to_string(&mut answer).unwrap();
    let waited = started.elapsed();
    assert!(
        answer.starts_with("HTTP/1.1 408 ")
            && answer.contains(
                "the request did not arrive in time: a request's head and body must come \
                 within 10 s"
            ),
        "{answer}"
    );
    assert!(
        waited >= Duration::from_secs(9) && waited < Duration::from_secs(25),
        "{waited:?}"
    );
    drop(pages);
    assert_eq!(server.get("/").0, 200);
}

/// Issue 50, item 16: a refusal quotes what it refuses at about a line's
/// width, however long the request's header or value.
#[test]
fn refusals_quote_long_requests_at_a_lines_width() {
    let server = Server::start(&scene_text(), &SIZE);
    let long = "h".repeat(15_000);
    let (status, body) = server.raw(&format!("GET / HTTP/1.1\r\nHost: {long}"), b"");
    assert_eq!(status, 403);
    let text = String::from_utf8_lossy(&body);
    assert!(body.len() < 500, "{text}");
    assert!(
        text.starts_with(&format!("requests for host `{}…` are refused", &long[..71])),
        "{text}"
    );
    let (status, text) = server.view(&format!("aov={}", "x".repeat(50_000)));
    assert_eq!(status, 400);
    assert!(text.len() < 500, "{text}");
    assert!(text.contains("…"), "{text}");
}

/// The scene reader's warnings (here a model's, passed on by a
/// definition) are printed and shown on the page as `render` prints them.
#[test]
fn the_readers_warnings_are_shown_on_the_page() {
    let scene = format!(
        "{}[definitions.tri]\nmesh = 'tri.obj'\n[[objects]]\ninstance = 'tri'\n",
        scene_text()
    );
    let server = Server::start(
        "[camera]\neye = [0, 0, 4]\nlook_at = [0, 0, 0]\nfov = 40\n",
        &["--width", "4", "--height", "4"],
    );
    let mut events = server.events();
    std::fs::write(
        server.dir.path().join("tri.obj"),
        "mtllib gone.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n",
    )
    .unwrap();
    std::fs::write(server.scene(), scene).unwrap();
    let (_, warnings) = events
        .until(|name, data| name == "warnings" && data["messages"] != serde_json::json!([]))
        .pop()
        .unwrap();
    assert!(
        only_warning(&warnings).contains("tri.obj:1:8: warning: cannot read the material library"),
        "{warnings}"
    );
}

/// The one message of a `warnings` event.
fn only_warning(warnings: &serde_json::Value) -> &str {
    let messages = warnings["messages"].as_array().unwrap();
    assert_eq!(messages.len(), 1, "{warnings}");
    messages[0].as_str().unwrap()
}

/// Issue 50, item 10: an implicit surface estimated slow is warned of on
/// the page, and the warning goes when the scene is fixed.
#[test]
fn a_slow_implicit_surface_is_warned_of_on_the_page() {
    let slow = include_str!("../../../whitted/tests/hostile_scenes/slow_implicit.toml");
    let fixed = include_str!("../../../whitted/tests/hostile_scenes/slow_implicit_fixed.toml");
    let server = Server::start(slow, &["--width", "4", "--height", "4"]);
    let mut events = server.events();
    let (_, warnings) = events.until(|name, _| name == "warnings").pop().unwrap();
    assert!(
        only_warning(&warnings).starts_with("warning: the implicit surface objects[0]"),
        "{warnings}"
    );
    std::fs::write(server.scene(), fixed).unwrap();
    let (_, warnings) = events.until(|name, _| name == "warnings").pop().unwrap();
    assert_eq!(warnings["messages"], serde_json::json!([]), "{warnings}");
}
