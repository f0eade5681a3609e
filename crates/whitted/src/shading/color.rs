//! Colours: linear RGB triples of `f64`, kept apart from points and
//! directions by their own type, so a colour can never be added to a normal
//! by mistake.
//!
//! Arithmetic is per channel: colours add and multiply channel by channel
//! (a filter times a light), and scale by a number. Nothing is clamped:
//! lights and sums may exceed 1.

use std::iter::Sum;
use std::ops::{Add, AddAssign, Div, DivAssign, Mul, MulAssign, Sub};

/// A linear RGB colour (or a per-channel weight such as a reflectance).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Color {
    /// Red.
    pub r: f64,
    /// Green.
    pub g: f64,
    /// Blue.
    pub b: f64,
}

impl Color {
    /// Black: no light, or a weight that lets nothing through.
    pub const ZERO: Self = Self::splat(0.0);
    /// White: a weight that lets everything through.
    pub const ONE: Self = Self::splat(1.0);
    /// Pure red.
    pub const RED: Self = Self::new(1.0, 0.0, 0.0);
    /// Pure green.
    pub const GREEN: Self = Self::new(0.0, 1.0, 0.0);
    /// Pure blue.
    pub const BLUE: Self = Self::new(0.0, 0.0, 1.0);

    /// The colour with these channels.
    #[inline]
    pub const fn new(r: f64, g: f64, b: f64) -> Self {
        Self { r, g, b }
    }

    /// The grey with every channel `v`.
    #[inline]
    pub const fn splat(v: f64) -> Self {
        Self::new(v, v, v)
    }

    /// The channels as `[r, g, b]`.
    #[inline]
    pub const fn to_array(self) -> [f64; 3] {
        [self.r, self.g, self.b]
    }

    /// The colour whose channels are `f` of this one's.
    #[inline]
    pub fn map(self, f: impl Fn(f64) -> f64) -> Self {
        Self::new(f(self.r), f(self.g), f(self.b))
    }

    /// Every channel's absolute value.
    #[inline]
    pub fn abs(self) -> Self {
        self.map(f64::abs)
    }

    /// The largest channel.
    #[inline]
    pub fn max_element(self) -> f64 {
        self.r.max(self.g).max(self.b)
    }

    /// The smallest channel.
    #[inline]
    pub fn min_element(self) -> f64 {
        self.r.min(self.g).min(self.b)
    }

    /// Per channel, the larger of the two.
    #[inline]
    pub fn max(self, o: Self) -> Self {
        Self::new(self.r.max(o.r), self.g.max(o.g), self.b.max(o.b))
    }

    /// Per channel, the smaller of the two.
    #[inline]
    pub fn min(self, o: Self) -> Self {
        Self::new(self.r.min(o.r), self.g.min(o.g), self.b.min(o.b))
    }

    /// Every channel clamped to `[low, high]`.
    #[inline]
    pub fn clamp(self, low: f64, high: f64) -> Self {
        self.map(|v| v.clamp(low, high))
    }

    /// True when every channel is finite.
    #[inline]
    pub fn is_finite(self) -> bool {
        self.r.is_finite() && self.g.is_finite() && self.b.is_finite()
    }

    /// The channels as `f32`, for films.
    #[inline]
    pub fn to_f32(self) -> [f32; 3] {
        [self.r as f32, self.g as f32, self.b as f32]
    }
}

impl From<[f64; 3]> for Color {
    fn from([r, g, b]: [f64; 3]) -> Self {
        Self::new(r, g, b)
    }
}

impl From<Color> for [f64; 3] {
    fn from(c: Color) -> Self {
        c.to_array()
    }
}

impl std::fmt::Display for Color {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "[{}, {}, {}]", self.r, self.g, self.b)
    }
}

impl Add for Color {
    type Output = Self;
    #[inline]
    fn add(self, o: Self) -> Self {
        Self::new(self.r + o.r, self.g + o.g, self.b + o.b)
    }
}

impl AddAssign for Color {
    #[inline]
    fn add_assign(&mut self, o: Self) {
        *self = *self + o;
    }
}

impl Sub for Color {
    type Output = Self;
    #[inline]
    fn sub(self, o: Self) -> Self {
        Self::new(self.r - o.r, self.g - o.g, self.b - o.b)
    }
}

impl Mul for Color {
    type Output = Self;
    #[inline]
    fn mul(self, o: Self) -> Self {
        Self::new(self.r * o.r, self.g * o.g, self.b * o.b)
    }
}

impl MulAssign for Color {
    #[inline]
    fn mul_assign(&mut self, o: Self) {
        *self = *self * o;
    }
}

impl Mul<f64> for Color {
    type Output = Self;
    #[inline]
    fn mul(self, s: f64) -> Self {
        Self::new(self.r * s, self.g * s, self.b * s)
    }
}

impl Mul<Color> for f64 {
    type Output = Color;
    #[inline]
    fn mul(self, c: Color) -> Color {
        Color::new(self * c.r, self * c.g, self * c.b)
    }
}

impl MulAssign<f64> for Color {
    #[inline]
    fn mul_assign(&mut self, s: f64) {
        *self = *self * s;
    }
}

impl Div<f64> for Color {
    type Output = Self;
    #[inline]
    fn div(self, s: f64) -> Self {
        Self::new(self.r / s, self.g / s, self.b / s)
    }
}

impl DivAssign<f64> for Color {
    #[inline]
    fn div_assign(&mut self, s: f64) {
        *self = *self / s;
    }
}

impl Sum for Color {
    fn sum<I: Iterator<Item = Self>>(iter: I) -> Self {
        iter.fold(Self::ZERO, Add::add)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn arithmetic_is_per_channel() {
        let a = Color::new(1.0, 2.0, 3.0);
        let b = Color::new(0.5, 0.25, 2.0);
        assert_eq!(a + b, Color::new(1.5, 2.25, 5.0));
        assert_eq!(a - b, Color::new(0.5, 1.75, 1.0));
        assert_eq!(a * b, Color::new(0.5, 0.5, 6.0));
        assert_eq!(a * 2.0, 2.0 * a);
        assert_eq!(a / 2.0, Color::new(0.5, 1.0, 1.5));
        assert_eq!(a.max_element(), 3.0);
        assert_eq!(b.min_element(), 0.25);
        assert_eq!([a, b].into_iter().sum::<Color>(), a + b);
    }

    #[test]
    fn clamping_and_finiteness_look_at_every_channel() {
        let c = Color::new(-1.0, 0.5, 7.0);
        assert_eq!(c.clamp(0.0, 1.0), Color::new(0.0, 0.5, 1.0));
        assert!(c.is_finite());
        assert!(!Color::new(0.0, f64::NAN, 0.0).is_finite());
        assert!(!Color::new(0.0, 0.0, f64::INFINITY).is_finite());
    }
}
