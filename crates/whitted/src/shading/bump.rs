//! Bump and normal maps: how a material tilts the shading normal.
//!
//! Scene syntax (TOML; see `docs/scene-format.md`):
//!
//! ```toml
//! [materials.stone]
//! normal_map = { image = "stone_normal.png", strength = 1, flip_green = false }
//! [materials.plaster]
//! bump_map = { image = "plaster_height.png", strength = 0.02 }
//! ```
//!
//! and in MTL files `norm`, `bump` or `map_Bump` (see `docs/obj.md`).
//!
//! - A **normal map** stores a tangent-space normal per texel, `rgb` in
//!   [0, 1] read as `2 rgb - 1`: x along the [`TangentFrame`]'s tangent
//!   (where `u` grows, the image's right), y along its bitangent (where `v`
//!   grows, the image's up: the OpenGL convention; `flip_green` reads
//!   DirectX maps, whose y points down), z along the shading normal. A
//!   `strength` scales x and y.
//! - A **bump map** is a height field: the texture's luminance times
//!   `strength` is a displacement along the normal, in scene units. Its
//!   slope is taken by central differences in texture space (half a texel
//!   either side for an image) and turned into a gradient on the surface
//!   through `dpdu` and `dpdv`; the normal tilts against it (pbrt-v4's
//!   `BumpMap`, without the curvature term).
//!
//! Both are computed on the outward side of the surface and the result is
//! then turned to the viewer's side, so a relief seen from behind is a
//! relief inverted. A tilted normal facing away from the viewer would shade
//! black (no light reaches such a facet, and mirror rays leave into the
//! surface); [`shading_normal`] bends it back until it makes an angle of at
//! most `acos(0.01)` with the direction to the viewer.

use crate::math::{DVec2, Vec3};
use crate::shading::Texture;
use crate::shading::tangent_frame::TangentFrame;
use crate::shading::texture::luminance;
use crate::world::Surface;

/// How far a tilted normal may turn from the viewer: the smallest cosine
/// allowed between it and the direction to the viewer.
const MIN_COS_TO_VIEWER: f64 = 0.01;

/// Texture-space step of the finite differences of a height field that is
/// not an image.
const PROCEDURAL_STEP: f64 = 1e-3;

/// What tilts a material's shading normal.
#[derive(Clone, Debug, PartialEq)]
pub enum Bump {
    /// A height field: the luminance of `texture` times `strength` is the
    /// displacement along the normal, in scene units.
    Height {
        /// The heights (luminance, usually in [0, 1]).
        texture: Texture,
        /// Scene units of displacement per unit of luminance (MTL `-bm`).
        strength: f64,
    },
    /// A tangent-space normal map.
    Normal {
        /// The normals, `rgb` in [0, 1] encoding `2 rgb - 1`.
        texture: Texture,
        /// Multiplies the tangential (x, y) part: 0 flattens, 1 is the map.
        strength: f64,
        /// Read y pointing down the image (DirectX maps).
        flip_green: bool,
    },
}

impl Bump {
    /// The tilted unit normal at texture coordinates `uv` of a surface
    /// with unit shading `normal` and derivatives `dpdu`, `dpdv`. The
    /// normal is returned unchanged where the tangents cannot orient a
    /// height field (they are parallel or vanish).
    pub fn perturb(&self, normal: Vec3, uv: DVec2, dpdu: Vec3, dpdv: Vec3) -> Vec3 {
        match self {
            Bump::Height { texture, strength } => {
                let slope = *strength * height_slope(texture, uv);
                tilt_by_height(normal, dpdu, dpdv, slope)
            }
            Bump::Normal {
                texture,
                strength,
                flip_green,
            } => {
                // A normal map stores a direction in its colour channels.
                let c = 2.0 * Vec3::from_array(texture.at(uv).to_array()) - Vec3::ONE;
                let y = if *flip_green { -c.y } else { c.y };
                let local = Vec3::new(*strength * c.x, *strength * y, c.z);
                TangentFrame::new(normal, dpdu, dpdv)
                    .to_world(local)
                    .try_normalize()
                    .unwrap_or(normal)
            }
        }
    }
}

/// The derivatives (∂h/∂u, ∂h/∂v) of the luminance of `texture` at `uv`,
/// by central differences.
fn height_slope(texture: &Texture, uv: DVec2) -> DVec2 {
    let step = match texture {
        Texture::Image(image) => {
            let texels = DVec2::new(image.data.width() as f64, image.data.height() as f64);
            let step = 0.5 / (texels * image.scale.abs());
            if step.is_finite() {
                step
            } else {
                DVec2::splat(PROCEDURAL_STEP)
            }
        }
        _ => DVec2::splat(PROCEDURAL_STEP),
    };
    let h = |du: f64, dv: f64| luminance(texture.at(uv + DVec2::new(du, dv)));
    DVec2::new(
        (h(step.x, 0.0) - h(-step.x, 0.0)) / (2.0 * step.x),
        (h(0.0, step.y) - h(0.0, -step.y)) / (2.0 * step.y),
    )
}

/// The normal of the surface displaced along unit `normal` by a height with
/// derivatives `slope` = (∂d/∂u, ∂d/∂v): `normalize(normal - ∇d)`, where the
/// surface gradient `∇d = ∂d/∂u ∇u + ∂d/∂v ∇v` comes from the dual basis of
/// `dpdu`, `dpdv` projected into the tangent plane. Unchanged when those
/// span no area.
fn tilt_by_height(normal: Vec3, dpdu: Vec3, dpdv: Vec3, slope: DVec2) -> Vec3 {
    let a = dpdu - normal * normal.dot(dpdu);
    let b = dpdv - normal * normal.dot(dpdv);
    let area = a.cross(b).dot(normal);
    if area.abs() <= 1e-12 * a.length() * b.length() || !area.is_finite() {
        return normal;
    }
    let grad_u = b.cross(normal) / area;
    let grad_v = normal.cross(a) / area;
    (normal - slope.x * grad_u - slope.y * grad_v)
        .try_normalize()
        .unwrap_or(normal)
}

/// The normal to shade `s` with, seen along `view` (unit, towards the
/// viewer), on the viewer's side of the geometric normal `facing`: the
/// shading normal turned to that side, tilted by `bump` if there is one and
/// then kept within `acos(0.01)` of facing away from the viewer.
pub fn shading_normal(bump: Option<&Bump>, s: &Surface, facing: Vec3, view: Vec3) -> Vec3 {
    let side = if s.shading_normal.dot(facing) < 0.0 {
        -1.0
    } else {
        1.0
    };
    let Some(bump) = bump else {
        return side * s.shading_normal;
    };
    let tilted = side * bump.perturb(s.shading_normal, s.uv, s.dpdu, s.dpdv);
    towards_viewer(tilted, view)
}

/// `normal` bent towards `view` (both unit) just enough that their cosine
/// is at least about [`MIN_COS_TO_VIEWER`].
fn towards_viewer(normal: Vec3, view: Vec3) -> Vec3 {
    let cos = normal.dot(view);
    if cos >= MIN_COS_TO_VIEWER {
        return normal;
    }
    (normal + (MIN_COS_TO_VIEWER - cos) * view)
        .try_normalize()
        .unwrap_or(view)
}

#[cfg(test)]
mod tests {
    use std::sync::Arc;

    use super::*;
    use crate::math::random::Rng;
    use crate::shading::Color;
    use crate::shading::texture::{ImageData, ImageTexture, Wrap};

    fn constant_normal_map(rgb: Color) -> Bump {
        Bump::Normal {
            texture: Texture::Constant(rgb),
            strength: 1.0,
            flip_green: false,
        }
    }

    /// A height image whose luminance grows linearly in u, from 0 at the
    /// left edge to `top` at the right, clamped at the edges.
    fn ramp_in_u(width: usize, top: f32) -> Texture {
        let texels = (0..width)
            .map(|x| [top * (x as f32 + 0.5) / width as f32; 3])
            .collect();
        let data = ImageData::new(width, 1, texels).unwrap();
        Texture::Image(ImageTexture {
            wrap: Wrap::Clamp,
            ..ImageTexture::new(Arc::new(data))
        })
    }

    #[test]
    fn a_flat_normal_map_leaves_the_normal_unchanged() {
        let mut rng = Rng::new(1);
        let flat = constant_normal_map(Color::new(0.5, 0.5, 1.0));
        for _ in 0..100 {
            let normal = rng.unit_vector();
            let (dpdu, dpdv) = (rng.unit_vector(), rng.unit_vector());
            let n = flat.perturb(normal, DVec2::ZERO, dpdu, dpdv);
            assert!((n - normal).length() < 1e-12, "{n} {normal}");
        }
    }

    #[test]
    fn a_normal_map_tilts_towards_u_and_v_as_the_image_says() {
        // (1, 0.5, 0.5) is +x, the image's right: along dpdu.
        let right = constant_normal_map(Color::new(1.0, 0.5, 0.5));
        let n = right.perturb(Vec3::Z, DVec2::ZERO, Vec3::new(0.0, 3.0, 0.0), -Vec3::X);
        assert!((n - Vec3::Y).length() < 1e-12, "{n}");
        // 45° towards the image's up, along dpdv, and down when flipped.
        let up = Color::new(0.5, 1.0, 1.0);
        let n = constant_normal_map(up).perturb(Vec3::Z, DVec2::ZERO, Vec3::X, Vec3::Y);
        assert!((n - Vec3::new(0.0, 1.0, 1.0).normalize()).length() < 1e-12);
        let flipped = Bump::Normal {
            texture: Texture::Constant(up),
            strength: 1.0,
            flip_green: true,
        };
        let n = flipped.perturb(Vec3::Z, DVec2::ZERO, Vec3::X, Vec3::Y);
        assert!((n - Vec3::new(0.0, -1.0, 1.0).normalize()).length() < 1e-12);
        let half = Bump::Normal {
            texture: Texture::Constant(up),
            strength: 0.5,
            flip_green: false,
        };
        let n = half.perturb(Vec3::Z, DVec2::ZERO, Vec3::X, Vec3::Y);
        assert!((n - Vec3::new(0.0, 0.5, 1.0).normalize()).length() < 1e-12);
    }

    #[test]
    fn a_constant_height_leaves_the_normal_unchanged() {
        let mut rng = Rng::new(2);
        let bump = Bump::Height {
            texture: Texture::Constant(Color::splat(0.7)),
            strength: 5.0,
        };
        for _ in 0..100 {
            let normal = rng.unit_vector();
            let uv = DVec2::new(rng.range(-2.0, 2.0), rng.range(-2.0, 2.0));
            let n = bump.perturb(normal, uv, rng.unit_vector(), rng.unit_vector());
            assert!((n - normal).length() < 1e-12);
        }
    }

    #[test]
    fn a_height_ramp_tilts_the_normal_downhill_by_its_slope() {
        // Luminance from 0 to 1 over u in [0, 1], times strength 0.5: on a
        // plane with u along x in scene units, the height rises 0.5 per
        // unit of x, so the normal leans 26.57° towards -x.
        let bump = Bump::Height {
            texture: ramp_in_u(64, 1.0),
            strength: 0.5,
        };
        let n = bump.perturb(Vec3::Z, DVec2::new(0.4, 0.5), Vec3::X, Vec3::Y);
        let expected = Vec3::new(-0.5, 0.0, 1.0).normalize();
        assert!((n - expected).length() < 1e-5, "{n}");
        // u running twice as fast over the surface (|dpdu| = 0.5) makes the
        // slope twice as steep; a v axis along -y does not matter.
        let n = bump.perturb(Vec3::Z, DVec2::new(0.4, 0.5), 0.5 * Vec3::X, -Vec3::Y);
        assert!(
            (n - Vec3::new(-1.0, 0.0, 1.0).normalize()).length() < 1e-5,
            "{n}"
        );
    }

    #[test]
    fn degenerate_tangents_leave_a_height_field_flat() {
        let bump = Bump::Height {
            texture: ramp_in_u(8, 1.0),
            strength: 1.0,
        };
        let n = bump.perturb(Vec3::Z, DVec2::splat(0.5), Vec3::ZERO, Vec3::Y);
        assert_eq!(n, Vec3::Z);
        let n = bump.perturb(Vec3::Z, DVec2::splat(0.5), Vec3::X, 2.0 * Vec3::X);
        assert_eq!(n, Vec3::Z);
    }

    #[test]
    fn normals_facing_away_from_the_viewer_are_bent_back() {
        let mut rng = Rng::new(4);
        for _ in 0..1000 {
            let (normal, view) = (rng.unit_vector(), rng.unit_vector());
            let n = towards_viewer(normal, view);
            assert!((n.length() - 1.0).abs() < 1e-12);
            assert!(n.dot(view) > 0.5 * MIN_COS_TO_VIEWER, "{n} {view}");
            if normal.dot(view) >= MIN_COS_TO_VIEWER {
                assert_eq!(n, normal);
            }
        }
        assert_eq!(towards_viewer(-Vec3::Z, Vec3::Z), Vec3::Z);
    }
}
