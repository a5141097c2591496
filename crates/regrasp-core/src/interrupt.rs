//! Interruption of long computations (Ctrl-C): a caller runs a computation [`within`] a poll
//! (a callback answering "stop now?"), and every long loop of the core — the T-RRT* search, the
//! quasi-static time stepping, the path checks — calls [`check`], which returns
//! [`Error::Interrupted`] once the poll has said so.
//!
//! The poll is scoped to the calling thread (a thread-local set for the duration of
//! [`within`]), so no signature carries it and a computation without one never stops early.
//! Calls are rate limited: the poll runs at most once every [`POLL_INTERVAL`], so a loop may
//! call [`check`] as often as it likes. Parallel batches (rayon) check between their chunks on
//! the calling thread; worker threads see no poll.

use crate::error::{Error, Result};
use std::cell::RefCell;
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
}
