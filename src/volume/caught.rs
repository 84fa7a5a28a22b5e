//! Panics the code expects: a third-party parser or decoder that panics on a corrupt
//! file runs under [`caught`], which turns the panic into an error value and marks it,
//! on its thread, as expected ([`is_expected`]). The app's panic hook
//! (`ui::recovery::install_panic_hook`) takes any other panic for a crash: it keeps
//! the session and writes why. (A panic on another thread that such code started, a
//! rayon worker, is not marked.)

use std::cell::Cell;
use std::panic::{AssertUnwindSafe, catch_unwind};

thread_local! {
    /// How many [`caught`] calls are under way on this thread.
    static EXPECTED: Cell<u32> = const { Cell::new(0) };
}

/// Runs `f`, its panic an `Err` (expected: see the module).
pub fn caught<T>(f: impl FnOnce() -> T) -> std::thread::Result<T> {
    EXPECTED.with(|e| e.set(e.get() + 1));
    let result = catch_unwind(AssertUnwindSafe(f));
    EXPECTED.with(|e| e.set(e.get().saturating_sub(1)));
    result
}

/// Whether a panic now would be one [`caught`] expects.
pub fn is_expected() -> bool {
    EXPECTED.with(|e| e.get() > 0)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_caught_panic_is_expected_while_it_runs_and_an_error_after() {
        assert!(!is_expected());
        let inside = caught(is_expected).unwrap();
        assert!(inside);
        let r: std::thread::Result<()> = caught(|| panic!("corrupt"));
        assert!(r.is_err());
        assert!(!is_expected(), "the mark ends with the call");
    }
}
