//! # whitted
//!
//! A CPU ray tracer in the tradition of Appel and Whitted: a pinhole camera
//! shoots rays through every pixel, finds the closest hit among exactly
//! intersected primitives, shades it with the Phong model, casts shadow rays
//! and recurses for reflection and refraction.
//!
//! The data flow is parse → prepare → trace → write: a [`scene::Scene`] comes
//! from a scene file (or is built in code), [`render::render`] turns it into
//! an [`image::Film`] plus optional per-pixel data, and the writers in
//! [`image`] save it as PNG, EXR or PFM.
//!
//! ```
//! use whitted::camera::Camera;
//! use whitted::light::{Attenuation, Light};
//! use whitted::material::Material;
//! use whitted::math::{Color, Transform, Vec3};
//! use whitted::render::{RenderOptions, render};
//! use whitted::scene::Scene;
//! use whitted::shape::{Shape, Sphere};
//!
//! let camera = Camera::new(Vec3::new(0.0, 0.0, 4.0), Vec3::ZERO, Vec3::Y, 40.0)?;
//! let mut scene = Scene::new(camera);
//! scene.settings.width = 32;
//! scene.settings.height = 24;
//! let red = scene.add_material(Material {
//!     diffuse: Color::new(0.9, 0.1, 0.1).into(),
//!     ..Material::default()
//! });
//! scene.add_primitive(Shape::Sphere(Sphere::new(Vec3::ZERO, 1.0)?), red, Transform::IDENTITY);
//! scene.lights.push(Light::Point {
//!     position: Vec3::new(2.0, 3.0, 4.0),
//!     intensity: Color::ONE,
//!     attenuation: Attenuation::NONE,
//! });
//!
//! let output = render(&scene, &RenderOptions::default(), &|_progress| {})?;
//! let centre = output.image.pixel(16, 12);
//! assert!(centre[0] > centre[1]);
//! assert_eq!(output.rays.primary, 32 * 24);
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```
#![deny(missing_docs)]

pub mod accel;
pub mod bench;
pub mod bump;
pub mod camera;
pub mod color_space;
pub mod geometry;
pub mod heat_map;
pub mod image;
pub mod light;
pub mod material;
pub mod math;
pub mod mesh;
pub mod random;
pub mod render;
pub mod sampling;
pub mod scene;
pub mod shape;
pub mod tangent_frame;
#[cfg(all(test, target_arch = "x86_64"))]
mod test_support;
pub mod texture;
pub mod trace;
pub mod triangle_clip;
