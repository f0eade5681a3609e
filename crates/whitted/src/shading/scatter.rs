//! What a material does with light: evaluating its Phong reflection for one
//! light direction, and sampling the ray (or photon) it scatters.
//!
//! Conventions shared by everything here:
//!
//! - Directions are unit vectors. `incident` travels towards the surface;
//!   `view = -incident` points back to where it came from.
//! - `n` is the unit shading normal turned to the incident side
//!   (`n · incident ≤ 0`), as the Whitted integrator turns it (two-sided
//!   shading, then [`crate::shading::shading_normal`]).
//! - `n_from` and `n_to` are the indices of refraction before and after the
//!   surface, from [`crate::shading::MediumStack::cross`] (a refracted ray
//!   then travels in that crossing's `after` media).
//! - Opacity `α` (see [`crate::shading::material`]): the present part `α`
//!   of the surface reflects `α kd` diffusely, `α kr` by mirror and
//!   transmits `α kt`; the dissolved part `1 - α` goes on along the
//!   refracted ray (straight on when the indices are equal). So the mirror
//!   gets `α kr` and the refracted ray `α kt + 1 - α`; with `fresnel`,
//!   `α (kr + kt F)` and `α kt (1 - F) + 1 - α`; under total internal
//!   reflection the refracted weight moves onto the mirror. These are
//!   exactly the weights of the Whitted integrator's secondary rays.
//! - The Phong highlight `ks` is a direct-lighting term only: it is in
//!   [`Material::eval`] but not among the scattered lobes (a photon is
//!   reflected diffusely, by mirror or refracted, or absorbed).

use crate::math::sampling::{about_axis, cosine_hemisphere};
use crate::math::{DVec2, Vec3};
use crate::shading::optics::{reflect, refract, schlick_reflectance};
use crate::shading::{Color, Material};

/// The Phong local reflection of light arriving from `to_light` (unit, from
/// the point towards the light) seen from `view` (unit), about the unit
/// normal `n`: `kd (N·L) + ks (R·V)^shininess`, and zero when `N·L ≤ 0`.
///
/// The same floating-point operations in the same order as the Whitted
/// integrator's direct lighting, so switching it to this changes no bit.
/// Taking the coefficients rather than a material lets a caller look its
/// textures up once for many lights.
#[inline]
pub fn phong(kd: Color, ks: Color, shininess: f64, n: Vec3, to_light: Vec3, view: Vec3) -> Color {
    let n_dot_l = n.dot(to_light);
    if n_dot_l <= 0.0 {
        return Color::ZERO;
    }
    let mut direct = kd * n_dot_l;
    let r_dot_v = reflect(-to_light, n).dot(view);
    if r_dot_v > 0.0 && ks != Color::ZERO {
        direct += ks * r_dot_v.powf(shininess);
    }
    direct
}

/// How a surface point splits the light arriving along one direction among
/// its scattering lobes: the weights (per channel) of its diffuse
/// reflection, its mirror ray and its refracted ray, opacity, Fresnel and
/// total internal reflection included (see the module documentation).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Lobes {
    /// `α kd`: the Lambertian part, scattered into the hemisphere of the
    /// normal (where a photon map stores photons).
    pub diffuse: Color,
    /// The weight of the mirror-reflected ray.
    pub mirror: Color,
    /// The weight of the refracted ray (zero under total internal
    /// reflection).
    pub refraction: Color,
    /// The unit refracted direction: present exactly when `refraction` is
    /// not zero.
    pub refracted: Option<Vec3>,
}

/// Which lobe a scattered ray was drawn from.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ScatterKind {
    /// Lambertian reflection, cosine-distributed about the normal.
    Diffuse,
    /// Mirror reflection (including Fresnel reflection and total internal
    /// reflection of the transmitted part).
    Mirror,
    /// Refraction by Snell's law, or straight through a dissolved surface.
    Refract,
}

impl ScatterKind {
    /// True for a direction fixed by the incident one (mirror and
    /// refraction: a delta distribution, which no other direction could
    /// have sampled); false for the diffuse lobe, whose direction has a
    /// density.
    pub fn is_specular(self) -> bool {
        !matches!(self, ScatterKind::Diffuse)
    }
}

/// A ray scattered by a surface, as a photon tracer follows it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ScatterSample {
    /// The unit direction it leaves in.
    pub direction: Vec3,
    /// What the carried power (or radiance) is multiplied by: per channel
    /// in `[0, 1]`, largest channel exactly 1, so nothing gains energy.
    pub weight: Color,
    /// The lobe it was drawn from.
    pub kind: ScatterKind,
    /// The probability that this lobe was chosen. For [`ScatterKind::Diffuse`]
    /// the direction additionally has the density
    /// [`crate::math::sampling::cosine_hemisphere_pdf`] of its cosine.
    pub probability: f64,
}

/// A surface point's coefficients, looked up from its material's textures
/// at one (u, v).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Weights {
    /// `α`, the opacity.
    pub opacity: Color,
    /// `kd`.
    pub diffuse: Color,
    /// `kr`.
    pub reflection: Color,
    /// `kt`.
    pub transmission: Color,
}

impl Lobes {
    /// The lobes of a point with coefficients `weights` (the transmission
    /// split by Schlick's term when `fresnel`), for light arriving along
    /// `incident` through the shading normal `n` between media of indices
    /// `n_from` and `n_to`. [`Material::lobes`] looks the coefficients up
    /// first; a caller that has them already (the Whitted integrator)
    /// passes them.
    #[inline]
    pub fn new(
        weights: Weights,
        fresnel: bool,
        incident: Vec3,
        n: Vec3,
        n_from: f64,
        n_to: f64,
    ) -> Self {
        let Weights {
            opacity: alpha,
            diffuse: kd,
            reflection: kr,
            transmission: kt,
        } = weights;
        let cos_i = (-incident).dot(n).clamp(0.0, 1.0);
        let (reflected, transmitted) = if fresnel && kt != Color::ZERO {
            let f = schlick_reflectance(cos_i, n_from, n_to);
            (kr + kt * f, kt * (1.0 - f))
        } else {
            (kr, kt)
        };
        let mut mirror = alpha * reflected;
        let mut refraction = alpha * transmitted + (Color::ONE - alpha);
        let refracted = if refraction == Color::ZERO {
            None
        } else {
            refract(incident, n, n_from / n_to)
        };
        if refracted.is_none() {
            mirror += refraction;
            refraction = Color::ZERO;
        }
        Lobes {
            diffuse: alpha * kd,
            mirror,
            refraction,
            refracted: refracted.map(Vec3::normalize),
        }
    }
}

impl Lobes {
    /// The fraction of the arriving light the surface scatters, per
    /// channel: the sum of the three lobes.
    pub fn albedo(&self) -> Color {
        self.diffuse + self.mirror + self.refraction
    }

    /// Draws the scattered ray for light arriving along `incident` at the
    /// normal `n` these lobes were computed for, or `None` if it is
    /// absorbed (Russian roulette). `u[0]` chooses the lobe, `u[1]` and
    /// `u[2]` the diffuse direction; all in `[0, 1)`.
    ///
    /// Each lobe is chosen with a probability equal to its largest channel,
    /// and its weight is the lobe divided by that channel, so a grey lobe
    /// passes the photon on unchanged and a coloured one filters it. The
    /// expected weight is then exactly the albedo when the lobes' largest
    /// channels sum to at most 1 (every energy-conserving grey surface, and
    /// most coloured ones). When they sum to `s > 1` (say red diffuse plus
    /// green mirror) the probabilities are divided by `s`, keeping each
    /// weight at most 1: the expected weight is then `albedo / s`, losing
    /// energy rather than letting one photon gain any.
    pub fn sample(&self, incident: Vec3, n: Vec3, u: [f64; 3]) -> Option<ScatterSample> {
        let lobes = [
            (ScatterKind::Diffuse, self.diffuse),
            (ScatterKind::Mirror, self.mirror),
            (ScatterKind::Refract, self.refraction),
        ];
        let largest = lobes.map(|(_, weight)| weight.max_element().max(0.0));
        let total: f64 = largest.iter().sum();
        let scale = if total > 1.0 { 1.0 / total } else { 1.0 };
        let mut below = 0.0;
        for ((kind, lobe), largest) in lobes.into_iter().zip(largest) {
            if largest <= 0.0 {
                continue;
            }
            let probability = largest * scale;
            below += probability;
            if u[0] >= below {
                continue;
            }
            let direction = match kind {
                ScatterKind::Diffuse => about_axis(cosine_hemisphere([u[1], u[2]]), n),
                ScatterKind::Mirror => reflect(incident, n),
                ScatterKind::Refract => self.refracted?,
            };
            return Some(ScatterSample {
                direction,
                weight: (lobe / largest).max(Color::ZERO),
                kind,
                probability,
            });
        }
        None
    }
}

impl Material {
    /// The Phong local reflection at `uv` for light from `to_light` seen
    /// from `view` about the shading normal `n` (all unit): `kd (N·L) + ks
    /// (R·V)^n`, zero when `N·L ≤ 0`. See [`phong`]: bit for bit what the
    /// Whitted integrator adds per light, before the caller's factors
    /// (opacity `α`, the shadow ray's transmittance, the light's arriving
    /// intensity) and its check that a bump-tilted normal does not see a
    /// light behind the geometric surface.
    pub fn eval(&self, uv: DVec2, n: Vec3, to_light: Vec3, view: Vec3) -> Color {
        phong(
            self.diffuse.at(uv),
            self.specular.at(uv),
            self.shininess,
            n,
            to_light,
            view,
        )
    }

    /// How the surface at `uv` splits light arriving along `incident`
    /// through the shading normal `n` (facing the incident side) between
    /// media of indices `n_from` and `n_to`: the same weights, by the same
    /// operations, as the Whitted integrator's reflected and refracted rays
    /// (module documentation).
    pub fn lobes(&self, uv: DVec2, incident: Vec3, n: Vec3, n_from: f64, n_to: f64) -> Lobes {
        let weights = Weights {
            opacity: self.opacity.at(uv),
            diffuse: self.diffuse.at(uv),
            reflection: self.reflection.at(uv),
            transmission: self.transmission.at(uv),
        };
        Lobes::new(weights, self.fresnel, incident, n, n_from, n_to)
    }

    /// Draws the ray (or photon) the surface at `uv` scatters when light
    /// arrives along `incident` through the shading normal `n` (facing the
    /// incident side) between media of indices `n_from` and `n_to`; `None`
    /// when it is absorbed. `u` holds three numbers in `[0, 1)`: the first
    /// picks diffuse, mirror or refraction, the other two the diffuse
    /// direction. See [`Lobes::sample`] for the probabilities and why no
    /// sample's weight exceeds 1.
    pub fn sample(
        &self,
        uv: DVec2,
        incident: Vec3,
        n: Vec3,
        n_from: f64,
        n_to: f64,
        u: [f64; 3],
    ) -> Option<ScatterSample> {
        self.lobes(uv, incident, n, n_from, n_to)
            .sample(incident, n, u)
    }

    /// True when the surface has no diffuse reflection anywhere: light
    /// leaves it only by mirror or refraction, so a photon map stores no
    /// photon on it. May say false for a surface that is dissolved
    /// wherever it is diffuse.
    pub fn is_specular(&self) -> bool {
        self.diffuse.is_black()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::random::Rng;

    fn random_color(rng: &mut Rng) -> Color {
        Color::new(rng.uniform(), rng.uniform(), rng.uniform())
    }

    fn three(rng: &mut Rng) -> [f64; 3] {
        [rng.uniform(), rng.uniform(), rng.uniform()]
    }

    /// A copy of the Whitted integrator's direct lighting per light as it
    /// was when `eval` was written (integrator/whitted.rs, `shade`).
    fn whitted_direct(
        diffuse: Color,
        specular: Color,
        shininess: f64,
        n: Vec3,
        to_light: Vec3,
        view: Vec3,
    ) -> Option<Color> {
        let n_dot_l = n.dot(to_light);
        if n_dot_l <= 0.0 {
            return None;
        }
        let mut direct = diffuse * n_dot_l;
        let r_dot_v = reflect(-to_light, n).dot(view);
        if r_dot_v > 0.0 && specular != Color::ZERO {
            direct += specular * r_dot_v.powf(shininess);
        }
        Some(direct)
    }

    /// A copy of the Whitted integrator's secondary-ray weights (`shade`),
    /// with the refracted direction it traces.
    fn whitted_weights(
        m: &Material,
        uv: DVec2,
        incident: Vec3,
        n: Vec3,
        n_from: f64,
        n_to: f64,
    ) -> (Color, Color, Option<Vec3>) {
        let view = -incident;
        let alpha = m.opacity.at(uv);
        let kr = m.reflection.at(uv);
        let kt = m.transmission.at(uv);
        let cos_i = view.dot(n).clamp(0.0, 1.0);
        let (reflected, transmitted) = if m.fresnel && kt != Color::ZERO {
            let f = schlick_reflectance(cos_i, n_from, n_to);
            (kr + kt * f, kt * (1.0 - f))
        } else {
            (kr, kt)
        };
        let mut reflected_weight = alpha * reflected;
        let mut transmitted_weight = alpha * transmitted + (Color::ONE - alpha);
        let refracted = if transmitted_weight == Color::ZERO {
            None
        } else {
            refract(incident, n, n_from / n_to)
        };
        if refracted.is_none() {
            reflected_weight += transmitted_weight;
            transmitted_weight = Color::ZERO;
        }
        (
            reflected_weight,
            transmitted_weight,
            refracted.map(|d| d.normalize()),
        )
    }

    fn random_material(rng: &mut Rng) -> Material {
        // Zero coefficients now and then, so every branch is taken.
        let maybe = |rng: &mut Rng| {
            if rng.uniform() < 0.25 {
                Color::ZERO
            } else {
                random_color(rng)
            }
        };
        let (diffuse, specular, reflection, transmission) =
            (maybe(rng), maybe(rng), maybe(rng), maybe(rng));
        let opacity = if rng.uniform() < 0.5 {
            Color::ONE
        } else {
            random_color(rng)
        };
        Material {
            diffuse: diffuse.into(),
            specular: specular.into(),
            shininess: rng.range(0.0, 200.0),
            reflection: reflection.into(),
            transmission: transmission.into(),
            ior: rng.range(1.0, 2.5),
            fresnel: rng.uniform() < 0.5,
            opacity: opacity.into(),
            ..Material::default()
        }
    }

    /// A random incident direction and a normal facing it.
    fn random_incidence(rng: &mut Rng) -> (Vec3, Vec3) {
        let incident = rng.unit_vector();
        let n = rng.unit_vector();
        (incident, if n.dot(incident) > 0.0 { -n } else { n })
    }

    #[test]
    fn eval_equals_the_whitted_direct_lighting_bit_for_bit() {
        let mut rng = Rng::new(2024);
        let uv = DVec2::ZERO;
        let mut lit = 0;
        for _ in 0..20_000 {
            let m = random_material(&mut rng);
            let (n, to_light, view) = (rng.unit_vector(), rng.unit_vector(), rng.unit_vector());
            let expected = whitted_direct(
                m.diffuse.at(uv),
                m.specular.at(uv),
                m.shininess,
                n,
                to_light,
                view,
            );
            let got = m.eval(uv, n, to_light, view);
            match expected {
                None => assert_eq!(got, Color::ZERO),
                Some(direct) => {
                    lit += 1;
                    let bits = |c: Color| c.to_array().map(f64::to_bits);
                    assert_eq!(bits(got), bits(direct), "{m:?} {n} {to_light} {view}");
                }
            }
        }
        // Both branches were exercised.
        assert!((5_000..15_000).contains(&lit), "{lit}");
    }

    #[test]
    fn eval_is_zero_for_a_light_behind_the_surface_even_with_a_highlight() {
        let m = Material {
            specular: Color::ONE.into(),
            ..Material::default()
        };
        let n = Vec3::Z;
        let to_light = Vec3::new(0.0, 0.6, -0.8);
        // The mirror of the light would be seen from here.
        let view = -reflect(-to_light, n);
        assert_eq!(m.eval(DVec2::ZERO, n, to_light, view), Color::ZERO);
        let lit = m.eval(DVec2::ZERO, n, Vec3::Z, Vec3::Z);
        assert_eq!(lit, Color::splat(0.8) + Color::ONE);
    }

    #[test]
    fn lobes_equal_the_whitted_secondary_weights_bit_for_bit() {
        let mut rng = Rng::new(7);
        let uv = DVec2::ZERO;
        let (mut total_internal, mut refracting) = (0, 0);
        for _ in 0..20_000 {
            let m = random_material(&mut rng);
            let (incident, n) = random_incidence(&mut rng);
            let (n_from, n_to) = if rng.uniform() < 0.5 {
                (1.0, m.ior)
            } else {
                (m.ior, 1.0)
            };
            let lobes = m.lobes(uv, incident, n, n_from, n_to);
            let (mirror, refraction, refracted) =
                whitted_weights(&m, uv, incident, n, n_from, n_to);
            assert_eq!(lobes.mirror, mirror);
            assert_eq!(lobes.refraction, refraction);
            assert_eq!(lobes.refracted, refracted);
            assert_eq!(lobes.diffuse, m.opacity.at(uv) * m.diffuse.at(uv));
            assert_eq!(lobes.refracted.is_some(), lobes.refraction != Color::ZERO);
            total_internal +=
                usize::from(refract(incident, n, n_from / n_to).is_none() && mirror != Color::ZERO);
            refracting += usize::from(refracted.is_some());
        }
        assert!(total_internal > 100 && refracting > 100);
    }

    #[test]
    fn a_perfect_mirror_always_reflects_with_full_weight() {
        let mirror = Material {
            diffuse: Color::ZERO.into(),
            reflection: Color::ONE.into(),
            ..Material::default()
        };
        let mut rng = Rng::new(5);
        for _ in 0..1000 {
            let (incident, n) = random_incidence(&mut rng);
            let s = mirror
                .sample(DVec2::ZERO, incident, n, 1.0, 1.0, three(&mut rng))
                .unwrap();
            assert_eq!(s.kind, ScatterKind::Mirror);
            assert_eq!(s.direction, reflect(incident, n));
            assert_eq!(s.weight, Color::ONE);
            assert_eq!(s.probability, 1.0);
        }
    }

    #[test]
    fn a_coloured_mirror_reflects_with_probability_of_its_largest_channel() {
        let kr = Color::new(0.8, 0.4, 0.2);
        let mirror = Material {
            diffuse: Color::ZERO.into(),
            reflection: kr.into(),
            ..Material::default()
        };
        let mut rng = Rng::new(6);
        let (incident, n) = (Vec3::new(0.6, 0.0, -0.8), Vec3::Z);
        let count = 100_000;
        let mut reflected = 0;
        for _ in 0..count {
            if let Some(s) = mirror.sample(DVec2::ZERO, incident, n, 1.0, 1.0, three(&mut rng)) {
                reflected += 1;
                assert_eq!(s.kind, ScatterKind::Mirror);
                assert_eq!(s.direction, reflect(incident, n));
                assert_eq!(s.weight, Color::new(1.0, 0.5, 0.25));
                assert_eq!(s.probability, 0.8);
            }
        }
        let fraction = reflected as f64 / count as f64;
        assert!((fraction - 0.8).abs() < 0.005, "{fraction}");
    }

    #[test]
    fn fresnel_glass_reflects_the_schlick_fraction_and_refracts_the_rest() {
        let glass = Material {
            diffuse: Color::ZERO.into(),
            transmission: Color::ONE.into(),
            ior: 1.5,
            fresnel: true,
            ..Material::default()
        };
        let mut rng = Rng::new(8);
        for degrees in [0.0f64, 40.0, 70.0, 85.0] {
            let theta = degrees.to_radians();
            let incident = Vec3::new(theta.sin(), 0.0, -theta.cos());
            let n = Vec3::Z;
            let f = schlick_reflectance(theta.cos(), 1.0, 1.5);
            let count = 100_000;
            let mut reflected = 0;
            for _ in 0..count {
                let s = glass
                    .sample(DVec2::ZERO, incident, n, 1.0, 1.5, three(&mut rng))
                    .expect("clear glass absorbs nothing");
                assert_eq!(s.weight, Color::ONE);
                match s.kind {
                    ScatterKind::Mirror => {
                        reflected += 1;
                        assert_eq!(s.direction, reflect(incident, n));
                    }
                    ScatterKind::Refract => {
                        let t = refract(incident, n, 1.0 / 1.5).unwrap().normalize();
                        assert_eq!(s.direction, t);
                    }
                    ScatterKind::Diffuse => panic!("glass has no diffuse lobe"),
                }
            }
            let fraction = reflected as f64 / count as f64;
            assert!(
                (fraction - f).abs() < 0.005,
                "{degrees}°: {fraction} vs {f}"
            );
        }
    }

    #[test]
    fn past_the_critical_angle_glass_reflects_everything() {
        let glass = Material {
            diffuse: Color::ZERO.into(),
            transmission: Color::splat(0.9).into(),
            ior: 1.5,
            ..Material::default()
        };
        // Leaving the glass at 60°, beyond its critical angle of 41.8°.
        let theta = 60f64.to_radians();
        let incident = Vec3::new(theta.sin(), 0.0, -theta.cos());
        let mut rng = Rng::new(9);
        let count = 10_000;
        let mut reflected = 0;
        for _ in 0..count {
            if let Some(s) = glass.sample(DVec2::ZERO, incident, Vec3::Z, 1.5, 1.0, three(&mut rng))
            {
                assert_eq!(s.kind, ScatterKind::Mirror);
                assert_eq!(s.weight, Color::ONE);
                reflected += 1;
            }
        }
        let fraction = reflected as f64 / count as f64;
        assert!((fraction - 0.9).abs() < 0.01, "{fraction}");
    }

    #[test]
    fn a_dissolved_surface_lets_photons_through_in_proportion_to_one_minus_alpha() {
        let half = Material {
            diffuse: Color::ZERO.into(),
            reflection: Color::splat(0.4).into(),
            opacity: Color::splat(0.5).into(),
            ..Material::default()
        };
        let incident = Vec3::new(0.6, 0.0, -0.8);
        let lobes = half.lobes(DVec2::ZERO, incident, Vec3::Z, 1.0, 1.0);
        assert_eq!(lobes.mirror, Color::splat(0.2));
        assert_eq!(lobes.refraction, Color::splat(0.5));
        // Index 1 on both sides: straight on.
        assert_eq!(lobes.refracted, Some(incident));
        let clear = Material {
            opacity: Color::ZERO.into(),
            ..half.clone()
        };
        let mut rng = Rng::new(10);
        for _ in 0..1000 {
            let s = clear
                .sample(DVec2::ZERO, incident, Vec3::Z, 1.0, 1.0, three(&mut rng))
                .unwrap();
            assert_eq!(s.kind, ScatterKind::Refract);
            assert_eq!((s.direction, s.weight), (incident, Color::ONE));
        }
        // Half dissolved: half the photons go straight on, a fifth are
        // mirrored (α kr), the rest are absorbed.
        let samples = 20_000;
        let (mut through, mut mirrored) = (0, 0);
        for _ in 0..samples {
            match half.sample(DVec2::ZERO, incident, Vec3::Z, 1.0, 1.0, three(&mut rng)) {
                Some(s) if s.kind == ScatterKind::Refract => {
                    assert_eq!(s.direction, incident);
                    through += 1;
                }
                Some(s) => {
                    assert_eq!(s.kind, ScatterKind::Mirror);
                    mirrored += 1;
                }
                None => {}
            }
        }
        let fraction = |n: i32| f64::from(n) / f64::from(samples);
        assert!((fraction(through) - 0.5).abs() < 0.02, "{through}");
        assert!((fraction(mirrored) - 0.2).abs() < 0.02, "{mirrored}");
    }

    #[test]
    fn diffuse_photons_leave_on_the_incident_side_cosine_distributed() {
        let matte = Material::default();
        let mut rng = Rng::new(11);
        let n = Vec3::new(0.0, 0.6, 0.8);
        let incident = -n;
        let count = 100_000;
        let (mut scattered, mut cos) = (0, 0.0);
        for _ in 0..count {
            if let Some(s) = matte.sample(DVec2::ZERO, incident, n, 1.0, 1.0, three(&mut rng)) {
                assert_eq!(s.kind, ScatterKind::Diffuse);
                assert!(!s.kind.is_specular());
                assert_eq!(s.weight, Color::ONE);
                assert!((s.direction.length() - 1.0).abs() < 1e-12);
                assert!(s.direction.dot(n) >= 0.0);
                scattered += 1;
                cos += s.direction.dot(n);
            }
        }
        let fraction = scattered as f64 / count as f64;
        assert!((fraction - 0.8).abs() < 0.005, "{fraction}");
        let mean_cos = cos / scattered as f64;
        assert!((mean_cos - 2.0 / 3.0).abs() < 0.005, "{mean_cos}");
    }

    #[test]
    fn no_sample_gains_energy_and_the_mean_weight_is_the_albedo() {
        let mut rng = Rng::new(12);
        let uv = DVec2::ZERO;
        let (mut exact, mut capped) = (0, 0);
        for _ in 0..60 {
            let m = random_material(&mut rng);
            let (incident, n) = random_incidence(&mut rng);
            let (n_from, n_to) = (1.0, m.ior);
            let lobes = m.lobes(uv, incident, n, n_from, n_to);
            let albedo = lobes.albedo();
            let largest = [lobes.diffuse, lobes.mirror, lobes.refraction]
                .map(Color::max_element)
                .iter()
                .sum::<f64>();
            let count = 20_000;
            let mut mean = Color::ZERO;
            for _ in 0..count {
                if let Some(s) = m.sample(uv, incident, n, n_from, n_to, three(&mut rng)) {
                    assert!(s.weight.max_element() <= 1.0, "{s:?}");
                    assert!(s.weight.min_element() >= 0.0, "{s:?}");
                    mean += s.weight;
                }
            }
            mean /= count as f64;
            // Never more than the albedo; exactly it unless the lobes'
            // largest channels sum past 1, then scaled down by that sum.
            let expected = if largest > 1.0 {
                capped += 1;
                albedo / largest
            } else {
                exact += 1;
                albedo
            };
            for (got, (want, most)) in mean
                .to_array()
                .into_iter()
                .zip(expected.to_array().into_iter().zip(albedo.to_array()))
            {
                assert!((got - want).abs() < 0.02, "{m:?}: {mean} vs {expected}");
                assert!(got <= most + 0.02);
            }
        }
        assert!(exact > 5 && capped > 5, "{exact} exact, {capped} capped");
    }

    #[test]
    fn specular_kinds_are_mirror_and_refraction() {
        assert!(ScatterKind::Mirror.is_specular());
        assert!(ScatterKind::Refract.is_specular());
        assert!(!ScatterKind::Diffuse.is_specular());
        assert!(!Material::default().is_specular());
        let glass = Material {
            diffuse: Color::ZERO.into(),
            transmission: Color::ONE.into(),
            ..Material::default()
        };
        assert!(glass.is_specular());
    }
}
