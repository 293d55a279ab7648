//! The file targets (issue 33, item 8): how a request's file reference (a mesh, a policy
//! file, a G-code `program_uri`) becomes a path the node may read (the shared reader
//! `kerf_robot::file::resolve_uri` and its three callers, then
//! `kerf_robot::roots::AllowedRoots::check`), and how it is read
//! (`kerf_robot::file::{check_regular_file, open_regular, CappedReader}`).
//!
//! `file_uri` resolves arbitrary references against a fixed tree of roots ([`Scratch`]);
//! `capped_reader` reads arbitrary streams through a [`CappedReader`] with a cap of at most
//! 4 KiB.

use std::{
    borrow::Cow,
    io::{BufRead, BufReader, Read},
    path::{Component, Path, PathBuf},
    sync::OnceLock,
};

use kerf_robot::{
    file::{check_regular_file, open_regular, CappedReader},
    roots::AllowedRoots,
};

// ---------------------------------------------------------------------------------------------
// The tree of roots
// ---------------------------------------------------------------------------------------------

/// The fixed tree the `file_uri` target resolves references against, built once per process
/// in `<temp>/kerf_fuzz_files_<pid>` ([`scratch`]; [`remove_scratch`] deletes it):
///
/// ```text
/// a/         a root: part.ngc (30 bytes), empty.ngc, big.ngc (5 000 bytes), sub/inner.ngc,
///            link-in -> part.ngc, link-out -> ../outside/secret.ngc,
///            link-dir-out -> ../outside, loop -> loop, dangling -> missing, sock (a socket)
/// b/         a root: part.ngc
/// bb/        not a root (its name extends b's): part.ngc
/// c-link     a root given through a link to a/
/// outside/   not a root: secret.ngc
/// ```
#[derive(Debug)]
pub struct Scratch {
    /// The tree's directory, canonical.
    pub dir: PathBuf,
    /// The allowed roots a node would build from `a`, `b` and `c-link`
    /// (`AllowedRoots::only`, which adds the shipped data).
    pub allowed: AllowedRoots,
    /// Where every accepted path must lie: the roots canonicalized here, and the shipped
    /// data's root.
    pub under: Vec<PathBuf>,
}

/// The directory of this process's tree.
fn scratch_dir() -> PathBuf {
    std::env::temp_dir().join(format!("kerf_fuzz_files_{}", std::process::id()))
}

/// Creates the files and links of the tree in `dir` ([`Scratch`]).
fn build_tree(dir: &Path) -> std::io::Result<()> {
    use std::os::unix::fs::symlink;
    let _ = std::fs::remove_dir_all(dir);
    for sub in ["a/sub", "b", "bb", "outside"] {
        std::fs::create_dir_all(dir.join(sub))?;
    }
    let part = b"G21 G90\nG1 X10 F600\nG1 Y10\nM2\n";
    std::fs::write(dir.join("a/part.ngc"), &part[..30])?;
    std::fs::write(dir.join("a/empty.ngc"), b"")?;
    std::fs::write(dir.join("a/big.ngc"), vec![b';'; 5_000])?;
    std::fs::write(dir.join("a/sub/inner.ngc"), b"G1 X1 F100\n")?;
    std::fs::write(dir.join("b/part.ngc"), b"G1 X2 F100\n")?;
    std::fs::write(dir.join("bb/part.ngc"), b"G1 X3 F100\n")?;
    std::fs::write(dir.join("outside/secret.ngc"), b"secret\n")?;
    symlink("part.ngc", dir.join("a/link-in"))?;
    symlink("../outside/secret.ngc", dir.join("a/link-out"))?;
    symlink("../outside", dir.join("a/link-dir-out"))?;
    symlink("loop", dir.join("a/loop"))?;
    symlink("missing", dir.join("a/dangling"))?;
    symlink("a", dir.join("c-link"))?;
    // A socket: a file that is neither regular nor a directory (the listener may go; the
    // file stays).
    drop(std::os::unix::net::UnixListener::bind(dir.join("a/sock")));
    Ok(())
}

/// Builds the tree and its roots, or `None` when the temp directory is not writable.
fn build_scratch() -> Option<Scratch> {
    let dir = scratch_dir();
    build_tree(&dir).ok()?;
    let dir = std::fs::canonicalize(dir).ok()?;
    let given: Vec<PathBuf> = ["a", "b", "c-link"].iter().map(|r| dir.join(r)).collect();
    let allowed = AllowedRoots::only(&given).ok()?;
    let mut under: Vec<PathBuf> = given
        .iter()
        .filter_map(|r| std::fs::canonicalize(r).ok())
        .collect();
    if let Some(data) = kerf_robot::data::root()
        .ok()
        .and_then(|r| std::fs::canonicalize(r.path).ok())
    {
        under.push(data);
    }
    Some(Scratch {
        dir,
        allowed,
        under,
    })
}

/// This process's tree, built on first use; `None` when it cannot be built (the target then
/// checks nothing, and `tests/fuzz.rs` fails).
pub fn scratch() -> Option<&'static Scratch> {
    static SCRATCH: OnceLock<Option<Scratch>> = OnceLock::new();
    SCRATCH.get_or_init(build_scratch).as_ref()
}

/// Deletes this process's tree (after the last `file_uri` input: later inputs only see its
/// files missing).
pub fn remove_scratch() {
    let _ = std::fs::remove_dir_all(scratch_dir());
}

// ---------------------------------------------------------------------------------------------
// file_uri
// ---------------------------------------------------------------------------------------------

/// What the control bytes 0x01–0x1f of a `file_uri` input stand for (0x01 + index); `{a}`,
/// `{b}`, `{bb}`, `{c}`, `{out}` and `{dir}` are the tree's absolute paths ([`Scratch`]).
const PIECES: [&str; 31] = [
    "{a}",
    "{b}",
    "{out}",
    "{c}",
    "{bb}",
    "{dir}",
    "../",
    "file://",
    "package://kerf/",
    "/part.ngc",
    "/link-out",
    "/link-dir-out/secret.ngc",
    "/loop",
    "/dangling",
    "/sock",
    "/sub/",
    "%2e%2e%2f",
    "%00",
    "/big.ngc",
    "/empty.ngc",
    "//",
    "./",
    "file://localhost",
    "/etc/passwd",
    "/dev/zero",
    "{long}",
    "/link-in",
    "%",
    "~/",
    " ",
    "/..",
];

/// The piece the control byte `b` (0x01–0x1f) stands for, with the tree's paths filled in.
fn piece(b: u8, s: &Scratch) -> Cow<'static, str> {
    let text = PIECES[usize::from(b - 1) % PIECES.len()];
    let path = |rel: &str| Cow::Owned(s.dir.join(rel).to_string_lossy().into_owned());
    match text {
        "{a}" => path("a"),
        "{b}" => path("b"),
        "{bb}" => path("bb"),
        "{c}" => path("c-link"),
        "{out}" => path("outside"),
        "{dir}" => Cow::Owned(s.dir.to_string_lossy().into_owned()),
        "{long}" => Cow::Owned(format!("{}/", "x".repeat(255))),
        other => Cow::Borrowed(other),
    }
}

/// The reference a `file_uri` input spells: its bytes, each control byte 0x01–0x1f replaced by
/// its [`PIECES`] piece, read as UTF-8 (lossily); NUL and every other byte stand for
/// themselves.
fn reference(data: &[u8], s: &Scratch) -> String {
    let mut out = Vec::with_capacity(data.len());
    for &b in data {
        if (1..0x20).contains(&b) {
            out.extend_from_slice(piece(b, s).as_bytes());
        } else {
            out.push(b);
        }
    }
    String::from_utf8_lossy(&out).into_owned()
}

/// The path the shared reader resolves the reference `r` to
/// (`kerf_robot::file::resolve_uri`), checked: it holds no NUL byte (`%00` included), a
/// `file://` URI gives an absolute path, a refusal's message holds no NUL byte either; and
/// the three callers, a mesh (`kerf_mjto::mesh::resolve`), a program file
/// (`kerf_gcodeplan::GcodeRequest::source`) and a policy file
/// (`kerf_millplan::policy::resolve_policy_file`), resolve it to the same path or all refuse
/// it.
fn resolution(r: &str) -> Option<PathBuf> {
    let shared = kerf_robot::file::resolve_uri(r);
    match &shared {
        Ok(p) => {
            assert!(
                !p.as_os_str().as_encoded_bytes().contains(&0),
                "{r:?} resolves to a path with a NUL byte"
            );
            assert!(
                !r.trim().starts_with("file://") || p.is_absolute(),
                "the file:// URI {r:?} resolves to the relative path {}",
                p.display()
            );
        }
        Err(e) => assert!(
            !e.to_string().contains('\0') && !e.uri_reason().contains('\0'),
            "the refusal of {r:?} writes a NUL byte"
        ),
    }
    let shared = shared.ok();
    let mesh = kerf_mjto::mesh::resolve(r).ok();
    let program = kerf_gcodeplan::GcodeRequest {
        program_file: Some(r.to_string()),
        ..Default::default()
    }
    .source();
    let program = match program {
        Ok(kerf_gcodeplan::ProgramSource::File(p)) => Some(p),
        _ => None,
    };
    let policy = kerf_millplan::policy::resolve_policy_file(r).ok();
    assert!(
        mesh == shared && program == shared && policy == shared,
        "{r:?} resolves differently: shared {shared:?}, mesh {mesh:?}, program {program:?}, \
         policy {policy:?}"
    );
    shared
}

/// A `package://kerf/` reference resolves below the data root, with no `..` and no root
/// component after it: it cannot name a file outside the data root before links are resolved.
fn check_package_uri(r: &str) {
    let r = r.trim();
    if !r.starts_with("package://") {
        return;
    }
    let (Ok(p), Ok(root)) = (
        kerf_robot::data::resolve_package_uri(r),
        kerf_robot::data::root(),
    ) else {
        return;
    };
    let rest = p.strip_prefix(&root.path).ok();
    assert!(
        rest.is_some_and(|rest| rest
            .components()
            .all(|c| matches!(c, Component::Normal(_) | Component::CurDir))),
        "{r:?} resolves to {}, not inside the data root {}",
        p.display(),
        root.path.display()
    );
}

/// A path the allowed roots accept lies under one of them: the path they return is absolute,
/// canonical (resolving it again changes nothing) and below a root of [`Scratch::under`]. An
/// accepted file of the tree is then read as a node reads it ([`read_accepted`]). Without
/// roots every path is accepted unchanged.
fn check_resolved(s: &Scratch, p: &Path, cap: u64) {
    assert!(
        AllowedRoots::any().check(p).ok().as_deref() == Some(p),
        "AllowedRoots::any() changed or refused {}",
        p.display()
    );
    let Ok(c) = s.allowed.check(p) else { return };
    assert!(
        c.is_absolute() && s.under.iter().any(|root| c.starts_with(root)),
        "{} is accepted as {}, outside every allowed root",
        p.display(),
        c.display()
    );
    assert!(
        std::fs::canonicalize(&c).ok().as_deref() == Some(c.as_path()),
        "{} is accepted as {}, which is not canonical",
        p.display(),
        c.display()
    );
    if c.starts_with(&s.dir) {
        read_accepted(&c, cap);
    }
}

/// An accepted file of the tree, read with the cap `cap`: `check_regular_file` and
/// `open_regular` agree; what they accept is a regular file of at most `cap` bytes, and it
/// reads whole, exactly its contents.
fn read_accepted(c: &Path, cap: u64) {
    let size = check_regular_file(c, cap);
    let opened = open_regular(c, cap);
    assert!(
        size.is_ok() == opened.is_ok(),
        "check_regular_file and open_regular disagree on {}",
        c.display()
    );
    let (Ok(size), Ok(mut reader)) = (size, opened) else {
        return;
    };
    let meta = std::fs::metadata(c);
    assert!(
        size <= cap && meta.is_ok_and(|m| m.is_file()),
        "{} accepted: {size} bytes under the cap {cap}, or not a regular file",
        c.display()
    );
    let mut bytes = Vec::new();
    let read = reader.read_to_end(&mut bytes);
    assert!(
        read.is_ok() && Some(bytes) == std::fs::read(c).ok(),
        "{} accepted but not read whole: {read:?}",
        c.display()
    );
}

/// A file reference from the bytes ([`reference`]: control bytes stand for the tree's roots,
/// `../`, `file://`, `package://kerf/`, links, percent escapes, a 256-byte component, …),
/// resolved as the nodes resolve meshes, program files and policy files ([`resolution`]),
/// then checked against the tree's allowed roots ([`Scratch`]) as a node checks it, and
/// also the reference taken as a plain path: never a panic; an accepted path lies under a
/// root after canonicalisation ([`check_resolved`]); a `package://kerf/` path stays in the
/// data root ([`check_package_uri`]); an accepted file of the tree reads whole under a cap of
/// 0, 16, 29, 30, 31 or 4096 bytes (picked by the input's length; `a/part.ngc` has 30).
pub fn file_uri(data: &[u8]) {
    let Some(s) = scratch() else { return };
    let r = reference(data, s);
    let cap = [0, 16, 29, 30, 31, 4096][data.len() % 6];
    check_package_uri(&r);
    if let Some(p) = resolution(&r) {
        check_resolved(s, &p, cap);
    }
    check_resolved(s, Path::new(&r), cap);
}

// ---------------------------------------------------------------------------------------------
// capped_reader
// ---------------------------------------------------------------------------------------------

/// A stream of `left` bytes (`None`: endless) cycling through `data` (empty `data`: an empty
/// stream), handing out at most the next of `chunks` bytes (at least 1) per read.
struct Source<'a> {
    /// The bytes cycled through.
    data: &'a [u8],
    /// Bytes still to hand out (`None`: endless).
    left: Option<usize>,
    /// Bytes handed out so far.
    pos: usize,
    /// The most bytes each read hands out, in turn.
    chunks: &'a [u8],
    /// The next entry of `chunks`.
    next_chunk: usize,
}

impl Source<'_> {
    /// Byte `i` of the stream.
    fn at(data: &[u8], i: usize) -> u8 {
        data[i % data.len()]
    }

    /// The stream's length (`None`: endless).
    fn len(data: &[u8], left: Option<usize>) -> Option<usize> {
        if data.is_empty() {
            Some(0)
        } else {
            left
        }
    }
}

impl Read for Source<'_> {
    /// The next chunk of the stream (at most `buf.len()` bytes; 0 at its end).
    fn read(&mut self, buf: &mut [u8]) -> std::io::Result<usize> {
        let left = Self::len(self.data, self.left).unwrap_or(usize::MAX);
        let chunk = self
            .chunks
            .get(self.next_chunk % self.chunks.len().max(1))
            .map_or(usize::MAX, |&c| usize::from(c).max(1));
        self.next_chunk += 1;
        let n = chunk.min(buf.len()).min(left);
        for b in &mut buf[..n] {
            *b = Self::at(self.data, self.pos);
            self.pos += 1;
        }
        if let Some(l) = &mut self.left {
            *l -= n;
        }
        Ok(n)
    }
}

/// How a stream ended so far.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum End {
    /// Still open.
    Open,
    /// It said end of stream.
    Eof,
    /// It failed (the cap error).
    Failed,
}

/// One step of reading: what it delivered and how the stream ended.
struct Step {
    /// The bytes delivered.
    bytes: Vec<u8>,
    /// How the stream ended.
    end: End,
    /// The error, when it failed.
    error: Option<std::io::Error>,
}

impl Step {
    /// A step from a `read`-like result: `bytes` delivered, end of stream when `eof`.
    fn of(bytes: Vec<u8>, result: std::io::Result<bool>) -> Step {
        match result {
            Ok(eof) => Step {
                bytes,
                end: if eof { End::Eof } else { End::Open },
                error: None,
            },
            Err(e) => Step {
                bytes,
                end: End::Failed,
                error: Some(e),
            },
        }
    }
}

/// `read` into a buffer of `len` bytes (0 included: it says nothing).
fn read_step(r: &mut impl Read, len: usize) -> Step {
    let mut buf = vec![0; len];
    match r.read(&mut buf) {
        Ok(n) => {
            buf.truncate(n);
            Step::of(buf, Ok(n == 0 && len > 0))
        }
        Err(e) => Step::of(Vec::new(), Err(e)),
    }
}

/// `read_to_end`: the bytes it appended (also on an error), end of stream on success.
fn read_to_end_step(r: &mut impl Read) -> Step {
    let mut buf = Vec::new();
    let result = r.read_to_end(&mut buf).map(|_| true);
    Step::of(buf, result)
}

/// `fill_buf`, then `consume` of at most `amount` of what it showed.
fn fill_step(r: &mut impl BufRead, amount: usize) -> Step {
    match r.fill_buf() {
        Ok(shown) => {
            let n = amount.min(shown.len());
            let bytes = shown[..n].to_vec();
            let eof = shown.is_empty();
            r.consume(n);
            Step::of(bytes, Ok(eof))
        }
        Err(e) => Step::of(Vec::new(), Err(e)),
    }
}

/// `read_until` a newline: the bytes it appended (also on an error), end of stream when it
/// read none.
fn read_until_step(r: &mut impl BufRead) -> Step {
    let mut buf = Vec::new();
    let result = r.read_until(b'\n', &mut buf);
    let eof = buf.is_empty();
    Step::of(buf, result.map(|_| eof))
}

/// The step an op byte asks of a buffered reader: `read` of up to 63 bytes, `fill_buf` +
/// `consume`, `read_until`, or `read_to_end`.
fn buf_step(r: &mut impl BufRead, op: u8) -> Step {
    let arg = usize::from(op >> 2);
    match op % 4 {
        0 => read_step(r, arg),
        1 => fill_step(r, arg + 1),
        2 => read_until_step(r),
        _ => read_to_end_step(r),
    }
}

/// The step an op byte asks of an unbuffered reader: `read` of 1 to 64 bytes, or
/// `read_to_end`.
fn plain_step(r: &mut impl Read, op: u8) -> Step {
    match op % 4 {
        3 => read_to_end_step(r),
        _ => read_step(r, usize::from(op >> 2) + 1),
    }
}

/// What a capped stream has delivered, against what it must.
struct Check<'a> {
    /// The source's data (the stream cycles through it).
    data: &'a [u8],
    /// The stream's length (`None`: endless).
    len: Option<usize>,
    /// The reader's cap.
    cap: usize,
    /// Bytes delivered so far.
    got: usize,
    /// How the stream ended so far.
    end: End,
}

impl Check<'_> {
    /// One step's result (before the stream failed): the bytes continue the stream, the
    /// total stays within the cap, the stream ends only when it is whole, and fails only when
    /// it is longer than the cap, with an error naming the cap.
    fn step(&mut self, step: Step) {
        for (k, &b) in step.bytes.iter().enumerate() {
            assert!(
                b == Source::at(self.data, self.got + k),
                "byte {} of the capped stream is not the source's",
                self.got + k
            );
        }
        self.got += step.bytes.len();
        self.end = step.end;
        assert!(
            self.got <= self.cap,
            "{} bytes through a reader capped at {}",
            self.got,
            self.cap
        );
        match step.end {
            End::Open => {}
            End::Eof => assert!(
                self.len == Some(self.got),
                "the capped stream ended after {} of {:?} bytes (cap {})",
                self.got,
                self.len,
                self.cap
            ),
            End::Failed => {
                let message = step.error.map(|e| e.to_string()).unwrap_or_default();
                assert!(
                    self.len.is_none_or(|l| l > self.cap)
                        && message.contains(&format!("limit of {} bytes", self.cap)),
                    "the capped stream of {:?} bytes (cap {}) failed: {message}",
                    self.len,
                    self.cap
                );
            }
        }
    }

    /// A step after the stream failed: whatever it still delivers, the total stays within
    /// the cap.
    fn after_failure(&mut self, step: Step) {
        self.got += step.bytes.len();
        assert!(
            self.got <= self.cap,
            "{} bytes through a reader capped at {} (read on after its error)",
            self.got,
            self.cap
        );
    }
}

/// Runs `ops` (then `read_to_end` if the stream is still open), then two more ops after a
/// failure, checking every step ([`Check`]).
fn drive<R>(r: &mut R, ops: &[u8], check: &mut Check, step: fn(&mut R, u8) -> Step) {
    for &op in ops.iter().chain([&3u8]) {
        if check.end != End::Open {
            break;
        }
        check.step(step(r, op));
    }
    if check.end == End::Failed {
        for &op in ops.iter().chain([&3u8]).take(2) {
            check.after_failure(step(r, op));
        }
    }
}

/// `CappedReader` over a stream from the bytes: `[cap lo, cap hi, stack, length, n, ops × n
/// (n < 16), chunks × 4, data …]`. The cap is at most 4 096 bytes; the stack (byte mod 3)
/// is `CappedReader<Source>` (`read` only), `CappedReader<BufReader<Source>>` (as
/// `open_regular` builds it) or `BufReader<CappedReader<Source>>`, the buffer capacity from
/// its bits 2–4; the stream (length byte mod 4) is `data` once, the data cycled to exactly
/// the cap, to the cap + 1, or endlessly. Never a panic; never more than the cap delivered
/// (even when reading on after the error); the bytes delivered are the stream's; it ends
/// only when whole, and fails, naming the cap, exactly when it is longer than the cap.
pub fn capped_reader(data: &[u8]) {
    let byte = |i: usize| data.get(i).copied().unwrap_or(0);
    let cap = usize::from(u16::from_le_bytes([byte(0), byte(1)])) % 4097;
    let n_ops = usize::from(byte(4) % 16);
    let ops = data.get(5..(5 + n_ops).min(data.len())).unwrap_or_default();
    let chunks = data
        .get(5 + n_ops..(9 + n_ops).min(data.len()))
        .unwrap_or_default();
    let body = data.get(9 + n_ops..).unwrap_or_default();
    let left = match byte(3) % 4 {
        0 => Some(body.len()),
        1 => Some(cap),
        2 => Some(cap + 1),
        _ => None,
    };
    let source = Source {
        data: body,
        left,
        pos: 0,
        chunks,
        next_chunk: 0,
    };
    let mut check = Check {
        data: body,
        len: Source::len(body, left),
        cap,
        got: 0,
        end: End::Open,
    };
    let capacity = [1, 2, 3, 7, 8, 64, 512, 8192][usize::from(byte(2) >> 2) % 8];
    let cap64 = cap as u64;
    match byte(2) % 3 {
        0 => drive(
            &mut CappedReader::new(source, cap64, "fuzz"),
            ops,
            &mut check,
            plain_step,
        ),
        1 => drive(
            &mut CappedReader::new(BufReader::with_capacity(capacity, source), cap64, "fuzz"),
            ops,
            &mut check,
            buf_step,
        ),
        _ => drive(
            &mut BufReader::with_capacity(capacity, CappedReader::new(source, cap64, "fuzz")),
            ops,
            &mut check,
            buf_step,
        ),
    }
}
