//! # whitted
//!
//! A CPU ray tracer in the tradition of Appel and Whitted: a pinhole camera
//! shoots rays through every pixel, finds the closest hit among exactly
//! intersected primitives, shades it with the Phong model, casts shadow rays
//! and recurses for reflection and refraction.
//!
//! The library is built in layers, each importing only from the ones
//! before it (ARCHITECTURE.md draws them; a test checks it):
//!
//! | layer | what it holds |
//! |---|---|
//! | [`limits`] | the memory budget, bounded reading of input files |
//! | [`math`] | vectors, rays, boxes, transforms, error bounds, random numbers, sample patterns |
//! | [`shape`] | the primitives, each intersected exactly |
//! | [`mesh`] | triangle meshes with shared vertices |
//! | [`accel`] | acceleration structures over boxes (they know `math` only) |
//! | [`world`] | what is traced: objects prepared once for ray queries |
//! | [`shading`] | colours, materials, textures, bump maps, lights, optics |
//! | [`integrator`] | the algorithms that turn rays into colours (Whitted) |
//! | [`image`] | films and their writers (PNG, EXR, PFM), heat maps |
//! | [`render`](mod@render) | the scene description, settings, camera, tiles over threads |
//! | [`scene`] | readers: TOML, NFF, OBJ → one [`Scene`] |
//! | [`bench`](mod@bench) | measuring the acceleration structures |
//!
//! The data flow is parse → prepare → trace → write: a [`Scene`] comes from
//! a scene file (or is built in code), [`render::render`] turns it into an
//! [`image::Film`] plus optional per-pixel data, and the writers in
//! [`image`] save it as PNG, EXR or PFM.
//!
//! ```
//! use whitted::math::{Transform, Vec3};
//! use whitted::render::{Camera, Scene, render};
//! use whitted::shading::{Attenuation, Color, Light, Material};
//! use whitted::integrator::RayKind;
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
//! let output = render(&scene, &|_progress| {})?;
//! let centre = output.image.pixel(16, 12);
//! assert!(centre[0] > centre[1]);
//! assert_eq!(output.rays[RayKind::Primary], 32 * 24);
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```
#![deny(missing_docs)]
// The library never prints: it returns what happened, and the command
// reports it (a failed print would panic in `println!`).
#![deny(clippy::print_stdout, clippy::print_stderr, clippy::dbg_macro)]

pub mod accel;
pub mod bench;
pub mod image;
pub mod integrator;
pub mod limits;
pub mod math;
pub mod mesh;
pub mod render;
pub mod scene;
pub mod shading;
pub mod shape;
pub mod world;

pub use render::{RenderSettings, Scene, render};
pub use scene::load_any;
