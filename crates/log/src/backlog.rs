//! The bytes of encoded messages waiting for the log's writer thread, bounded: a caller
//! with more waits until the thread has written enough of them.

use std::sync::{Condvar, Mutex, MutexGuard, PoisonError};

/// Bytes of encoded messages waiting for a writer thread, shared by the caller (who adds
/// them) and the thread (who takes them away as it writes them).
#[derive(Debug)]
pub(crate) struct Backlog {
    state: Mutex<State>,
    /// Signalled when bytes are taken away or the thread ends.
    drained: Condvar,
    /// The most bytes waiting at once, but for one message bigger than that alone.
    limit: usize,
}

#[derive(Debug, Default)]
struct State {
    bytes: usize,
    /// The thread ended: nobody will take bytes away any more.
    closed: bool,
}

impl Backlog {
    pub(crate) fn new(limit: usize) -> Backlog {
        Backlog {
            state: Mutex::default(),
            drained: Condvar::new(),
            limit,
        }
    }

    fn state(&self) -> MutexGuard<'_, State> {
        // A panic while the lock was held left only a count: it is still a count.
        self.state.lock().unwrap_or_else(PoisonError::into_inner)
    }

    /// Counts `n` more bytes as waiting, first waiting while they would take the backlog
    /// past its limit (a message bigger than the limit waits for an empty backlog) and the
    /// thread is still running.
    pub(crate) fn add(&self, n: usize) {
        let mut state = self.state();
        while !state.closed && state.bytes > 0 && state.bytes.saturating_add(n) > self.limit {
            state = self
                .drained
                .wait(state)
                .unwrap_or_else(PoisonError::into_inner);
        }
        state.bytes = state.bytes.saturating_add(n);
    }

    /// Counts `n` bytes as written.
    pub(crate) fn take(&self, n: usize) {
        if n == 0 {
            return;
        }
        let mut state = self.state();
        state.bytes = state.bytes.saturating_sub(n);
        self.drained.notify_all();
    }

    /// The thread ended (however it ended): a caller waiting for room waits no more.
    pub(crate) fn close(&self) {
        self.state().closed = true;
        self.drained.notify_all();
    }

    #[cfg(test)]
    fn bytes(&self) -> usize {
        self.state().bytes
    }
}

/// Closes a [`Backlog`] when dropped: held by the writer thread, so that it is closed
/// however the thread ends (its jobs done, an error, a panic).
pub(crate) struct CloseOnDrop<'a>(pub(crate) &'a Backlog);

impl Drop for CloseOnDrop<'_> {
    fn drop(&mut self) {
        self.0.close();
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::sync::Arc;
    use std::sync::atomic::{AtomicBool, Ordering};
    use std::time::Duration;

    /// Waits up to ten seconds for `done`, and says whether it came.
    fn comes(done: &AtomicBool) -> bool {
        for _ in 0..1000 {
            if done.load(Ordering::SeqCst) {
                return true;
            }
            std::thread::sleep(Duration::from_millis(10));
        }
        false
    }

    /// Runs `add(n)` on another thread, gives it `wait`, and returns whether it is done.
    fn adds_within(backlog: &Arc<Backlog>, n: usize, wait: Duration) -> Arc<AtomicBool> {
        let done = Arc::new(AtomicBool::new(false));
        let (b, d) = (Arc::clone(backlog), Arc::clone(&done));
        std::thread::spawn(move || {
            b.add(n);
            d.store(true, Ordering::SeqCst);
        });
        std::thread::sleep(wait);
        done
    }

    #[test]
    fn bytes_past_the_limit_wait_until_enough_are_taken() {
        let backlog = Arc::new(Backlog::new(100));
        backlog.add(60);
        backlog.add(40);
        let done = adds_within(&backlog, 10, Duration::from_millis(50));
        assert!(
            !done.load(Ordering::SeqCst),
            "110 bytes past a limit of 100"
        );
        backlog.take(5);
        std::thread::sleep(Duration::from_millis(50));
        assert!(!done.load(Ordering::SeqCst), "105 bytes still past it");
        backlog.take(5);
        assert!(comes(&done), "100 bytes fit");
        assert_eq!(backlog.bytes(), 100);
    }

    #[test]
    fn a_message_bigger_than_the_limit_waits_only_for_an_empty_backlog() {
        let backlog = Arc::new(Backlog::new(100));
        backlog.add(500);
        assert_eq!(backlog.bytes(), 500, "alone, it goes at once");
        let done = adds_within(&backlog, 1, Duration::from_millis(50));
        assert!(!done.load(Ordering::SeqCst));
        backlog.take(500);
        assert!(comes(&done));
    }

    #[test]
    fn a_caller_waiting_for_room_goes_on_when_the_thread_ends() {
        let backlog = Arc::new(Backlog::new(10));
        backlog.add(10);
        let done = adds_within(&backlog, 10, Duration::from_millis(50));
        assert!(!done.load(Ordering::SeqCst));
        drop(CloseOnDrop(&backlog));
        assert!(comes(&done), "never stuck behind a thread that is gone");
    }
}
