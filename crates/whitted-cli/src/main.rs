//! The `whitted` command: renders scenes with the whitted ray tracer.

mod arguments;
mod bench_command;
mod progress;
mod render_command;

use std::process::ExitCode;

use clap::{Parser, Subcommand};

/// A classic (Whitted-style) ray tracer: exact primitives, Phong shading,
/// shadows, mirror reflection and refraction.
///
/// Start with `whitted render`: with no scene file it renders the built-in
/// scene (a mirror sphere and a glass sphere over a checkered floor) to
/// whitted.png. Scene files are described in docs/scene-format.md.
#[derive(Debug, Parser)]
#[command(name = "whitted", version, about, long_about)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Debug, Subcommand)]
enum Command {
    Render(render_command::RenderArgs),
    Bench(bench_command::BenchArgs),
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    let result = match cli.command {
        Command::Render(args) => render_command::run(&args),
        Command::Bench(args) => bench_command::run(&args),
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(message) => {
            eprintln!("error: {message}");
            ExitCode::FAILURE
        }
    }
}
