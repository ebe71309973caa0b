//! Work started beside the caller's on the rayon pool and joined when its
//! result is needed (a solver's symbolic factorisation while a method
//! computes its prior and light): a free worker runs it meanwhile, or the
//! caller runs it itself on joining when no worker took it.
//!
//! A thread spawned for it instead deadlocks once the caller is itself a
//! pool worker (a sweep's rows run in parallel): the caller blocks on the
//! thread while the thread's own rayon work waits for the busy pool.

use std::panic::{AssertUnwindSafe, catch_unwind};
use std::sync::{Condvar, Mutex};

/// Where a task stands.
enum State<F, T> {
    /// Not started: the closure, for whoever comes first.
    Waiting(F),
    Running,
    Done(std::thread::Result<T>),
    Taken,
}

/// A task [`scope`] started; [`Handle::join`] gives its result.
pub struct Handle<'s, F, T> {
    shared: &'s (Mutex<State<F, T>>, Condvar),
}

impl<F: FnOnce() -> T, T> Handle<'_, F, T> {
    /// The task's result (`Err` with the payload when it panicked), running
    /// it here when no worker has started it.
    pub fn join(self) -> std::thread::Result<T> {
        let (state, done) = self.shared;
        let mut guard = state.lock().unwrap_or_else(|e| e.into_inner());
        if let State::Waiting(_) = &*guard {
            let State::Waiting(f) = std::mem::replace(&mut *guard, State::Taken) else {
                unreachable!("checked above")
            };
            drop(guard);
            return catch_unwind(AssertUnwindSafe(f));
        }
        while let State::Running = &*guard {
            guard = done.wait(guard).unwrap_or_else(|e| e.into_inner());
        }
        match std::mem::replace(&mut *guard, State::Taken) {
            State::Done(result) => result,
            _ => unreachable!("a task is joined once"),
        }
    }
}

/// Runs `body` with a `spawn` that starts `task` on the rayon pool.
pub fn scope<'a, F, T, R>(task: F, body: impl FnOnce(Handle<'_, F, T>) -> R) -> R
where
    F: FnOnce() -> T + Send + 'a,
    T: Send + 'a,
{
    let shared = (Mutex::new(State::Waiting(task)), Condvar::new());
    rayon::in_place_scope(|s| {
        s.spawn(|_| {
            let (state, done) = &shared;
            let mut guard = state.lock().unwrap_or_else(|e| e.into_inner());
            let State::Waiting(f) = std::mem::replace(&mut *guard, State::Running) else {
                // The caller took it first.
                *guard = State::Taken;
                return;
            };
            drop(guard);
            let result = catch_unwind(AssertUnwindSafe(f));
            *state.lock().unwrap_or_else(|e| e.into_inner()) = State::Done(result);
            done.notify_all();
        });
        body(Handle { shared: &shared })
    })
}

#[cfg(test)]
mod tests {
    use super::scope;

    /// Rows on every worker of a pool, each with a task that needs the pool
    /// itself: they finish (a spawned thread joined here would hang).
    #[test]
    fn tasks_finish_when_every_worker_waits_for_one() {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(2)
            .build()
            .unwrap();
        let sums: Vec<u64> = pool.install(|| {
            use rayon::prelude::*;
            (0..8u64)
                .into_par_iter()
                .map(|row| {
                    let task = || (0..1000u64).into_par_iter().map(|v| v * row).sum::<u64>();
                    scope(task, |handle| handle.join().unwrap())
                })
                .collect()
        });
        assert_eq!(sums, (0..8).map(|row| 499_500 * row).collect::<Vec<_>>());
    }

    #[test]
    fn a_panicking_task_is_an_error_on_joining() {
        let joined = scope(|| -> u32 { panic!("task failed") }, |handle| handle.join());
        assert!(joined.is_err());
    }
}
