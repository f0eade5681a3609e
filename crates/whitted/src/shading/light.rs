//! Light sources: point, directional and spot lights.
//!
//! Distance attenuation is `f_att = 1 / (constant + linear·d + quadratic·d²)`
//! (not clamped: `[1, 0, 0]`, the default, means no fall-off). A spot light
//! (Warn's model) scales its intensity by `cos(α)^falloff` for directions at
//! angle `α` from its axis, and is dark beyond its cut-off angle.
//!
//! A light is used two ways: towards a point ([`Light::sample`],
//! [`Light::sample_towards`]: the light arriving there, for direct lighting
//! and shadow rays) and from the light ([`Light::power`], [`Light::emit`] in
//! [`crate::shading::emission`]: its flux and the rays it sends out, for
//! photon tracing).
//!
//! An area light ([`crate::shading::area_light`]) is one more variant:
//! [`Light::sample_towards`] picks a point on it from its two numbers, and
//! [`direct_samples`] gives the stratified samples of every light that
//! shade one point (one for a point, spot or directional light).

use crate::math::Vec3;
use crate::math::random::hash64;
use crate::math::sampling::pixel_sample;
use crate::shading::Color;
use crate::shading::area_light::AreaLight;

/// Distance fall-off coefficients.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Attenuation {
    /// Constant term.
    pub constant: f64,
    /// Linear term.
    pub linear: f64,
    /// Quadratic term.
    pub quadratic: f64,
}

impl Default for Attenuation {
    fn default() -> Self {
        Self::NONE
    }
}

impl Attenuation {
    /// No fall-off with distance.
    pub const NONE: Self = Self {
        constant: 1.0,
        linear: 0.0,
        quadratic: 0.0,
    };

    /// The factor at distance `d`.
    #[inline]
    pub fn factor(&self, d: f64) -> f64 {
        let denominator = self.constant + d * (self.linear + d * self.quadratic);
        if denominator > 0.0 {
            1.0 / denominator
        } else {
            0.0
        }
    }
}

/// A light source.
#[derive(Clone, Debug, PartialEq)]
pub enum Light {
    /// Light from a point, in all directions.
    Point {
        /// Where the light is.
        position: Vec3,
        /// Its colour and strength.
        intensity: Color,
        /// How it falls off with distance.
        attenuation: Attenuation,
    },
    /// Parallel light from infinitely far away.
    Directional {
        /// The unit direction the light travels in.
        direction: Vec3,
        /// Its colour and strength.
        intensity: Color,
    },
    /// Light from a point, in a cone.
    Spot {
        /// Where the light is.
        position: Vec3,
        /// The unit direction of the cone's axis.
        direction: Vec3,
        /// Its colour and strength on the axis.
        intensity: Color,
        /// Cosine of the cone's half-angle; darker beyond.
        cos_cutoff: f64,
        /// Warn exponent: how fast it dims away from the axis.
        falloff: f64,
        /// How it falls off with distance.
        attenuation: Attenuation,
    },
    /// A glowing rectangle, disk or sphere: soft shadows.
    Area(AreaLight),
}

/// What a light delivers to one point.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LightSample {
    /// Unit vector from the point towards the light.
    pub to_light: Vec3,
    /// Distance to the light (infinite for directional lights; for an area
    /// light, just short of the sampled point, see
    /// [`crate::shading::area_light::SHADOW_GAP`]).
    pub distance: f64,
    /// Arriving intensity, with attenuation and spot fall-off applied.
    pub intensity: Color,
}

impl Light {
    /// The light arriving at `p`, or `None` when none can (outside a spot's
    /// cone, or at the light's own position). For an area light, the whole
    /// estimate from the middle of its sample square.
    ///
    /// The arms give a direction, a distance and a factor on the light's
    /// intensity, and one sample is built after them: samples built in each
    /// arm met in memory, a stall (docs/performance-log.md).
    #[inline(always)]
    pub fn sample(&self, p: Vec3) -> Option<LightSample> {
        let (to_light, distance, intensity, factor) = match self {
            Light::Point {
                position,
                intensity,
                attenuation,
            } => {
                let (to_light, distance) = direction_to(*position, p)?;
                (to_light, distance, intensity, attenuation.factor(distance))
            }
            Light::Directional {
                direction,
                intensity,
            } => (-*direction, f64::INFINITY, intensity, 1.0),
            Light::Spot {
                position,
                direction,
                intensity,
                cos_cutoff,
                falloff,
                attenuation,
            } => {
                let (to_light, distance) = direction_to(*position, p)?;
                let cos_axis = -to_light.dot(*direction);
                if cos_axis < *cos_cutoff || cos_axis <= 0.0 {
                    return None;
                }
                let cone = if *falloff == 0.0 {
                    1.0
                } else {
                    cos_axis.powf(*falloff)
                };
                (
                    to_light,
                    distance,
                    intensity,
                    cone * attenuation.factor(distance),
                )
            }
            Light::Area(area) => return area.sample(p, [0.5, 0.5], 1),
        };
        Some(LightSample {
            to_light,
            distance,
            intensity: *intensity * factor,
        })
    }
}

impl Light {
    /// The light arriving at `p` from one point of the light chosen by `u`
    /// (two numbers in `[0, 1)`), or `None` when none can arrive.
    ///
    /// Point, directional and spot lights are single points or directions,
    /// so `u` is not used and this is [`Light::sample`]; the sample is here
    /// so that an area light can choose its point (and divide by that
    /// choice's density) behind the same call.
    #[inline]
    pub fn sample_towards(&self, p: Vec3, u: [f64; 2]) -> Option<LightSample> {
        match self {
            Light::Area(area) => area.sample(p, u, 1),
            _ => self.sample(p),
        }
    }

    /// How many samples shade one point: an area light's `samples`, 1
    /// for the others.
    pub fn sample_count(&self) -> u32 {
        match self {
            Light::Area(area) => area.samples.max(1),
            _ => 1,
        }
    }
}

/// Every sample of the direct light of `lights` at `p`, with its light
/// and the light's index:
/// [`Light::sample`] for a point, spot or directional light, and an area
/// light's `samples` stratified points (Kensler's pattern over its sample
/// square), each carrying its share of the estimate. The pattern is chosen
/// by a hash of `p`'s coordinates, a function of the pixel sample alone,
/// so the picture is the same for any number of threads.
pub fn direct_samples(lights: &[Light], p: Vec3) -> DirectSamples<'_> {
    DirectSamples {
        lights,
        p,
        light: 0,
        index: 0,
        count: 0,
        pattern: 0,
    }
}

/// The iterator [`direct_samples`] returns: a loop over the lights and
/// each light's samples written out, which costs less per shaded point
/// than the nested iterator adapters it replaced (docs/performance-log.md).
#[derive(Clone, Debug)]
pub struct DirectSamples<'l> {
    lights: &'l [Light],
    p: Vec3,
    /// The light whose samples come next.
    light: usize,
    /// The next sample of that light, of `count` (0 before its first).
    index: u32,
    count: u32,
    /// The area light's sample pattern.
    pattern: u32,
}

impl<'l> DirectSamples<'l> {
    /// The same samples, made [`AHEAD`] at a time before any is handed out:
    /// each takes a square root and divisions that do not depend on the
    /// others, so made together they overlap, where a shadow ray traced
    /// between two of them would keep each waiting for the last.
    pub fn ahead(self) -> SamplesAhead<'l> {
        SamplesAhead {
            samples: self,
            ready: [None; AHEAD - 1],
            next: AHEAD - 1,
        }
    }
}

/// How many light samples [`SamplesAhead`] makes at a time.
const AHEAD: usize = 4;

/// The iterator [`DirectSamples::ahead`] returns.
#[derive(Clone, Debug)]
pub struct SamplesAhead<'l> {
    samples: DirectSamples<'l>,
    /// The samples made after the one handed out with them.
    ready: [Option<(usize, &'l Light, LightSample)>; AHEAD - 1],
    /// The next of `ready` to hand out; `AHEAD - 1` when all were.
    next: usize,
}

impl<'l> Iterator for SamplesAhead<'l> {
    type Item = (usize, &'l Light, LightSample);

    /// The first sample of each batch goes out as it is made, in
    /// registers: stored with the others and read back at once, its read
    /// waited on those stores (see docs/performance-log.md, "Light samples
    /// handed out in registers"). The others are read a shadow ray later,
    /// from the cache.
    #[inline(always)]
    fn next(&mut self) -> Option<Self::Item> {
        if let Some(slot) = self.ready.get_mut(self.next) {
            let sample = slot.take();
            self.next = if sample.is_some() {
                self.next + 1
            } else {
                AHEAD - 1
            };
            return sample;
        }
        let first = self.samples.next();
        if first.is_some() {
            // Every slot is empty here (each was taken or never filled),
            // and after its first `None` the samples give only `None`.
            for slot in &mut self.ready {
                *slot = self.samples.next();
                if slot.is_none() {
                    break;
                }
            }
            self.next = 0;
        }
        first
    }
}

impl<'l> Iterator for DirectSamples<'l> {
    type Item = (usize, &'l Light, LightSample);

    #[inline(always)]
    fn next(&mut self) -> Option<Self::Item> {
        while let Some(light) = self.lights.get(self.light) {
            let light_index = self.light;
            if let Light::Area(area) = light {
                if self.index == 0 {
                    self.count = light.sample_count();
                    self.pattern = point_hash(self.p);
                }
                let index = self.index;
                self.index += 1;
                if self.index >= self.count {
                    self.light += 1;
                    self.index = 0;
                }
                let u = pixel_sample(index, self.count, self.pattern);
                if let Some(sample) = area.sample(self.p, [u.x, u.y], self.count) {
                    return Some((light_index, light, sample));
                }
            } else {
                self.light += 1;
                if let Some(sample) = light.sample(self.p) {
                    return Some((light_index, light, sample));
                }
            }
        }
        None
    }
}

/// A 32-bit hash of a point's coordinates, to pick a sample pattern.
fn point_hash(p: Vec3) -> u32 {
    let h = hash64(p.x.to_bits() ^ hash64(p.y.to_bits() ^ hash64(p.z.to_bits())));
    (h >> 32) as u32
}

fn direction_to(position: Vec3, p: Vec3) -> Option<(Vec3, f64)> {
    let delta = position - p;
    let distance = delta.length();
    (distance > 0.0 && distance.is_finite()).then(|| (delta / distance, distance))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::shading::{AreaLight, Emitter};

    #[test]
    fn direct_samples_are_each_light_s_samples_in_order() {
        let point = |y: f64| Light::Point {
            position: Vec3::new(0.3, y, 0.0),
            intensity: Color::ONE,
            attenuation: Attenuation::default(),
        };
        let area = |samples: u32| {
            Light::Area(AreaLight {
                emitter: Emitter::Disk {
                    center: Vec3::new(0.0, 2.0, 0.0),
                    normal: -Vec3::Y,
                    radius: 1.0,
                },
                radiance: Color::splat(2.0),
                samples,
            })
        };
        // The second point light sits on the point: it has no sample.
        let lights = [
            point(2.0),
            area(4),
            point(0.0),
            area(1),
            area(9),
            point(-3.0),
        ];
        let p = Vec3::new(0.3, 0.0, 0.0);
        let mut expected = Vec::new();
        for (i, light) in lights.iter().enumerate() {
            let count = light.sample_count();
            for k in 0..count {
                let sample = match light {
                    Light::Area(a) => {
                        let u = pixel_sample(k, count, point_hash(p));
                        a.sample(p, [u.x, u.y], count)
                    }
                    _ => light.sample(p),
                };
                expected.extend(sample.map(|s| (i, light, s)));
            }
        }
        let got: Vec<_> = direct_samples(&lights, p).collect();
        assert_eq!(expected.len(), 1 + 4 + 1 + 9 + 1);
        assert_eq!(got, expected);
        // Made ahead, the same samples in the same order, for any number of
        // lights around the batch size; and none after the last.
        for n in 0..=lights.len() {
            let plain: Vec<_> = direct_samples(&lights[..n], p).collect();
            let mut ahead = direct_samples(&lights[..n], p).ahead();
            let made: Vec<_> = ahead.by_ref().collect();
            assert_eq!(made, plain, "{n} lights");
            assert_eq!(ahead.next(), None);
        }
    }

    #[test]
    fn point_light_attenuates_with_distance() {
        let light = Light::Point {
            position: Vec3::new(0.0, 2.0, 0.0),
            intensity: Color::ONE,
            attenuation: Attenuation {
                constant: 0.0,
                linear: 0.0,
                quadratic: 1.0,
            },
        };
        let s = light.sample(Vec3::ZERO).unwrap();
        assert_eq!(s.to_light, Vec3::Y);
        assert_eq!(s.distance, 2.0);
        assert_eq!(s.intensity, Color::splat(0.25));
    }

    #[test]
    fn spot_light_is_dark_outside_its_cone_and_dims_towards_the_edge() {
        let light = Light::Spot {
            position: Vec3::new(0.0, 1.0, 0.0),
            direction: -Vec3::Y,
            intensity: Color::ONE,
            cos_cutoff: 45f64.to_radians().cos(),
            falloff: 2.0,
            attenuation: Attenuation::NONE,
        };
        let on_axis = light.sample(Vec3::ZERO).unwrap();
        assert_eq!(on_axis.intensity, Color::ONE);
        let inside = light.sample(Vec3::new(0.5, 0.0, 0.0)).unwrap();
        let cos = 1.0 / 1.25f64.sqrt();
        assert!((inside.intensity.r - cos * cos).abs() < 1e-12);
        assert!(light.sample(Vec3::new(1.5, 0.0, 0.0)).is_none());
    }

    #[test]
    fn directional_light_comes_from_against_its_direction() {
        let light = Light::Directional {
            direction: -Vec3::Y,
            intensity: Color::ONE,
        };
        let s = light.sample(Vec3::new(5.0, 5.0, 5.0)).unwrap();
        assert_eq!(s.to_light, Vec3::Y);
        assert!(s.distance.is_infinite());
    }

    #[test]
    fn zero_denominator_attenuation_gives_no_light_instead_of_infinity() {
        let a = Attenuation {
            constant: 0.0,
            linear: 0.0,
            quadratic: 0.0,
        };
        assert_eq!(a.factor(3.0), 0.0);
    }

    #[test]
    fn sampling_towards_a_point_is_the_plain_sample_for_singular_lights() {
        let lights = [
            Light::Point {
                position: Vec3::new(1.0, 2.0, 3.0),
                intensity: Color::new(1.0, 0.5, 0.25),
                attenuation: Attenuation {
                    constant: 0.5,
                    linear: 0.1,
                    quadratic: 0.2,
                },
            },
            Light::Directional {
                direction: Vec3::new(0.0, -0.6, -0.8),
                intensity: Color::ONE,
            },
            Light::Spot {
                position: Vec3::new(0.0, 4.0, 0.0),
                direction: -Vec3::Y,
                intensity: Color::splat(3.0),
                cos_cutoff: 0.7,
                falloff: 2.5,
                attenuation: Attenuation::NONE,
            },
        ];
        let points = [
            Vec3::ZERO,
            Vec3::new(0.5, -1.0, 0.2),
            Vec3::new(5.0, 0.0, 0.0),
        ];
        let mut lit = 0;
        for light in &lights {
            for p in points {
                for u in [[0.0, 0.0], [0.25, 0.75], [0.999, 0.5]] {
                    assert_eq!(light.sample_towards(p, u), light.sample(p));
                }
                lit += usize::from(light.sample(p).is_some());
            }
        }
        // Some points are lit and one is outside the spot's cone.
        assert_eq!(lit, 8);
    }
}
