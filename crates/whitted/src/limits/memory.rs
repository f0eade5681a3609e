//! The memory budget: the most bytes one request sized by input may take.
//!
//! The budget is one per process. By default it is 3/4 of the memory this
//! process may use: the smallest of the machine's `MemTotal`
//! (`/proc/meminfo`), the control group's limit (`memory.max`, or
//! `memory.limit_in_bytes` under cgroup v1) and the process's own limits
//! on its address space and its data (`ulimit -v`, `ulimit -d`); where
//! none can be read it is 4 GiB. The command replaces it with `--max-memory`
//! ([`MemoryBudget::set_current`]). A request ([`MemoryBudget::check`]) is
//! measured before anything is allocated for it, so what input declares
//! (an image size, a texture header) is refused with a message instead of
//! ending in the allocator's abort.
//!
//! The budget is for the whole run, not for each request: what stays in
//! memory once made (decoded textures with their mipmaps, Bézier patches
//! and their pieces, a render's films) is charged to one ledger while it
//! is held ([`MemoryBudget::charge`], a [`Charge`] given back when
//! dropped), and every request is weighed together with what the ledger
//! holds.

use std::fmt;
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::{Arc, OnceLock};

/// Budget used where the machine's memory cannot be read.
const FALLBACK_BYTES: u64 = 4 << 30;

/// The share of the machine's memory the default budget takes, as a
/// fraction numerator / denominator.
const SHARE: (u64, u64) = (3, 4);

/// What bounds the memory a process may use.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum MemoryLimit {
    /// The machine's memory, or its control group's limit.
    Machine,
    /// The process's address space (`RLIMIT_AS`, `ulimit -v`).
    AddressSpace,
    /// The process's data segment (`RLIMIT_DATA`, `ulimit -d`).
    Data,
}

/// Where a budget comes from.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum BudgetOrigin {
    /// 3/4 of the memory this process may use, which is `total` bytes.
    Machine {
        /// The memory this process may use.
        total: u64,
        /// What bounds it.
        by: MemoryLimit,
    },
    /// The machine's memory could not be read.
    Fallback,
    /// Given by the user (`--max-memory`).
    Given,
}

/// The most bytes one request sized by input may take, and why.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct MemoryBudget {
    /// The budget in bytes.
    pub bytes: u64,
    /// Where it comes from.
    pub origin: BudgetOrigin,
}

/// A request larger than what the budget has left.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
pub struct MemoryError {
    /// What was asked for, such as "a 16384x16384 image with 2 AOVs".
    pub what: String,
    /// The bytes it needs.
    pub needed: u64,
    /// The bytes the run held already (textures, patches, films).
    pub held: u64,
    /// The budget it exceeds.
    pub budget: MemoryBudget,
    /// How to ask for less, such as "render a smaller image".
    pub remedy: String,
}

impl fmt::Display for MemoryError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{} needs {}", self.what, format_bytes(self.needed))?;
        if self.held > 0 {
            write!(
                f,
                " beside the {} the run holds already (textures, models, patches, worlds, images)",
                format_bytes(self.held)
            )?;
        }
        write!(
            f,
            "; the memory budget is {}: {}, or raise the budget with --max-memory",
            self.budget, self.remedy
        )
    }
}

/// The bytes held by charges.
#[derive(Debug)]
struct Ledger {
    held: AtomicU64,
}

/// The process's ledger.
static LEDGER: Ledger = Ledger {
    held: AtomicU64::new(0),
};

/// Memory charged to the process's ledger ([`MemoryBudget::charge`]),
/// given back when dropped: keep it with what it pays for.
#[derive(Debug)]
#[must_use = "the memory is given back when the charge is dropped"]
pub struct Charge {
    bytes: u64,
    ledger: &'static Ledger,
}

impl Default for Charge {
    fn default() -> Self {
        Self {
            bytes: 0,
            ledger: &LEDGER,
        }
    }
}

impl Charge {
    /// A charge of nothing, to [`Charge::grow`].
    pub fn none() -> Self {
        Self::default()
    }

    /// The bytes it holds.
    pub fn bytes(&self) -> u64 {
        self.bytes
    }

    /// Adds `more` bytes for `what` (see [`MemoryBudget::charge`]); on a
    /// refusal it holds what it held.
    pub fn grow(
        &mut self,
        budget: &MemoryBudget,
        what: &str,
        more: u64,
        remedy: &str,
    ) -> Result<(), MemoryError> {
        let added = budget.charge_in(self.ledger, what, more, remedy)?;
        self.bytes += added.bytes;
        std::mem::forget(added);
        Ok(())
    }

    /// Follows data that grows as it is read: once its `bytes` pass what
    /// the charge holds by [`GROWTH_STEP`] or more, grows the charge to
    /// them (so that a file is charged a few times, not per statement).
    /// Refused as [`Charge::grow`] is.
    pub fn follow(
        &mut self,
        budget: &MemoryBudget,
        what: &str,
        bytes: u64,
        remedy: &str,
    ) -> Result<(), MemoryError> {
        let more = bytes.saturating_sub(self.bytes);
        if more < GROWTH_STEP {
            return Ok(());
        }
        self.grow(budget, what, more, remedy)
    }
}

/// How far data read from a file may grow past what it is charged before
/// [`Charge::follow`] charges it again.
pub const GROWTH_STEP: u64 = 16 << 20;

impl Drop for Charge {
    fn drop(&mut self) {
        self.ledger.held.fetch_sub(self.bytes, Ordering::Relaxed);
    }
}

/// Charges kept with the value they pay for. It compares equal whatever
/// it holds, so that values that carry it compare by their content.
#[derive(Clone, Debug, Default)]
pub struct Held(Vec<Arc<Charge>>);

impl Held {
    /// Keeps `charge` (a charge of nothing is dropped).
    pub fn keep(&mut self, charge: Charge) {
        if charge.bytes > 0 {
            self.0.push(Arc::new(charge));
        }
    }

    /// The bytes it holds.
    pub fn bytes(&self) -> u64 {
        self.0.iter().map(|c| c.bytes).sum()
    }
}

impl PartialEq for Held {
    fn eq(&self, _: &Self) -> bool {
        true
    }
}

/// The budget given for this process in bytes; 0 when none was given.
static GIVEN: AtomicU64 = AtomicU64::new(0);

impl MemoryBudget {
    /// A budget of `bytes` given by the user.
    pub fn given(bytes: u64) -> Self {
        Self {
            bytes,
            origin: BudgetOrigin::Given,
        }
    }

    /// The default budget: 3/4 of the memory this process may use, or
    /// 4 GiB where that cannot be read. Read from the system once.
    pub fn of_machine() -> Self {
        static MACHINE: OnceLock<MemoryBudget> = OnceLock::new();
        *MACHINE.get_or_init(|| Self::from_total(usable_memory()))
    }

    /// The default budget for a process that may use `total` bytes, bound
    /// by what the limit says (`None`: unknown).
    fn from_total(total: Option<(u64, MemoryLimit)>) -> Self {
        match total {
            Some((total, by)) => Self {
                bytes: total / SHARE.1 * SHARE.0,
                origin: BudgetOrigin::Machine { total, by },
            },
            None => Self {
                bytes: FALLBACK_BYTES,
                origin: BudgetOrigin::Fallback,
            },
        }
    }

    /// This process's budget: the one set by [`MemoryBudget::set_current`],
    /// else [`MemoryBudget::of_machine`].
    pub fn current() -> Self {
        match GIVEN.load(Ordering::Relaxed) {
            0 => Self::of_machine(),
            bytes => Self::given(bytes),
        }
    }

    /// Makes `self` this process's budget (the command does this for
    /// `--max-memory`). A budget of 0 bytes restores the default.
    pub fn set_current(self) {
        GIVEN.store(self.bytes, Ordering::Relaxed);
    }

    /// Refuses a request for `needed` bytes that, with what the ledger
    /// holds, exceeds the budget: `what` names the request ("a 16384x16384
    /// image with 2 AOVs"), `remedy` how to ask for less ("render a
    /// smaller image").
    pub fn check(&self, what: &str, needed: u64, remedy: &str) -> Result<(), MemoryError> {
        self.check_beside(LEDGER.held.load(Ordering::Relaxed), what, needed, remedy)
    }

    /// [`MemoryBudget::check`] beside `held` bytes.
    fn check_beside(
        &self,
        held: u64,
        what: &str,
        needed: u64,
        remedy: &str,
    ) -> Result<(), MemoryError> {
        if held.saturating_add(needed) <= self.bytes {
            return Ok(());
        }
        Err(MemoryError {
            what: what.to_string(),
            needed,
            held,
            budget: *self,
            remedy: remedy.to_string(),
        })
    }

    /// Charges `needed` bytes to the process's ledger, refused as
    /// [`MemoryBudget::check`] refuses; the bytes count against every later
    /// request until the charge is dropped.
    pub fn charge(&self, what: &str, needed: u64, remedy: &str) -> Result<Charge, MemoryError> {
        self.charge_in(&LEDGER, what, needed, remedy)
    }

    /// [`MemoryBudget::charge`] to `ledger`.
    fn charge_in(
        &self,
        ledger: &'static Ledger,
        what: &str,
        needed: u64,
        remedy: &str,
    ) -> Result<Charge, MemoryError> {
        let mut held = ledger.held.load(Ordering::Relaxed);
        loop {
            self.check_beside(held, what, needed, remedy)?;
            match ledger.held.compare_exchange_weak(
                held,
                held + needed,
                Ordering::Relaxed,
                Ordering::Relaxed,
            ) {
                Ok(_) => {
                    return Ok(Charge {
                        bytes: needed,
                        ledger,
                    });
                }
                Err(now) => held = now,
            }
        }
    }
}

impl fmt::Display for MemoryBudget {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let bytes = format_bytes(self.bytes);
        match self.origin {
            BudgetOrigin::Machine { total, by } => write!(
                f,
                "{bytes} ({}/{} of the {} {})",
                SHARE.0,
                SHARE.1,
                format_bytes(total),
                match by {
                    MemoryLimit::Machine => "this machine gives the process",
                    MemoryLimit::AddressSpace => {
                        "of address space the process may use (ulimit -v)"
                    }
                    MemoryLimit::Data => "of data the process may use (ulimit -d)",
                }
            ),
            BudgetOrigin::Fallback => {
                write!(f, "{bytes} (the machine's memory could not be read)")
            }
            BudgetOrigin::Given => write!(f, "{bytes} (as given)"),
        }
    }
}

/// The memory this process may use and what bounds it: the smallest of
/// the machine's total, its control group's limit and the process's
/// limits on its address space and data, where they can be read.
fn usable_memory() -> Option<(u64, MemoryLimit)> {
    let read = |path: &str| std::fs::read_to_string(path).ok();
    let total = read("/proc/meminfo").and_then(|text| mem_total(&text));
    let group = [
        "/sys/fs/cgroup/memory.max",
        "/sys/fs/cgroup/memory/memory.limit_in_bytes",
    ]
    .into_iter()
    .filter_map(|path| read(path)?.trim().parse::<u64>().ok());
    let machine = total
        .into_iter()
        .chain(group)
        .map(|bytes| (bytes, MemoryLimit::Machine));
    machine
        .chain(process_limits())
        .min_by_key(|&(bytes, _)| bytes)
}

/// The process's own limits on its memory, where set.
#[cfg(unix)]
fn process_limits() -> Vec<(u64, MemoryLimit)> {
    use rustix::process::{Resource, getrlimit};
    [
        (Resource::As, MemoryLimit::AddressSpace),
        (Resource::Data, MemoryLimit::Data),
    ]
    .into_iter()
    .filter_map(|(resource, by)| Some((getrlimit(resource).current?, by)))
    .collect()
}

/// The process's own limits on its memory: none known here.
#[cfg(not(unix))]
fn process_limits() -> Vec<(u64, MemoryLimit)> {
    Vec::new()
}

/// `MemTotal` in bytes from the text of `/proc/meminfo`.
fn mem_total(meminfo: &str) -> Option<u64> {
    let line = meminfo.lines().find(|l| l.starts_with("MemTotal:"))?;
    let kib: u64 = line
        .trim_start_matches("MemTotal:")
        .trim()
        .trim_end_matches("kB")
        .trim()
        .parse()
        .ok()?;
    kib.checked_mul(1024)
}

/// Bytes as people read them: "800 bytes", "1.5 KiB", "9.6 GiB".
pub fn format_bytes(bytes: u64) -> String {
    ByteSize(bytes).to_string()
}

/// A size in bytes, displayed as [`format_bytes`] writes it; writing it
/// allocates nothing (for a process whose memory was refused).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct ByteSize(pub u64);

impl std::fmt::Display for ByteSize {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        const UNITS: [&str; 5] = ["KiB", "MiB", "GiB", "TiB", "PiB"];
        if self.0 < 1024 {
            return write!(f, "{} bytes", self.0);
        }
        let mut value = self.0 as f64 / 1024.0;
        let mut unit = 0;
        while value >= 1024.0 && unit + 1 < UNITS.len() {
            value /= 1024.0;
            unit += 1;
        }
        write!(f, "{value:.1} {}", UNITS[unit])
    }
}

/// Parses a size such as `4G`, `512MiB`, `1.5g` or `1000000` (bytes): a
/// number, then optionally K, M, G or T (powers of 1024, any case), with or
/// without a trailing `B` or `iB`. At least one byte.
pub fn parse_size(text: &str) -> Result<u64, String> {
    let expected = || {
        format!(
            "`{text}` is not a size: expected a number of bytes, or one with K, M, G or T, like 512M or 4G"
        )
    };
    let lower = text.trim().to_ascii_lowercase();
    let unitless = lower
        .strip_suffix("ib")
        .or_else(|| lower.strip_suffix('b'))
        .unwrap_or(&lower);
    let (number, shift) = match unitless.chars().last() {
        Some('k') => (&unitless[..unitless.len() - 1], 10),
        Some('m') => (&unitless[..unitless.len() - 1], 20),
        Some('g') => (&unitless[..unitless.len() - 1], 30),
        Some('t') => (&unitless[..unitless.len() - 1], 40),
        _ if lower.ends_with("ib") => return Err(expected()),
        _ => (unitless, 0),
    };
    let value: f64 = number.trim().parse().map_err(|_| expected())?;
    let bytes = value * (1u64 << shift) as f64;
    if !bytes.is_finite() || bytes < 1.0 || bytes >= u64::MAX as f64 {
        return Err(format!("`{text}` is not a size between 1 byte and 16 EiB"));
    }
    Ok(bytes as u64)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_request_above_the_budget_says_what_it_needs_and_how_to_proceed() {
        let budget = MemoryBudget::from_total(Some((16 << 30, MemoryLimit::Machine)));
        assert_eq!(budget.bytes, 12 << 30);
        assert!(
            budget
                .check_beside(0, "a small image", 12 << 30, "render smaller")
                .is_ok()
        );
        let error = budget
            .check_beside(0, "a 16384x16384 image", 13 << 30, "render a smaller image")
            .unwrap_err();
        assert_eq!(
            error.to_string(),
            "a 16384x16384 image needs 13.0 GiB; the memory budget is 12.0 GiB (3/4 of the \
             16.0 GiB this machine gives the process): render a smaller image, or raise the \
             budget with --max-memory"
        );
        let given = MemoryBudget::given(1 << 20).check("x", 1 << 21, "less");
        assert!(
            given
                .unwrap_err()
                .to_string()
                .contains("1.0 MiB (as given)")
        );
    }

    #[test]
    fn charges_add_up_against_the_budget_until_dropped_and_say_what_is_held() {
        // A ledger of its own: the process's is charged by other tests.
        static OWN: Ledger = Ledger {
            held: AtomicU64::new(0),
        };
        let budget = MemoryBudget::given(1 << 40);
        let charge = |bytes: u64| budget.charge_in(&OWN, "a texture", bytes, "use a smaller one");
        let first = charge(600 << 30).unwrap();
        let mut second = Charge {
            bytes: 0,
            ledger: &OWN,
        };
        second.grow(&budget, "b", 300 << 30, "less").unwrap();
        let error = charge(200 << 30).unwrap_err();
        assert_eq!(error.held, 900 << 30);
        assert_eq!(
            error.to_string(),
            "a texture needs 200.0 GiB beside the 900.0 GiB the run holds already (textures, \
             models, patches, worlds, images); the memory budget is 1.0 TiB (as given): use a \
             smaller one, or raise the budget with --max-memory"
        );
        assert!(second.grow(&budget, "c", 200 << 30, "less").is_err());
        assert_eq!(
            second.bytes(),
            300 << 30,
            "a refused growth holds what it held"
        );
        let mut held = Held::default();
        held.keep(second);
        let copy = held.clone();
        drop(held);
        assert_eq!(copy.bytes(), 300 << 30, "shared until the last copy goes");
        drop(first);
        let third = charge(200 << 30).unwrap();
        assert!(charge(600 << 30).is_err());
        drop(copy);
        drop(third);
        assert_eq!(OWN.held.load(Ordering::Relaxed), 0);
        assert!(charge(1 << 40).is_ok());
    }

    #[test]
    fn a_charge_follows_growing_data_a_step_at_a_time() {
        static OWN: Ledger = Ledger {
            held: AtomicU64::new(0),
        };
        let budget = MemoryBudget::given(100 << 20);
        let mut charge = Charge {
            bytes: 0,
            ledger: &OWN,
        };
        let follow = |charge: &mut Charge, bytes| charge.follow(&budget, "a model", bytes, "less");
        follow(&mut charge, GROWTH_STEP - 1).unwrap();
        assert_eq!(charge.bytes(), 0, "less than a step is not charged yet");
        follow(&mut charge, 40 << 20).unwrap();
        assert_eq!(charge.bytes(), 40 << 20);
        follow(&mut charge, (40 << 20) + GROWTH_STEP - 1).unwrap();
        assert_eq!(charge.bytes(), 40 << 20);
        follow(&mut charge, 10 << 20).unwrap();
        assert_eq!(
            charge.bytes(),
            40 << 20,
            "data that shrank is not given back"
        );
        assert!(follow(&mut charge, 120 << 20).is_err());
        assert_eq!(charge.bytes(), 40 << 20, "a refusal holds what it held");
        drop(charge);
        assert_eq!(OWN.held.load(Ordering::Relaxed), 0);
    }

    #[test]
    fn a_process_limit_says_which_it_is() {
        let budget = MemoryBudget::from_total(Some((4 << 30, MemoryLimit::AddressSpace)));
        assert_eq!(
            budget.to_string(),
            "3.0 GiB (3/4 of the 4.0 GiB of address space the process may use (ulimit -v))"
        );
        let budget = MemoryBudget::from_total(Some((2 << 30, MemoryLimit::Data)));
        assert_eq!(
            budget.to_string(),
            "1.5 GiB (3/4 of the 2.0 GiB of data the process may use (ulimit -d))"
        );
    }

    #[test]
    fn an_unreadable_machine_falls_back_to_four_gibibytes() {
        let budget = MemoryBudget::from_total(None);
        assert_eq!(budget.bytes, 4 << 30);
        assert_eq!(
            budget.to_string(),
            "4.0 GiB (the machine's memory could not be read)"
        );
    }

    #[test]
    fn the_machine_budget_is_a_share_of_a_positive_total() {
        let budget = MemoryBudget::of_machine();
        assert!(budget.bytes > 0);
        if let BudgetOrigin::Machine { total, .. } = budget.origin {
            assert_eq!(budget.bytes, total / 4 * 3);
        }
    }

    #[test]
    fn mem_total_is_read_in_kibibytes() {
        let text = "MemTotal:       24684084 kB\nMemFree:         2730424 kB\n";
        assert_eq!(mem_total(text), Some(24684084 * 1024));
        assert_eq!(mem_total("MemFree: 3 kB"), None);
    }

    #[test]
    fn sizes_parse_with_binary_units() {
        assert_eq!(parse_size("1000"), Ok(1000));
        assert_eq!(parse_size("4G"), Ok(4 << 30));
        assert_eq!(parse_size("4gib"), Ok(4 << 30));
        assert_eq!(parse_size("512MB"), Ok(512 << 20));
        assert_eq!(parse_size("1.5k"), Ok(1536));
        assert_eq!(parse_size(" 2T "), Ok(2 << 40));
        for bad in ["", "G", "4X", "-1G", "0", "4iB", "nan", "1e30T"] {
            assert!(parse_size(bad).is_err(), "{bad}");
        }
    }

    #[test]
    fn bytes_format_in_the_largest_whole_unit() {
        assert_eq!(format_bytes(800), "800 bytes");
        assert_eq!(format_bytes(1536), "1.5 KiB");
        assert_eq!(format_bytes(9_600 << 20), "9.4 GiB");
    }
}
