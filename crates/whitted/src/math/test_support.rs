//! Helpers for the crate's own tests.

/// The environment variable that lets the AVX tests pass on a processor
/// without AVX, where they cannot run: set it to `1`.
pub(crate) const ALLOW_NO_AVX: &str = "WHITTED_ALLOW_NO_AVX";

/// True when the processor has AVX, so that a test of an AVX code path can
/// run. Without AVX such a test would prove nothing, so this panics (the
/// test fails) unless [`ALLOW_NO_AVX`] is `1`; then it prints that the test
/// is skipped and returns false.
#[allow(
    clippy::print_stderr,
    reason = "a skipped test says so in the test harness's output"
)]
pub(crate) fn has_avx_or_skip_allowed() -> bool {
    let allowed = std::env::var(ALLOW_NO_AVX).ok();
    match avx_decision(is_x86_feature_detected!("avx"), allowed.as_deref()) {
        Ok(true) => true,
        Ok(false) => {
            eprintln!("skipped: this processor has no AVX ({ALLOW_NO_AVX}=1)");
            false
        }
        Err(message) => panic!("{message}"),
    }
}

/// Whether to run an AVX test, given whether the processor has AVX and the
/// value of [`ALLOW_NO_AVX`]: run it, skip it, or fail with why.
fn avx_decision(has_avx: bool, allowed: Option<&str>) -> Result<bool, String> {
    match (has_avx, allowed) {
        (true, _) => Ok(true),
        (false, Some("1")) => Ok(false),
        (false, _) => Err(format!(
            "this processor has no AVX, so the AVX code path cannot be tested; \
             set {ALLOW_NO_AVX}=1 to skip the AVX tests on purpose"
        )),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_missing_avx_fails_unless_the_switch_is_exactly_one() {
        assert_eq!(avx_decision(true, None), Ok(true));
        assert_eq!(avx_decision(true, Some("1")), Ok(true));
        assert_eq!(avx_decision(false, Some("1")), Ok(false));
        for allowed in [None, Some(""), Some("0"), Some("yes")] {
            let error = avx_decision(false, allowed).unwrap_err();
            assert!(error.contains("WHITTED_ALLOW_NO_AVX=1"), "{error}");
        }
    }
}
