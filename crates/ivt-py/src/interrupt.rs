//! Ctrl-C during a long Rust call: the one place where the bindings turn a
//! SIGINT into `KeyboardInterrupt` while Rust computes.
//!
//! Python runs its signal handlers only on the main thread and only when
//! that thread asks (`PyErr_CheckSignals`). So the call runs on a worker
//! thread with the GIL released while the calling thread waits, waking
//! every [`POLL`] to ask Python for pending signals; on one it requests
//! cancellation ([`ivt_num::cancel::request`]: the continuation stepper, the
//! grid loops and the deflation search stop at their next check, each
//! within one point) and, once the worker has returned, raises the
//! signal's exception (`KeyboardInterrupt`) instead of the truncated
//! result. The request is repeated at every poll until the worker returns,
//! so that a computation the call starts after the first request stops too.
//! A cancellation reaches every Rust computation running in the process at
//! that moment (those of other Python threads included; they raise
//! `KeyboardInterrupt` as well).

use pyo3::exceptions::{PyKeyboardInterrupt, PyRuntimeError};
use pyo3::prelude::*;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::Duration;

/// How often the waiting thread asks Python for signals.
const POLL: Duration = Duration::from_millis(50);

/// Stack of the worker thread: the main thread's usual 8 MiB.
const STACK: usize = 8 << 20;

/// Run `work` with the GIL released on a worker thread; a signal whose
/// handler raises (Ctrl-C: `KeyboardInterrupt`) cancels it and is raised.
///
/// # Errors
/// The signal handler's exception, or a RuntimeError when no thread can be
/// started.
pub(crate) fn detach_interruptible<T: Send>(
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
    match (result, signal) {
        (_, Some(e)) => Err(e),
        // cancelled by another thread's Ctrl-C: the result is truncated
        (Some(_), None) if token.cancelled() => Err(PyKeyboardInterrupt::new_err(
            "interrupted by a signal in another thread",
        )),
        (Some(out), None) => Ok(out),
        (None, None) => Err(PyRuntimeError::new_err("the call did not run")),
    }
}
