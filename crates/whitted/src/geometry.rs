//! The scene's primitives made ready for ray queries: world-space bounds, an
//! acceleration structure over the bounded ones, a short list of the
//! unbounded ones, and the two queries every tracer needs — the closest hit
//! and any hit — plus the full surface description of a final hit.

use crate::accel::{AccelKind, Accelerator, TraversalCounters};
use crate::material::MaterialId;
use crate::math::{Aabb, DVec2, Ray, Transform, Vec3};
use crate::scene::{Primitive, Scene};
use crate::shape::{LocalSurface, ShapeHit};

/// The closest hit found by [`Geometry::intersect`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Hit {
    /// Index of the primitive in [`Scene::primitives`].
    pub primitive: u32,
    /// What the shape recorded (its `t` is the ray parameter).
    pub shape_hit: ShapeHit,
}

impl Hit {
    /// The ray parameter of the hit.
    pub fn t(&self) -> f64 {
        self.shape_hit.t
    }
}

/// The surface at a hit, in world space.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Surface {
    /// The hit point.
    pub point: Vec3,
    /// Absolute bound on the error of `point`, per axis.
    pub point_error: Vec3,
    /// Unit geometric normal, outward (not yet turned towards the ray).
    pub normal: Vec3,
    /// Texture coordinates.
    pub uv: DVec2,
    /// Tangent along u (not normalised).
    pub dpdu: Vec3,
    /// The surface's material.
    pub material: MaterialId,
}

/// The scene's geometry, ready for ray queries.
#[derive(Debug)]
pub struct Geometry<'a> {
    primitives: &'a [Primitive],
    transforms: &'a [Transform],
    accel: Accelerator,
    bounds: Aabb,
    bounded: Vec<u32>,
    unbounded: Vec<u32>,
}

impl<'a> Geometry<'a> {
    /// Prepares the scene's primitives with the default structure.
    pub fn new(scene: &'a Scene) -> Self {
        Self::with_accel(scene, AccelKind::default())
    }

    /// Prepares the scene's primitives with the structure `kind`.
    pub fn with_accel(scene: &'a Scene, kind: AccelKind) -> Self {
        let mut bounded = Vec::new();
        let mut unbounded = Vec::new();
        let mut boxes = Vec::new();
        for (i, p) in scene.primitives.iter().enumerate() {
            let local = p.shape.bounds();
            if local.is_finite() {
                let world = match p.transform {
                    Some(id) => scene.transforms[id.0 as usize].bounds_to_world(&local),
                    None => local,
                };
                boxes.push(world);
                bounded.push(i as u32);
            } else {
                unbounded.push(i as u32);
            }
        }
        Self {
            primitives: &scene.primitives,
            transforms: &scene.transforms,
            accel: Accelerator::build(kind, &boxes),
            bounds: boxes.iter().fold(Aabb::EMPTY, |a, b| a.union(b)),
            bounded,
            unbounded,
        }
    }

    fn transform(&self, p: &Primitive) -> Option<&Transform> {
        p.transform.map(|id| &self.transforms[id.0 as usize])
    }

    /// Primitive `index` hit by the world-space `ray`, closer than `t_max`.
    #[inline]
    fn intersect_primitive(&self, index: u32, ray: &Ray, t_max: f64) -> Option<ShapeHit> {
        let p = &self.primitives[index as usize];
        let mut ray = *ray;
        ray.t_max = t_max;
        match self.transform(p) {
            Some(t) => p.shape.intersect(&t.ray_to_object(&ray)),
            None => p.shape.intersect(&ray),
        }
    }

    #[inline]
    fn occluded_by(&self, index: u32, ray: &Ray) -> bool {
        let p = &self.primitives[index as usize];
        match self.transform(p) {
            Some(t) => p.shape.occluded(&t.ray_to_object(ray)),
            None => p.shape.occluded(ray),
        }
    }

    /// The box around every bounded primitive.
    pub fn bounds(&self) -> Aabb {
        self.bounds
    }

    /// The acceleration structure over the bounded primitives.
    pub fn accelerator(&self) -> &Accelerator {
        &self.accel
    }

    /// The closest hit in the ray's interval.
    pub fn intersect(&self, ray: &Ray) -> Option<Hit> {
        self.intersect_counted(ray, &mut TraversalCounters::default())
    }

    /// The closest hit, adding the traversal work to `counters`.
    pub fn intersect_counted(&self, ray: &Ray, counters: &mut TraversalCounters) -> Option<Hit> {
        let mut best: Option<Hit> = None;
        let mut t_max = ray.t_max;
        for &i in &self.unbounded {
            if let Some(h) = self.intersect_primitive(i, ray, t_max) {
                t_max = h.t;
                best = Some(Hit {
                    primitive: i,
                    shape_hit: h,
                });
            }
        }
        let mut clipped = *ray;
        clipped.t_max = t_max;
        self.accel.intersect(&clipped, counters, |slot, t_max| {
            let i = self.bounded[slot as usize];
            let h = self.intersect_primitive(i, ray, t_max)?;
            best = Some(Hit {
                primitive: i,
                shape_hit: h,
            });
            Some(h.t)
        });
        best
    }

    /// True when anything lies in the ray's interval.
    pub fn occluded(&self, ray: &Ray) -> bool {
        self.occluded_counted(ray, &mut TraversalCounters::default())
    }

    /// Any hit, adding the traversal work to `counters`.
    pub fn occluded_counted(&self, ray: &Ray, counters: &mut TraversalCounters) -> bool {
        self.unbounded.iter().any(|&i| self.occluded_by(i, ray))
            || self.accel.occluded(ray, counters, |slot| {
                self.occluded_by(self.bounded[slot as usize], ray)
            })
    }

    /// The world-space surface at a hit returned for `ray`.
    pub fn surface(&self, ray: &Ray, hit: &Hit) -> Surface {
        let p = &self.primitives[hit.primitive as usize];
        match self.transform(p) {
            None => {
                let s = p.shape.surface(ray, &hit.shape_hit);
                Surface::from_local(s, p.material)
            }
            Some(t) => {
                let s = p.shape.surface(&t.ray_to_object(ray), &hit.shape_hit);
                let (point, point_error) = t.point_with_error_to_world(s.point, s.point_error);
                Surface {
                    point,
                    point_error,
                    normal: t.normal_to_world(s.normal).normalize(),
                    uv: s.uv,
                    dpdu: t.vector_to_world(s.dpdu),
                    material: p.material,
                }
            }
        }
    }
}

impl Surface {
    fn from_local(s: LocalSurface, material: MaterialId) -> Self {
        Self {
            point: s.point,
            point_error: s.point_error,
            normal: s.normal,
            uv: s.uv,
            dpdu: s.dpdu,
            material,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::camera::Camera;
    use crate::material::Material;
    use crate::shape::{Plane, Shape, Sphere};

    fn scene_with(shape: Shape, transform: Transform) -> Scene {
        let camera = Camera::new(Vec3::Z, Vec3::ZERO, Vec3::Y, 45.0).unwrap();
        let mut scene = Scene::new(camera);
        let m = scene.add_material(Material::default());
        scene.add_primitive(shape, m, transform);
        scene
    }

    #[test]
    fn scaled_rotated_translated_sphere_is_hit_where_expected_with_correct_normals() {
        // A unit sphere stretched to an ellipsoid with semi-axes (2, 1, 1),
        // turned 90° about z (long axis now along y), moved to (5, 0, 0).
        let transform = Transform::translate(Vec3::new(5.0, 0.0, 0.0))
            .unwrap()
            .then_after(&Transform::rotate(Vec3::Z, 90.0).unwrap())
            .then_after(&Transform::scale(Vec3::new(2.0, 1.0, 1.0)).unwrap());
        let sphere = Shape::Sphere(Sphere::new(Vec3::ZERO, 1.0).unwrap());
        let scene = scene_with(sphere, transform);
        let geometry = Geometry::new(&scene);

        let down = Ray::new(Vec3::new(5.0, 10.0, 0.0), -Vec3::Y);
        let hit = geometry.intersect(&down).unwrap();
        assert!((hit.t() - 8.0).abs() < 1e-12);
        let s = geometry.surface(&down, &hit);
        assert!((s.point - Vec3::new(5.0, 2.0, 0.0)).length() < 1e-12);
        assert!((s.normal - Vec3::Y).length() < 1e-12);

        let across = Ray::new(Vec3::new(0.0, 0.0, 0.0), Vec3::X);
        let hit = geometry.intersect(&across).unwrap();
        assert!((hit.t() - 4.0).abs() < 1e-12);
        assert!((geometry.surface(&across, &hit).normal + Vec3::X).length() < 1e-12);

        // Off-axis: the ellipsoid x'² + (y/2)² + z² = 1 around (5, 0, 0) has
        // its normal along (x', y/4, z) at (x', y, z).
        let y = 3f64.sqrt();
        let oblique = Ray::new(Vec3::new(10.0, y, 0.0), -Vec3::X);
        let hit = geometry.intersect(&oblique).unwrap();
        let s = geometry.surface(&oblique, &hit);
        assert!((s.point - Vec3::new(5.5, y, 0.0)).length() < 1e-12);
        let expected = Vec3::new(0.5, y / 4.0, 0.0).normalize();
        assert!((s.normal - expected).length() < 1e-12);
        assert!(geometry.occluded(&oblique));
    }

    #[test]
    fn transformed_bounds_contain_the_transformed_shape() {
        let transform = Transform::rotate(Vec3::new(1.0, 1.0, 1.0), 30.0)
            .unwrap()
            .then_after(&Transform::scale(Vec3::new(3.0, 0.5, 1.0)).unwrap());
        let sphere = Shape::Sphere(Sphere::new(Vec3::new(1.0, 0.0, 0.0), 1.0).unwrap());
        let scene = scene_with(sphere, transform);
        let geometry = Geometry::new(&scene);
        assert_eq!(geometry.accel.stats().references, 1);
        let world = transform.bounds_to_world(&scene.primitives[0].shape.bounds());
        let mut rng = crate::random::Rng::new(5);
        let mut hits = 0;
        for _ in 0..500 {
            let target = rng.unit_vector() * 3.0;
            let ray = Ray::new(Vec3::splat(20.0), target - Vec3::splat(20.0));
            if let Some(hit) = geometry.intersect(&ray) {
                let p = geometry.surface(&ray, &hit).point;
                assert!(p.cmpge(world.min - 1e-9).all() && p.cmple(world.max + 1e-9).all());
                hits += 1;
            }
        }
        assert!(hits > 50);
    }

    #[test]
    fn unbounded_planes_are_tested_beside_the_structure() {
        let plane = Shape::Plane(Plane::new(Vec3::ZERO, Vec3::Y).unwrap());
        let scene = scene_with(plane, Transform::IDENTITY);
        let geometry = Geometry::new(&scene);
        assert_eq!(geometry.accel.stats().references, 0);
        let ray = Ray::new(Vec3::new(0.0, 1.0, 0.0), Vec3::new(1.0, -1.0, 0.0));
        assert_eq!(geometry.intersect(&ray).unwrap().t(), 1.0);
        assert!(geometry.occluded(&ray));
        let up = Ray::new(Vec3::new(0.0, 1.0, 0.0), Vec3::Y);
        assert!(geometry.intersect(&up).is_none() && !geometry.occluded(&up));
    }
}
