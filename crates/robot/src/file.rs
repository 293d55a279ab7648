//! [`read_regular`]: reading a file a request names (a mesh, a policy) without letting the
//! request hang or exhaust the node: regular files only, under a size cap checked before
//! reading.

use std::{io::Read, path::Path};

/// Reads the file at `path` if, after resolving symbolic links, it is a regular file of at
/// most `max_bytes` bytes.
///
/// A FIFO, a device, a socket or a directory is refused before it is opened (opening a FIFO
/// blocks until a writer appears; reading a device may never end), and so is a file over the
/// cap; a file that grows past the cap while it is read is refused too. Errors name the path
/// and the reason, never the file's contents.
///
/// # Arguments
/// * `path` — the file.
/// * `max_bytes` — the largest accepted size.
///
/// # Returns
/// The bytes, or the reason the file was not read.
///
/// # Performance
/// One `stat` and one read of at most `max_bytes + 1` bytes.
pub fn read_regular(path: &Path, max_bytes: u64) -> Result<Vec<u8>, String> {
    let shown = path.display();
    let meta = std::fs::metadata(path).map_err(|e| format!("cannot read {shown}: {e}"))?;
    if !meta.is_file() {
        let kind = if meta.is_dir() {
            "a directory"
        } else {
            "not a regular file (a FIFO, socket or device)"
        };
        return Err(format!("{shown} is {kind}; a regular file is required"));
    }
    if meta.len() > max_bytes {
        return Err(format!(
            "{shown} is {} bytes, over the limit of {max_bytes} bytes",
            meta.len()
        ));
    }
    let file = std::fs::File::open(path).map_err(|e| format!("cannot read {shown}: {e}"))?;
    let mut bytes = Vec::with_capacity(usize::try_from(meta.len()).unwrap_or(0));
    file.take(max_bytes.saturating_add(1))
        .read_to_end(&mut bytes)
        .map_err(|e| format!("cannot read {shown}: {e}"))?;
    if bytes.len() as u64 > max_bytes {
        return Err(format!(
            "{shown} grew past the limit of {max_bytes} bytes while it was read"
        ));
    }
    Ok(bytes)
}

#[cfg(test)]
mod tests {
    use super::read_regular;

    fn scratch(name: &str) -> std::path::PathBuf {
        let d = std::env::temp_dir().join(format!("kerf_file_{name}_{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&d);
        std::fs::create_dir_all(&d).unwrap();
        d
    }

    #[test]
    fn regular_files_under_the_cap_are_read_and_nothing_else() {
        let d = scratch("read");
        let f = d.join("a.txt");
        std::fs::write(&f, "secret contents").unwrap();
        assert_eq!(read_regular(&f, 100).unwrap(), b"secret contents");
        // Over the cap: refused before reading, the contents not quoted.
        let e = read_regular(&f, 5).unwrap_err();
        assert!(e.contains("15 bytes") && e.contains("limit of 5"), "{e}");
        assert!(!e.contains("secret"), "{e}");
        // A sparse 1 GB file is refused by its size alone.
        let big = d.join("big.bin");
        std::fs::File::create(&big)
            .unwrap()
            .set_len(1 << 30)
            .unwrap();
        assert!(read_regular(&big, 1 << 20)
            .unwrap_err()
            .contains("over the limit"));
        // A directory, a missing file.
        assert!(read_regular(&d, 100).unwrap_err().contains("a directory"));
        assert!(read_regular(&d.join("none"), 100)
            .unwrap_err()
            .contains("cannot read"));
        // A FIFO, directly and through a symbolic link: refused without blocking.
        let fifo = d.join("pipe.stl");
        let c = std::ffi::CString::new(fifo.to_str().unwrap()).unwrap();
        // SAFETY: mkfifo(3) on a NUL-terminated path we own.
        assert_eq!(unsafe { libc::mkfifo(c.as_ptr(), 0o600) }, 0);
        assert!(read_regular(&fifo, 100).unwrap_err().contains("FIFO"));
        let link = d.join("link.stl");
        std::os::unix::fs::symlink(&fifo, &link).unwrap();
        assert!(read_regular(&link, 100).unwrap_err().contains("FIFO"));
        let _ = std::fs::remove_dir_all(&d);
    }
}
