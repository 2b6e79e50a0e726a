//! Cooperative cancellation of long computations: the one hook by which a
//! caller (the Python bindings on Ctrl-C) stops a path, a grid or a search
//! between its points.
//!
//! A long loop takes a [`Token`] when it starts and asks
//! [`Token::cancelled`] between its units of work (a continuation point, a
//! grid cell, a deflation start): one relaxed atomic load, so the check
//! costs nothing measurable. [`request`] cancels every computation whose
//! token was taken before it; work started after it runs normally.
//!
//! A caller that can only learn of a stop on its own thread (Python asks for
//! its signals on the main thread) runs the work inside [`polling`]: the
//! checks the work makes on that thread then also ask the caller, at most
//! once per interval, and a yes is a [`request`]. No thread is started for
//! it; a check without a poller installed costs one thread-local read more.

use core::sync::atomic::{AtomicU64, Ordering};
use std::cell::RefCell;
use std::time::{Duration, Instant};

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
        poll();
        REQUESTS.load(Ordering::Relaxed) != self.0
    }
}

/// The caller's question "stop?" ([`polling`]) and when it was last asked.
struct Poller {
    every: Duration,
    last: Instant,
    ask: Box<dyn FnMut() -> bool>,
}

thread_local! {
    /// The poller of the [`polling`] call running on this thread, if any.
    static POLLER: RefCell<Option<Poller>> = const { RefCell::new(None) };
}

/// Restores the poller a [`polling`] call replaced, also on unwinding.
struct Restore(Option<Poller>);

impl Drop for Restore {
    fn drop(&mut self) {
        let previous = self.0.take();
        POLLER.with(|p| *p.borrow_mut() = previous);
    }
}

/// Run `work` on this thread while every [`Token::cancelled`] check it makes
/// here also calls `ask` (at most once per `every`, first after `every`);
/// `ask` returning true is a [`request`]. `ask` may re-enter the toolkit (a
/// nested `polling` installs its own poller and puts this one back).
pub fn polling<T>(every: Duration, ask: Box<dyn FnMut() -> bool>, work: impl FnOnce() -> T) -> T {
    let poller = Poller {
        every,
        last: Instant::now(),
        ask,
    };
    let _restore = Restore(POLLER.with(|p| p.borrow_mut().replace(poller)));
    work()
}

/// Ask this thread's poller if its interval has passed.
fn poll() {
    // Taken out while it runs, so that `ask` may re-enter (a nested check
    // sees no poller; a nested `polling` restores the empty slot).
    let Some(mut poller) = POLLER.with(|p| p.borrow_mut().take()) else {
        return;
    };
    let now = Instant::now();
    if now.duration_since(poller.last) >= poller.every {
        poller.last = now;
        if (poller.ask)() {
            request();
        }
    }
    POLLER.with(|p| *p.borrow_mut() = Some(poller));
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

    /// Inside `polling`, a check asks the poller once its interval has
    /// passed and cancels on a yes; outside it, nothing is asked.
    #[test]
    fn polling_asks_on_the_checks_and_cancels_on_yes() {
        use std::rc::Rc;
        let asked = Rc::new(core::cell::Cell::new(0));
        let counter = asked.clone();
        let ask = Box::new(move || {
            counter.set(counter.get() + 1);
            counter.get() >= 2
        });
        let token = Token::now();
        polling(Duration::ZERO, ask, || {
            assert!(!token.cancelled(), "first answer is no");
            assert!(token.cancelled(), "second answer is yes");
            // re-entry: a nested polling call with its own poller
            let inner = Token::now();
            polling(Duration::from_secs(3600), Box::new(|| true), || {
                assert!(!inner.cancelled())
            });
        });
        assert_eq!(asked.get(), 2);
        let after = Token::now();
        assert!(!after.cancelled(), "no poller outside polling");
        assert_eq!(asked.get(), 2);
    }
}
