//! Four primitives tested against one ray at once: what each kernel's
//! backend offers for it ([`FourLanes`]; the world picks a kernel's, by
//! whether it has `f64` lanes). The portable backend offers nothing, and its
//! callers test one primitive at a time; the AVX backends test four
//! triangles ([`watertight4`](super::watertight_avx::watertight4)) or cull
//! four spheres ([`sphere_candidates4`](super::sphere_avx::sphere_candidates4))
//! in one register of four `f64`s, or one triangle against four rays
//! ([`watertight_rays4`](super::watertight_avx::watertight_rays4), a
//! packet's leaf), with the answers of the one-by-one tests bit for bit.

use super::triangle::RayShear;
#[cfg(target_arch = "x86_64")]
use super::watertight_avx::RayLanes4;
use crate::math::{Ray, Vec3};

/// Lanes per test.
pub const LANES: usize = 4;

/// What a four-lane triangle test found: which lanes hit, and each lane's
/// `t` and barycentric coordinates (meaningful for the lanes that hit).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Hits4 {
    /// Bit `i` set when lane `i` hit.
    pub mask: u32,
    /// The ray parameter per lane.
    pub t: [f64; LANES],
    /// The barycentric coordinate `b1` per lane.
    pub u: [f64; LANES],
    /// The barycentric coordinate `b2` per lane.
    pub v: [f64; LANES],
}

/// The four-lane tests of one backend.
///
/// # Safety of the methods
///
/// Each may be called only where the processor runs the backend's
/// instruction set: in a kernel of that backend (`accel::kernel::run`
/// enters one only for a processor that runs it), or after checking.
pub(crate) trait FourLanes {
    /// Whether the backend has any four-lane test: where it has none, its
    /// callers skip looking for runs of primitives to give them.
    const ANY: bool;

    /// The watertight test of `triangles` against `ray` (sheared by
    /// `shear`) ending at `t_max`, lane `i` for `triangles[i]`, each lane's
    /// answer [`watertight`](super::watertight)'s; `None` where the
    /// backend has no such test (the caller then tests one at a time).
    ///
    /// # Safety
    ///
    /// See the trait's doc.
    unsafe fn triangles(
        triangles: [&[Vec3; 3]; LANES],
        ray: &Ray,
        shear: &RayShear,
        t_max: f64,
    ) -> Option<Hits4>;

    /// The lanes (bit `i` for `centers[i]`, `radii[i]`) whose sphere the
    /// one-sphere test would not cull for `ray` ending at `t_max`; the
    /// others have no hit in `(t_min, t_max)`. `None` where the backend
    /// has no such test.
    ///
    /// # Safety
    ///
    /// See the trait's doc.
    unsafe fn sphere_candidates(
        centers: [&Vec3; LANES],
        radii: [&f64; LANES],
        ray: &Ray,
        t_max: f64,
    ) -> Option<u32>;

    /// Four rays set up to be tested together ([`FourLanes::rays`]).
    type Rays: Copy;

    /// The rays `rays` with their shears `shears` (the same ray in several
    /// lanes is fine), set up for [`FourLanes::triangle_across`]; `None`
    /// when the shears do not all make the same axis z, or where the
    /// backend has no such test.
    ///
    /// # Safety
    ///
    /// See the trait's doc.
    unsafe fn rays(rays: [&Ray; LANES], shears: [&RayShear; LANES]) -> Option<Self::Rays>;

    /// The triangle `corners` tested against each of the four rays of
    /// `rays`, lane `i`'s interval ending at `t_max[i]`: lane by lane what
    /// [`watertight`](super::watertight) returns for that ray.
    ///
    /// # Safety
    ///
    /// See the trait's doc.
    unsafe fn triangle_across(corners: &[Vec3; 3], rays: &Self::Rays, t_max: [f64; LANES])
    -> Hits4;
}

/// No rays: the portable backend never sets four up together.
#[derive(Clone, Copy, Debug)]
pub(crate) enum NoRays {}

/// The portable backend's: none, every primitive is tested on its own.
pub(crate) struct OneByOne;

impl FourLanes for OneByOne {
    const ANY: bool = false;

    #[inline(always)]
    unsafe fn triangles(_: [&[Vec3; 3]; LANES], _: &Ray, _: &RayShear, _: f64) -> Option<Hits4> {
        None
    }

    #[inline(always)]
    unsafe fn sphere_candidates(
        _: [&Vec3; LANES],
        _: [&f64; LANES],
        _: &Ray,
        _: f64,
    ) -> Option<u32> {
        None
    }

    type Rays = NoRays;

    #[inline(always)]
    unsafe fn rays(_: [&Ray; LANES], _: [&RayShear; LANES]) -> Option<NoRays> {
        None
    }

    #[inline(always)]
    unsafe fn triangle_across(_: &[Vec3; 3], rays: &NoRays, _: [f64; LANES]) -> Hits4 {
        match *rays {}
    }
}

/// The widest lanes this target has: [`AvxLanes`] on x86-64, none
/// ([`OneByOne`]) elsewhere. The walks of packets, which run only in AVX
/// kernels, use them.
#[cfg(target_arch = "x86_64")]
pub(crate) type WideLanes = AvxLanes;

/// As above: no four-lane tests on this target.
#[cfg(not(target_arch = "x86_64"))]
pub(crate) type WideLanes = OneByOne;

/// The AVX backends': four `f64` lanes.
#[cfg(target_arch = "x86_64")]
pub(crate) struct AvxLanes;

#[cfg(target_arch = "x86_64")]
impl FourLanes for AvxLanes {
    const ANY: bool = true;

    #[inline(always)]
    unsafe fn triangles(
        triangles: [&[Vec3; 3]; LANES],
        ray: &Ray,
        shear: &RayShear,
        t_max: f64,
    ) -> Option<Hits4> {
        // SAFETY: the caller's contract: the processor has AVX.
        Some(unsafe { super::watertight_avx::watertight4(triangles, ray, shear, t_max) })
    }

    #[inline(always)]
    unsafe fn sphere_candidates(
        centers: [&Vec3; LANES],
        radii: [&f64; LANES],
        ray: &Ray,
        t_max: f64,
    ) -> Option<u32> {
        // SAFETY: the caller's contract: the processor has AVX.
        Some(unsafe { super::sphere_avx::sphere_candidates4(centers, radii, ray, t_max) })
    }

    type Rays = RayLanes4;

    #[inline(always)]
    unsafe fn rays(rays: [&Ray; LANES], shears: [&RayShear; LANES]) -> Option<RayLanes4> {
        // SAFETY: the caller's contract: the processor has AVX.
        unsafe { RayLanes4::new(rays, shears) }
    }

    #[inline(always)]
    unsafe fn triangle_across(corners: &[Vec3; 3], rays: &RayLanes4, t_max: [f64; LANES]) -> Hits4 {
        // SAFETY: the caller's contract: the processor has AVX.
        unsafe { super::watertight_avx::watertight_rays4(corners, rays, t_max) }
    }
}
