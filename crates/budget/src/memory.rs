//! The memory side of a [`crate::Budget`]: a plan's memory limit, checked by estimates before a
//! stage allocates and by accounting while it runs (issue 33, item 3).
//!
//! The limit is cooperative like the deadline: a planner states what a stage will hold
//! ([`crate::Budget::check_memory`], [`crate::Budget::account`]) before allocating it, and a
//! request whose data would not fit is answered with [`crate::Interrupt::OverMemory`] naming
//! what grew. The planner-node harness also runs every plan in a worker process whose resident
//! memory it bounds (`kerf_budget::isolate`), so a stage that forgets to check cannot take the
//! node down either.

use std::sync::{
    atomic::{AtomicU64, Ordering},
    Arc,
};

use crate::Interrupt;

/// Default memory budget of one plan (bytes): 1 GiB, the `plan_memory` parameter's default.
pub const DEFAULT_PLAN_MEMORY: u64 = 1 << 30;

/// Smallest memory budget a node or command accepts (bytes): 16 MiB.
pub const MIN_PLAN_MEMORY: u64 = 16 << 20;

/// Largest memory budget a node or command accepts (bytes): 1 TiB.
pub const MAX_PLAN_MEMORY: u64 = 1 << 40;

/// Bytes of `count` values of `T`, saturating (an estimate never wraps around).
///
/// # Arguments
/// * `count` — how many values.
///
/// # Returns
/// `count × size_of::<T>()`, or `u64::MAX` when that overflows.
pub fn bytes_of<T>(count: u64) -> u64 {
    count.saturating_mul(std::mem::size_of::<T>() as u64)
}

/// Bytes as a short text for messages: `"1.50 GiB"`, `"12.0 MiB"`, `"512 B"`.
pub fn format_bytes(bytes: u64) -> String {
    const KIB: f64 = 1024.0;
    let b = bytes as f64;
    if b >= KIB * KIB * KIB {
        format!("{:.2} GiB", b / (KIB * KIB * KIB))
    } else if b >= KIB * KIB {
        format!("{:.1} MiB", b / (KIB * KIB))
    } else if b >= KIB {
        format!("{:.1} KiB", b / KIB)
    } else {
        format!("{bytes} B")
    }
}

/// Reads a memory budget given in bytes (a node parameter or a command-line value).
///
/// # Errors
/// A message (without the parameter's name) for a value outside
/// [[`MIN_PLAN_MEMORY`], [`MAX_PLAN_MEMORY`]]; nothing is clamped.
pub fn memory_from_bytes(bytes: i64) -> Result<u64, String> {
    match u64::try_from(bytes) {
        Ok(b) if (MIN_PLAN_MEMORY..=MAX_PLAN_MEMORY).contains(&b) => Ok(b),
        _ => Err(format!(
            "{bytes} bytes must be in [{MIN_PLAN_MEMORY}, {MAX_PLAN_MEMORY}] ({} to {})",
            format_bytes(MIN_PLAN_MEMORY),
            format_bytes(MAX_PLAN_MEMORY)
        )),
    }
}

/// A memory limit and the bytes accounted against it so far; clones share the account.
#[derive(Debug, Clone, Default)]
pub(crate) struct MemoryAccount {
    limit: Option<u64>,
    used: Arc<AtomicU64>,
}

impl MemoryAccount {
    /// An empty account under `limit` (none: unlimited).
    pub(crate) fn new(limit: Option<u64>) -> Self {
        Self {
            limit,
            used: Arc::new(AtomicU64::new(0)),
        }
    }

    pub(crate) fn limit(&self) -> Option<u64> {
        self.limit
    }

    pub(crate) fn used(&self) -> u64 {
        self.used.load(Ordering::Relaxed)
    }

    /// Whether `bytes` more, on top of what is accounted, stay within the limit.
    pub(crate) fn check(&self, bytes: u64, what: &str) -> Result<(), Interrupt> {
        let Some(limit) = self.limit else {
            return Ok(());
        };
        let used = self.used();
        let needed = used.saturating_add(bytes);
        if needed > limit {
            return Err(Interrupt::OverMemory {
                limit,
                needed,
                what: what.to_string(),
            });
        }
        Ok(())
    }

    /// Adds `bytes` to the account if they fit.
    pub(crate) fn account(&self, bytes: u64, what: &str) -> Result<(), Interrupt> {
        let Some(limit) = self.limit else {
            self.used
                .fetch_add(bytes.min(u64::MAX - self.used()), Ordering::Relaxed);
            return Ok(());
        };
        let mut current = self.used();
        loop {
            let needed = current.saturating_add(bytes);
            if needed > limit {
                return Err(Interrupt::OverMemory {
                    limit,
                    needed,
                    what: what.to_string(),
                });
            }
            match self.used.compare_exchange_weak(
                current,
                needed,
                Ordering::Relaxed,
                Ordering::Relaxed,
            ) {
                Ok(_) => return Ok(()),
                Err(now) => current = now,
            }
        }
    }

    /// Gives `bytes` back (saturating at zero).
    pub(crate) fn release(&self, bytes: u64) {
        let mut current = self.used();
        loop {
            let next = current.saturating_sub(bytes);
            match self.used.compare_exchange_weak(
                current,
                next,
                Ordering::Relaxed,
                Ordering::Relaxed,
            ) {
                Ok(_) => return,
                Err(now) => current = now,
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn accounting_refuses_past_the_limit_and_names_what_grew() {
        let a = MemoryAccount::new(Some(1000));
        assert!(a.account(600, "samples").is_ok());
        assert!(a.check(400, "more").is_ok());
        let e = a.account(401, "helix turns").unwrap_err();
        match &e {
            Interrupt::OverMemory {
                limit,
                needed,
                what,
            } => {
                assert_eq!(
                    (*limit, *needed, what.as_str()),
                    (1000, 1001, "helix turns")
                );
            }
            other => panic!("{other:?}"),
        }
        assert!(e.to_string().contains("helix turns"), "{e}");
        assert_eq!(a.used(), 600, "a refused amount is not accounted");
        a.release(700);
        assert_eq!(a.used(), 0);
        assert!(a.check(u64::MAX, "anything").is_err());
        assert!(MemoryAccount::new(None).check(u64::MAX, "x").is_ok());
    }

    #[test]
    fn bytes_saturate_and_budgets_are_range_checked() {
        assert_eq!(bytes_of::<f64>(3), 24);
        assert_eq!(bytes_of::<[f64; 4]>(u64::MAX), u64::MAX);
        assert_eq!(format_bytes(1 << 30), "1.00 GiB");
        assert_eq!(format_bytes(512), "512 B");
        assert_eq!(memory_from_bytes(1 << 30), Ok(1 << 30));
        for bad in [-1, 0, 1 << 20, i64::MAX] {
            assert!(
                memory_from_bytes(bad).unwrap_err().contains("must be in"),
                "{bad}"
            );
        }
    }
}
