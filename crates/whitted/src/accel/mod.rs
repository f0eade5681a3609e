//! Acceleration structures: index structures over bounding boxes.
//!
//! A structure never knows what a shape is. It is built from the primitives'
//! world-space boxes, and its queries take a closure that intersects
//! primitive `i`; the caller keeps whatever hit data it needs in the
//! closure's state. Unbounded shapes (infinite planes) never enter a
//! structure: [`crate::geometry::Geometry`] tests them in a short list beside
//! it.

pub mod linear;

pub use linear::Linear;
