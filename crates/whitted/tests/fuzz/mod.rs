//! A seeded, deterministic mutation fuzzer for every reader, on stable Rust.
//!
//! Each case is a pure function of its seed: a starting input (a fixture of
//! the repository or a generated one), one to four mutations, and the
//! acceleration structure to render with. A case must not panic (caught per
//! case, then minimized and reported with its seed), must end within
//! `WHITTED_FUZZ_SLOW_SECONDS` (5 by default; a hang is stopped by the
//! watchdog in [`guard`]), and no single allocation may exceed
//! [`guard::MAX_ALLOCATION`].
//!
//! Environment:
//! - `WHITTED_FUZZ_CASES`: cases per target (default 1000, a few seconds);
//! - `WHITTED_FUZZ_SEED`: the run's seed (default fixed, so `cargo test`
//!   is reproducible);
//! - `WHITTED_FUZZ_REPLAY=target:seed`: run that one case and print it;
//! - `WHITTED_FUZZ_TRACE=1`: print each case's seed before running it (to
//!   find a case that kills the process, such as a stack overflow).

pub mod corpus;
pub mod guard;
pub mod mutate;
pub mod targets;

use std::any::Any;
use std::cell::{Cell, RefCell};
use std::panic::{AssertUnwindSafe, catch_unwind};
use std::time::{Duration, Instant};

use whitted::accel::AccelKind;
use whitted::math::random::{Rng, hash64};

use self::mutate::Mutator;
use self::targets::{Target, Workspace};

/// A number from the environment, or `default`.
fn setting(name: &str, default: u64) -> u64 {
    std::env::var(name)
        .ok()
        .and_then(|s| {
            let s = s.trim();
            match s.strip_prefix("0x") {
                Some(hex) => u64::from_str_radix(hex, 16).ok(),
                None => s.parse().ok(),
            }
        })
        .unwrap_or(default)
}

/// One case: its input parts and the structure to render with.
struct Case {
    parts: Vec<Vec<u8>>,
    accel: AccelKind,
}

/// The case of `target` named by `seed`.
fn make_case(target: &Target, seed: u64) -> Case {
    let rng = Rng::new(seed);
    let flat: Vec<Vec<u8>> = target.corpus.concat();
    let mut m = Mutator::new(rng, target.text, &flat, &target.vocabulary);
    let parts = target
        .corpus
        .iter()
        .enumerate()
        .map(|(part, corpus)| {
            let mut input = if corpus.is_empty() || m.chance(0.5) {
                (target.generate)(&mut m.rng, part)
            } else {
                corpus[m.below(corpus.len())].clone()
            };
            if m.chance(0.9) {
                m.mutate(&mut input);
            }
            input
        })
        .collect();
    let accel = AccelKind::ALL[m.below(AccelKind::ALL.len())];
    Case { parts, accel }
}

thread_local! {
    /// Set while this thread runs a case: its panics are expected, so the
    /// panic hook keeps quiet and notes where it happened.
    static IN_CASE: Cell<bool> = const { Cell::new(false) };
    /// Where the last panic of a case on this thread happened.
    static LOCATION: RefCell<String> = const { RefCell::new(String::new()) };
}

/// Installs, once, a panic hook that is silent inside cases.
fn quiet_panics_in_cases() {
    static HOOK: std::sync::Once = std::sync::Once::new();
    HOOK.call_once(|| {
        let default = std::panic::take_hook();
        std::panic::set_hook(Box::new(move |info| {
            if IN_CASE.with(Cell::get) {
                let place = info
                    .location()
                    .map(|l| format!("{}:{}", l.file(), l.line()))
                    .unwrap_or_default();
                LOCATION.with(|l| *l.borrow_mut() = place);
            } else {
                default(info);
            }
        }));
    });
}

/// The text of a panic's payload.
fn payload_text(payload: &(dyn Any + Send)) -> String {
    if let Some(text) = payload.downcast_ref::<&str>() {
        text.to_string()
    } else if let Some(text) = payload.downcast_ref::<String>() {
        text.clone()
    } else {
        "a panic without a message".to_string()
    }
}

/// How a case went.
#[derive(Clone, Debug, PartialEq)]
enum Outcome {
    /// It ran to the end; the reader accepted the input or not.
    Fine { accepted: bool },
    /// It panicked: where, and with what message.
    Panicked { place: String, message: String },
    /// It took longer than allowed.
    Slow(Duration),
}

/// Runs one case of `target`, marked in `slot` for the guards.
fn run_case(
    target: &Target,
    slot: usize,
    workspace: &Workspace,
    seed: u64,
    parts: &[Vec<u8>],
    accel: AccelKind,
) -> Outcome {
    let slow = Duration::from_secs(setting("WHITTED_FUZZ_SLOW_SECONDS", 5));
    guard::start(slot, target.name, seed);
    IN_CASE.with(|c| c.set(true));
    LOCATION.with(|l| l.borrow_mut().clear());
    let started = Instant::now();
    let result = catch_unwind(AssertUnwindSafe(|| (target.run)(workspace, parts, accel)));
    let took = started.elapsed();
    IN_CASE.with(|c| c.set(false));
    guard::finish(slot);
    match result {
        Err(payload) => Outcome::Panicked {
            place: LOCATION.with(|l| l.borrow().clone()),
            message: payload_text(payload.as_ref()),
        },
        Ok(_) if took > slow => Outcome::Slow(took),
        Ok(accepted) => Outcome::Fine { accepted },
    }
}

/// The smallest input found that still panics at the same place, by
/// removing ever smaller pieces of each part (lines first, for text).
fn minimize(
    target: &Target,
    slot: usize,
    workspace: &Workspace,
    seed: u64,
    case: &Case,
    failure: &Outcome,
) -> Vec<Vec<u8>> {
    let mut parts = case.parts.clone();
    let mut budget = 2000;
    let deadline = Instant::now() + Duration::from_secs(60);
    let same = |outcome: &Outcome| match (outcome, failure) {
        (Outcome::Panicked { place: a, .. }, Outcome::Panicked { place: b, .. }) => a == b,
        _ => false,
    };
    for part in 0..parts.len() {
        let mut chunk = parts[part].len().div_ceil(2).max(1);
        loop {
            let mut start = 0;
            while start < parts[part].len() && budget > 0 && Instant::now() < deadline {
                budget -= 1;
                let end = (start + chunk).min(parts[part].len());
                let mut trial = parts.clone();
                trial[part].drain(start..end);
                if same(&run_case(target, slot, workspace, seed, &trial, case.accel)) {
                    parts = trial;
                } else {
                    start = end;
                }
            }
            if chunk == 1 {
                break;
            }
            chunk = chunk.div_ceil(2);
        }
    }
    parts
}

/// An input as it is printed in a report.
fn show(target: &Target, input: &[u8]) -> String {
    if target.text {
        String::from_utf8_lossy(input).into_owned()
    } else {
        input.escape_ascii().to_string()
    }
}

/// The report of a failed case.
fn report(target: &Target, seed: u64, outcome: &Outcome, parts: &[Vec<u8>]) -> String {
    let what = match outcome {
        Outcome::Panicked { place, message } => format!("panicked at {place}: {message}"),
        Outcome::Slow(took) => format!("took {took:?}"),
        Outcome::Fine { .. } => "is".to_string(),
    };
    let mut text = format!(
        "{} case {seed:#018x} {what}\n(replay: WHITTED_FUZZ_REPLAY={}:{seed:#018x})",
        target.name, target.name
    );
    for (i, part) in parts.iter().enumerate() {
        text.push_str(&format!(
            "\n--- part {i} ({} bytes):\n{}",
            part.len(),
            show(target, part)
        ));
    }
    text
}

/// Fuzzes `target` in guard slot `slot`; fails with a report of every
/// distinct failure (by panic place) found.
pub fn fuzz(target: Target, slot: usize) {
    quiet_panics_in_cases();
    let workspace = Workspace::new();
    let replay = std::env::var("WHITTED_FUZZ_REPLAY").ok();
    let seeds: Vec<u64> = match replay.as_deref().and_then(|r| r.split_once(':')) {
        Some((name, _)) if name != target.name => return,
        Some((_, seed)) => {
            let seed = seed.trim_start_matches("0x");
            vec![u64::from_str_radix(seed, 16).expect("WHITTED_FUZZ_REPLAY=target:hex-seed")]
        }
        None => {
            let base = setting("WHITTED_FUZZ_SEED", 0x5eed);
            let cases = setting("WHITTED_FUZZ_CASES", 1000);
            let name = hash64(target.name.bytes().fold(0, |h, b| h * 31 + u64::from(b)));
            (0..cases)
                .map(|i| hash64(base ^ name ^ hash64(i)))
                .collect()
        }
    };
    let trace = std::env::var_os("WHITTED_FUZZ_TRACE").is_some() || replay.is_some();
    let mut failures: Vec<(Outcome, String)> = Vec::new();
    let mut accepted_count = 0;
    let started = Instant::now();
    for &seed in &seeds {
        let case = make_case(&target, seed);
        if trace {
            eprintln!(
                "{}",
                report(
                    &target,
                    seed,
                    &Outcome::Fine { accepted: true },
                    &case.parts
                )
            );
        }
        let outcome = run_case(&target, slot, &workspace, seed, &case.parts, case.accel);
        let known = failures.iter().any(|(o, _)| match (o, &outcome) {
            (Outcome::Panicked { place: a, .. }, Outcome::Panicked { place: b, .. }) => a == b,
            (Outcome::Slow(_), Outcome::Slow(_)) => true,
            _ => false,
        });
        if let Outcome::Fine { accepted } = outcome {
            accepted_count += usize::from(accepted);
            continue;
        }
        if known {
            continue;
        }
        let parts = match outcome {
            Outcome::Panicked { .. } => minimize(&target, slot, &workspace, seed, &case, &outcome),
            _ => case.parts.clone(),
        };
        let text = report(&target, seed, &outcome, &parts);
        eprintln!("{text}\n");
        failures.push((outcome, text));
    }
    eprintln!(
        "fuzz: {} cases of {} ({accepted_count} accepted) in {:.1?}, {} distinct failures",
        seeds.len(),
        target.name,
        started.elapsed(),
        failures.len()
    );
    assert!(
        failures.is_empty(),
        "{} distinct failures of {}:\n\n{}",
        failures.len(),
        target.name,
        failures
            .iter()
            .map(|(_, text)| text.as_str())
            .collect::<Vec<_>>()
            .join("\n\n")
    );
}
