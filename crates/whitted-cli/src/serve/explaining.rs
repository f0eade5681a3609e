//! The ray trees of `whitted serve`: one thread keeps the world (and the
//! caustic map) of the scene as last rendered, built once by
//! [`Explainer`], and explains each clicked pixel against it. The world is
//! built again only when the scene it was built from changes: the file
//! read again, another structure chosen (the session hands a new
//! [`Arc<Scene>`] then, and the same one while only the camera or the
//! view moves).

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

/// The queue of pixels to explain and the thread's end of it.
pub struct Explaining {
    jobs: Mutex<Sender<Job>>,
    queue: Mutex<Option<Receiver<Job>>>,
}

impl Explaining {
    /// An empty queue; [`Self::run`] serves it.
    pub fn new() -> Self {
        let (jobs, queue) = channel();
        Self {
            jobs: Mutex::new(jobs),
            queue: Mutex::new(Some(queue)),
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
            serve(&queue);
        }
    }
}

/// Answers the jobs of `queue`, keeping the world of the last one's scene.
fn serve(queue: &Receiver<Job>) {
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
            let explanation = explainer
                .explain(&job.camera, job.pixel, job.sample)
                .map_err(|e| e.to_string());
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
