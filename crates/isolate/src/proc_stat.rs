//! Memory of a process, from `/proc/<pid>/statm`.

/// Bytes of a page (`sysconf(_SC_PAGESIZE)`, 4096 where unknown).
fn page_bytes() -> u64 {
    // SAFETY: sysconf has no preconditions.
    let page = unsafe { libc::sysconf(libc::_SC_PAGESIZE) };
    u64::try_from(page).ok().filter(|p| *p > 0).unwrap_or(4096)
}

/// The `field`-th number of `/proc/<pid>/statm`, in bytes.
fn statm_bytes(pid: u32, field: usize) -> Option<u64> {
    let text = std::fs::read_to_string(format!("/proc/{pid}/statm")).ok()?;
    let pages: u64 = text.split_whitespace().nth(field)?.parse().ok()?;
    Some(pages.saturating_mul(page_bytes()))
}

/// Resident memory of process `pid` (bytes); `None` where it cannot be read (gone, not Linux).
///
/// # Performance
/// One read of a small procfs file (about 10 µs).
pub fn resident_bytes(pid: u32) -> Option<u64> {
    statm_bytes(pid, 1)
}

/// Virtual memory (address space) of process `pid` (bytes); `None` where it cannot be read.
pub fn virtual_bytes(pid: u32) -> Option<u64> {
    statm_bytes(pid, 0)
}

#[cfg(test)]
mod tests {
    #[test]
    fn own_memory_is_read() {
        let me = std::process::id();
        let rss = super::resident_bytes(me).unwrap();
        let vsz = super::virtual_bytes(me).unwrap();
        assert!(rss > 0 && rss <= vsz, "{rss} {vsz}");
        assert_eq!(super::resident_bytes(u32::MAX), None);
    }
}
