//! The ray trees of `whitted serve`: one thread keeps the world (and the
//! caustic map) of the scene as last rendered, built once by
//! [`Explainer`], and explains each clicked pixel against it. The world is
//! built again only when the scene it was built from changes: the file
//! read again, another structure chosen (the session hands a new
//! [`Arc<Scene>`] then, and the same one while only the camera or the
//! view moves). A pixel being explained is given up when a newer scene or
//! camera makes its tree stale ([`Explaining::cancel_unless`]); the world
//! kept is let go, with its memory charge, once another scene (or none)
//! is shown.

use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::mpsc::{Receiver, RecvTimeoutError, Sender, channel};
use std::sync::{Arc, Mutex, PoisonError};
use std::time::{Duration, Instant};

use whitted::render::{Camera, Explainer, PixelExplanation, Scene};

/// How often the idle explaining thread looks whether the world it keeps
/// is still the one shown.
const IDLE_CHECK: Duration = Duration::from_millis(100);

/// One pixel to explain.
pub struct Job {
    /// The scene the world is built from (the camera does not matter).
    pub world: Arc<Scene>,
    /// The camera the pixel is seen through.
    pub camera: Camera,
    /// The pixel.
    pub pixel: (u32, u32),
    /// Which of its samples.
    pub sample: u32,
    /// Where the answer goes.
    pub reply: Sender<Answer>,
}

/// The explanation, or why there is none, and what it took.
pub struct Answer {
    /// The explanation, or the error in words.
    pub explanation: Result<PixelExplanation, String>,
    /// Seconds spent building the world for this job (0 when it was kept).
    pub build_seconds: f64,
    /// Seconds spent tracing the pixel.
    pub explain_seconds: f64,
}

/// What the pixels are seen in now: unknown until told, a scene's world
/// through a camera, or nothing (the scene could not be read).
enum Current {
    Unknown,
    Seen(Arc<Scene>, Camera),
    Nothing,
}

impl Current {
    /// Whether pixels are seen in `world` (or may be: unknown yet).
    fn shows(&self, world: &Arc<Scene>) -> bool {
        match self {
            Current::Unknown => true,
            Current::Seen(w, _) => Arc::ptr_eq(w, world),
            Current::Nothing => false,
        }
    }

    /// Whether a pixel seen in `world` through `camera` is stale.
    fn makes_stale(&self, world: &Arc<Scene>, camera: &Camera) -> bool {
        match self {
            Current::Unknown => false,
            Current::Seen(w, c) => !Arc::ptr_eq(w, world) || c != camera,
            Current::Nothing => true,
        }
    }
}

/// The pixel being explained: what it is seen in, and the flag that gives
/// it up.
struct Running {
    world: Arc<Scene>,
    camera: Camera,
    cancel: Arc<AtomicBool>,
}

/// What the explaining thread is doing, and what is current.
struct State {
    current: Current,
    running: Option<Running>,
}

/// The queue of pixels to explain and the thread's end of it.
pub struct Explaining {
    jobs: Mutex<Sender<Job>>,
    queue: Mutex<Option<Receiver<Job>>>,
    state: Mutex<State>,
}

impl Explaining {
    /// An empty queue; [`Self::run`] serves it.
    pub fn new() -> Self {
        let (jobs, queue) = channel();
        Self {
            jobs: Mutex::new(jobs),
            queue: Mutex::new(Some(queue)),
            state: Mutex::new(State {
                current: Current::Unknown,
                running: None,
            }),
        }
    }

    fn lock(&self) -> std::sync::MutexGuard<'_, State> {
        self.state.lock().unwrap_or_else(PoisonError::into_inner)
    }

    /// Makes `current` what pixels are seen in (`None`: nothing, the scene
    /// could not be read), and gives up the pixel being explained, or any
    /// waiting to be, seen in something else: its answer is then an error
    /// saying it was cancelled.
    pub fn cancel_unless(&self, current: Option<(&Arc<Scene>, &Camera)>) {
        let mut state = self.lock();
        state.current = match current {
            Some((world, camera)) => Current::Seen(Arc::clone(world), camera.clone()),
            None => Current::Nothing,
        };
        if let Some(r) = &state.running
            && state.current.makes_stale(&r.world, &r.camera)
        {
            r.cancel.store(true, Ordering::Relaxed);
        }
    }

    /// Marks `job` as the one being explained, from before its world is
    /// built: the flag that gives it up, set already when it is stale.
    fn begin(&self, job: &Job) -> Arc<AtomicBool> {
        let mut state = self.lock();
        let stale = state.current.makes_stale(&job.world, &job.camera);
        let cancel = Arc::new(AtomicBool::new(stale));
        state.running = Some(Running {
            world: Arc::clone(&job.world),
            camera: job.camera.clone(),
            cancel: Arc::clone(&cancel),
        });
        cancel
    }

    /// No job is being explained.
    fn end(&self) {
        self.lock().running = None;
    }

    /// Explains a pixel on the explaining thread and waits for the answer.
    pub fn explain(
        &self,
        world: Arc<Scene>,
        camera: Camera,
        pixel: (u32, u32),
        sample: u32,
    ) -> Result<Answer, String> {
        let (reply, answer) = channel();
        let job = Job {
            world,
            camera,
            pixel,
            sample,
            reply,
        };
        let lost = || "the explaining thread is gone".to_string();
        self.cancel_unless(Some((&job.world, &job.camera)));
        self.jobs
            .lock()
            .unwrap_or_else(PoisonError::into_inner)
            .send(job)
            .map_err(|_| lost())?;
        answer.recv().map_err(|_| lost())
    }

    /// Serves the queue until the session ends (the first caller only).
    pub fn run(&self) {
        let queue = self
            .queue
            .lock()
            .unwrap_or_else(PoisonError::into_inner)
            .take();
        if let Some(queue) = queue {
            self.serve(&queue);
        }
    }

    /// Explains `job` with `explainer`, which may be given up meanwhile
    /// ([`Self::cancel_unless`]).
    fn explain_job(
        &self,
        explainer: &Explainer<'_>,
        job: &Job,
        cancel: &AtomicBool,
    ) -> Result<PixelExplanation, String> {
        let explanation = explainer
            .explain_unless(&job.camera, job.pixel, job.sample, cancel)
            .map_err(|e| e.to_string());
        self.end();
        explanation
    }

    /// Answers the jobs of `queue`, keeping the world of the last one's
    /// scene while it is shown.
    fn serve(&self, queue: &Receiver<Job>) {
        let mut next = queue.recv().ok();
        while let Some(job) = next.take() {
            // Waiting with nothing kept once the scene's world is let go.
            next = self.serve_scene(queue, job).or_else(|| queue.recv().ok());
        }
    }

    /// Builds the world of `job`'s scene and answers `job` and the jobs
    /// after it of the same scene. Returns the first job of another scene,
    /// or `None` once the scene is no longer shown (or the session ends),
    /// having let go of the world.
    fn serve_scene(&self, queue: &Receiver<Job>, job: Job) -> Option<Job> {
        let mut cancel = self.begin(&job);
        let world = Arc::clone(&job.world);
        let start = Instant::now();
        let explainer = match Explainer::new(&world) {
            Ok(explainer) => explainer,
            Err(e) => {
                self.end();
                let _ = job.reply.send(Answer {
                    explanation: Err(e.to_string()),
                    build_seconds: start.elapsed().as_secs_f64(),
                    explain_seconds: 0.0,
                });
                return None;
            }
        };
        let mut build_seconds = start.elapsed().as_secs_f64();
        let mut job = job;
        loop {
            let start = Instant::now();
            let explanation = self.explain_job(&explainer, &job, &cancel);
            let _ = job.reply.send(Answer {
                explanation,
                build_seconds,
                explain_seconds: start.elapsed().as_secs_f64(),
            });
            build_seconds = 0.0;
            match self.next_while_current(queue, &world) {
                Some(same) if Arc::ptr_eq(&same.world, &world) => {
                    cancel = self.begin(&same);
                    job = same;
                }
                other => return other,
            }
        }
    }

    /// The next job, or `None` once `world` is no longer what pixels are
    /// seen in (another scene read, or none) while none came, so that the
    /// world kept for it is let go. Also `None` when the session ends.
    fn next_while_current(&self, queue: &Receiver<Job>, world: &Arc<Scene>) -> Option<Job> {
        loop {
            match queue.recv_timeout(IDLE_CHECK) {
                Ok(job) => return Some(job),
                Err(RecvTimeoutError::Disconnected) => return None,
                Err(RecvTimeoutError::Timeout) => {
                    if !self.lock().current.shows(world) {
                        return None;
                    }
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::time::Duration;

    /// The glass ball in its mirror box lit by an area light of 4096
    /// samples: a pixel that takes millions of shadow rays.
    fn heavy_scene() -> Scene {
        let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("../whitted/tests/hostile_scenes/glass_in_mirrors_area_light.toml");
        whitted::scene::load_any(&path).unwrap()
    }

    #[test]
    fn a_newer_scene_gives_up_the_pixels_being_explained_and_waiting() {
        let explaining = Arc::new(Explaining::new());
        let server = Arc::clone(&explaining);
        // Serves until the process ends.
        std::thread::spawn(move || server.run());
        let world = Arc::new(heavy_scene());
        let camera = world.camera.clone();
        let start = Instant::now();
        let answers = std::thread::scope(|scope| {
            let asked =
                scope.spawn(|| explaining.explain(Arc::clone(&world), camera.clone(), (4, 4), 0));
            std::thread::sleep(Duration::from_millis(300));
            // A second pixel waits behind the first.
            let waiting =
                scope.spawn(|| explaining.explain(Arc::clone(&world), camera.clone(), (3, 3), 0));
            std::thread::sleep(Duration::from_millis(100));
            // The same scene and camera do not cancel it; another scene does.
            explaining.cancel_unless(Some((&world, &camera)));
            let state = explaining.lock();
            let flag = &state
                .running
                .as_ref()
                .expect("the pixel is being explained")
                .cancel;
            assert!(!flag.load(Ordering::Relaxed));
            drop(state);
            let newer = Arc::new(Scene::clone(&world));
            explaining.cancel_unless(Some((&newer, &camera)));
            [asked.join().unwrap(), waiting.join().unwrap()]
        });
        // Both: the one under way, and the one that was waiting, given up
        // as it was taken from the queue.
        for answer in answers {
            let error = answer.unwrap().explanation.unwrap_err();
            assert_eq!(
                error,
                "the explanation was cancelled: a newer scene or camera replaced it"
            );
        }
        assert!(
            start.elapsed() < Duration::from_secs(20),
            "{:?}",
            start.elapsed()
        );
    }

    #[test]
    fn the_world_kept_is_let_go_once_another_scene_is_shown() {
        let explaining = Arc::new(Explaining::new());
        let server = Arc::clone(&explaining);
        // Serves until the process ends.
        std::thread::spawn(move || server.run());
        let shown = Arc::new(whitted::scene::default_scene());
        let camera = shown.camera.clone();
        let answer = explaining.explain(Arc::clone(&shown), camera.clone(), (1, 1), 0);
        assert!(answer.unwrap().explanation.is_ok());
        // Kept for the next pixel while the scene is shown.
        std::thread::sleep(3 * IDLE_CHECK);
        assert!(Arc::strong_count(&shown) > 1);
        let newer = Arc::new(Scene::clone(&shown));
        explaining.cancel_unless(Some((&newer, &camera)));
        let start = Instant::now();
        while Arc::strong_count(&shown) > 1 && start.elapsed() < Duration::from_secs(10) {
            std::thread::sleep(IDLE_CHECK / 4);
        }
        // Only this test's remains: the state names the newer scene.
        assert_eq!(Arc::strong_count(&shown), 1, "{:?}", start.elapsed());
    }
}
