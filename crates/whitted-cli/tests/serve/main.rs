//! `whitted serve`: its HTTP interface (`api.rs`) and its page in a real
//! browser, headless chromium driven over WebDriver (`browser.rs`).

mod api;
mod browser;
#[path = "../common/pfm.rs"]
mod pfm;
mod support;
