//! Ctrl-C during a long Rust call: the one place where the bindings turn a
//! SIGINT into `KeyboardInterrupt` while Rust computes.
//!
//! Python runs its signal handlers only on the main thread and only when
//! that thread asks (`PyErr_CheckSignals`). A call releases the GIL and
//! computes on the calling thread ([`detach_interruptible`]): the
//! computation's own cancellation checks (the continuation stepper, the
//! grid loops and the deflation search, between their points) ask Python
//! for pending signals every [`POLL`] ([`ivt_num::cancel::polling`]), and a
//! signal whose handler raises cancels the computation
//! ([`ivt_num::cancel::request`]) and is raised instead of the truncated
//! result. No thread is started: the call costs what the computation costs.
//! Work that runs on rayon's pool leaves the calling thread blocked, so
//! [`detach_interruptible_threaded`] runs it from a worker thread while the
//! calling thread polls. A cancellation reaches every Rust computation
//! running in the process at that moment (those of other Python threads
//! included; they raise `KeyboardInterrupt` as well). One long point (a
//! single dense solve) is not interrupted inside: the stop comes at the
//! next check.

use pyo3::exceptions::{PyKeyboardInterrupt, PyRuntimeError};
use pyo3::prelude::*;
use std::cell::RefCell;
use std::rc::Rc;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::Duration;

/// How often a running call asks Python for signals.
const POLL: Duration = Duration::from_millis(50);

/// Stack of the worker thread: the main thread's usual 8 MiB.
const STACK: usize = 8 << 20;

/// Run `work` on this thread with the GIL released; a signal whose handler
/// raises (Ctrl-C: `KeyboardInterrupt`) cancels it and is raised.
///
/// # Errors
/// The signal handler's exception, or `KeyboardInterrupt` when another
/// thread's signal cancelled the work.
pub(crate) fn detach_interruptible<T: Send>(
    py: Python<'_>,
    work: impl FnOnce() -> T + Send,
) -> PyResult<T> {
    let token = ivt_num::cancel::Token::now();
    let (out, signal) = py.detach(|| {
        let signal: Rc<RefCell<Option<PyErr>>> = Rc::default();
        let slot = Rc::clone(&signal);
        let ask = Box::new(move || {
            let mut slot = slot.borrow_mut();
            if slot.is_none() {
                *slot = Python::attach(|py| py.check_signals().err());
            }
            // asked again after a signal: a computation started since stops too
            slot.is_some()
        });
        let out = ivt_num::cancel::polling(POLL, ask, work);
        let signal = signal.borrow_mut().take();
        (out, signal)
    });
    outcome(Some(out), signal, token)
}

/// As [`detach_interruptible`] for work that runs on rayon's pool (the
/// calling thread would block in it): the work runs on a worker thread and
/// the calling thread polls for signals every [`POLL`] until it returns.
///
/// # Errors
/// As [`detach_interruptible`], or a RuntimeError when no thread can be
/// started.
pub(crate) fn detach_interruptible_threaded<T: Send>(
    py: Python<'_>,
    work: impl FnOnce() -> T + Send,
) -> PyResult<T> {
    let done = AtomicBool::new(false);
    let token = ivt_num::cancel::Token::now();
    let (result, signal) = py.detach(|| {
        std::thread::scope(|s| {
            let (waiter, finished) = (std::thread::current(), &done);
            let worker = std::thread::Builder::new()
                .name("ivt-call".into())
                .stack_size(STACK)
                .spawn_scoped(s, move || {
                    let out = work();
                    finished.store(true, Ordering::Release);
                    waiter.unpark();
                    out
                });
            let worker = match worker {
                Ok(w) => w,
                Err(e) => {
                    let e = PyRuntimeError::new_err(format!("cannot start a thread: {e}"));
                    return (None, Some(e));
                }
            };
            let mut signal: Option<PyErr> = None;
            while !done.load(Ordering::Acquire) {
                std::thread::park_timeout(POLL);
                if done.load(Ordering::Acquire) {
                    break;
                }
                if signal.is_none() {
                    signal = Python::attach(|py| py.check_signals().err());
                }
                if signal.is_some() {
                    ivt_num::cancel::request();
                }
            }
            match worker.join() {
                Ok(out) => (Some(out), signal),
                Err(panic) => std::panic::resume_unwind(panic),
            }
        })
    });
    outcome(result, signal, token)
}

/// The call's result: the signal's exception if one was raised, a
/// `KeyboardInterrupt` if another thread cancelled the work (`token` taken
/// before it started; the result is then truncated), else the result.
fn outcome<T>(
    result: Option<T>,
    signal: Option<PyErr>,
    token: ivt_num::cancel::Token,
) -> PyResult<T> {
    match (result, signal) {
        (_, Some(e)) => Err(e),
        (Some(_), None) if token.cancelled() => Err(PyKeyboardInterrupt::new_err(
            "interrupted by a signal in another thread",
        )),
        (Some(out), None) => Ok(out),
        (None, None) => Err(PyRuntimeError::new_err("the call did not run")),
    }
}
