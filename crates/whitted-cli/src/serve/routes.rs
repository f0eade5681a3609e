//! What `whitted serve` answers: the page (embedded in the binary), the
//! session's state, a change of view, a pixel's ray tree, and the current
//! picture to save. Nothing is read from the disk on a request: there is
//! no path to traverse.

use whitted::accel::AccelKind;
use whitted::image::Film;
use whitted::render::{Aov, explain_pixel};
use whitted::scene::parse_whole_number;

use crate::arguments;
use crate::explain_json::explanation_json;
use crate::explain_svg::svg_drawing;
use crate::serve::http::{Refusal, Request, Response, form_pairs};
use crate::serve::picture::{display_film, raw_film};
use crate::serve::session::{CameraView, Session, View};

const PAGE: &str = include_str!("page/index.html");
const SCRIPT: &str = include_str!("page/page.js");
const STYLE: &str = include_str!("page/page.css");

/// The answer to `request` (all but the event stream).
pub fn answer(session: &Session, request: &Request) -> Result<Response, Refusal> {
    let get = request.method == "GET" || request.method == "HEAD";
    let allowed = match request.path.as_str() {
        "/api/view" => request.method == "POST",
        _ => get,
    };
    if !allowed {
        return Err(Refusal::new(
            405,
            format!("{} is not allowed on {}", request.method, request.path),
        ));
    }
    match request.path.as_str() {
        "/" | "/index.html" => Ok(Response::ok("text/html; charset=utf-8", PAGE)),
        "/page.js" => Ok(Response::ok("text/javascript; charset=utf-8", SCRIPT)),
        "/page.css" => Ok(Response::ok("text/css; charset=utf-8", STYLE)),
        "/api/state" => Ok(Response::json(&session.state())),
        "/api/view" => change_view(session, request),
        "/api/explain" => explain(session, request, false),
        "/api/explain.svg" => explain(session, request, true),
        "/api/save.png" => save(session, "png"),
        "/api/save.exr" => save(session, "exr"),
        "/api/save.pfm" => save(session, "pfm"),
        path => Err(Refusal::new(404, format!("{path}: no such page"))),
    }
}

/// `POST /api/view`: a form of what changes (`eye`, `look_at`, `up`,
/// `fov`, `camera=scene`, `aov`, `accel`, `preview`).
fn change_view(session: &Session, request: &Request) -> Result<Response, Refusal> {
    let body = std::str::from_utf8(&request.body)
        .map_err(|_| Refusal::new(400, "the form is not UTF-8"))?;
    let mut view = View {
        preview: false,
        ..session.view()
    };
    let bad = |name: &str, e: String| Refusal::new(400, format!("{name}: {e}"));
    for (name, value) in form_pairs(body)? {
        let camera = |view: &mut View| -> Result<CameraView, Refusal> {
            view.camera
                .or_else(|| session.camera())
                .ok_or_else(|| Refusal::new(409, "there is no camera: the scene is not read"))
        };
        match name.as_str() {
            "eye" | "look_at" | "up" => {
                let v = arguments::vec3(&value).map_err(|e| bad(&name, e))?;
                let mut c = camera(&mut view)?;
                match name.as_str() {
                    "eye" => c.eye = v,
                    "look_at" => c.look_at = v,
                    _ => c.up = v,
                }
                view.camera = Some(c);
            }
            "fov" => {
                let fov = arguments::field_of_view(&value).map_err(|e| bad(&name, e))?;
                let mut c = camera(&mut view)?;
                c.fov = fov;
                view.camera = Some(c);
            }
            "camera" if value == "scene" => view.camera = None,
            "aov" => {
                view.aov =
                    match value.as_str() {
                        "color" => None,
                        name => Some(Aov::from_name(name).ok_or_else(|| {
                            bad("aov", format!("`{name}` is not color or an AOV"))
                        })?),
                    }
            }
            "accel" => {
                view.accel = match value.as_str() {
                    "scene" => None,
                    name => Some(
                        AccelKind::from_name(name)
                            .ok_or_else(|| bad("accel", format!("`{name}` is not a structure")))?,
                    ),
                }
            }
            "preview" => view.preview = value == "1",
            _ => return Err(Refusal::new(400, format!("`{name}` is not part of a view"))),
        }
    }
    if let Some(camera) = &view.camera {
        camera.camera().map_err(|e| Refusal::new(400, e))?;
    }
    session.request(view);
    Ok(Response::json(&session.state()))
}

/// A whole number query parameter.
fn number(request: &Request, name: &str, default: Option<u32>) -> Result<u32, Refusal> {
    match (request.query(name), default) {
        (None, Some(n)) => Ok(n),
        (None, None) => Err(Refusal::new(400, format!("`{name}` is missing"))),
        (Some(text), _) => parse_whole_number(text, 0, u64::from(u32::MAX))
            .map(|n| n as u32)
            .map_err(|_| Refusal::new(400, format!("{name}: `{text}` is not a whole number"))),
    }
}

/// `GET /api/explain?x=X&y=Y[&sample=K]`: the pixel's ray tree as
/// `explain --json` prints it; `.svg`: drawn over the last full picture.
fn explain(session: &Session, request: &Request, svg: bool) -> Result<Response, Refusal> {
    let pixel = (number(request, "x", None)?, number(request, "y", None)?);
    let sample = number(request, "sample", Some(0))?;
    let scene = session
        .scene()
        .ok_or_else(|| Refusal::new(409, "the scene could not be read; nothing to explain"))?;
    let explanation =
        explain_pixel(&scene, pixel, sample).map_err(|e| Refusal::new(400, e.to_string()))?;
    let file = session.file();
    if !svg {
        return Ok(Response::json(&explanation_json(
            &scene,
            file,
            &explanation,
        )));
    }
    let frame = session
        .full_frame()
        .filter(|f| std::sync::Arc::ptr_eq(&f.scene, &scene))
        .ok_or_else(|| Refusal::new(409, "the full picture is not rendered yet"))?;
    let png = frame
        .output
        .image
        .png_bytes()
        .map_err(|e| Refusal::new(500, e.to_string()))?;
    let drawing = svg_drawing(&scene, file, &explanation, &png);
    Ok(Response::ok("image/svg+xml", drawing))
}

/// `GET /api/save.FORMAT`: the last full picture, as shown (PNG) or its
/// values (EXR, PFM), through the library's writers.
fn save(session: &Session, format: &str) -> Result<Response, Refusal> {
    let frame = session
        .full_frame()
        .ok_or_else(|| Refusal::new(409, "no full picture is rendered yet"))?;
    let film = match format {
        "png" => display_film(&frame.output, frame.aov),
        _ => raw_film(&frame.output, frame.aov).clone(),
    };
    let bytes = encoded(&film, format).map_err(|e| Refusal::new(500, e))?;
    let name = match frame.aov {
        None => format!("whitted.{format}"),
        Some(aov) => format!("whitted-{}.{format}", aov.name()),
    };
    let content_type = match format {
        "png" => "image/png",
        "exr" => "image/x-exr",
        _ => "application/octet-stream",
    };
    let mut response = Response::ok(content_type, bytes);
    response.headers.push((
        "Content-Disposition",
        format!("attachment; filename=\"{name}\""),
    ));
    Ok(response)
}

/// The film encoded as `format` by its writer, through a private folder.
fn encoded(film: &Film, format: &str) -> Result<Vec<u8>, String> {
    let folder = std::env::temp_dir().join(format!(
        "whitted-serve-{}-{}",
        std::process::id(),
        std::time::SystemTime::now()
            .duration_since(std::time::UNIX_EPOCH)
            .map_or(0, |d| d.as_nanos())
    ));
    std::fs::create_dir(&folder).map_err(|e| format!("{}: {e}", folder.display()))?;
    let path = folder.join(format!("picture.{format}"));
    let bytes = film
        .write(&path)
        .map_err(|e| e.to_string())
        .and_then(|()| std::fs::read(&path).map_err(|e| format!("{}: {e}", path.display())));
    let _ = std::fs::remove_dir_all(&folder);
    bytes
}

#[cfg(test)]
mod tests {
    use super::*;

    fn request(method: &str, path: &str, query: &[(&str, &str)], body: &str) -> Request {
        Request {
            method: method.to_string(),
            path: path.to_string(),
            query: query
                .iter()
                .map(|(n, v)| (n.to_string(), v.to_string()))
                .collect(),
            headers: Vec::new(),
            body: body.as_bytes().to_vec(),
        }
    }

    fn session() -> Session {
        use clap::Parser;
        #[derive(Parser)]
        struct Wrapper {
            #[command(flatten)]
            scene: crate::scene_arguments::SceneArgs,
        }
        Session::new(Wrapper::parse_from(["whitted"]).scene)
    }

    #[test]
    fn unknown_paths_methods_and_views_are_refused() {
        let s = session();
        let status = |r: Request| answer(&s, &r).unwrap_err().status;
        assert_eq!(status(request("GET", "/../etc/passwd", &[], "")), 404);
        assert_eq!(status(request("GET", "/scene.toml", &[], "")), 404);
        assert_eq!(status(request("DELETE", "/", &[], "")), 405);
        assert_eq!(status(request("GET", "/api/view", &[], "")), 405);
        assert_eq!(status(request("POST", "/api/view", &[], "aov=colour")), 400);
        assert_eq!(status(request("POST", "/api/view", &[], "nonsense=1")), 400);
        assert_eq!(status(request("POST", "/api/view", &[], "fov=200")), 400);
        assert_eq!(
            status(request("GET", "/api/explain", &[("x", "1")], "")),
            400
        );
        assert_eq!(
            status(request(
                "GET",
                "/api/explain",
                &[("x", "-1"), ("y", "0")],
                ""
            )),
            400
        );
        assert_eq!(status(request("GET", "/api/save.png", &[], "")), 409);
        assert_eq!(
            answer(&s, &request("GET", "/", &[], "")).unwrap().status,
            200
        );
    }
}
