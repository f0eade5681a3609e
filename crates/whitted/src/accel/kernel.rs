//! The instruction set the walks and their leaf tests run with, chosen in
//! this one place.
//!
//! A query enters its kernel once: [`run`] looks at the [`Backend`] the
//! caller holds and calls the task's generic code through a function
//! compiled for that instruction set. Everything the task inlines (the
//! walk, the slab test, the caller's leaf tests) is compiled under the same
//! target features, so a leaf visit is no call into code built for another
//! instruction set, with its register spills around it. The walks and the
//! world name a [`Kernel`] type, never a `cfg` or a feature check.
//!
//! Every backend gives the same answers bit for bit: the `f64` tests are
//! the same operations whatever the instruction set (Rust never fuses a
//! multiply and an add on its own, so FMA in the target features changes
//! no result), and the slab tests of the backends are checked against each
//! other.
//!
//! The choice is the widest backend this processor runs, unless the
//! environment variable [`ISA_VARIABLE`] names a narrower one (as the tests
//! do, to check every backend on one machine).

use std::sync::OnceLock;

#[cfg(target_arch = "x86_64")]
use super::bvh::SlabsAvx;
use super::bvh::{Halves, SlabTest};

/// The environment variable that picks a backend by name
/// ([`Isa::name`]): no wider than the processor runs.
pub const ISA_VARIABLE: &str = "WHITTED_ISA";

/// An instruction set a backend is compiled for, narrowest first.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub enum Isa {
    /// What every processor of the target runs: SSE2 on x86-64, glam's
    /// portable code elsewhere.
    Sse2,
    /// AVX: eight `f32` lanes, four `f64` lanes.
    Avx,
    /// AVX2 with FMA, BMI1, BMI2 and LZCNT (x86-64-v3).
    Avx2,
}

impl Isa {
    /// Every instruction set, narrowest first.
    pub const ALL: [Isa; 3] = [Isa::Sse2, Isa::Avx, Isa::Avx2];

    /// Its name, as [`ISA_VARIABLE`] takes it.
    pub fn name(self) -> &'static str {
        match self {
            Isa::Sse2 => "sse2",
            Isa::Avx => "avx",
            Isa::Avx2 => "avx2",
        }
    }

    /// The instruction set called `name`.
    pub fn from_name(name: &str) -> Option<Isa> {
        Self::ALL.into_iter().find(|isa| isa.name() == name)
    }

    /// The widest instruction set this processor runs.
    pub fn widest() -> Isa {
        #[cfg(target_arch = "x86_64")]
        {
            let v3 = is_x86_feature_detected!("avx2")
                && is_x86_feature_detected!("fma")
                && is_x86_feature_detected!("bmi1")
                && is_x86_feature_detected!("bmi2")
                && is_x86_feature_detected!("lzcnt");
            if v3 {
                return Isa::Avx2;
            }
            if is_x86_feature_detected!("avx") {
                return Isa::Avx;
            }
        }
        Isa::Sse2
    }

    /// The instruction set [`ISA_VARIABLE`] asks for, if it is set: an
    /// error names a value that is no instruction set, or one this
    /// processor does not run.
    pub fn from_environment() -> Result<Option<Isa>, String> {
        let Some(value) = std::env::var_os(ISA_VARIABLE) else {
            return Ok(None);
        };
        let names = Self::ALL.map(Isa::name).join(", ");
        let value = value.to_string_lossy();
        let isa = Self::from_name(&value).ok_or_else(|| {
            format!("{ISA_VARIABLE}={value:?} is no instruction set; expected one of {names}")
        })?;
        let widest = Self::widest();
        if isa > widest {
            return Err(format!(
                "{ISA_VARIABLE}={value}: this processor runs at most {}",
                widest.name()
            ));
        }
        Ok(Some(isa))
    }
}

/// An instruction set this processor runs: the only way to enter a
/// kernel ([`run`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct Backend(Isa);

impl Backend {
    /// The backend queries use: the one [`ISA_VARIABLE`] names, else the
    /// widest; chosen once per process. A value of the variable that
    /// [`Isa::from_environment`] refuses is ignored here (the command
    /// refuses it before it starts).
    pub fn current() -> Backend {
        static CURRENT: OnceLock<Backend> = OnceLock::new();
        *CURRENT.get_or_init(|| {
            Backend(
                Isa::from_environment()
                    .ok()
                    .flatten()
                    .unwrap_or_else(Isa::widest),
            )
        })
    }

    /// The backend for `isa`, if this processor runs it.
    pub fn new(isa: Isa) -> Option<Backend> {
        (isa <= Isa::widest()).then_some(Backend(isa))
    }

    /// Every backend this processor runs, narrowest first.
    pub fn available() -> impl Iterator<Item = Backend> {
        Isa::ALL.into_iter().filter_map(Backend::new)
    }

    /// Its instruction set.
    pub fn isa(self) -> Isa {
        self.0
    }

    /// Whether it has AVX's `f64` lanes, which the leaf tests of runs of
    /// triangles and spheres use.
    pub fn has_avx(self) -> bool {
        self.0 >= Isa::Avx
    }
}

impl Default for Backend {
    fn default() -> Self {
        Backend::current()
    }
}

/// What a kernel is compiled with: the code each walk uses on its
/// instruction set. Implemented by one type per [`Isa`].
pub(crate) trait Kernel {
    /// Its instruction set.
    const ISA: Isa;
    /// The BVH's slab test of a node's eight children.
    type Slabs: SlabTest;
    /// Whether it has AVX's four `f64` lanes, for the leaf tests of four
    /// primitives at once (the world maps this to its lanes).
    const F64_LANES: bool;
}

/// The portable kernel.
pub(crate) struct Sse2Kernel;

impl Kernel for Sse2Kernel {
    const ISA: Isa = Isa::Sse2;
    type Slabs = Halves;
    const F64_LANES: bool = false;
}

/// The AVX kernel.
#[cfg(target_arch = "x86_64")]
pub(crate) struct AvxKernel;

#[cfg(target_arch = "x86_64")]
impl Kernel for AvxKernel {
    const ISA: Isa = Isa::Avx;
    type Slabs = SlabsAvx;
    const F64_LANES: bool = true;
}

/// The AVX2 + FMA kernel.
#[cfg(target_arch = "x86_64")]
pub(crate) struct Avx2Kernel;

#[cfg(target_arch = "x86_64")]
impl Kernel for Avx2Kernel {
    const ISA: Isa = Isa::Avx2;
    type Slabs = SlabsAvx;
    const F64_LANES: bool = true;
}

/// Runs `f` out of line, compiled with the target features of the kernels
/// packets are walked together in (AVX), so that the four-lane
/// tests `f` inlines are compiled into it rather than called one by one
/// (a packet's leaf callback, which cannot name its kernel, is compiled
/// without them). Give `f` `#[inline(always)]`.
///
/// # Safety
///
/// Call it only where the processor runs those features: in a packet's
/// walk.
#[inline(always)]
pub(crate) unsafe fn with_packet_features<R>(f: impl FnOnce() -> R) -> R {
    #[cfg(target_arch = "x86_64")]
    // SAFETY: the caller's contract.
    return unsafe { with_avx(f) };
    #[cfg(not(target_arch = "x86_64"))]
    f()
}

/// `f`, compiled for AVX.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx")]
#[inline(never)]
fn with_avx<R>(f: impl FnOnce() -> R) -> R {
    f()
}

/// Work generic over the kernel it runs with. [`KernelTask::run`] should
/// be `#[inline(always)]`, and so should what it calls that is hot, so that
/// it is compiled under the kernel's target features.
pub(crate) trait KernelTask {
    /// What the task returns.
    type Output;

    /// The task, with kernel `K`.
    fn run<K: Kernel>(self) -> Self::Output;
}

/// Runs `task` with the kernel of `backend`.
#[inline(always)]
pub(crate) fn run<T: KernelTask>(backend: Backend, task: T) -> T::Output {
    match backend.0 {
        #[cfg(target_arch = "x86_64")]
        // SAFETY: a `Backend` is made only for an instruction set the
        // processor runs.
        Isa::Avx2 => unsafe { run_avx2(task) },
        #[cfg(target_arch = "x86_64")]
        // SAFETY: as above.
        Isa::Avx => unsafe { run_avx(task) },
        _ => task.run::<Sse2Kernel>(),
    }
}

/// `task` with the AVX kernel, compiled for it.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx")]
fn run_avx<T: KernelTask>(task: T) -> T::Output {
    task.run::<AvxKernel>()
}

/// `task` with the AVX2 kernel, compiled for it.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2,fma,bmi1,bmi2,lzcnt")]
fn run_avx2<T: KernelTask>(task: T) -> T::Output {
    task.run::<Avx2Kernel>()
}

/// For tests of the walks that only the AVX backends take (the packet
/// walks): true when the current backend has AVX. A backend narrowed on
/// purpose (`WHITTED_ISA`) skips them, saying so; a processor without AVX
/// fails them unless skipping is allowed (`math::test_support`).
#[cfg(test)]
#[allow(
    clippy::print_stderr,
    reason = "a skipped test says so in the test harness's output"
)]
pub(crate) fn walks_with_avx_or_skip() -> bool {
    if Isa::widest() >= Isa::Avx && !Backend::current().has_avx() {
        eprintln!("skipped: {ISA_VARIABLE} asks for a backend without AVX");
        return false;
    }
    crate::math::test_support::has_avx_or_skip_allowed()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_round_trip_and_backends_never_exceed_the_processor() {
        for isa in Isa::ALL {
            assert_eq!(Isa::from_name(isa.name()), Some(isa));
            assert_eq!(Backend::new(isa).is_some(), isa <= Isa::widest());
        }
        assert_eq!(Isa::from_name("avx512"), None);
        assert!(Backend::current().isa() <= Isa::widest());
        assert_eq!(
            Backend::available().last().map(Backend::isa),
            Some(Isa::widest())
        );
    }

    /// Which kernel a task ran with.
    struct WhichIsa;

    impl KernelTask for WhichIsa {
        type Output = Isa;

        #[inline(always)]
        fn run<K: Kernel>(self) -> Isa {
            K::ISA
        }
    }

    #[test]
    fn each_backend_runs_its_own_kernel() {
        for backend in Backend::available() {
            assert_eq!(run(backend, WhichIsa), backend.isa());
        }
    }
}
