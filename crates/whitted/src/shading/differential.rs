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
    if !det.is_finite() || det <= 1e-12 * a * c {
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
pub fn reflected(
    hit: &HitDifferential,
    incident: Vec3,
    n: Vec3,
    dndx: Vec3,
    dndy: Vec3,
) -> RayDifferential {
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
        if off_plane.is_nan() || off_plane > 0.25 * dp.length() {
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::accel::AccelKind;
    use crate::math::Transform;
    use crate::shading::optics::{reflect, refract};
    use crate::shape::{Plane, Shape, Sphere};
    use crate::world::{MaterialId, Objects};

    /// A pinhole at the origin looking along +z: the ray through image
    /// position (x, y), where one unit of x or y turns the view by
    /// `PIXEL` radians (to first order), and its differential.
    const PIXEL: f64 = 2e-3;

    fn pixel_ray(x: f64, y: f64) -> Ray {
        let v = Vec3::new(PIXEL * x, PIXEL * y, 1.0);
        Ray::new(Vec3::new(0.0, 0.0, -6.0), v.normalize())
    }

    fn pixel_differential(x: f64, y: f64) -> RayDifferential {
        let v = Vec3::new(PIXEL * x, PIXEL * y, 1.0);
        let d = v.normalize();
        let unit = |dv: Vec3| (dv - d.dot(dv) * d) / v.length();
        RayDifferential {
            dox: Vec3::ZERO,
            ddx: unit(Vec3::new(PIXEL, 0.0, 0.0)),
            doy: Vec3::ZERO,
            ddy: unit(Vec3::new(0.0, PIXEL, 0.0)),
        }
    }

    /// The hit of `ray` and its shading normal turned against the ray.
    fn hit(world: &World<'_>, ray: &Ray) -> (Surface, Vec3) {
        let h = world.intersect(ray).expect("the ray hits");
        let s = world.surface(ray, &h);
        let n = if s.shading_normal.dot(ray.dir) > 0.0 {
            -s.shading_normal
        } else {
            s.shading_normal
        };
        (s, n)
    }

    /// A sphere squashed by a transform (an ellipsoid: the differential
    /// goes through the instance's transform), and a tilted plane.
    fn objects() -> Vec<Objects> {
        let mut ellipsoid = Objects::default();
        let squash = Transform::scale(Vec3::new(1.3, 0.8, 1.0)).unwrap();
        let sphere = Sphere::new(Vec3::ZERO, 1.5).unwrap();
        ellipsoid.add_primitive(Shape::Sphere(sphere), MaterialId(0), squash);
        let mut plane = Objects::default();
        let p = Plane::new(Vec3::new(0.0, 0.0, 1.0), Vec3::new(0.3, -0.2, -1.0)).unwrap();
        plane.add_primitive(Shape::Plane(p), MaterialId(0), Transform::IDENTITY);
        vec![ellipsoid, plane]
    }

    fn close(a: Vec3, b: Vec3, tolerance: f64) -> bool {
        (a - b).length() <= tolerance * b.length().max(1e-9)
    }

    const PIXELS: [(f64, f64); 4] = [(40.0, -20.0), (120.0, 40.0), (-90.0, 40.0), (60.0, -90.0)];

    #[test]
    fn the_transferred_differential_matches_neighbouring_hits_and_their_uv() {
        for objects in objects() {
            let world = World::build(&objects, AccelKind::default());
            for (x, y) in PIXELS {
                let ray = pixel_ray(x, y);
                let (s, _) = hit(&world, &ray);
                let h = pixel_differential(x, y).at_hit(&ray, &s).unwrap();
                let e = 1e-3;
                let (sx0, _) = hit(&world, &pixel_ray(x - e, y));
                let (sx1, _) = hit(&world, &pixel_ray(x + e, y));
                let (sy0, _) = hit(&world, &pixel_ray(x, y - e));
                let (sy1, _) = hit(&world, &pixel_ray(x, y + e));
                let fx = (sx1.point - sx0.point) / (2.0 * e);
                let fy = (sy1.point - sy0.point) / (2.0 * e);
                assert!(close(h.dpdx, fx, 1e-5), "{} {fx}", h.dpdx);
                assert!(close(h.dpdy, fy, 1e-5), "{} {fy}", h.dpdy);
                let ux = (sx1.uv - sx0.uv) / (2.0 * e);
                let uy = (sy1.uv - sy0.uv) / (2.0 * e);
                let f = h.footprint;
                assert!(
                    (f.duv_dx - ux).length() < 1e-5 * ux.length().max(1e-6),
                    "{f:?} {ux}"
                );
                assert!(
                    (f.duv_dy - uy).length() < 1e-5 * uy.length().max(1e-6),
                    "{f:?} {uy}"
                );
            }
        }
    }

    /// The reflected and refracted differentials against the reflected and
    /// refracted rays of the neighbouring pixels (a quarter pixel either
    /// side, the differential scaled to that step as for 16 samples per
    /// pixel). The normal's change is measured over one step forward, so it
    /// is first-order accurate in the step: 0.3% to 4% off over a whole
    /// pixel here, a quarter of that over a quarter pixel.
    #[test]
    fn reflection_and_refraction_match_traced_neighbour_rays() {
        let eta = 1.0 / 1.5;
        let step = 0.25;
        for objects in objects() {
            let world = World::build(&objects, AccelKind::default());
            for (x, y) in PIXELS {
                let ray = pixel_ray(x, y);
                let differential = pixel_differential(x, y).scaled(step);
                let (s, n) = hit(&world, &ray);
                let h = differential.at_hit(&ray, &s).unwrap();
                let bend = Bend::new(&world, &ray, &differential, h, &s, n, n);
                let t = refract(ray.dir, n, eta).unwrap();
                let (r_diff, t_diff) = (bend.reflected(), bend.refracted(t, eta));
                let outgoing = |x: f64, y: f64| {
                    let ray = pixel_ray(x, y);
                    let (s, n) = hit(&world, &ray);
                    let r = reflect(ray.dir, n);
                    (s.point, r, refract(ray.dir, n, eta).unwrap())
                };
                let (px0, rx0, tx0) = outgoing(x - step, y);
                let (px1, rx1, tx1) = outgoing(x + step, y);
                let (py0, ry0, ty0) = outgoing(x, y - step);
                let (py1, ry1, ty1) = outgoing(x, y + step);
                let fd = |a: Vec3, b: Vec3| (b - a) / 2.0;
                let tolerance = 0.02;
                assert!(close(r_diff.dox, fd(px0, px1), tolerance));
                assert!(close(r_diff.doy, fd(py0, py1), tolerance));
                let (frx, fry) = (fd(rx0, rx1), fd(ry0, ry1));
                assert!(close(r_diff.ddx, frx, tolerance), "{} {frx}", r_diff.ddx);
                assert!(close(r_diff.ddy, fry, tolerance), "{} {fry}", r_diff.ddy);
                let (ftx, fty) = (fd(tx0, tx1), fd(ty0, ty1));
                assert!(close(t_diff.ddx, ftx, tolerance), "{} {ftx}", t_diff.ddx);
                assert!(close(t_diff.ddy, fty, tolerance), "{} {fty}", t_diff.ddy);
            }
        }
    }

    /// Taking the surface as flat gets a curved mirror wrong: the test
    /// above can fail.
    #[test]
    fn a_flat_normal_misses_the_curvature_of_the_ellipsoid() {
        let objects = objects();
        let world = World::build(&objects[0], AccelKind::default());
        let (x, y) = PIXELS[1];
        let ray = pixel_ray(x, y);
        let (s, n) = hit(&world, &ray);
        let h = pixel_differential(x, y).at_hit(&ray, &s).unwrap();
        let flat = reflected(&h, ray.dir, n, Vec3::ZERO, Vec3::ZERO);
        let curved = Bend::new(&world, &ray, &pixel_differential(x, y), h, &s, n, n).reflected();
        assert!(
            !close(flat.ddx, curved.ddx, 0.5),
            "{} {}",
            flat.ddx,
            curved.ddx
        );
    }

    #[test]
    fn tangents_without_area_give_no_footprint() {
        let dp = Vec3::new(1.0, 0.0, 0.0);
        assert_eq!(uv_footprint(dp, 2.0 * dp, dp, dp), None);
        assert_eq!(uv_footprint(dp, Vec3::ZERO, dp, dp), None);
    }
}
