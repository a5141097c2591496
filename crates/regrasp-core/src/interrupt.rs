//! Interruption of long computations (Ctrl-C): a caller runs a computation [`within`] a poll
//! (a callback answering "stop now?"), and every long loop of the core — the T-RRT* search, the
//! quasi-static time stepping, the path checks — calls [`check`], which returns
//! [`Error::Interrupted`] once the poll has said so.
//!
//! The poll is scoped to the calling thread (a thread-local set for the duration of
//! [`within`]), so no signature carries it and a computation without one never stops early.
//! Calls are rate limited: the poll runs at most once every [`POLL_INTERVAL`], so a loop may
//! call [`check`] as often as it likes. Parallel work runs through [`parallel`]: the calling
//! thread keeps polling while the work runs on other threads, and each item of the work runs
//! [`Shared::within`] a poll that reads the caller's answer, so an item stops at its next check.

use crate::error::{Error, Result};
use std::cell::RefCell;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::mpsc::RecvTimeoutError;
use std::time::{Duration, Instant};

/// Least time between two polls (a check in between answers from the last poll).
pub const POLL_INTERVAL: Duration = Duration::from_millis(20);

/// The active poll of this thread and when it last ran.
struct Poll<'a> {
    stop: &'a dyn Fn() -> bool,
    last: Instant,
    stopped: bool,
}

thread_local! {
    static ACTIVE: RefCell<Option<Poll<'static>>> = const { RefCell::new(None) };
}

/// Runs `f` with `stop` as this thread's poll: [`check`] inside `f` fails once `stop()` has
/// returned true. The previous poll (if any) is restored afterwards, even if `f` panics.
pub fn within<T>(stop: &dyn Fn() -> bool, f: impl FnOnce() -> T) -> T {
    // SAFETY: the reference is removed from the thread-local before `stop` goes out of scope
    // (the guard below restores the previous poll on return and on unwinding).
    let stop: &'static dyn Fn() -> bool = unsafe { std::mem::transmute::<&dyn Fn() -> bool, &'static dyn Fn() -> bool>(stop) };
    let previous = ACTIVE.with(|a| a.replace(Some(Poll { stop, last: Instant::now(), stopped: false })));
    struct Restore(Option<Option<Poll<'static>>>);
    impl Drop for Restore {
        fn drop(&mut self) {
            let previous = self.0.take().flatten();
            ACTIVE.with(|a| *a.borrow_mut() = previous);
        }
    }
    let _restore = Restore(Some(previous));
    f()
}

/// `Err(Error::Interrupted)` when this thread's poll (see [`within`]) asks to stop; polls at
/// most once every [`POLL_INTERVAL`]. Without a poll, always `Ok`.
pub fn check() -> Result<()> {
    let stopped = ACTIVE.with(|a| {
        let mut a = a.borrow_mut();
        let Some(p) = a.as_mut() else { return false };
        if !p.stopped && p.last.elapsed() >= POLL_INTERVAL {
            p.last = Instant::now();
            p.stopped = (p.stop)();
        }
        p.stopped
    });
    if stopped { Err(Error::Interrupted) } else { Ok(()) }
}

/// The stop flag that [`parallel`] shares with the threads doing its work.
pub struct Shared(AtomicBool);

impl Shared {
    /// Runs `f` (one item of parallel work, on any thread) with a poll that says stop once the
    /// caller of [`parallel`] has been asked to stop; an item not yet started then does not start.
    pub fn within<R>(&self, f: impl FnOnce() -> Result<R>) -> Result<R> {
        if self.0.load(Ordering::Relaxed) {
            return Err(Error::Interrupted);
        }
        within(&|| self.0.load(Ordering::Relaxed), f)
    }
}

/// Runs `work` (e.g. a rayon iterator whose items use [`Shared::within`]) on a helper thread
/// while this thread keeps polling every few milliseconds; `Err(Error::Interrupted)` when this
/// thread's poll said stop (the work then stops at its items' next [`check`]). Without a poll on
/// this thread, `work` simply runs here. A panic in `work` is resumed on this thread.
pub fn parallel<T: Send>(work: impl FnOnce(&Shared) -> T + Send) -> Result<T> {
    let shared = Shared(AtomicBool::new(false));
    if ACTIVE.with(|a| a.borrow().is_none()) {
        return Ok(work(&shared));
    }
    let out = std::thread::scope(|s| {
        let (done, finished) = std::sync::mpsc::channel();
        let shared = &shared;
        let handle = s.spawn(move || {
            let out = work(shared);
            let _ = done.send(()); // wakes the caller at once (a panic drops `done` instead)
            out
        });
        // wait for the work, polling every few milliseconds meanwhile
        while let Err(RecvTimeoutError::Timeout) = finished.recv_timeout(Duration::from_millis(5)) {
            if check().is_err() {
                shared.0.store(true, Ordering::Relaxed);
            }
        }
        handle.join().unwrap_or_else(|panic| std::panic::resume_unwind(panic))
    });
    if shared.0.load(Ordering::Relaxed) { Err(Error::Interrupted) } else { Ok(out) }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::cell::Cell;

    #[test]
    fn a_poll_stops_the_loop_and_is_rate_limited() {
        let calls = Cell::new(0);
        let stop = || {
            calls.set(calls.get() + 1);
            calls.get() >= 3
        };
        let t0 = Instant::now();
        let r = within(&stop, || loop {
            if let Err(e) = check() {
                break e;
            }
        });
        assert_eq!(r, Error::Interrupted);
        assert_eq!(calls.get(), 3, "polled until it said stop");
        assert!(t0.elapsed() >= 3 * POLL_INTERVAL, "at most one poll per interval");
        assert!(check().is_ok(), "no poll outside `within`");
    }

    #[test]
    fn polls_nest_and_are_restored() {
        let yes = || true;
        let no = || false;
        within(&no, || {
            within(&yes, || {
                std::thread::sleep(POLL_INTERVAL);
                assert!(check().is_err());
            });
            std::thread::sleep(POLL_INTERVAL);
            assert!(check().is_ok(), "the outer poll is back");
        });
    }

    #[test]
    fn parallel_work_stops_when_the_caller_is_asked_to() {
        let t0 = Instant::now();
        let stop = || t0.elapsed() > Duration::from_millis(100);
        let r = within(&stop, || {
            parallel(|s| {
                std::thread::scope(|sc| {
                    let item = || s.within(|| loop {
                        check()?;
                    });
                    let a = sc.spawn(item);
                    assert_eq!(item(), Err::<(), _>(Error::Interrupted));
                    assert_eq!(a.join().unwrap(), Err(Error::Interrupted));
                    assert_eq!(s.within(|| Ok(1)), Err(Error::Interrupted), "a later item does not start");
                })
            })
        });
        assert_eq!(r, Err(Error::Interrupted));
        assert!(t0.elapsed() < Duration::from_secs(2), "stopped in {:?}", t0.elapsed());
        assert_eq!(parallel(|_| 7), Ok(7), "without a poll the work runs to its end");
    }
}
