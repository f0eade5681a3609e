//! The ray trees of `whitted serve`: one thread keeps the world (and the
//! caustic map) of the scene as last rendered, built once by
//! [`Explainer`], and explains each clicked pixel against it. The world is
//! built again only when the scene it was built from changes: the file
//! read again, another structure chosen (the session hands a new
//! [`Arc<Scene>`] then, and the same one while only the camera or the
//! view moves). A pixel being explained is given up when a newer scene or
//! camera makes its tree stale ([`Explaining::cancel_unless`]).

use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::mpsc::{Receiver, Sender, channel};
use std::sync::{Arc, Mutex, PoisonError};
use std::time::Instant;

use whitted::render::{Camera, Explainer, PixelExplanation, Scene};

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

/// The pixel being explained: what it is seen in, and the flag that gives
/// it up.
struct Running {
    world: Arc<Scene>,
    camera: Camera,
    cancel: Arc<AtomicBool>,
}

/// The queue of pixels to explain and the thread's end of it.
pub struct Explaining {
    jobs: Mutex<Sender<Job>>,
    queue: Mutex<Option<Receiver<Job>>>,
    running: Mutex<Option<Running>>,
}

impl Explaining {
    /// An empty queue; [`Self::run`] serves it.
    pub fn new() -> Self {
        let (jobs, queue) = channel();
        Self {
            jobs: Mutex::new(jobs),
            queue: Mutex::new(Some(queue)),
            running: Mutex::new(None),
        }
    }

    /// Gives up the pixel being explained, if any, unless it is seen in
    /// `world` through `camera` (`None`: whatever it is seen in): its
    /// answer is then an error saying it was cancelled.
    pub fn cancel_unless(&self, current: Option<(&Arc<Scene>, &Camera)>) {
        let running = self.running.lock().unwrap_or_else(PoisonError::into_inner);
        if let Some(r) = running.as_ref() {
            let same = current
                .is_some_and(|(world, camera)| Arc::ptr_eq(world, &r.world) && *camera == r.camera);
            if !same {
                r.cancel.store(true, Ordering::Relaxed);
            }
        }
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
    ) -> Result<PixelExplanation, String> {
        let cancel = Arc::new(AtomicBool::new(false));
        *self.running.lock().unwrap_or_else(PoisonError::into_inner) = Some(Running {
            world: Arc::clone(&job.world),
            camera: job.camera.clone(),
            cancel: Arc::clone(&cancel),
        });
        let explanation = explainer
            .explain_unless(&job.camera, job.pixel, job.sample, &cancel)
            .map_err(|e| e.to_string());
        *self.running.lock().unwrap_or_else(PoisonError::into_inner) = None;
        explanation
    }

    /// Answers the jobs of `queue`, keeping the world of the last one's
    /// scene.
    fn serve(&self, queue: &Receiver<Job>) {
        let mut next = queue.recv().ok();
        while let Some(job) = next.take() {
            let world = Arc::clone(&job.world);
            let start = Instant::now();
            let explainer = match Explainer::new(&world) {
                Ok(explainer) => explainer,
                Err(e) => {
                    let _ = job.reply.send(Answer {
                        explanation: Err(e.to_string()),
                        build_seconds: start.elapsed().as_secs_f64(),
                        explain_seconds: 0.0,
                    });
                    next = queue.recv().ok();
                    continue;
                }
            };
            let mut build_seconds = start.elapsed().as_secs_f64();
            let mut job = job;
            loop {
                let start = Instant::now();
                let explanation = self.explain_job(&explainer, &job);
                let _ = job.reply.send(Answer {
                    explanation,
                    build_seconds,
                    explain_seconds: start.elapsed().as_secs_f64(),
                });
                build_seconds = 0.0;
                match queue.recv() {
                    Ok(same) if Arc::ptr_eq(&same.world, &world) => job = same,
                    other => {
                        next = other.ok();
                        break;
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
            .join("../whitted/tests/hostile_scenes/glass_in_mirrors.toml");
        let source = std::fs::read_to_string(&path).unwrap().replace(
            "type = \"point\"\nposition = [0, 1, -1]",
            "type = \"rect\"\norigin = [-0.5, 1.9, -0.5]\nedge_u = [1, 0, 0]\n\
             edge_v = [0, 0, 1]\nradiance = 1\nsamples = 4096",
        );
        whitted::scene::parse_scene(&source, &path).unwrap()
    }

    #[test]
    fn a_newer_scene_gives_up_the_pixel_being_explained() {
        let explaining = Arc::new(Explaining::new());
        let server = Arc::clone(&explaining);
        // Serves until the process ends.
        std::thread::spawn(move || server.run());
        let world = Arc::new(heavy_scene());
        let camera = world.camera.clone();
        let start = Instant::now();
        let answer = std::thread::scope(|scope| {
            let asked =
                scope.spawn(|| explaining.explain(Arc::clone(&world), camera.clone(), (4, 4), 0));
            std::thread::sleep(Duration::from_millis(300));
            // The same scene and camera do not cancel it; another scene does.
            explaining.cancel_unless(Some((&world, &camera)));
            let running = explaining.running.lock().unwrap();
            let flag = &running
                .as_ref()
                .expect("the pixel is being explained")
                .cancel;
            assert!(!flag.load(Ordering::Relaxed));
            drop(running);
            let newer = Arc::new(Scene::clone(&world));
            explaining.cancel_unless(Some((&newer, &camera)));
            asked.join().unwrap()
        });
        let error = answer.unwrap().explanation.unwrap_err();
        assert_eq!(
            error,
            "the explanation was cancelled: a newer scene or camera replaced it"
        );
        assert!(
            start.elapsed() < Duration::from_secs(20),
            "{:?}",
            start.elapsed()
        );
    }
}
