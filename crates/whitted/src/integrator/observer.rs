//! What the Whitted integrator tells an observer as it traces one camera
//! sample: each ray it starts and what it hit, how the surface is shaded,
//! each light's shadow rays and verdict, the branches it leaves out, and
//! the colour each ray passes up.
//!
//! The integrator is generic over the observer. The renderer passes
//! [`Unobserved`], whose methods are the trait's empty defaults: once
//! monomorphised, every call vanishes, so rendering costs the same and
//! gives the same bits as with no observer at all. `whitted explain`
//! passes a [`super::RayTreeRecorder`], which builds the ray tree.
//!
//! The calls of one camera sample come in this order (a grammar):
//!
//! ```text
//! sample  = ray
//! ray     = ray_start ray_hit [shade] ray_end
//! shade   = shading light* [caustic] [depth_limit | lobes branch*]
//! light   = shadow_ray* light
//! branch  = ray_start ray_hit [shade] ray_end | branch_skipped
//! ```

use std::sync::atomic::{AtomicBool, Ordering};

use crate::integrator::RayKind;
use crate::math::{Ray, Vec3};
use crate::shading::{Color, LightSample};
use crate::world::{Hit, Surface};

/// How one step of a shadow ray was answered.
#[derive(Clone, Copy, Debug)]
pub enum ShadowStep<'s> {
    /// By the any-hit query (no surface in the scene lets light through):
    /// whether anything blocks the segment.
    AnyHit {
        /// True when the segment is blocked.
        blocked: bool,
    },
    /// By the closest-hit query (some surfaces let light through): the
    /// surface crossed first, if any. A shadow ray that crosses only
    /// spheres is answered from their crossings at once; its steps are
    /// then the segments from each crossing on (starting on the surface,
    /// not at an offset origin), each hit the next crossing.
    Closest {
        /// Where the segment meets a surface first.
        blocker: Option<&'s Hit>,
    },
}

/// Watches the Whitted integrator trace one camera sample. Every method
/// does nothing unless implemented; see the module documentation for the
/// order of the calls.
pub trait RayObserver {
    /// Whether it reads the (u, v) and tangents of the surfaces it is
    /// shown: when not, the integrator leaves them out for materials that
    /// do not read them either.
    const READS_UV: bool = true;

    /// A ray of `kind` starts; the parent multiplies its colour by
    /// `coefficient` (one for the camera ray), and `weight` is the largest
    /// factor by which it reaches the pixel.
    #[inline(always)]
    fn ray_start(&mut self, _kind: RayKind, _ray: &Ray, _coefficient: Color, _weight: f64) {}

    /// What the ray started last hit first, if anything.
    #[inline(always)]
    fn ray_hit(&mut self, _ray: &Ray, _hit: Option<(&Hit, &Surface)>) {}

    /// The hit surface is shaded with the shading normal `normal` (turned
    /// towards the viewer, tilted by a bump map); `entering` is true when
    /// the ray arrives on the outward side.
    #[inline(always)]
    fn shading(&mut self, _normal: Vec3, _entering: bool) {}

    /// One step of the shadow ray towards the light being considered.
    #[inline(always)]
    fn shadow_ray(&mut self, _ray: &Ray, _step: ShadowStep<'_>) {}

    /// The verdict on light `index`: `None` as `sample` when none of its
    /// light reaches the point (outside a spot's cone); `None` as
    /// `transmittance` when the surface faces away from it, so no shadow
    /// ray was traced; otherwise what of it arrives (zero: blocked).
    #[inline(always)]
    fn light(
        &mut self,
        _index: usize,
        _sample: Option<&LightSample>,
        _transmittance: Option<Color>,
    ) {
    }

    /// The caustic map's light at the point, `kd` times the irradiance of
    /// the photons gathered there, added to the local terms.
    #[inline(always)]
    fn caustic(&mut self, _term: Color) {}

    /// The ray is at the deepest recursion allowed: no secondary rays.
    #[inline(always)]
    fn depth_limit(&mut self) {}

    /// The surface's secondary rays: the weights of the mirror and
    /// refracted rays, the refracted direction (`None` under total internal
    /// reflection or for an opaque surface), and the indices of refraction
    /// on either side.
    #[inline(always)]
    fn lobes(&mut self, _mirror: Color, _refraction: Color, _refracted: bool, _indices: [f64; 2]) {}

    /// A secondary ray of `kind` with `coefficient` and pixel weight
    /// `weight` was not traced (its weight is under the cut-off, or the
    /// sample's budget of secondary rays is spent).
    #[inline(always)]
    fn branch_skipped(&mut self, _kind: RayKind, _coefficient: Color, _weight: f64) {}

    /// The ray started last passes `color` up to its parent (for the camera
    /// ray: the sample's colour).
    #[inline(always)]
    fn ray_end(&mut self, _color: Color) {}

    /// Whether the answer is no longer wanted (an explanation superseded):
    /// the integrator then starts no further shadow or secondary rays, and
    /// the colour it returns is not the sample's. Never, unless an
    /// observer says so.
    #[inline(always)]
    fn stopped(&self) -> bool {
        false
    }
}

/// The observer that watches nothing: what the renderer passes.
#[derive(Clone, Copy, Debug, Default)]
pub struct Unobserved;

impl RayObserver for Unobserved {
    const READS_UV: bool = false;
}

/// The observer that watches nothing and stops the sample once `0` is set
/// ([`RayObserver::stopped`]).
#[derive(Clone, Copy, Debug)]
pub struct Cancellable<'c>(pub &'c AtomicBool);

impl RayObserver for Cancellable<'_> {
    const READS_UV: bool = false;

    #[inline(always)]
    fn stopped(&self) -> bool {
        self.0.load(Ordering::Relaxed)
    }
}

/// The observer that keeps the camera ray's first hit and its surface,
/// for the per-pixel data (AOVs), and watches nothing else. It reads no
/// (u, v), so the surfaces it is shown are the renderer's own.
#[derive(Clone, Copy, Debug, Default)]
pub struct FirstHit {
    /// The camera ray's first hit and its surface, once it was traced
    /// (`None` also when it hit nothing).
    pub hit: Option<(Hit, Surface)>,
    seen: bool,
}

impl RayObserver for FirstHit {
    const READS_UV: bool = false;

    #[inline(always)]
    fn ray_hit(&mut self, _ray: &Ray, hit: Option<(&Hit, &Surface)>) {
        if !self.seen {
            self.seen = true;
            self.hit = hit.map(|(h, s)| (*h, *s));
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::Vec3;
    use crate::scene::default_scene;
    use crate::world::World;

    #[test]
    fn first_hit_keeps_the_camera_rays_hit_not_a_later_one() {
        let scene = default_scene();
        let world = World::new(&scene.objects);
        let down = Ray::new(Vec3::new(0.0, 50.0, 0.0), -Vec3::Y);
        let hit = world.intersect(&down).unwrap();
        let surface = world.surface(&down, &hit);
        let mut first = FirstHit::default();
        first.ray_hit(&down, Some((&hit, &surface)));
        first.ray_hit(&down, None);
        assert_eq!(first.hit, Some((hit, surface)));
        let mut missed = FirstHit::default();
        missed.ray_hit(&down, None);
        missed.ray_hit(&down, Some((&hit, &surface)));
        assert_eq!(missed.hit, None);
    }
}
