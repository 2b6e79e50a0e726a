//! Cooperative cancellation of long computations: the one hook by which a
//! caller (the Python bindings on Ctrl-C) stops a path, a grid or a search
//! between its points.
//!
//! A long loop takes a [`Token`] when it starts and asks
//! [`Token::cancelled`] between its units of work (a continuation point, a
//! grid cell, a deflation start): one relaxed atomic load, so the check
//! costs nothing measurable. [`request`] cancels every computation whose
//! token was taken before it; work started after it runs normally.

use core::sync::atomic::{AtomicU64, Ordering};

/// Cancellation requests so far.
static REQUESTS: AtomicU64 = AtomicU64::new(0);

/// The cancellation requests seen when a computation started.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Token(u64);

impl Token {
    /// A token for a computation starting now.
    #[must_use]
    pub fn now() -> Self {
        Self(REQUESTS.load(Ordering::Relaxed))
    }

    /// True once [`request`] has been called after this token was taken.
    #[must_use]
    #[inline]
    pub fn cancelled(self) -> bool {
        REQUESTS.load(Ordering::Relaxed) != self.0
    }
}

/// Cancel every computation running now (each stops at its next check).
pub fn request() {
    REQUESTS.fetch_add(1, Ordering::Relaxed);
}

/// What a cancelled computation that has no result to return reports.
pub const CANCELLED: &str = "interrupted (cancelled by the caller)";

#[cfg(test)]
mod tests {
    use super::*;

    /// A request cancels the tokens taken before it, not those taken after.
    #[test]
    fn request_cancels_earlier_tokens_only() {
        let before = Token::now();
        assert!(!before.cancelled());
        request();
        let after = Token::now();
        assert!(before.cancelled());
        assert!(!after.cancelled());
    }
}
