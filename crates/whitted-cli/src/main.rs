//! The `whitted` command: renders scenes with the whitted ray tracer.
//!
//! It prints only through [`report`], which never panics.
#![deny(clippy::print_stdout, clippy::print_stderr, clippy::dbg_macro)]

mod anti_aliasing;
mod arguments;
mod bench_command;
#[cfg(unix)]
mod closed_streams;
mod explain_command;
mod explain_json;
mod explain_svg;
mod explain_text;
mod merge_command;
mod outputs;
mod progress;
#[cfg(unix)]
mod refused_memory;
mod render_command;
mod render_stats;
mod report;
mod scene_arguments;
mod serve;
#[cfg(unix)]
mod signals;
mod split;

use std::process::ExitCode;

use clap::{Parser, Subcommand};

use crate::report::note;

#[cfg(unix)]
#[global_allocator]
static ALLOCATOR: refused_memory::Noting = refused_memory::Noting;

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
    Merge(merge_command::MergeArgs),
    Explain(explain_command::ExplainArgs),
    Serve(serve::ServeArgs),
}

fn main() -> ExitCode {
    let cli = match Cli::try_parse() {
        Ok(cli) => cli,
        // Help and the version go to standard output as clap prints them.
        Err(e) if !e.use_stderr() => e.exit(),
        // Usage errors quote the arguments, which may be long: they are
        // printed as every report is (see report::bounded).
        Err(e) => {
            note!("{}", e.render().to_string().trim_end());
            return ExitCode::from(e.exit_code().clamp(0, 255) as u8);
        }
    };
    #[cfg(unix)]
    if let Err(message) = refused_memory::end_refusals_as_errors() {
        note!("warning: {message}; memory the system refuses will abort the run");
    }
    #[cfg(unix)]
    if let Err(message) = signals::remove_partial_files_on_signals() {
        note!("warning: {message}; an interrupted render may leave .partial files behind");
    }
    // A backend asked for by name that is no instruction set, or one the
    // processor lacks, is refused before any work (the library would use
    // the widest instead).
    let result = whitted::accel::Isa::from_environment().and_then(|_| match cli.command {
        Command::Render(args) => render_command::run(&args),
        Command::Bench(args) => bench_command::run(&args),
        Command::Merge(args) => merge_command::run(&args),
        Command::Explain(args) => explain_command::run(&args),
        Command::Serve(args) => serve::run(args),
    });
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(message) => {
            note!("error: {message}");
            ExitCode::FAILURE
        }
    }
}
