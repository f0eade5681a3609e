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
#![deny(missing_docs)]

pub mod camera;
pub mod light;
pub mod material;
pub mod math;
pub mod random;
pub mod scene;
pub mod shape;
pub mod texture;
