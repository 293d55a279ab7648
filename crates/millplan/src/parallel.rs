//! An ordered parallel map on scoped threads, for work items that are pure functions of
//! their index (so the result does not depend on the thread count or the scheduling).

use std::sync::atomic::{AtomicUsize, Ordering};

/// `f(0)`, …, `f(n − 1)` on up to `threads` threads (the calling thread included), results in
/// index order. Items are handed out in increasing order from a shared counter. A helper
/// thread the OS refuses to start is not an error: the others do its work. A panic in `f`
/// is passed on to the caller.
///
/// # Arguments
/// * `n` — the number of items; `threads` — at most this many threads (0 is taken as 1);
/// * `name` — the helper threads' name prefix (`name-1`, `name-2`, …);
/// * `f` — the work of one item.
pub(crate) fn map_ordered<T: Send>(
    n: usize,
    threads: usize,
    name: &str,
    f: impl Fn(usize) -> T + Sync,
) -> Vec<T> {
    let workers = threads.clamp(1, n.max(1));
    if workers == 1 {
        return (0..n).map(f).collect();
    }
    let next = AtomicUsize::new(0);
    let work = || {
        let mut done = Vec::new();
        loop {
            let k = next.fetch_add(1, Ordering::Relaxed);
            if k >= n {
                break done;
            }
            done.push((k, f(k)));
        }
    };
    let mut all: Vec<(usize, T)> = std::thread::scope(|scope| {
        let helpers: Vec<_> = (1..workers)
            .filter_map(|w| {
                std::thread::Builder::new()
                    .name(format!("{name}-{w}"))
                    .spawn_scoped(scope, work)
                    .ok()
            })
            .collect();
        let mut all = work();
        for h in helpers {
            match h.join() {
                Ok(done) => all.extend(done),
                Err(panic) => std::panic::resume_unwind(panic),
            }
        }
        all
    });
    all.sort_by_key(|(k, _)| *k);
    all.into_iter().map(|(_, v)| v).collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn results_are_in_index_order_on_any_number_of_threads() {
        for threads in [0, 1, 2, 5] {
            let out = map_ordered(20, threads, "test", |k| k * k);
            assert_eq!(out, (0..20).map(|k| k * k).collect::<Vec<_>>(), "{threads}");
        }
        assert!(map_ordered(0, 3, "test", |k| k).is_empty());
    }
}
