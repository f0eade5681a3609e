//! Ray differentials (Igehy 1999, "Tracing ray differentials"): how a
//! ray's origin and direction change from one pixel to the next, carried
//! from the camera to each hit, through mirror reflection and refraction,
//! and turned there into the texture-space footprint of the pixel that
//! [`Texture::filtered`](crate::shading::Texture::filtered) averages over.
//!
//! - **Transfer** to a hit is Igehy's: the offset ray meets the tangent
//!   plane of the hit, `∂p = ∂o + t ∂d + ∂t d` with
//!   `∂t = −(∂o + t ∂d)·n / (d·n)`.
//! - **Footprint**: `∂p` is written as `∂u ∂p/∂u + ∂v ∂p/∂v` by least
//!   squares (the normal equations of the surface's two tangents); a
//!   surface whose tangents are degenerate (no (u, v)) gives none.
//! - **Reflection and refraction** use Igehy's derivatives of the mirror
//!   and Snell directions, which need the normal's change `∂n`. No shape
//!   gives `∂n/∂u`, `∂n/∂v`, so `∂n` is measured: the two neighbour rays
//!   are traced in the world ([`normal_differentials`]) and the change of
//!   the shading normal between the hit and theirs is `∂n`, exact for
//!   every shape, mesh normal interpolation and transform alike. Where a
//!   neighbour misses, or lands on another surface (more than a quarter of
//!   its offset off the tangent plane), that direction is taken as flat
//!   (`∂n = 0`).

use crate::math::{DVec2, Ray, Vec3};
use crate::world::{Surface, World};

/// How to filter textures: the render setting `texture_filter`.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum TextureFilter {
    /// Textures are looked up at the hit point only (point sampling of
    /// checkers, bilinear lookup of images): the pictures as they always
    /// were.
    #[default]
    None,
    /// Each camera ray carries ray differentials; images are sampled from
    /// a mipmap pyramid (trilinear) and checkers box-filtered over the
    /// pixel's footprint.
    Mipmap,
}

impl TextureFilter {
    /// Every filter, in the order the documentation lists them.
    pub const ALL: [TextureFilter; 2] = [TextureFilter::None, TextureFilter::Mipmap];

    /// The name in scene files and on the command line.
    pub fn name(self) -> &'static str {
        match self {
            TextureFilter::None => "none",
            TextureFilter::Mipmap => "mipmap",
        }
    }

    /// The filter called `name`.
    pub fn from_name(name: &str) -> Option<Self> {
        Self::ALL.into_iter().find(|f| f.name() == name)
    }
}

/// The change of a ray's origin and direction per pixel step in x and in
/// y of the image.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RayDifferential {
    /// ∂origin/∂x.
    pub dox: Vec3,
    /// ∂direction/∂x.
    pub ddx: Vec3,
    /// ∂origin/∂y.
    pub doy: Vec3,
    /// ∂direction/∂y.
    pub ddy: Vec3,
}

/// The area of texture space one pixel covers at a hit, to first order:
/// how (u, v) change per pixel step in x and in y.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Footprint {
    /// (∂u/∂x, ∂v/∂x).
    pub duv_dx: DVec2,
    /// (∂u/∂y, ∂v/∂y).
    pub duv_dy: DVec2,
}

impl Footprint {
    /// No extent: filtering reduces to a point lookup.
    pub const POINT: Footprint = Footprint {
        duv_dx: DVec2::ZERO,
        duv_dy: DVec2::ZERO,
    };

    /// The footprint of texture coordinates `uv · scale` (a texture's own
    /// placement).
    pub fn scaled(self, scale: DVec2) -> Footprint {
        Footprint {
            duv_dx: self.duv_dx * scale,
            duv_dy: self.duv_dy * scale,
        }
    }
}

/// A ray differential transferred to a hit: how the hit point moves per
/// pixel, and the footprint in the surface's (u, v).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct HitDifferential {
    /// ∂p/∂x on the tangent plane.
    pub dpdx: Vec3,
    /// ∂p/∂y on the tangent plane.
    pub dpdy: Vec3,
    /// ∂d/∂x of the ray that arrived.
    pub ddx: Vec3,
    /// ∂d/∂y of the ray that arrived.
    pub ddy: Vec3,
    /// The footprint in (u, v); [`Footprint::POINT`] where the surface has
    /// no usable (u, v) tangents.
    pub footprint: Footprint,
}

impl RayDifferential {
    /// Every derivative multiplied by `s` (a sample grid of `k × k` per
    /// pixel spaces its rays `1/k` of a pixel apart).
    pub fn scaled(self, s: f64) -> Self {
        Self {
            dox: self.dox * s,
            ddx: self.ddx * s,
            doy: self.doy * s,
            ddy: self.ddy * s,
        }
    }

    /// The differential moved along `ray` to its hit on `s` (Igehy's
    /// transfer onto the tangent plane), with the footprint there; `None`
    /// when an offset ray runs parallel to the tangent plane or a value is
    /// not finite.
    pub fn at_hit(&self, ray: &Ray, s: &Surface) -> Option<HitDifferential> {
        let n = s.normal;
        let d = ray.dir;
        let d_n = d.dot(n);
        if d_n == 0.0 {
            return None;
        }
        let t = (s.point - ray.origin).dot(d) / d.length_squared();
        let transfer = |d_o: Vec3, d_d: Vec3| {
            let moved = d_o + t * d_d;
            moved - (moved.dot(n) / d_n) * d
        };
        let dpdx = transfer(self.dox, self.ddx);
        let dpdy = transfer(self.doy, self.ddy);
        if !(dpdx.is_finite() && dpdy.is_finite()) {
            return None;
        }
        let footprint = uv_footprint(s.dpdu, s.dpdv, dpdx, dpdy).unwrap_or(Footprint::POINT);
        Some(HitDifferential {
            dpdx,
            dpdy,
            ddx: self.ddx,
            ddy: self.ddy,
            footprint,
        })
    }
}

/// Solves `dp = du dpdu + dv dpdv` in the least-squares sense for the two
/// pixel steps; `None` when the tangents are (nearly) parallel or zero.
fn uv_footprint(dpdu: Vec3, dpdv: Vec3, dpdx: Vec3, dpdy: Vec3) -> Option<Footprint> {
    let (a, b, c) = (dpdu.dot(dpdu), dpdu.dot(dpdv), dpdv.dot(dpdv));
    let det = a * c - b * b;
    if !(det > 1e-12 * a * c) || !det.is_finite() {
        return None;
    }
    let solve = |dp: Vec3| {
        let (ru, rv) = (dpdu.dot(dp), dpdv.dot(dp));
        DVec2::new((c * ru - b * rv) / det, (a * rv - b * ru) / det)
    };
    let footprint = Footprint {
        duv_dx: solve(dpdx),
        duv_dy: solve(dpdy),
    };
    (footprint.duv_dx.is_finite() && footprint.duv_dy.is_finite()).then_some(footprint)
}

/// The differential of the ray leaving `s.point` in the mirror direction
/// of `incident` (unit) about the unit normal `n` (facing the incoming
/// side), whose change per pixel is `dndx`, `dndy`.
pub fn reflected(hit: &HitDifferential, incident: Vec3, n: Vec3, dndx: Vec3, dndy: Vec3) -> RayDifferential {
    // r = d − 2 (d·n) n  ⇒  ∂r = ∂d − 2 [(d·n) ∂n + (∂d·n + d·∂n) n].
    let d_n = incident.dot(n);
    let turn = |dd: Vec3, dn: Vec3| dd - 2.0 * (d_n * dn + (dd.dot(n) + incident.dot(dn)) * n);
    RayDifferential {
        dox: hit.dpdx,
        ddx: turn(hit.ddx, dndx),
        doy: hit.dpdy,
        ddy: turn(hit.ddy, dndy),
    }
}

/// The differential of the ray refracted from `incident` (unit) into
/// `refracted` (unit) through the unit normal `n` (facing the incoming
/// side) with relative index `eta = n_from / n_to`, the normal changing by
/// `dndx`, `dndy` per pixel.
pub fn refracted(
    hit: &HitDifferential,
    incident: Vec3,
    refracted: Vec3,
    n: Vec3,
    eta: f64,
    dndx: Vec3,
    dndy: Vec3,
) -> RayDifferential {
    // t = η d + μ n with μ = η c − c', c = −d·n, c' = −t·n:
    // ∂t = η ∂d + μ ∂n + ∂μ n, ∂μ = (η − η² c / c') ∂c, ∂c = −(∂d·n + d·∂n).
    let c = -incident.dot(n);
    let c_t = -refracted.dot(n);
    let mu = eta * c - c_t;
    let bend = |dd: Vec3, dn: Vec3| {
        let dc = -(dd.dot(n) + incident.dot(dn));
        let dmu = if c_t > 0.0 {
            (eta - eta * eta * c / c_t) * dc
        } else {
            0.0
        };
        eta * dd + mu * dn + dmu * n
    };
    RayDifferential {
        dox: hit.dpdx,
        ddx: bend(hit.ddx, dndx),
        doy: hit.dpdy,
        ddy: bend(hit.ddy, dndy),
    }
}

/// The change of the shading normal per pixel step in x and in y at the
/// hit `s` of `ray`, measured by tracing the two neighbour rays in
/// `world`: each gives its shading normal minus the hit's (both turned to
/// the side of `facing`), or zero (flat) where the neighbour misses or
/// lands on another surface. Costs two closest-hit queries.
pub fn normal_differentials(
    world: &World<'_>,
    ray: &Ray,
    differential: &RayDifferential,
    hit: &HitDifferential,
    s: &Surface,
    facing: Vec3,
) -> (Vec3, Vec3) {
    let oriented = |n: Vec3| if n.dot(facing) < 0.0 { -n } else { n };
    let n = oriented(s.shading_normal);
    let change = |d_o: Vec3, d_d: Vec3, dp: Vec3| {
        let neighbour = Ray::new(ray.origin + d_o, ray.dir + d_d);
        let Some(other) = world.intersect(&neighbour) else {
            return Vec3::ZERO;
        };
        let there = world.surface(&neighbour, &other);
        let predicted = s.point + dp;
        let off_plane = (there.point - predicted).length();
        if !(off_plane <= 0.25 * dp.length()) {
            return Vec3::ZERO;
        }
        oriented(there.shading_normal) - n
    };
    (
        change(differential.dox, differential.ddx, hit.dpdx),
        change(differential.doy, differential.ddy, hit.dpdy),
    )
}

/// What a hit needs to pass a differential on to its reflected and
/// refracted rays: the differential there and the normal's change.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Bend {
    hit: HitDifferential,
    incident: Vec3,
    n: Vec3,
    dndx: Vec3,
    dndy: Vec3,
}

impl Bend {
    /// At the hit `s` of `ray` (whose differential is `differential`,
    /// `hit` there), where the unit shading normal `n` faces the incoming
    /// side `facing`; measures the normal's change in `world`
    /// ([`normal_differentials`]).
    pub fn new(
        world: &World<'_>,
        ray: &Ray,
        differential: &RayDifferential,
        hit: HitDifferential,
        s: &Surface,
        facing: Vec3,
        n: Vec3,
    ) -> Self {
        let (dndx, dndy) = normal_differentials(world, ray, differential, &hit, s, facing);
        Self {
            hit,
            incident: ray.dir,
            n,
            dndx,
            dndy,
        }
    }

    /// The differential of the mirror-reflected ray.
    pub fn reflected(&self) -> RayDifferential {
        reflected(&self.hit, self.incident, self.n, self.dndx, self.dndy)
    }

    /// The differential of the ray refracted into `direction` (unit) with
    /// relative index `eta = n_from / n_to`.
    pub fn refracted(&self, direction: Vec3, eta: f64) -> RayDifferential {
        refracted(
            &self.hit,
            self.incident,
            direction,
            self.n,
            eta,
            self.dndx,
            self.dndy,
        )
    }
}
