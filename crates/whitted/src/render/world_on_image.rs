//! Where the world can appear on the image: the cells of a coarse grid
//! over the image that the camera's view of some box around primitives
//! reaches. A camera ray through a pixel (any position in its square) of a
//! cell no box reaches misses every primitive, so the renderer gives it the
//! background without walking the world (a tile row's packets in the
//! background of jacks or tetra).
//!
//! The boxes are the world's first BVH levels' (about [`BOXES`] of them,
//! [`World::covering_boxes`]): the world's own box leaves little
//! background outside it, a level's boxes follow the shapes closer.
//!
//! # Why a culled ray hits nothing
//!
//! Every primitive lies in one of the boxes, so a ray that hits one meets
//! that box at a positive parameter. When every corner of a box lies in
//! front of the eye (positive depth along the view direction), the camera's
//! projection maps the box onto the convex hull of its corners' images,
//! which their bounding rectangle holds; a camera ray meets the box only if
//! its position on the image lies in that hull, since the projection of its
//! points in front of the eye is that position. Each rectangle is grown by
//! [`MARGIN`] pixels, and every cell it touches is marked.
//!
//! The margin covers what the exact argument leaves out: the rounding of
//! the ray's direction and of the corners' images (units of `2⁻⁵³`), and
//! the hits a shape's test reports just outside its box within its
//! tolerance (as the structures' early exits also assume), the widest
//! being CSG's coincidence, `1e-9` of its size, under `4e-9` of the
//! largest coordinate `c` of the boxes and the eye. The guards make that
//! under a fifth of a pixel: every corner's depth is at least
//! [`MIN_DEPTH`] of `c` and of its distance from the eye, so a hit moved
//! by `4e-9·c` moves on the image plane (at distance one) by at most
//! `4e-7·(1 + |s|)`, with `s` the plane's coordinates, and a pixel's step
//! there, `2·tan(fov/2)/height`, is at least [`MIN_PIXEL_STEP`] times
//! `1 + |s|` at the image's edge. Outside the guards, or with an unbounded
//! primitive, nothing is culled.

use super::camera::Camera;
use std::ops::Range;

use crate::math::{Aabb, DVec2};
use crate::world::World;

/// About how many boxes are projected (a level of the BVH with at most
/// this many): each costs eight projections, once per render.
const BOXES: usize = 1024;

/// Pixels each box's rectangle is grown by on each side.
const MARGIN: f64 = 1.0;

/// The least step of a pixel on the image plane at distance one, relative
/// to one plus the plane's largest coordinate on the image, for which
/// positions are culled (five times the `4e-7` of the module
/// documentation).
const MIN_PIXEL_STEP: f64 = 2e-6;

/// The least depth of a corner, relative to its distance from the eye and
/// to the largest coordinate of the boxes and the eye, for which positions
/// are culled.
const MIN_DEPTH: f64 = 1e-2;

/// The side of a cell in pixels, as a power of two: eight, the width of
/// a packet of camera rays (most start at multiples of eight), or more on
/// images over 4096 pixels wide or high, so that a side has at most 512
/// cells.
fn cell_shift(width: u32, height: u32) -> u32 {
    width
        .max(height)
        .div_ceil(512)
        .next_power_of_two()
        .max(8)
        .trailing_zeros()
}

/// The cell of `cells` cells of `side` pixels that holds coordinate `v`,
/// clamped to the grid (a NaN to the first): a rectangle off the image
/// marks the cells at its border, more than needed, and a position off it
/// reads them. (The conversion truncates, which is the floor where it
/// matters, and takes everything below zero to zero.)
#[inline]
fn cell_index(v: f64, side: f64, cells: usize) -> usize {
    ((v / side) as usize).min(cells - 1)
}

/// The rectangle around the images of `b`'s corners on a `size` image,
/// grown by [`MARGIN`]; `None` when a corner is not safely ahead of the
/// eye (`scale` is the largest coordinate of the eye and the boxes).
fn rectangle(camera: &Camera, size: (u32, u32), b: &Aabb, scale: f64) -> Option<(DVec2, DVec2)> {
    let mut low = DVec2::splat(f64::INFINITY);
    let mut high = DVec2::splat(f64::NEG_INFINITY);
    for corner in b.corners() {
        let (position, depth) = camera.project(size.0, size.1, corner);
        let distance = (corner - camera.eye()).length();
        let ahead = depth > MIN_DEPTH * distance && depth > MIN_DEPTH * scale;
        if !ahead || !position.is_finite() {
            return None;
        }
        low = low.min(position);
        high = high.max(position);
    }
    Some((low - MARGIN, high + MARGIN))
}

/// The cells of the image a camera ray may hit the world through.
#[derive(Clone, Debug, PartialEq)]
pub(crate) struct WorldOnImage {
    /// Pixels per cell side, as a power of two.
    shift: u32,
    /// Cells per row.
    columns: usize,
    /// Rows of cells.
    rows: usize,
    /// Whether some box's rectangle touches each cell, row by row.
    reached: Vec<bool>,
}

impl WorldOnImage {
    /// The cells for `world`'s primitives seen by `camera` on a `width` ×
    /// `height` image; `None` when it cannot be told safely (see the module
    /// documentation): then no position is culled.
    pub(crate) fn new(camera: &Camera, width: u32, height: u32, world: &World) -> Option<Self> {
        Self::of_boxes(camera, width, height, &world.covering_boxes(BOXES)?)
    }

    /// The cells for primitives that lie in `boxes` between them.
    fn of_boxes(camera: &Camera, width: u32, height: u32, boxes: &[Aabb]) -> Option<Self> {
        let (w, h) = (f64::from(width), f64::from(height));
        let tan_half_fov = (camera.fov_degrees().to_radians() / 2.0).tan();
        let reach = 1.0 + tan_half_fov * (w / h).max(1.0);
        if 2.0 * tan_half_fov / h < MIN_PIXEL_STEP * reach {
            return None;
        }
        let eye = camera.eye();
        let boxes: Vec<&Aabb> = boxes.iter().filter(|b| !b.is_empty()).collect();
        let mut scale = eye.abs().max_element();
        for b in &boxes {
            if !b.is_finite() {
                return None;
            }
            scale = scale.max(b.min.abs().max(b.max.abs()).max_element());
        }
        let shift = cell_shift(width, height);
        let columns = width.div_ceil(1 << shift) as usize;
        let rows = height.div_ceil(1 << shift) as usize;
        let side = f64::from(1u32 << shift);
        let cell = |v: f64, cells: usize| cell_index(v, side, cells);
        // Each rectangle adds one to a corner of its block of cells and
        // takes it away past the others; the sums over rows and columns
        // then count the rectangles touching each cell.
        let mut counts = vec![0i32; (rows + 1) * (columns + 1)];
        let at = |row: usize, column: usize| row * (columns + 1) + column;
        for b in boxes {
            let (low, high) = rectangle(camera, (width, height), b, scale)?;
            let (c0, c1) = (cell(low.x, columns), cell(high.x, columns) + 1);
            let (r0, r1) = (cell(low.y, rows), cell(high.y, rows) + 1);
            counts[at(r0, c0)] += 1;
            counts[at(r0, c1)] -= 1;
            counts[at(r1, c0)] -= 1;
            counts[at(r1, c1)] += 1;
        }
        for row in 0..=rows {
            for column in 1..=columns {
                counts[at(row, column)] += counts[at(row, column - 1)];
            }
        }
        for row in 1..=rows {
            for column in 0..=columns {
                counts[at(row, column)] += counts[at(row - 1, column)];
            }
        }
        let reached = (0..rows)
            .flat_map(|row| (0..columns).map(move |column| (row, column)))
            .map(|(row, column)| counts[at(row, column)] > 0)
            .collect();
        Some(Self {
            shift,
            columns,
            rows,
            reached,
        })
    }

    /// True when the camera rays through the pixels `columns` of row
    /// `y` miss the world.
    pub(crate) fn misses_pixels(&self, columns: Range<u32>, y: u32) -> bool {
        let row = (y >> self.shift) as usize * self.columns;
        let cells = columns.start >> self.shift..=columns.end.saturating_sub(1) >> self.shift;
        cells.into_iter().all(|c| !self.reached[row + c as usize])
    }

    /// True unless the camera rays through pixel (`x`, `y`) miss the
    /// world.
    pub(crate) fn may_hit(&self, x: u32, y: u32) -> bool {
        !self.misses_pixels(x..x + 1, y)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::random::Rng;
    use crate::math::{Transform, Vec3};
    use crate::shape::{Plane, Shape, Sphere, Triangle};
    use crate::world::{MaterialId, Objects};

    fn camera(eye: Vec3, look_at: Vec3, fov: f64) -> Camera {
        Camera::new(eye, look_at, Vec3::Y, fov).unwrap()
    }

    fn unit_box() -> Aabb {
        Aabb::new(Vec3::splat(-1.0), Vec3::splat(1.0))
    }

    fn add(objects: &mut Objects, shape: Shape) {
        objects.add_primitive(shape, MaterialId(0), Transform::IDENTITY);
    }

    #[test]
    fn a_box_ahead_is_a_rectangle_around_its_corners_images_grown_by_a_pixel() {
        let c = camera(Vec3::new(0.0, 0.0, -10.0), Vec3::ZERO, 40.0);
        let (low, high) = rectangle(&c, (200, 100), &unit_box(), 10.0).unwrap();
        let inside = |p: DVec2| p.cmpge(low).all() && p.cmple(high).all();
        for corner in unit_box().corners() {
            assert!(inside(c.project(200, 100, corner).0));
        }
        // The near face's top edge is the highest image.
        let top = c.project(200, 100, Vec3::new(0.0, 1.0, -1.0)).0.y;
        assert!(inside(DVec2::new(100.0, top - 0.99)));
        assert!(!inside(DVec2::new(100.0, top - 1.01)));
    }

    #[test]
    fn the_cells_marked_are_those_a_rectangle_touches() {
        let c = camera(Vec3::new(0.3, -0.2, -10.0), Vec3::ZERO, 40.0);
        let boxes = [
            unit_box(),
            Aabb::new(Vec3::new(3.0, 1.0, 0.0), Vec3::new(3.5, 1.2, 0.5)),
        ];
        let (width, height) = (203, 101);
        let grid = WorldOnImage::of_boxes(&c, width, height, &boxes).unwrap();
        assert_eq!((grid.columns, grid.rows), (26, 13));
        let rectangles = boxes.map(|b| rectangle(&c, (width, height), &b, 10.0).unwrap());
        let mut reached = 0;
        for y in 0..height {
            for x in 0..width {
                let (left, top) = (f64::from(x & !7), f64::from(y & !7));
                let touched = rectangles.iter().any(|(low, high)| {
                    low.x < left + 8.0 && high.x >= left && low.y < top + 8.0 && high.y >= top
                });
                assert_eq!(grid.may_hit(x, y), touched, "{x}, {y}");
                reached += usize::from(touched);
            }
        }
        let pixels = (width * height) as usize;
        assert!(reached > 0 && reached < pixels / 2, "{reached}");
        let centre = c.project(width, height, Vec3::ZERO).0.as_uvec2();
        assert!(grid.misses_pixels(0..16, 0));
        assert!(!grid.misses_pixels(0..centre.x + 1, centre.y));
        assert!(!grid.misses_pixels(centre.x..centre.x + 1, centre.y));
    }

    #[test]
    fn nothing_is_culled_when_it_cannot_be_told() {
        let ahead = camera(Vec3::new(0.0, 0.0, -10.0), Vec3::ZERO, 40.0);
        let of = |camera: &Camera, b: Aabb| WorldOnImage::of_boxes(camera, 64, 64, &[b]);
        assert!(of(&ahead, unit_box()).is_some());
        // An unbounded primitive.
        let mut objects = Objects::default();
        add(
            &mut objects,
            Shape::Plane(Plane::new(Vec3::ZERO, Vec3::Y).unwrap()),
        );
        assert_eq!(
            WorldOnImage::new(&ahead, 64, 64, &World::new(&objects)),
            None
        );
        // The eye inside a box, or a box partly or wholly behind it.
        let inside = camera(Vec3::ZERO, Vec3::Z, 40.0);
        assert_eq!(of(&inside, unit_box()), None);
        let beside = camera(Vec3::new(0.0, 0.0, -1.5), Vec3::new(0.0, 0.0, 5.0), 40.0);
        let long = Aabb::new(Vec3::new(-1.0, -1.0, -3.0), Vec3::splat(1.0));
        assert_eq!(of(&beside, long), None);
        let away = camera(Vec3::new(0.0, 0.0, -10.0), Vec3::new(0.0, 0.0, -20.0), 40.0);
        assert_eq!(of(&away, unit_box()), None);
        // A box that is not finite.
        let endless = Aabb::new(Vec3::splat(-1.0), Vec3::new(1.0, 1.0, f64::INFINITY));
        assert_eq!(of(&ahead, endless), None);
        // A pixel's step too fine for the margin to cover the rounding.
        let narrow = camera(Vec3::new(0.0, 0.0, -10.0), Vec3::ZERO, 1e-5);
        assert_eq!(
            WorldOnImage::of_boxes(&narrow, 1024, 1024, &[unit_box()]),
            None
        );
    }

    /// Random spheres and triangles, and a random camera looking their way.
    fn random_scene(rng: &mut Rng) -> (Objects, Camera) {
        let mut objects = Objects::default();
        let centre = rng.point_in(Vec3::splat(-3.0), Vec3::splat(3.0));
        for _ in 0..40 {
            let c = centre + rng.point_in(Vec3::splat(-1.5), Vec3::splat(1.5));
            if rng.range(0.0, 1.0) < 0.5 {
                let sphere = Sphere::new(c, rng.range(0.02, 0.3)).unwrap();
                add(&mut objects, Shape::Sphere(sphere));
            } else {
                let mut corner = || c + rng.point_in(Vec3::splat(-0.4), Vec3::splat(0.4));
                let (a, b, d) = (corner(), corner(), corner());
                if let Ok(triangle) = Triangle::new(a, b, d) {
                    add(&mut objects, Shape::Triangle(triangle));
                }
            }
        }
        let eye = centre + 5.0 * rng.unit_vector();
        let look_at = centre + rng.point_in(Vec3::splat(-0.5), Vec3::splat(0.5));
        let fov = rng.range(20.0, 90.0);
        (objects, camera(eye, look_at, fov))
    }

    #[test]
    fn every_culled_position_misses_the_world_and_both_kinds_are_common() {
        let mut rng = Rng::new(7);
        let (width, height) = (96, 64);
        let (mut culled, mut hits, mut kept_misses) = (0, 0, 0);
        for _ in 0..40 {
            let (objects, camera) = random_scene(&mut rng);
            let world = World::new(&objects);
            let Some(grid) = WorldOnImage::new(&camera, width, height, &world) else {
                continue;
            };
            for _ in 0..600 {
                let p = DVec2::new(
                    rng.range(0.0, f64::from(width)),
                    rng.range(0.0, f64::from(height)),
                );
                let hit = world.intersect(&camera.ray(width, height, p.x, p.y));
                if grid.may_hit(p.x as u32, p.y as u32) {
                    kept_misses += usize::from(hit.is_none());
                } else {
                    culled += 1;
                    assert_eq!(hit, None, "culled {p:?} hits");
                }
                hits += usize::from(hit.is_some());
            }
        }
        // The level's boxes leave background between the shapes too.
        assert!(culled > 3000 && hits > 2000, "culled {culled}, hits {hits}");
        assert!(culled > kept_misses, "culled {culled}, kept {kept_misses}");
    }

    #[test]
    fn a_square_facing_the_eye_is_hit_to_its_edges_and_kept_there() {
        // The square fills its box's face, so positions just inside its
        // image hit it.
        let mut objects = Objects::default();
        let corner = |x: f64, y: f64| Vec3::new(x, y, 0.0);
        let (a, b, c, d) = (
            corner(-1.0, -1.0),
            corner(1.0, -1.0),
            corner(1.0, 1.0),
            corner(-1.0, 1.0),
        );
        add(
            &mut objects,
            Shape::Triangle(Triangle::new(a, b, c).unwrap()),
        );
        add(
            &mut objects,
            Shape::Triangle(Triangle::new(a, c, d).unwrap()),
        );
        let camera = camera(Vec3::new(0.0, 0.0, -4.0), Vec3::ZERO, 60.0);
        let world = World::new(&objects);
        let (width, height) = (64, 64);
        let grid = WorldOnImage::new(&camera, width, height, &world).unwrap();
        let image = [a, b, c, d].map(|v| camera.project(width, height, v).0);
        let low = image.iter().fold(DVec2::INFINITY, |m, &p| m.min(p));
        let high = image.iter().fold(DVec2::NEG_INFINITY, |m, &p| m.max(p));
        for inset in [1e-9, 1e-3, 0.5] {
            for p in [low + inset, high - inset] {
                let ray = camera.ray(width, height, p.x, p.y);
                assert!(world.intersect(&ray).is_some(), "{p:?} misses");
                assert!(grid.may_hit(p.x as u32, p.y as u32), "{p:?} culled");
            }
        }
        assert!(!grid.may_hit(0, 0) && !grid.may_hit(63, 63));
    }

    #[test]
    fn culled_pixels_miss_the_example_scenes_in_every_structure() {
        // The example scenes hold every kind of shape, transformed, in CSG,
        // as Bézier patches and as instances; their unbounded shapes (which
        // keep any grid from being made) are dropped. Each structure's
        // world gives the grid its boxes: the BVH its levels, the others
        // their one box.
        use crate::accel::AccelKind;
        let scenes = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenes");
        let mut paths: Vec<_> = std::fs::read_dir(&scenes)
            .unwrap()
            .map(|entry| entry.unwrap().path())
            .filter(|path| path.extension().is_some_and(|e| e == "toml"))
            .collect();
        paths.sort();
        let (width, height) = (64, 48);
        // The centre and the four corners, just inside the far edges.
        let offsets = [
            (0.5, 0.5),
            (0.0, 0.0),
            (0.999, 0.0),
            (0.0, 0.999),
            (0.999, 0.999),
        ];
        let (mut grids, mut culled) = (0, 0);
        for path in &paths {
            let mut scene = crate::scene::load_any(path).unwrap();
            scene
                .objects
                .primitives
                .retain(|p| p.shape.bounds().is_finite());
            let kinds = [
                AccelKind::Bvh,
                AccelKind::KdTree,
                AccelKind::Grid,
                AccelKind::Linear,
            ];
            for (top, bottom) in kinds.into_iter().zip(kinds.into_iter().rev()) {
                let world = World::build_levels(&scene.objects, top, bottom);
                let grid = WorldOnImage::new(&scene.camera, width, height, &world);
                let grid = grid.unwrap_or_else(|| panic!("{path:?}, {top:?}: no grid"));
                grids += 1;
                for (x, y) in (0..height).flat_map(|y| (0..width).map(move |x| (x, y))) {
                    if grid.may_hit(x, y) {
                        continue;
                    }
                    culled += 1;
                    for (dx, dy) in offsets {
                        let (px, py) = (f64::from(x) + dx, f64::from(y) + dy);
                        let ray = scene.camera.ray(width, height, px, py);
                        let hit = world.intersect(&ray);
                        assert!(hit.is_none(), "{path:?}, {top:?}/{bottom:?}: ({px}, {py})");
                    }
                }
            }
        }
        assert!(
            grids >= 60 && culled > 20_000,
            "{grids} grids, {culled} culled"
        );
    }
}
