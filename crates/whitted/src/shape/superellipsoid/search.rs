//! The search along a ray for the first place where the superellipsoid's
//! function changes sign.
//!
//! The ray, already clipped to the box `[-1, 1]³`, is cut where a
//! coordinate crosses zero and where `|x| = |y|` (the planes POV-Ray
//! splits at): on each piece `|x|`, `|y|`, `|z|`, the larger and the
//! smaller of `|x|`, `|y|` are affine in `t`, so their ranges over any
//! stretch are their values at its ends. From those ranges
//! ([`super::implicit`]) come exact bounds of `f` and of its slope:
//!
//! - a stretch whose bounds of `f` exclude 0 holds no surface (however
//!   thin a part: this is not a sampling with a step that might skip it)
//!   and is dropped;
//! - a stretch whose bounds of the slope exclude 0 is monotone: it holds
//!   one root if its ends differ in sign, none otherwise; the root is then
//!   refined by the Illinois variant of regula falsi to a few ulps, the
//!   third step of every three a bisection when the first two have not
//!   halved the bracket, so it takes at most three times bisection's
//!   steps (tried bisecting every third step regardless, and the
//!   Anderson–Björck variant: more evaluations of `f`, see
//!   docs/performance-log.md, "The new shapes against meshes of the same
//!   look");
//! - any other stretch is halved, the near half searched first, down to
//!   [`RESOLUTION`] of the clipped ray: a stretch that small that is still
//!   neither is a tangent touch or a part thinner than that, kept when its
//!   ends differ in sign and dropped when they do not.
//!
//! Every crossing found is the first, since the stretches are visited in
//! order along the ray.

use super::implicit::{Exponents, Range, Stretch};
use crate::math::Vec3;

/// The shortest stretch, as a fraction of the clipped ray, that is halved
/// further when neither its values nor its slope have one sign.
pub(super) const RESOLUTION: f64 = 1e-12;

/// The deepest halving (a stop for stretches whose halves no longer shrink).
const MAX_DEPTH: u32 = 64;

/// The most stretches examined for one ray. A ray lying along the surface
/// (in the flat face of a near-cube) keeps every stretch undecided down to
/// [`RESOLUTION`], which would be a tree of 2⁴⁰; past this budget the
/// stretches left are decided by the signs at their ends, as at the
/// resolution. Ordinary rays use a few dozen.
const MAX_STRETCHES: u32 = 4096;

/// The most refining steps (enough for 64 halvings, one per three steps).
const MAX_REFINE_STEPS: u32 = 200;

/// True on the outer side of the surface. `f = 0` counts as inside, so a
/// ray starting on the surface and leaving it sees a crossing.
fn outside(f: f64) -> bool {
    f > 0.0
}

/// A ray in the superellipsoid's unit space.
pub(super) struct Line<'a> {
    /// The shape's exponents.
    pub(super) exponents: &'a Exponents,
    /// Where the ray starts.
    pub(super) origin: Vec3,
    /// Where it goes.
    pub(super) dir: Vec3,
}

/// A piece of the ray along which no coordinate changes sign and one of
/// `|x|`, `|y|` stays the larger.
#[derive(Clone, Copy)]
struct Piece {
    /// The signs of x, y, z on the piece.
    signs: Vec3,
    /// True when `|x| ≥ |y|` on the piece.
    x_larger: bool,
}

impl Line<'_> {
    /// `f` at `t`.
    fn value(&self, t: f64) -> f64 {
        let p = (self.origin + t * self.dir).abs();
        self.exponents.value(p.x, p.y, p.z)
    }

    /// The first `t` in `(t_start, t_end]` where `f` changes sign
    /// (computed within a few ulps), or `None`.
    pub(super) fn first_crossing(&self, t_start: f64, t_end: f64) -> Option<f64> {
        let (o, d) = (self.origin, self.dir);
        let cuts = [
            (o.x, d.x),
            (o.y, d.y),
            (o.z, d.z),
            (o.x - o.y, d.x - d.y),
            (o.x + o.y, d.x + d.y),
        ];
        // The cuts inside the stretch, then its end.
        let mut breaks = [t_end; 6];
        for (slot, (at, rate)) in breaks.iter_mut().zip(cuts) {
            let t = -at / rate;
            if t > t_start && t < t_end {
                *slot = t;
            }
        }
        breaks.sort_by(f64::total_cmp);
        let resolution = RESOLUTION * (t_end - t_start);
        let mut t0 = t_start;
        let mut f0 = self.value(t0);
        let mut budget = MAX_STRETCHES;
        for t1 in breaks {
            if t1 <= t0 {
                continue;
            }
            let f1 = self.value(t1);
            let piece = self.piece(0.5 * (t0 + t1));
            if let Some(t) = self.search(&piece, [t0, t1], [f0, f1], resolution, &mut budget, 0) {
                return Some(t);
            }
            (t0, f0) = (t1, f1);
        }
        None
    }

    /// The piece around `t`.
    fn piece(&self, t: f64) -> Piece {
        let p = self.origin + t * self.dir;
        Piece {
            signs: Vec3::new(p.x.signum(), p.y.signum(), p.z.signum()),
            x_larger: p.x.abs() >= p.y.abs(),
        }
    }

    /// The ranges of the magnitudes over `[t0, t1]` within `piece`.
    fn stretch(&self, piece: &Piece, [t0, t1]: [f64; 2]) -> Stretch {
        let ends = [t0, t1].map(|t| {
            let p = (self.origin + t * self.dir).abs();
            if piece.x_larger {
                [p.x, p.y, p.z]
            } else {
                [p.y, p.x, p.z]
            }
        });
        let slopes = self.dir * piece.signs;
        let ratio = |[m, l, _]: [f64; 3]| if m > 0.0 { Some(l / m) } else { None };
        let k = match (ratio(ends[0]), ratio(ends[1])) {
            (Some(k0), Some(k1)) => Range::between(k0, k1),
            _ => Range { lo: 0.0, hi: 1.0 },
        };
        Stretch {
            m: Range::between(ends[0][0], ends[1][0]),
            l: Range::between(ends[0][1], ends[1][1]),
            c: Range::between(ends[0][2], ends[1][2]),
            k,
            slopes: if piece.x_larger {
                [slopes.x, slopes.y, slopes.z]
            } else {
                [slopes.y, slopes.x, slopes.z]
            },
        }
    }

    /// The first crossing in `[t0, t1]` (values `f0`, `f1` at the ends),
    /// searched as the module doc says.
    fn search(
        &self,
        piece: &Piece,
        [t0, t1]: [f64; 2],
        [f0, f1]: [f64; 2],
        resolution: f64,
        budget: &mut u32,
        depth: u32,
    ) -> Option<f64> {
        *budget = budget.saturating_sub(1);
        let stretch = self.stretch(piece, [t0, t1]);
        let values = self.exponents.value_range(&stretch);
        let values = Range {
            lo: values.lo.min(f0).min(f1),
            hi: values.hi.max(f0).max(f1),
        };
        if values.excludes_zero() {
            return None;
        }
        let crossing = outside(f0) != outside(f1);
        let mid = 0.5 * (t0 + t1);
        let monotone = self.exponents.slope_range(&stretch).excludes_zero();
        if monotone
            || depth >= MAX_DEPTH
            || *budget == 0
            || t1 - t0 <= resolution
            || !(mid > t0 && mid < t1)
        {
            return crossing.then(|| self.refine([t0, t1], [f0, f1]));
        }
        let fm = self.value(mid);
        self.search(piece, [t0, mid], [f0, fm], resolution, budget, depth + 1)
            .or_else(|| self.search(piece, [mid, t1], [fm, f1], resolution, budget, depth + 1))
    }

    /// The crossing within `[t0, t1]`, whose ends differ in sign: the far
    /// end of a bracket shrunk to a few ulps (so strictly after `t0`).
    fn refine(&self, [mut t0, mut t1]: [f64; 2], [mut f0, mut f1]: [f64; 2]) -> f64 {
        let start_outside = outside(f0);
        // Which end moved last: the Illinois rule halves the other end's
        // value when the same end moves twice in a row.
        let mut moved_near = None;
        // The bracket's width at the start of the current round of three
        // steps: the third step bisects only when the round has not
        // halved it (the secant stalling), so bisection's guarantee costs
        // nothing while the Illinois steps converge.
        let mut round_width = t1 - t0;
        for step in 0..MAX_REFINE_STEPS {
            if t1 - t0 <= 4.0 * f64::EPSILON * t0.abs().max(t1.abs()) {
                break;
            }
            if step % 3 == 0 {
                round_width = t1 - t0;
            }
            let mid = 0.5 * (t0 + t1);
            let secant = t0 - f0 * (t1 - t0) / (f1 - f0);
            let stalled = step % 3 == 2 && t1 - t0 > 0.5 * round_width;
            let t = if stalled || !(secant > t0 && secant < t1) {
                mid
            } else {
                secant
            };
            if !(t > t0 && t < t1) {
                break;
            }
            let f = self.value(t);
            if outside(f) == start_outside {
                (t0, f0) = (t, f);
                if moved_near == Some(true) {
                    f1 *= 0.5;
                }
                moved_near = Some(true);
            } else {
                (t1, f1) = (t, f);
                if moved_near == Some(false) {
                    f0 *= 0.5;
                }
                moved_near = Some(false);
            }
        }
        t1
    }
}
