//! How to render: the one settings type. A scene file fills the picture's
//! part (size, samples, depth, structure), the command line may replace any
//! of it and adds the rest (threads, per-pixel data).

use crate::accel::AccelKind;
use crate::integrator::IntegratorKind;

/// The deepest recursion a render accepts. Each level takes a few
/// kilobytes of a worker's stack, which is sized for it.
pub const MAX_DEPTH: u32 = 1000;

/// Longest side of an image a render accepts, in pixels.
pub const MAX_SIDE: u32 = 65535;

/// Largest image (in pixels) a render accepts: a few gigabytes of film.
pub const MAX_PIXELS: u64 = 1 << 28;

/// Per-pixel data besides the colour.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Aov {
    /// Distance along the unit-length primary ray through the pixel centre
    /// to the first hit; +∞ where nothing is hit.
    Depth,
    /// World-space shading normal at that hit (facing the camera); 0 for a
    /// miss.
    Normal,
    /// Index of the primitive hit, as a float; -1 for a miss.
    Id,
    /// Traversal cost of that ray: acceleration-structure nodes visited plus
    /// primitives tested.
    Cost,
}

impl Aov {
    /// Every AOV.
    pub const ALL: [Aov; 4] = [Aov::Depth, Aov::Normal, Aov::Id, Aov::Cost];

    /// The name used on the command line.
    pub fn name(&self) -> &'static str {
        match self {
            Aov::Depth => "depth",
            Aov::Normal => "normal",
            Aov::Id => "id",
            Aov::Cost => "cost",
        }
    }

    /// The AOV called `name`.
    pub fn from_name(name: &str) -> Option<Self> {
        Self::ALL.into_iter().find(|a| a.name() == name)
    }

    /// Values per pixel.
    pub fn channels(&self) -> usize {
        match self {
            Aov::Normal => 3,
            Aov::Depth | Aov::Id | Aov::Cost => 1,
        }
    }
}

/// How to render: image size, sampling, recursion limits, the acceleration
/// structure, threads and per-pixel data.
#[derive(Clone, Debug, PartialEq)]
pub struct RenderSettings {
    /// Image width in pixels.
    pub width: u32,
    /// Image height in pixels.
    pub height: u32,
    /// Samples per pixel (1 means exactly the pixel centre).
    pub samples_per_pixel: u32,
    /// Deepest reflection/refraction recursion; 0 traces primary rays only.
    pub max_depth: u32,
    /// A branch whose weight on the pixel falls below this stops early
    /// (adaptive depth control, Hall and Greenberg 1983).
    pub min_weight: f64,
    /// The acceleration structure to build over the primitives.
    pub accel: AccelKind,
    /// The algorithm that computes the colour along each camera ray.
    pub integrator: IntegratorKind,
    /// Worker threads; `None` uses every core. The picture is the same for
    /// any count.
    pub threads: Option<usize>,
    /// Per-pixel data to produce alongside the colour.
    pub aovs: Vec<Aov>,
}

impl Default for RenderSettings {
    fn default() -> Self {
        Self {
            width: 640,
            height: 480,
            samples_per_pixel: 1,
            max_depth: 8,
            min_weight: 1e-3,
            accel: AccelKind::default(),
            integrator: IntegratorKind::default(),
            threads: None,
            aovs: Vec::new(),
        }
    }
}
