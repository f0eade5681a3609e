//! The shared folder beside the repository (`../shared` from its root):
//! scenes and models too large to keep in it. The tests that read it are
//! `#[ignore]`d, so that `cargo test` passes without it, and CI runs them
//! with `cargo test -- --ignored`; run so, they fail when it is missing.

use std::path::{Path, PathBuf};

/// `relative`, a path under the shared folder, which must exist: a test
/// that needs it fails naming the missing path rather than passing.
pub fn shared_path(relative: &str) -> PathBuf {
    let path = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../../shared")
        .join(relative);
    assert!(
        path.exists(),
        "{} is missing: this test needs the shared folder `shared` beside the repository \
         (../shared from its root)",
        path.display()
    );
    path
}
