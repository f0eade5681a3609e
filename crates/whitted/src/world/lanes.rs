//! The four-lane leaf tests of each kernel: [`LanesOf`] maps a kernel
//! (`accel::kernel`, which names no shape) to the tests of
//! `shape::FourLanes` its instruction set runs.

use std::marker::PhantomData;

use crate::accel::kernel::Kernel;
use crate::math::{Ray, Vec3};
use crate::shape::{FourLanes, Hits4, LANES, OneByOne, RayShear, WideLanes};

/// The four-lane tests of kernel `K`: the widest lanes where `K` has
/// `f64` lanes ([`Kernel::F64_LANES`]), none otherwise. Its methods keep
/// the contract of [`FourLanes`]: called in `K`'s kernel, they run only
/// what `K`'s instruction set has.
pub(super) struct LanesOf<K>(PhantomData<K>);

impl<K: Kernel> FourLanes for LanesOf<K> {
    const ANY: bool = K::F64_LANES && WideLanes::ANY;

    #[inline(always)]
    unsafe fn triangles(
        triangles: [&[Vec3; 3]; LANES],
        ray: &Ray,
        shear: &RayShear,
        t_max: f64,
    ) -> Option<Hits4> {
        // SAFETY: in `K`'s kernel, which has the wide lanes' features when
        // it has `f64` lanes.
        unsafe {
            if K::F64_LANES {
                WideLanes::triangles(triangles, ray, shear, t_max)
            } else {
                OneByOne::triangles(triangles, ray, shear, t_max)
            }
        }
    }

    #[inline(always)]
    unsafe fn sphere_candidates(
        centers: [&Vec3; LANES],
        radii: [&f64; LANES],
        ray: &Ray,
        t_max: f64,
    ) -> Option<u32> {
        // SAFETY: as above.
        unsafe {
            if K::F64_LANES {
                WideLanes::sphere_candidates(centers, radii, ray, t_max)
            } else {
                OneByOne::sphere_candidates(centers, radii, ray, t_max)
            }
        }
    }

    type Rays = <WideLanes as FourLanes>::Rays;

    #[inline(always)]
    unsafe fn rays(rays: [&Ray; LANES], shears: [&RayShear; LANES]) -> Option<Self::Rays> {
        // SAFETY: as above.
        unsafe {
            if K::F64_LANES {
                WideLanes::rays(rays, shears)
            } else {
                None
            }
        }
    }

    #[inline(always)]
    unsafe fn triangle_across(
        corners: &[Vec3; 3],
        rays: &Self::Rays,
        t_max: [f64; LANES],
    ) -> Hits4 {
        // SAFETY: as above; rays are set up only where `K` has the wide
        // lanes (`rays`).
        unsafe { WideLanes::triangle_across(corners, rays, t_max) }
    }
}
