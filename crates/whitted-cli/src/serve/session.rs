//! The state of a `whitted serve` session: the view the page asked for,
//! the scene as last read, the newest frame or error, and the one worker
//! thread that renders. A new request cancels the running render
//! ([`Prepared::render`]); the worker then starts over with the newest
//! view, so it never renders a view nobody waits for. The world is built
//! once per scene read and structure chosen, not per pass.
//!
//! Each request is rendered in passes: 1/8 of the size with one sample
//! (there within a fraction of a second), 1/2, then the full picture; a
//! view asked for while the mouse moves gets only a 1/4 pass.

use std::collections::VecDeque;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, Condvar, Mutex, MutexGuard, PoisonError};
use std::time::{Duration, SystemTime};

use serde_json::{Value, json};
use whitted::accel::AccelKind;
use whitted::math::Vec3;
use whitted::render::{Aov, Camera, Pass, Prepared, RenderError, RenderOutput, Scene};

use crate::explain_svg::base64;
use crate::scene_arguments::SceneArgs;
use crate::serve::explaining::Explaining;
use crate::serve::picture::display_film;

/// How many of the newest events are kept for a page that reads them
/// late (older ones are skipped: a page needs the newest picture).
const EVENTS_KEPT: usize = 8;

/// A camera as the page moves it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CameraView {
    /// Where the eye is.
    pub eye: Vec3,
    /// The point looked at.
    pub look_at: Vec3,
    /// Up on the image.
    pub up: Vec3,
    /// Vertical field of view, degrees.
    pub fov: f64,
}

impl CameraView {
    fn of(camera: &Camera) -> Self {
        Self {
            eye: camera.eye(),
            look_at: camera.look_at(),
            up: camera.up(),
            fov: camera.fov_degrees(),
        }
    }

    /// The `render` flags that give this camera.
    pub fn flags(&self) -> String {
        let v = |v: Vec3| format!("{},{},{}", short(v.x), short(v.y), short(v.z));
        format!(
            "--eye {} --look-at {} --up {} --fov {}",
            v(self.eye),
            v(self.look_at),
            v(self.up),
            short(self.fov)
        )
    }

    /// The camera, if it is one.
    pub fn camera(&self) -> Result<Camera, String> {
        Camera::new(self.eye, self.look_at, self.up, self.fov)
            .map_err(|e| format!("the camera asked for is invalid: {e}"))
    }
}

/// A number with at most 6 decimals, without trailing zeros.
fn short(x: f64) -> String {
    let text = format!("{x:.6}");
    let text = text.trim_end_matches('0').trim_end_matches('.');
    if text == "-0" { "0" } else { text }.to_string()
}

/// What the page asks to see.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct View {
    /// The camera, when the page moved it (else the scene's).
    pub camera: Option<CameraView>,
    /// The AOV shown instead of the colour image.
    pub aov: Option<Aov>,
    /// The acceleration structure, when the page chose one.
    pub accel: Option<AccelKind>,
    /// The mouse is moving: a quick low-resolution pass only.
    pub preview: bool,
}

/// The last full frame, kept for saving and for the ray tree drawing.
pub struct FullFrame {
    /// The scene as rendered (the view applied).
    pub scene: Arc<Scene>,
    /// What the render made.
    pub output: RenderOutput,
    /// The AOV shown, if not the colour.
    pub aov: Option<Aov>,
}

/// What the page is told: the newest frame or error, as an SSE event.
#[derive(Clone)]
pub struct Event {
    /// `frame` or `error`.
    pub name: &'static str,
    /// The event's JSON.
    pub data: Arc<String>,
}

struct Inner {
    view: View,
    /// Counts the requests; the worker renders the newest.
    requested: u64,
    /// The scene file changed: read it again.
    reload: bool,
    /// Counts the events published.
    published: u64,
    /// The newest events (at most [`EVENTS_KEPT`]), each with its number.
    events: VecDeque<(u64, Event)>,
    /// The scene's camera (the arguments applied), when one was read.
    scene_camera: Option<CameraView>,
    /// The scene as the newest request renders it at full size.
    scene: Option<Arc<Scene>>,
    /// The scene the ray trees' world is built from: the same one while
    /// only the camera or the view changes.
    world: Option<Arc<Scene>>,
    full: Option<Arc<FullFrame>>,
}

/// The state shared by the connections and the worker.
pub struct Session {
    args: SceneArgs,
    inner: Mutex<Inner>,
    changed: Condvar,
    cancel: AtomicBool,
    /// The thread that explains clicked pixels, and its queue.
    pub explaining: Explaining,
}

/// A file's modification time and size.
pub type FileStamp = (SystemTime, u64);

/// The stamp of the file at `path`, if it can be read.
pub fn file_stamp(path: &Path) -> Option<FileStamp> {
    let meta = std::fs::metadata(path).ok()?;
    Some((meta.modified().ok()?, meta.len()))
}

impl Session {
    /// A session for the scene the arguments name; nothing rendered yet.
    pub fn new(args: SceneArgs) -> Self {
        Self {
            args,
            inner: Mutex::new(Inner {
                view: View::default(),
                requested: 1,
                reload: true,
                published: 0,
                events: VecDeque::new(),
                scene_camera: None,
                scene: None,
                world: None,
                full: None,
            }),
            changed: Condvar::new(),
            cancel: AtomicBool::new(false),
            explaining: Explaining::new(),
        }
    }

    fn lock(&self) -> MutexGuard<'_, Inner> {
        self.inner.lock().unwrap_or_else(PoisonError::into_inner)
    }

    /// The scene file, if there is one.
    pub fn file(&self) -> Option<&std::path::Path> {
        self.args.scene.as_deref()
    }

    /// Asks for a render of `view` (cancelling the running one).
    pub fn request(&self, view: View) {
        let mut inner = self.lock();
        inner.view = view;
        self.request_locked(&mut inner);
    }

    fn request_locked(&self, inner: &mut Inner) {
        inner.requested += 1;
        self.cancel.store(true, Ordering::Relaxed);
        self.changed.notify_all();
    }

    /// The view now asked for.
    pub fn view(&self) -> View {
        self.lock().view.clone()
    }

    /// The camera shown now: the page's, else the scene's.
    pub fn camera(&self) -> Option<CameraView> {
        let inner = self.lock();
        inner.view.camera.or(inner.scene_camera)
    }

    /// The scene as the newest request renders it and the scene its
    /// world is built from, if it could be read.
    pub fn explain_target(&self) -> Option<(Arc<Scene>, Arc<Scene>)> {
        let inner = self.lock();
        Some((inner.scene.clone()?, inner.world.clone()?))
    }

    /// The last full frame.
    pub fn full_frame(&self) -> Option<Arc<FullFrame>> {
        self.lock().full.clone()
    }

    /// The state the page shows beside the picture.
    pub fn state(&self) -> Value {
        let inner = self.lock();
        let camera = inner.view.camera.or(inner.scene_camera);
        json!({
            "scene": self.file().map(|f| f.display().to_string()),
            "camera": camera.map(|c| json!({
                "eye": [c.eye.x, c.eye.y, c.eye.z],
                "look_at": [c.look_at.x, c.look_at.y, c.look_at.z],
                "up": [c.up.x, c.up.y, c.up.z],
                "fov": c.fov,
            })),
            "flags": camera.map(|c| c.flags()),
            "aov": inner.view.aov.map(|a| a.name()),
            "accel": inner.view.accel.map(|a| a.name()),
            "aovs": Aov::ALL.iter().map(Aov::name).collect::<Vec<_>>(),
            "accels": AccelKind::ALL.iter().map(AccelKind::name).collect::<Vec<_>>(),
        })
    }

    /// Waits until an event newer than `seen` is published (or `timeout`
    /// passes) and returns the number of the newest with the events after
    /// `seen` still kept; for a page that saw nothing yet (`seen` 0), the
    /// newest only.
    pub fn next_events(&self, seen: u64, timeout: Duration) -> (u64, Vec<Event>) {
        let inner = self.lock();
        let (inner, _) = self
            .changed
            .wait_timeout_while(inner, timeout, |i| i.published <= seen)
            .unwrap_or_else(PoisonError::into_inner);
        let mut newer = inner.events.iter().filter(|(n, _)| *n > seen);
        let events = if seen == 0 {
            newer
                .next_back()
                .map(|(_, e)| e.clone())
                .into_iter()
                .collect()
        } else {
            newer.map(|(_, e)| e.clone()).collect()
        };
        (inner.published, events)
    }

    fn publish(&self, name: &'static str, mut data: Value) {
        data["state"] = self.state();
        let mut inner = self.lock();
        inner.published += 1;
        let number = inner.published;
        if inner.events.len() == EVENTS_KEPT {
            inner.events.pop_front();
        }
        inner.events.push_back((
            number,
            Event {
                name,
                data: Arc::new(data.to_string()),
            },
        ));
        self.changed.notify_all();
    }

    /// Watches the scene file: when its time or size changes from `last`
    /// ([`file_stamp`], taken before the file is first read, so that no
    /// change after that read goes unseen), it is read again and rendered.
    /// Runs forever.
    pub fn watch_file(&self, path: PathBuf, mut last: Option<FileStamp>) {
        loop {
            std::thread::sleep(Duration::from_millis(150));
            let now = file_stamp(&path);
            if now != last {
                last = now;
                let mut inner = self.lock();
                inner.reload = true;
                self.request_locked(&mut inner);
            }
        }
    }

    /// The newest request once there is one newer than `done` (which it
    /// becomes): its view, and whether the file is to be read again.
    fn next_request(&self, done: &mut u64) -> (View, bool) {
        let mut inner = self.lock();
        while inner.requested == *done {
            inner = self
                .changed
                .wait(inner)
                .unwrap_or_else(PoisonError::into_inner);
        }
        *done = inner.requested;
        self.cancel.store(false, Ordering::Relaxed);
        (inner.view.clone(), std::mem::take(&mut inner.reload))
    }

    /// Renders what is asked, newest first, forever. The world (and the
    /// caustic map) of the scene with the chosen structure is built once
    /// ([`Prepared`]) and kept while only the camera or the view moves.
    pub fn render_loop(&self) {
        let mut done = 0;
        let mut base: Option<Scene> = None;
        let mut next = None;
        loop {
            let (mut view, reload) = next.take().unwrap_or_else(|| self.next_request(&mut done));
            if reload {
                base = None;
                match self.args.load_with_warnings(true) {
                    Ok((scene, read)) => {
                        // The reader's (each with its place), then the
                        // slow surfaces'.
                        let slow = whitted::render::slow_implicit_surfaces(&scene);
                        let warnings: Vec<String> = read
                            .into_iter()
                            .chain(slow.iter().map(|slow| format!("warning: {slow}")))
                            .map(|warning| crate::report::bounded(&warning).into_owned())
                            .collect();
                        for warning in &warnings {
                            crate::report::note!("{warning}");
                        }
                        // Sent even when empty: the page then clears the
                        // last scene's.
                        self.publish("warnings", json!({ "request": done, "messages": warnings }));
                        self.lock().scene_camera = Some(CameraView::of(&scene.camera));
                        base = Some(scene);
                    }
                    Err(message) => self.publish_error(done, &message),
                }
            }
            let Some(base) = &base else { continue };
            // The scene with the structure chosen, and its world.
            let world = Arc::new(with_accel(base, view.accel));
            let prepared = match Prepared::new(&world) {
                Ok(prepared) => prepared,
                Err(e) => {
                    self.publish_error(done, &e.to_string());
                    continue;
                }
            };
            let mut build_seconds = prepared.build_seconds();
            loop {
                if let Err(message) =
                    self.render_view(done, &prepared, &world, &view, &mut build_seconds)
                {
                    self.publish_error(done, &message);
                }
                let (newer, reload) = self.next_request(&mut done);
                if reload || newer.accel != view.accel {
                    next = Some((newer, reload));
                    break;
                }
                view = newer;
            }
        }
    }

    fn publish_error(&self, request: u64, message: &str) {
        let mut inner = self.lock();
        inner.scene = None;
        inner.world = None;
        drop(inner);
        self.explaining.cancel_unless(None);
        let message = crate::report::bounded(message);
        self.publish("error", json!({ "request": request, "message": message }));
    }

    /// Renders `view` of `world` (the scene with the view's structure,
    /// `prepared` its world) in passes, publishing each frame, until the
    /// last or until a newer request cancels it. The first frame published
    /// reports `build_seconds`, which then becomes 0.
    fn render_view(
        &self,
        request: u64,
        prepared: &Prepared<'_>,
        world: &Arc<Scene>,
        view: &View,
        build_seconds: &mut f64,
    ) -> Result<(), String> {
        let mut scene = Scene::clone(world);
        if let Some(camera) = &view.camera {
            scene.camera = camera.camera()?;
        }
        scene.settings.aovs = view.aov.into_iter().collect();
        let full = Arc::new(scene);
        {
            let mut inner = self.lock();
            inner.scene = Some(Arc::clone(&full));
            inner.world = Some(Arc::clone(world));
        }
        // A tree of another scene or camera is stale now.
        self.explaining.cancel_unless(Some((world, &full.camera)));
        let passes: &[(&str, u32)] = if view.preview {
            &[("preview", 4)]
        } else {
            &[("coarse", 8), ("refining", 2), ("full", 1)]
        };
        for &(pass, divisor) in passes {
            let (width, height) = (full.settings.width, full.settings.height);
            let frame = Pass {
                width: width.div_ceil(divisor),
                height: height.div_ceil(divisor),
                samples_per_pixel: if divisor == 1 {
                    full.settings.samples_per_pixel
                } else {
                    1
                },
                ..Pass::of(&full)
            };
            let start = std::time::Instant::now();
            let output = match prepared.render(&frame, &self.cancel, &|_| {}) {
                Ok(output) => output,
                Err(RenderError::Cancelled) => return Ok(()),
                Err(e) => return Err(e.to_string()),
            };
            let seconds = start.elapsed().as_secs_f64();
            let png = display_film(&output, view.aov)
                .png_bytes()
                .map_err(|e| e.to_string())?;
            let trace = output.trace.seconds.max(1e-9);
            let data = json!({
                "request": request,
                "pass": pass,
                "width": frame.width,
                "height": frame.height,
                "full_width": width,
                "full_height": height,
                "aov": view.aov.map(|a| a.name()),
                "accel": full.settings.accel.name(),
                "build_seconds": std::mem::take(build_seconds),
                "render_seconds": seconds,
                "rays": output.rays.total(),
                "rays_per_second": output.rays.total() as f64 / trace,
                "png": format!("data:image/png;base64,{}", base64(&png)),
            });
            if pass == "full" {
                self.lock().full = Some(Arc::new(FullFrame {
                    scene: Arc::clone(&full),
                    output,
                    aov: view.aov,
                }));
            }
            self.publish("frame", data);
        }
        Ok(())
    }
}

/// `base` with the structure `accel`, if one is chosen.
fn with_accel(base: &Scene, accel: Option<AccelKind>) -> Scene {
    let mut scene = base.clone();
    if let Some(accel) = accel {
        scene.settings.accel = accel;
        scene.settings.accel_top = None;
        scene.settings.accel_bottom = None;
    }
    scene
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn flags_are_short_and_read_back_by_render() {
        let view = CameraView {
            eye: Vec3::new(1.0, -0.0, 2.5),
            look_at: Vec3::new(0.0, 0.1234567, 0.0),
            up: Vec3::new(0.0, 1.0, 0.0),
            fov: 45.0,
        };
        assert_eq!(
            view.flags(),
            "--eye 1,0,2.5 --look-at 0,0.123457,0 --up 0,1,0 --fov 45"
        );
        assert!(view.camera().is_ok());
        let bad = CameraView {
            look_at: view.eye,
            ..view
        };
        assert!(bad.camera().unwrap_err().contains("invalid"));
    }
}
