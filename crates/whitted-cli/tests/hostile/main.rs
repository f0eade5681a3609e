//! The hostile-input suite: one case per class of defect found by the
//! audit of issue 23, each asserting the exact outcome (message, exit code,
//! files on disk, and where memory is the point, the child's peak resident
//! memory). Every case runs the real `whitted` binary.

mod args;
mod limits;
mod obj;
mod outputs;
mod pictures;
mod support;
