//! Rows computed in parallel and recorded in plan order, each as soon as
//! every row before it is done: a sweep stopped half-way keeps the rows it
//! computed (they reach the result files one by one), and the files still do
//! not depend on the number of threads.

use rayon::prelude::*;
use std::collections::BTreeMap;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::mpsc::{Receiver, channel};

/// Runs `compute(i)` for every `i < n` on the current rayon pool and hands
/// each result to `record` in index order, on a thread of its own (not a
/// pool's: a one-thread pool computing cannot wait for it), as soon as those
/// before it are recorded. Once `record` fails nothing more is computed and
/// its error is returned.
pub fn compute_in_order<T: Send, E: Send>(
    n: usize,
    compute: impl Fn(usize) -> T + Sync,
    mut record: impl FnMut(T) -> Result<(), E> + Send,
) -> Result<(), E> {
    let failed = AtomicBool::new(false);
    std::thread::scope(|scope| {
        let (tx, rx) = channel();
        let (record, failed_flag) = (&mut record, &failed);
        let writer = scope.spawn(move || {
            let written = write_in_order(rx, record);
            if written.is_err() {
                failed_flag.store(true, Ordering::Relaxed);
            }
            written
        });
        (0..n).into_par_iter().for_each_with(tx, |tx, i| {
            if !failed.load(Ordering::Relaxed) {
                // The writer has stopped when this fails: nothing to do.
                let _ = tx.send((i, compute(i)));
            }
        });
        writer
            .join()
            .unwrap_or_else(|panic| std::panic::resume_unwind(panic))
    })
}

/// Records what `rx` brings in index order until every sender is gone.
fn write_in_order<T, E>(
    rx: Receiver<(usize, T)>,
    record: &mut impl FnMut(T) -> Result<(), E>,
) -> Result<(), E> {
    let mut pending = BTreeMap::new();
    let mut next = 0;
    for (i, item) in rx {
        pending.insert(i, item);
        while let Some(item) = pending.remove(&next) {
            record(item)?;
            next += 1;
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::sync::Mutex;
    use std::time::{Duration, Instant};

    #[test]
    fn the_first_row_is_recorded_before_the_last_is_computed() {
        // The last row waits (up to 20 s) for the first to be recorded:
        // recording only when every row is done would make it wait in vain.
        let recorded = Mutex::new(Vec::new());
        let first_seen = AtomicBool::new(false);
        let n = 6;
        compute_in_order(
            n,
            |i| {
                if i == n - 1 {
                    let start = Instant::now();
                    while !first_seen.load(Ordering::SeqCst)
                        && start.elapsed() < Duration::from_secs(20)
                    {
                        std::thread::sleep(Duration::from_millis(5));
                    }
                    assert!(
                        first_seen.load(Ordering::SeqCst),
                        "row 0 not recorded while the last row ran"
                    );
                }
                i * 10
            },
            |v| {
                first_seen.store(true, Ordering::SeqCst);
                recorded.lock().unwrap().push(v);
                Ok::<(), ()>(())
            },
        )
        .unwrap();
        assert_eq!(*recorded.lock().unwrap(), [0, 10, 20, 30, 40, 50]);
    }

    #[test]
    fn a_failed_record_stops_and_is_returned() {
        let mut seen = Vec::new();
        let r = compute_in_order(
            100,
            |i| i,
            |v| {
                seen.push(v);
                if v == 3 { Err("disk full") } else { Ok(()) }
            },
        );
        assert_eq!(r, Err("disk full"));
        assert_eq!(seen, [0, 1, 2, 3]);
    }
}
