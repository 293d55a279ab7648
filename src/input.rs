//! One capped reader for every file or stdin a `kerf` command reads (issue 33, item 7).
//!
//! A command names its input as an [`InputFile`] argument (so that the bounds test finds every
//! input in clap's model) and reads it with [`read_text`] or [`read_bytes`], or streams it with
//! [`open`]; a file a library opens by itself is checked first with [`check_file`]. The rules:
//!
//! * `-` is standard input; `/dev/stdin`, a shell pipe, a FIFO or a character device are
//!   streams: they are opened without blocking (a FIFO with no writer gives no data at once
//!   instead of hanging the command) and read up to the cap; the read fails, naming the
//!   argument, the file and the cap, as soon as one byte more arrives, and reads nothing after
//!   it (`/dev/zero` ends in milliseconds).
//! * A regular file over the cap is refused by its size before it is opened.
//! * A directory is refused before it is opened.
//!
//! The caps are stated per kind of input ([`REQUEST_CAP`] and the others below).

use std::{
    fmt,
    fs::{File, OpenOptions},
    io::Read,
    os::unix::fs::{FileTypeExt, OpenOptionsExt},
    path::{Path, PathBuf},
};

/// Cap of a request file or document (`kerf plan cut|mill --request`, `kerf demo --request`):
/// the nodes' `MAX_TEXT_REQUEST_BYTES` (4 MiB), so that a request the nodes refuse is refused
/// offline too.
pub(crate) const REQUEST_CAP: u64 = kerf_ros::planner::MAX_TEXT_REQUEST_BYTES as u64;

/// Cap of a message document of `kerf pub` (16 MiB): four times the 4 MiB that DDS delivers
/// promptly, since YAML text is about three times a message's CDR size.
pub(crate) const MESSAGE_CAP: u64 = 16 << 20;

/// Cap of a milling cell file (1 MiB; the shipped one is 10 kB).
pub(crate) const CELL_CAP: u64 = 1 << 20;

/// Cap of a robot description, URDF or limits YAML (4 MiB; the shipped ones are under 10 kB).
pub(crate) const ROBOT_CAP: u64 = 4 << 20;

/// Cap of an indicator cache (64 MiB; the shipped one is 1 MB).
pub(crate) const CACHE_CAP: u64 = 64 << 20;

/// Cap of a ROS parameter file of `kerf launch --ros-args --params-file` (1 MiB; the shipped
/// ones are under 2 kB).
pub(crate) const PARAMS_CAP: u64 = 1 << 20;

/// Cap of a training history, CSV or JSON (16 MiB: about 10⁵ episodes).
pub(crate) const HISTORY_CAP: u64 = 16 << 20;

/// A file argument a command reads: a path, or `-` for standard input where the command
/// accepts it. Its own type lets the bounds test find every input in clap's model.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct InputFile(PathBuf);

impl InputFile {
    /// The path as given.
    pub fn path(&self) -> &Path {
        &self.0
    }

    /// Whether it names standard input (`-`).
    pub fn is_stdin(&self) -> bool {
        self.0.as_os_str() == "-"
    }
}

impl From<std::ffi::OsString> for InputFile {
    fn from(s: std::ffi::OsString) -> Self {
        Self(PathBuf::from(s))
    }
}

impl fmt::Display for InputFile {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        if self.is_stdin() {
            f.write_str("- (standard input)")
        } else {
            write!(f, "{}", self.0.display())
        }
    }
}

/// Bytes with a binary prefix: `4194304 bytes (4 MiB)`.
fn show_cap(cap: u64) -> String {
    if cap >= 1 << 20 && cap.is_multiple_of(1 << 20) {
        format!("{cap} bytes ({} MiB)", cap >> 20)
    } else {
        format!("{cap} bytes")
    }
}

/// A stream that fails once more than `cap` bytes have come through it, without reading
/// further: the reader of every input of `kerf` ([`open`]).
pub(crate) struct Capped {
    inner: Box<dyn Read>,
    label: String,
    cap: u64,
    read: u64,
}

impl Read for Capped {
    fn read(&mut self, buf: &mut [u8]) -> std::io::Result<usize> {
        if self.read > self.cap {
            return Err(self.over());
        }
        // At most one byte past the cap is ever requested.
        let room = usize::try_from(self.cap + 1 - self.read).unwrap_or(usize::MAX);
        let take = buf.len().min(room);
        let n = self.inner.read(&mut buf[..take])?;
        self.read += n as u64;
        if self.read > self.cap {
            return Err(self.over());
        }
        Ok(n)
    }
}

impl Capped {
    fn over(&self) -> std::io::Error {
        std::io::Error::other(format!(
            "{} is over the limit of {}; nothing more was read",
            self.label,
            show_cap(self.cap)
        ))
    }
}

/// `--arg FILE` as errors name it.
fn label(arg: &str, file: &InputFile) -> String {
    format!("{arg} {file}")
}

/// Opens `file` (argument `arg`) as a stream of at most `cap` bytes: standard input for `-`;
/// a regular file under the cap; a FIFO, pipe or character device opened without blocking.
/// A G-code program, which is streamed, is read this way.
///
/// # Arguments
/// * `arg` — the argument's name in messages (`--request`, `FILE`).
/// * `file` — the input.
/// * `cap` — the largest number of bytes accepted.
///
/// # Returns
/// A reader whose `read` fails (naming the argument, the file and the cap) once more than
/// `cap` bytes came.
///
/// # Errors
/// A message naming the argument and the file: a directory, a regular file over the cap, a
/// file that cannot be opened.
///
/// # Performance
/// One `stat` and one `open`; nothing is read.
pub(crate) fn open(arg: &str, file: &InputFile, cap: u64) -> Result<Capped, String> {
    let label = label(arg, file);
    let inner: Box<dyn Read> = if file.is_stdin() {
        Box::new(std::io::stdin())
    } else {
        Box::new(open_path(&label, file.path(), cap)?)
    };
    Ok(Capped {
        inner,
        label,
        cap,
        read: 0,
    })
}

/// Opens a path that is no `-`: see [`open`].
fn open_path(label: &str, path: &Path, cap: u64) -> Result<File, String> {
    let meta = std::fs::metadata(path).map_err(|e| format!("{label}: cannot read: {e}"))?;
    let kind = meta.file_type();
    if kind.is_dir() {
        return Err(format!("{label} is a directory; a file is required"));
    }
    if kind.is_file() && meta.len() > cap {
        return Err(format!(
            "{label} is {} bytes, over the limit of {}",
            meta.len(),
            show_cap(cap)
        ));
    }
    let mut options = OpenOptions::new();
    options.read(true);
    if !kind.is_file() {
        // A FIFO without a writer would block `open` until one appears.
        options.custom_flags(libc::O_NONBLOCK);
    }
    let f = options
        .open(path)
        .map_err(|e| format!("{label}: cannot open: {e}"))?;
    if !kind.is_file() {
        blocking(&f).map_err(|e| format!("{label}: cannot read: {e}"))?;
    }
    Ok(f)
}

/// Clears `O_NONBLOCK` once a stream is open: a reader then waits for data that a writer
/// sends, and a FIFO without any writer reads as empty at once.
fn blocking(f: &File) -> std::io::Result<()> {
    use std::os::fd::AsRawFd;
    let fd = f.as_raw_fd();
    // SAFETY: fcntl(2) F_GETFL/F_SETFL on a descriptor this function borrows open; it
    // changes only the descriptor's status flags.
    unsafe {
        let flags = libc::fcntl(fd, libc::F_GETFL);
        if flags < 0 || libc::fcntl(fd, libc::F_SETFL, flags & !libc::O_NONBLOCK) < 0 {
            return Err(std::io::Error::last_os_error());
        }
    }
    Ok(())
}

/// Reads all of `file` (argument `arg`), at most `cap` bytes ([`open`]).
///
/// # Errors
/// As [`open`], and a read error or the cap passed, naming the argument and the file; an
/// empty FIFO or pipe is reported as such (it had no writer).
///
/// # Performance
/// Reads at most `cap + 1` bytes.
pub(crate) fn read_bytes(arg: &str, file: &InputFile, cap: u64) -> Result<Vec<u8>, String> {
    let mut reader = open(arg, file, cap)?;
    let mut bytes = Vec::new();
    reader.read_to_end(&mut bytes).map_err(|e| {
        if e.kind() == std::io::ErrorKind::Other {
            e.to_string()
        } else {
            format!("{}: cannot read: {e}", reader.label)
        }
    })?;
    if bytes.is_empty() && !file.is_stdin() && is_stream(file.path()) {
        return Err(format!(
            "{}: no data (a FIFO or pipe with no writer); start the writer first or pipe into -",
            reader.label
        ));
    }
    Ok(bytes)
}

/// Whether `path` is a FIFO or pipe.
fn is_stream(path: &Path) -> bool {
    std::fs::metadata(path).is_ok_and(|m| m.file_type().is_fifo())
}

/// Reads `file` as UTF-8 text ([`read_bytes`]).
///
/// # Errors
/// As [`read_bytes`], and text that is not UTF-8 (with the byte offset).
pub(crate) fn read_text(arg: &str, file: &InputFile, cap: u64) -> Result<String, String> {
    let bytes = read_bytes(arg, file, cap)?;
    String::from_utf8(bytes).map_err(|e| {
        format!(
            "{}: not UTF-8 text (invalid byte at offset {})",
            label(arg, file),
            e.utf8_error().valid_up_to()
        )
    })
}

/// Checks a file that a library opens by itself (a policy, a robot description): a regular
/// file of at most `cap` bytes, so that the library neither blocks on a FIFO nor reads a
/// device or an oversized file.
///
/// # Errors
/// A message naming the argument and the file: standard input, a directory, a FIFO, socket or
/// device, a file over the cap, a missing file.
pub(crate) fn check_file(arg: &str, file: &InputFile, cap: u64) -> Result<(), String> {
    let label = label(arg, file);
    if file.is_stdin() {
        return Err(format!(
            "{arg}: standard input (-) is not accepted here; name a file"
        ));
    }
    let meta = std::fs::metadata(file.path()).map_err(|e| format!("{label}: cannot read: {e}"))?;
    if meta.is_dir() {
        return Err(format!(
            "{label} is a directory; a regular file is required"
        ));
    }
    if !meta.is_file() {
        return Err(format!(
            "{label} is not a regular file (a FIFO, pipe, socket or device); a regular file is \
             required"
        ));
    }
    if meta.len() > cap {
        return Err(format!(
            "{label} is {} bytes, over the limit of {}",
            meta.len(),
            show_cap(cap)
        ));
    }
    Ok(())
}

/// Checks the `start` of a request file planned offline (`kerf plan cut`, `kerf plan mill`):
/// the start is resolved and the plan framed with an approach and a retract by the planner
/// nodes, against the robot's joint state and the cell (issue 27); offline there is neither,
/// so a request asking for one is refused instead of planned without it.
///
/// # Errors
/// A message naming `flag` for `start: current` or a list of positions.
pub fn check_offline_start(flag: &str, start: &kerf_approach::StartSpec) -> Result<(), String> {
    use kerf_approach::StartSpec;
    match start {
        StartSpec::Default | StartSpec::None => Ok(()),
        StartSpec::Current | StartSpec::Given(_) => Err(format!(
            "{flag}: start {:?} needs a planner node (kerf plans the approach and retract \
             against the robot's joint state and the cell there); `kerf plan` plans the process \
             alone: leave start out or set it to none",
            start.to_fields().0
        )),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn scratch(name: &str) -> PathBuf {
        let d = std::env::temp_dir().join(format!("kerf_input_{name}_{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&d);
        std::fs::create_dir_all(&d).unwrap();
        d
    }

    fn input(p: &Path) -> InputFile {
        InputFile(p.to_path_buf())
    }

    #[test]
    fn files_streams_and_devices_are_read_within_the_cap() {
        let d = scratch("read");
        let f = d.join("a.yaml");
        std::fs::write(&f, "a: 1\n").unwrap();
        assert_eq!(read_text("--request", &input(&f), 100).unwrap(), "a: 1\n");
        let e = read_text("--request", &input(&f), 3).unwrap_err();
        assert!(
            e.contains("--request") && e.contains("over the limit of 3 bytes"),
            "{e}"
        );
        let e = read_text("--request", &input(&d), 100).unwrap_err();
        assert!(e.contains("is a directory"), "{e}");
        // /dev/zero: the cap, then nothing more.
        let start = std::time::Instant::now();
        let e = read_text("--cell", &input(Path::new("/dev/zero")), 1 << 20).unwrap_err();
        assert!(
            e.contains("--cell /dev/zero is over the limit of 1048576 bytes (1 MiB)"),
            "{e}"
        );
        assert!(start.elapsed().as_secs() < 5);
        // A FIFO with no writer: no data at once, no hang.
        let fifo = d.join("pipe");
        let c = std::ffi::CString::new(fifo.to_str().unwrap()).unwrap();
        // SAFETY: mkfifo(3) on a NUL-terminated path we own.
        assert_eq!(unsafe { libc::mkfifo(c.as_ptr(), 0o600) }, 0);
        let e = read_text("--request", &input(&fifo), 100).unwrap_err();
        assert!(e.contains("no data"), "{e}");
        let e = check_file("--ddpg-policy", &input(&fifo), 100).unwrap_err();
        assert!(e.contains("not a regular file"), "{e}");
        // A FIFO with a writer is read.
        let writer = {
            let fifo = fifo.clone();
            std::thread::spawn(move || std::fs::write(fifo, "b: 2\n").unwrap())
        };
        // The writer's open() waits for this reader; give it time to count as a writer.
        std::thread::sleep(std::time::Duration::from_millis(200));
        assert_eq!(
            read_text("--request", &input(&fifo), 100).unwrap(),
            "b: 2\n"
        );
        writer.join().unwrap();
        let bad = d.join("bad");
        std::fs::write(&bad, [b'a', 0xff]).unwrap();
        assert!(read_text("--x", &input(&bad), 100)
            .unwrap_err()
            .contains("offset 1"));
        let _ = std::fs::remove_dir_all(&d);
    }
}
