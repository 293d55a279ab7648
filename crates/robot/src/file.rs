//! [`read_regular`] and [`open_regular`]: reading a file a request names (a mesh, a policy, a
//! G-code program) without letting the request hang or exhaust the node: regular files only,
//! under a size cap checked before reading and enforced while reading ([`CappedReader`]).
//! The file a request names is found by [`resolve_uri`] (a path, `file://` or
//! `package://kerf/`).

mod uri;

pub use uri::resolve_uri;

use std::{
    fs::File,
    io::{BufRead, BufReader, Read},
    path::Path,
};

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

/// A stream of the regular file at `path` (links resolved), of at most `max_bytes` bytes: for
/// a file read as it is parsed (a G-code program), which [`read_regular`] would hold whole.
///
/// The path is checked with `stat` before it is opened: a FIFO, a device, a socket or a
/// directory is refused without opening it, and so is a file over the cap. It is then opened
/// with `O_NONBLOCK` (a FIFO swapped in after the `stat` cannot block the open), checked again
/// on the open descriptor (`fstat`: still a regular file under the cap), and `O_NONBLOCK` is
/// cleared. Reading past `max_bytes` (a file that grows) fails with an error naming the cap
/// ([`CappedReader`]): the stream never ends early in silence.
///
/// # Arguments
/// * `path` — the file.
/// * `max_bytes` — the largest accepted size.
///
/// # Returns
/// A buffered reader of the file, or the reason it was not opened (naming the path and the
/// cap, never the file's contents).
///
/// # Performance
/// Two `stat`s, one `open`, two `fcntl`; the reading is buffered (64 KiB).
pub fn open_regular(path: &Path, max_bytes: u64) -> Result<CappedReader<BufReader<File>>, String> {
    use std::os::unix::fs::OpenOptionsExt;
    let shown = path.display();
    let meta = std::fs::metadata(path).map_err(|e| format!("cannot read {shown}: {e}"))?;
    check_regular(path, &meta, max_bytes)?;
    let file = std::fs::OpenOptions::new()
        .read(true)
        .custom_flags(libc::O_NONBLOCK)
        .open(path)
        .map_err(|e| format!("cannot read {shown}: {e}"))?;
    let meta = file
        .metadata()
        .map_err(|e| format!("cannot read {shown}: {e}"))?;
    check_regular(path, &meta, max_bytes)?;
    clear_nonblocking(&file).map_err(|e| format!("cannot read {shown}: {e}"))?;
    Ok(CappedReader::new(
        BufReader::with_capacity(64 * 1024, file),
        max_bytes,
        shown.to_string(),
    ))
}

/// Checks, without opening it, that `path` (links resolved) is a regular file of at most
/// `max_bytes` bytes: what a node checks before it queues a request naming a file, which
/// [`open_regular`] or [`read_regular`] checks again when it is read.
///
/// # Returns
/// The file's size in bytes, or the reason it would not be read (naming the path).
pub fn check_regular_file(path: &Path, max_bytes: u64) -> Result<u64, String> {
    let meta =
        std::fs::metadata(path).map_err(|e| format!("cannot read {}: {e}", path.display()))?;
    check_regular(path, &meta, max_bytes)?;
    Ok(meta.len())
}

/// Refuses what is not a regular file of at most `max_bytes` bytes.
fn check_regular(path: &Path, meta: &std::fs::Metadata, max_bytes: u64) -> Result<(), String> {
    let shown = path.display();
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
    Ok(())
}

/// Clears `O_NONBLOCK` on an open file (a regular file ignores it, but its reader should not
/// see `EAGAIN` from a file system that honours it).
fn clear_nonblocking(file: &File) -> std::io::Result<()> {
    use std::os::fd::AsRawFd;
    let fd = file.as_raw_fd();
    // SAFETY: fcntl(2) F_GETFL/F_SETFL on a descriptor `file` owns and keeps open.
    let flags = unsafe { libc::fcntl(fd, libc::F_GETFL) };
    if flags < 0 {
        return Err(std::io::Error::last_os_error());
    }
    // SAFETY: as above; only the O_NONBLOCK bit changes.
    if unsafe { libc::fcntl(fd, libc::F_SETFL, flags & !libc::O_NONBLOCK) } < 0 {
        return Err(std::io::Error::last_os_error());
    }
    Ok(())
}

/// A reader that fails once more than its cap has been read, instead of ending early or going
/// on: a stream read as it is parsed (a file that grows, standard input) stays bounded, and a
/// program is never planned cut short.
#[derive(Debug)]
pub struct CappedReader<R> {
    inner: R,
    remaining: u64,
    max_bytes: u64,
    name: String,
    /// The cap was passed: every later read fails too (found by fuzzing: a caller reading on
    /// after the error got the stream's later bytes).
    over: bool,
}

impl<R> CappedReader<R> {
    /// Reads at most `max_bytes` bytes of `inner`, which `name` names in the error.
    pub fn new(inner: R, max_bytes: u64, name: impl Into<String>) -> Self {
        Self {
            inner,
            remaining: max_bytes,
            max_bytes,
            name: name.into(),
            over: false,
        }
    }

    /// The error once the cap is passed.
    fn over(&self) -> std::io::Error {
        std::io::Error::other(format!(
            "{} is longer than the limit of {} bytes",
            self.name, self.max_bytes
        ))
    }
}

impl<R: Read> Read for CappedReader<R> {
    fn read(&mut self, buf: &mut [u8]) -> std::io::Result<usize> {
        if self.over {
            return Err(self.over());
        }
        if buf.is_empty() {
            return Ok(0);
        }
        // One byte past the cap is asked for, to tell "ends at the cap" from "goes on".
        let allowed = usize::try_from(self.remaining.saturating_add(1))
            .unwrap_or(usize::MAX)
            .min(buf.len());
        let n = self.inner.read(&mut buf[..allowed])?;
        if n as u64 > self.remaining {
            self.over = true;
            return Err(self.over());
        }
        self.remaining -= n as u64;
        Ok(n)
    }
}

impl<R: BufRead> BufRead for CappedReader<R> {
    fn fill_buf(&mut self) -> std::io::Result<&[u8]> {
        if self.over {
            return Err(self.over());
        }
        if self.remaining == 0 {
            let over = self.over();
            return if self.inner.fill_buf()?.is_empty() {
                Ok(&[])
            } else {
                self.over = true;
                Err(over)
            };
        }
        let remaining = usize::try_from(self.remaining).unwrap_or(usize::MAX);
        let buf = self.inner.fill_buf()?;
        let n = remaining.min(buf.len());
        Ok(&buf[..n])
    }

    fn consume(&mut self, amt: usize) {
        let amt = usize::try_from(self.remaining)
            .unwrap_or(usize::MAX)
            .min(amt);
        self.remaining -= amt as u64;
        self.inner.consume(amt);
    }
}

#[cfg(test)]
mod tests {
    use super::{check_regular_file, open_regular, read_regular, CappedReader};
    use std::io::{BufRead, Read};

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

    #[test]
    fn open_regular_streams_regular_files_and_refuses_the_rest_without_blocking() {
        let d = scratch("open");
        let f = d.join("part.ngc");
        std::fs::write(&f, "G1 X1\nG1 Y1\n").unwrap();
        let mut text = String::new();
        open_regular(&f, 100)
            .unwrap()
            .read_to_string(&mut text)
            .unwrap();
        assert_eq!(text, "G1 X1\nG1 Y1\n");
        let lines: Vec<String> = open_regular(&f, 12)
            .unwrap()
            .lines()
            .map(|l| l.unwrap())
            .collect();
        assert_eq!(
            lines,
            ["G1 X1", "G1 Y1"],
            "a file of exactly the cap is read whole"
        );
        let e = open_regular(&f, 11).unwrap_err();
        assert!(e.contains("12 bytes") && e.contains("limit of 11"), "{e}");
        assert!(open_regular(&d, 100).unwrap_err().contains("a directory"));
        assert_eq!(check_regular_file(&f, 12), Ok(12));
        assert!(check_regular_file(&d, 100)
            .unwrap_err()
            .contains("a directory"));
        assert!(open_regular(std::path::Path::new("/dev/zero"), 100)
            .unwrap_err()
            .contains("not a regular file"));
        assert!(open_regular(&d.join("none"), 100)
            .unwrap_err()
            .contains("cannot read"));
        let fifo = d.join("pipe.ngc");
        let c = std::ffi::CString::new(fifo.to_str().unwrap()).unwrap();
        // SAFETY: mkfifo(3) on a NUL-terminated path we own.
        assert_eq!(unsafe { libc::mkfifo(c.as_ptr(), 0o600) }, 0);
        let started = std::time::Instant::now();
        assert!(open_regular(&fifo, 100).unwrap_err().contains("FIFO"));
        let link = d.join("link.ngc");
        std::os::unix::fs::symlink(&fifo, &link).unwrap();
        assert!(open_regular(&link, 100).unwrap_err().contains("FIFO"));
        assert!(
            started.elapsed() < std::time::Duration::from_secs(15),
            "hang guard"
        );
        let _ = std::fs::remove_dir_all(&d);
    }

    #[test]
    fn a_capped_reader_fails_past_its_cap_instead_of_ending() {
        let mut exact = CappedReader::new(&b"abcd"[..], 4, "input");
        let mut out = Vec::new();
        exact.read_to_end(&mut out).unwrap();
        assert_eq!(out, b"abcd");
        let mut long = CappedReader::new(&b"abcde"[..], 4, "standard input");
        let e = long.read_to_end(&mut Vec::new()).unwrap_err();
        assert!(
            e.to_string()
                .contains("standard input is longer than the limit of 4 bytes"),
            "{e}"
        );
        // Through BufRead, as the G-code reader reads.
        let mut lines = CappedReader::new(&b"G1 X1\nG1 X2\n"[..], 8, "program").lines();
        assert_eq!(lines.next().unwrap().unwrap(), "G1 X1");
        assert!(lines
            .next()
            .unwrap()
            .unwrap_err()
            .to_string()
            .contains("limit of 8 bytes"));
        // An endless source stops at the cap.
        let mut zero = CappedReader::new(std::io::repeat(0), 1 << 20, "/dev/zero");
        assert!(zero.read_to_end(&mut Vec::new()).is_err());
    }

    /// Found by fuzzing: once past the cap, every later read fails, whatever the stream
    /// still holds ("abcdefg" read 2 bytes at a time with a cap of 3 gave "ab", an error,
    /// then "g" and an end).
    #[test]
    fn a_capped_reader_stays_failed_past_its_cap() {
        let mut r = CappedReader::new(&b"abcdefg"[..], 3, "input");
        let mut two = [0u8; 2];
        assert_eq!(r.read(&mut two).unwrap(), 2);
        for _ in 0..4 {
            assert!(r.read(&mut two).is_err());
            assert!(r.fill_buf().is_err());
        }
    }
}
