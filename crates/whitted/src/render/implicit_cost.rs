//! The warning before a render when an implicit surface's march will be
//! slow: its steps are `|f| / max_gradient` long (at least
//! [`MIN_STEP`] of the box's diagonal), so a bound far above the
//! function's true rate of change, or a function that is costly to
//! evaluate, can make each ray crossing the box take seconds. The cost is
//! estimated from the bound and the box before any ray is traced: the
//! function is evaluated at a grid of points in its box, timed, and the
//! march across the box is counted in steps of the typical `|f|` over the
//! bound.

use std::fmt;
use std::time::Instant;

use crate::math::Vec3;
use crate::render::Scene;
use crate::shape::{Implicit, MIN_STEP, NAN_STEP, Shape};

/// Points per axis of the grid the function is sampled at.
const GRID: usize = 8;

/// A ray estimated to take longer than this to cross a surface's box is
/// warned of: at 1 ms a ray, a 640x480 picture takes five minutes.
pub const SLOW_RAY_SECONDS: f64 = 1e-3;

/// An implicit surface whose march is estimated to be slow.
#[derive(Clone, Debug, PartialEq)]
pub struct SlowImplicit {
    /// What the scene file calls it (`objects[3]`), or its number.
    pub label: String,
    /// Its function, as written.
    pub function: String,
    /// Its bound.
    pub max_gradient: f64,
    /// The median `|f|` at the sample points.
    pub typical_value: f64,
    /// Steps of the march across its box's diagonal.
    pub steps: f64,
    /// Operations one evaluation of the function runs.
    pub operations: usize,
    /// Seconds one evaluation took here.
    pub seconds_per_evaluation: f64,
}

impl SlowImplicit {
    /// The estimated seconds of one ray crossing the box.
    pub fn seconds_per_ray(&self) -> f64 {
        self.steps * self.seconds_per_evaluation
    }
}

impl fmt::Display for SlowImplicit {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "the implicit surface {} (`{}`) may take about {} for each ray that crosses its \
             box: with max_gradient = {:e} against values of about {} there, its march takes \
             about {:.0} steps, each an evaluation of {} operations ({} here); a max_gradient \
             nearer the function's true rate of change, a tighter box or a simpler function \
             makes it faster",
            self.label,
            self.function,
            duration(self.seconds_per_ray()),
            self.max_gradient,
            number(self.typical_value),
            self.steps,
            self.operations,
            duration(self.seconds_per_evaluation),
        )
    }
}

/// `seconds` in the unit that reads best: "8.4 s", "12.0 ms", "3.1 µs".
fn duration(seconds: f64) -> String {
    match seconds {
        s if s >= 1.0 => format!("{s:.1} s"),
        s if s >= 1e-3 => format!("{:.1} ms", s * 1e3),
        s if s >= 1e-6 => format!("{:.1} µs", s * 1e6),
        s => format!("{:.0} ns", s * 1e9),
    }
}

/// `value` with four significant figures, in scientific notation when far
/// from 1.
fn number(value: f64) -> String {
    if (1e-3..1e6).contains(&value) {
        format!("{value:.4}")
    } else {
        format!("{value:.3e}")
    }
}

/// The implicit surfaces of `scene` (placed or in definitions) estimated
/// to take more than [`SLOW_RAY_SECONDS`] per ray, slowest first.
pub fn slow_implicit_surfaces(scene: &Scene) -> Vec<SlowImplicit> {
    let objects = &scene.objects;
    let placed = objects.primitives.iter().enumerate().map(|(i, p)| {
        let label = scene
            .sources
            .primitives
            .get(i)
            .map_or_else(|| format!("number {}", i + 1), |s| s.label.clone());
        (label, &p.shape)
    });
    let defined = objects.definitions.iter().flat_map(|d| {
        d.primitives
            .iter()
            .enumerate()
            .map(|(i, p)| (format!("number {} of a definition", i + 1), &p.shape))
    });
    let mut slow: Vec<SlowImplicit> = placed
        .chain(defined)
        .filter_map(|(label, shape)| match shape {
            Shape::Implicit(implicit) => Some(estimate(label, implicit)),
            _ => None,
        })
        .filter(|cost| cost.seconds_per_ray() > SLOW_RAY_SECONDS)
        .collect();
    slow.sort_by(|a, b| b.seconds_per_ray().total_cmp(&a.seconds_per_ray()));
    slow
}

/// The cost of `implicit`'s march across its box (see the module's doc).
fn estimate(label: String, implicit: &Implicit) -> SlowImplicit {
    let function = implicit.function();
    let bounds = implicit.bounds();
    let extent = bounds.extent();
    let size = extent.length();
    let at = |i: usize| (i as f64 + 0.5) / GRID as f64;
    let points: Vec<Vec3> = (0..GRID * GRID * GRID)
        .map(|k| {
            let (i, j, l) = (k % GRID, k / GRID % GRID, k / (GRID * GRID));
            bounds.min + extent * Vec3::new(at(i), at(j), at(l))
        })
        .collect();
    let start = Instant::now();
    let mut values: Vec<f64> = points.iter().map(|&p| function.eval(p).abs()).collect();
    let seconds_per_evaluation = start.elapsed().as_secs_f64() / points.len() as f64;
    values.retain(|v| !v.is_nan());
    values.sort_by(f64::total_cmp);
    let max_gradient = implicit.max_gradient();
    let (typical_value, steps) = match values.get(values.len() / 2) {
        // Values everywhere NaN: the march crosses in NaN steps.
        None => (f64::NAN, 1.0 / NAN_STEP),
        Some(&median) => {
            let step = (median / max_gradient).max(MIN_STEP * size);
            (median, (size / step).clamp(1.0, 1.0 / MIN_STEP))
        }
    };
    SlowImplicit {
        label,
        function: function.text().to_string(),
        max_gradient,
        typical_value,
        steps,
        operations: function.operations(),
        seconds_per_evaluation,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::shape::Expression;

    fn scene_with(function: &str, max_gradient: f64) -> Scene {
        let mut scene = crate::scene::default_scene();
        let shape = Implicit::new(
            Expression::parse(function).unwrap(),
            Vec3::splat(-2.0),
            Vec3::splat(2.0),
            max_gradient,
        )
        .unwrap();
        scene.add_primitive(
            Shape::Implicit(shape),
            crate::world::MaterialId(0),
            crate::math::Transform::IDENTITY,
        );
        scene
    }

    #[test]
    fn a_bound_far_above_the_rate_of_change_is_estimated_slow_and_a_fitting_one_is_not() {
        let sphere = "x^2 + y^2 + z^2 - 1";
        assert_eq!(slow_implicit_surfaces(&scene_with(sphere, 8.0)), []);
        let slow = slow_implicit_surfaces(&scene_with(sphere, 1e30));
        let [cost] = slow.as_slice() else {
            panic!("{slow:?}");
        };
        // Every step is the least one: a million across the box.
        assert_eq!(cost.steps, 1.0 / MIN_STEP);
        assert_eq!(cost.max_gradient, 1e30);
        assert!(
            cost.typical_value > 1.0 && cost.typical_value < 12.0,
            "{cost:?}"
        );
        assert!(cost.seconds_per_ray() > SLOW_RAY_SECONDS);
        let said = cost.to_string();
        assert!(
            said.starts_with(&format!(
                "the implicit surface {} (`{sphere}`) may take about",
                cost.label
            )) && said.contains("with max_gradient = 1e30 against values of about")
                && said.contains("its march takes about 1000000 steps"),
            "{said}"
        );
    }
}
