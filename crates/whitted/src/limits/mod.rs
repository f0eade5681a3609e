//! Limits on what input may make the program take: one memory budget,
//! checked before any allocation whose size comes from input (images,
//! per-pixel data, textures as their headers declare them, ray files, bench
//! sizes), and bounded reading of input files (regular files only, no
//! larger than the budget).
//!
//! The lowest layer: it imports nothing from the crate, so every other
//! layer may use it.

mod input;
mod memory;

pub use input::{InputFile, identify_input, inputs_read, read_input, read_input_text};
pub use memory::{
    BudgetOrigin, ByteSize, Charge, GROWTH_STEP, Held, MemoryBudget, MemoryError, MemoryLimit,
    format_bytes, parse_size,
};
