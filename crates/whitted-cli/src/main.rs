//! The `whitted` command.

fn main() {
    println!("whitted {}", env!("CARGO_PKG_VERSION"));
}
