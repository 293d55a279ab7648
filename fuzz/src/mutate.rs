//! A small deterministic mutation fuzzer: corpus replay, mutation (bit flips, byte
//! insert/delete/duplicate, dictionary tokens, interesting floats, splices between corpus
//! files), and a runner that turns a panic or a slow input into a [`Failure`] with the input
//! saved to a file.
//!
//! It has no coverage feedback (that is libFuzzer's job, `fuzz/libfuzzer/`): it exists so that
//! `cargo test` exercises every target with inputs near the corpus on every run, on the stable
//! toolchain, in a bounded and reproducible time.

use std::{
    hash::{Hash, Hasher},
    panic::{self, AssertUnwindSafe},
    path::{Path, PathBuf},
    time::{Duration, Instant},
};

use kerf_millplan::rng::SplitMix64;

use crate::Target;

/// The mutator's generator: kerf's SplitMix64 (`kerf_millplan::rng`), the same sequence for
/// the same seed everywhere.
#[derive(Debug, Clone)]
pub struct Rng(SplitMix64);

impl Rng {
    /// A generator starting from `seed`.
    pub fn new(seed: u64) -> Self {
        Self(SplitMix64::new(seed))
    }

    /// The next 64 random bits.
    pub fn next_u64(&mut self) -> u64 {
        self.0.next_u64()
    }

    /// A number in `0..n` (0 when `n` is 0).
    pub fn below(&mut self, n: usize) -> usize {
        if n == 0 {
            0
        } else {
            // The modulo bias is irrelevant here.
            (self.next_u64() % n as u64) as usize
        }
    }
}

/// Tokens of kerf's input formats that random bytes seldom spell: YAML and JSON syntax and
/// keys, float edge cases, escapes, STL and OBJ keywords.
pub const DICTIONARY: &[&[u8]] = &[
    b"points:",
    b"axes:",
    b"feedrate: ",
    b"sample_period: ",
    b"max_lead_angle: ",
    b"mesh: ",
    b"request_id: ",
    b"workpiece_pose: ",
    b"rto_indices: ",
    b"options:",
    b"gfd:",
    b"q4_steps: ",
    b"process:",
    b"limits:",
    b"initial:",
    b"segments: ",
    b"planner: ",
    b"teeth: ",
    b"\"points\": ",
    b"[",
    b"]",
    b"{",
    b"}",
    b", ",
    b": ",
    b"- ",
    b"? ",
    b"\n",
    b"\r\n",
    b"\t",
    b"  ",
    b"#",
    b"'",
    b"\"",
    b"\\",
    b"&a ",
    b"*a",
    b"!!str ",
    b"!!binary ",
    b"<<: ",
    b"---\n",
    b"...\n",
    b"|\n",
    b">-\n",
    b"1e308",
    b"-1e308",
    b"1e400",
    b"4.9e-324",
    b"nan",
    b".nan",
    b".inf",
    b"-.inf",
    b"NaN",
    b"Infinity",
    b"-0",
    b"0x1f",
    b"0o17",
    b"1_000",
    b"18446744073709551616",
    b"4294967296",
    b"-9223372036854775808",
    b"\\u00",
    b"\\ud83d",
    b"\\ude00",
    b"\\u0000",
    b"\xef\xbb\xbf",
    b"\xff\xfe",
    b"\xf0\x9f\x98\x80",
    b"solid ",
    b"facet normal 0 0 1\n",
    b"outer loop\n",
    b"vertex 0 0 0\n",
    b"endloop\n",
    b"endfacet\n",
    b"v 0 0 0\n",
    b"f 1 2 3\n",
    b"f -1 -2 -3\n",
    b"1//1",
    b"ddpg",
    b"naive",
    b"package://kerf/",
];

/// Float bit patterns written into binary inputs (CDR bodies, `arbitrary` bytes, binary STL).
const INTERESTING_F64: &[f64] = &[
    f64::NAN,
    f64::INFINITY,
    f64::NEG_INFINITY,
    f64::MAX,
    f64::MIN,
    f64::MIN_POSITIVE,
    5e-324,
    -0.0,
    1.0,
    1e308,
];

/// Lengths written into binary inputs (CDR sequence and string lengths, STL counts).
const INTERESTING_U32: &[u32] = &[0, 1, 2, 6, 7, 0x7f, 0x80, 0xffff, 0x7fff_ffff, 0xffff_ffff];

/// One mutation of `input`, with `others` (the corpus) for splices; at most `max_len` bytes.
pub fn mutate(input: &[u8], others: &[Vec<u8>], rng: &mut Rng, max_len: usize) -> Vec<u8> {
    let mut out = input.to_vec();
    let rounds = 1 + rng.below(4);
    for _ in 0..rounds {
        mutate_once(&mut out, others, rng);
    }
    out.truncate(max_len);
    out
}

fn mutate_once(out: &mut Vec<u8>, others: &[Vec<u8>], rng: &mut Rng) {
    let len = out.len();
    let at = rng.below(len + 1);
    match rng.below(12) {
        0 if len > 0 => {
            let i = rng.below(len);
            out[i] ^= 1 << rng.below(8);
        }
        1 if len > 0 => {
            let i = rng.below(len);
            out[i] = [0, 0xff, 0x7f, 0x80, b'0', b'9', b' ', b'\n'][rng.below(8)];
        }
        2 => out.insert(at, rng.next_u64() as u8),
        3 if len > 0 => {
            let start = at.min(len - 1);
            let n = 1 + rng.below((len - start).min(16));
            out.drain(start..start + n);
        }
        4 if len > 0 => {
            // Duplicate a range (nesting, repeated lines, more points).
            let start = rng.below(len);
            let n = 1 + rng.below((len - start).min(64));
            let copy = out[start..start + n].to_vec();
            let times = 1 + rng.below(8);
            for _ in 0..times {
                out.splice(at..at, copy.iter().copied());
            }
        }
        5 | 6 => {
            let token = DICTIONARY[rng.below(DICTIONARY.len())];
            out.splice(at..at, token.iter().copied());
        }
        7 if len > 0 => {
            // Overwrite with a token.
            let token = DICTIONARY[rng.below(DICTIONARY.len())];
            let start = rng.below(len);
            let end = (start + token.len()).min(len);
            out.splice(start..end, token.iter().copied());
        }
        8 if !others.is_empty() => {
            // Splice: a prefix of this input, a suffix of another corpus file.
            let other = &others[rng.below(others.len())];
            let from = rng.below(other.len() + 1);
            out.truncate(at);
            out.extend_from_slice(&other[from..]);
        }
        9 if len >= 8 => {
            let f = INTERESTING_F64[rng.below(INTERESTING_F64.len())];
            let bytes = if rng.below(2) == 0 {
                f.to_le_bytes()
            } else {
                f.to_be_bytes()
            };
            // Aligned as CDR aligns a float64, counted from the input's start or (for the
            // `cdr` target) from after its first, type-selecting byte.
            let start = rng.below(len - 7);
            let start = if rng.below(2) == 0 {
                start & !7
            } else {
                (start.saturating_sub(1) & !7) + 1
            }
            .min(len - 8);
            out[start..start + 8].copy_from_slice(&bytes);
        }
        10 if len >= 4 => {
            let v = INTERESTING_U32[rng.below(INTERESTING_U32.len())];
            let bytes = if rng.below(2) == 0 {
                v.to_le_bytes()
            } else {
                v.to_be_bytes()
            };
            let start = rng.below(len - 3);
            out[start..start + 4].copy_from_slice(&bytes);
        }
        11 if len > 0 => {
            // A digit changed: numbers stay numbers but move.
            if let Some(i) = (0..len)
                .map(|k| (at + k) % len)
                .find(|&i| out[i].is_ascii_digit())
            {
                out[i] = b'0' + rng.below(10) as u8;
            }
        }
        _ => out.insert(at, DICTIONARY[rng.below(DICTIONARY.len())][0]),
    }
}

/// A target that panicked, or took longer than the limit, on an input.
#[derive(Debug)]
pub struct Failure {
    /// The target's name.
    pub target: String,
    /// The panic message (or the time taken).
    pub message: String,
    /// The input.
    pub input: Vec<u8>,
    /// Where the input was written (`None` if writing failed).
    pub saved: Option<PathBuf>,
}

impl std::fmt::Display for Failure {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "fuzz target {}: {} ({} bytes of input, saved to {}; add it to fuzz/corpus/{}/ \
             once fixed)",
            self.target,
            self.message,
            self.input.len(),
            self.saved.as_deref().map_or_else(
                || "nowhere: writing failed".into(),
                |p| p.display().to_string()
            ),
            self.target
        )
    }
}

/// Longest a single input may take before it counts as a failure (a debug build on a busy
/// machine; kerf's inputs of a few KB parse in milliseconds).
pub const SLOW_INPUT: Duration = Duration::from_secs(10);

/// Runs `target` on `input`: a panic, or a run longer than [`SLOW_INPUT`], is a [`Failure`]
/// with the input written to a file under the system temp directory.
///
/// # Errors
/// The failure.
pub fn run_one(name: &str, target: Target, input: &[u8]) -> Result<(), Failure> {
    let start = Instant::now();
    let result = panic::catch_unwind(AssertUnwindSafe(|| target(input)));
    let elapsed = start.elapsed();
    let message = match result {
        Err(payload) => payload
            .downcast_ref::<String>()
            .cloned()
            .or_else(|| payload.downcast_ref::<&str>().map(|s| (*s).to_string()))
            .unwrap_or_else(|| "panic with a non-string payload".into()),
        Ok(()) if elapsed > SLOW_INPUT => {
            format!("took {elapsed:?}, over the limit of {SLOW_INPUT:?}")
        }
        Ok(()) => return Ok(()),
    };
    Err(Failure {
        target: name.to_string(),
        message: format!("panicked: {message}"),
        input: input.to_vec(),
        saved: save(name, input),
    })
}

/// Writes a failing input to `<temp>/kerf_fuzz/<target>-<hash>`.
fn save(name: &str, input: &[u8]) -> Option<PathBuf> {
    let mut h = std::collections::hash_map::DefaultHasher::new();
    input.hash(&mut h);
    let dir = std::env::temp_dir().join("kerf_fuzz");
    std::fs::create_dir_all(&dir).ok()?;
    let path = dir.join(format!("{name}-{:016x}", h.finish()));
    std::fs::write(&path, input).ok()?;
    Some(path)
}

/// The files of a corpus directory, sorted by name (an absent directory is an empty corpus).
///
/// # Errors
/// A directory or file that exists but cannot be read.
pub fn load_corpus(dir: &Path) -> std::io::Result<Vec<(String, Vec<u8>)>> {
    let entries = match std::fs::read_dir(dir) {
        Ok(e) => e,
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => return Ok(Vec::new()),
        Err(e) => return Err(e),
    };
    let mut files = Vec::new();
    for entry in entries {
        let entry = entry?;
        if entry.file_type()?.is_file() {
            let name = entry.file_name().to_string_lossy().into_owned();
            files.push((name, std::fs::read(entry.path())?));
        }
    }
    files.sort();
    Ok(files)
}

/// What a fuzz run did.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct Stats {
    /// Corpus files replayed.
    pub replayed: usize,
    /// Mutated inputs run.
    pub executions: u64,
}

/// When a [`fuzz`] run stops.
#[derive(Debug, Clone, Copy)]
pub enum Budget {
    /// After this many mutated inputs (deterministic).
    Iterations(u64),
    /// After this much time.
    Time(Duration),
}

/// Replays `corpus` through `target`, then runs mutated inputs (seeded by `seed`) until the
/// budget is spent. Inputs grow to at most twice the largest corpus file plus 1 KiB.
///
/// # Errors
/// The first [`Failure`].
pub fn fuzz(
    name: &str,
    target: Target,
    corpus: &[Vec<u8>],
    seed: u64,
    budget: Budget,
) -> Result<Stats, Failure> {
    let mut stats = Stats::default();
    for input in corpus {
        run_one(name, target, input)?;
        stats.replayed += 1;
    }
    let max_len = corpus.iter().map(Vec::len).max().unwrap_or(0) * 2 + 1024;
    let mut rng = Rng::new(seed);
    let start = Instant::now();
    loop {
        match budget {
            Budget::Iterations(n) if stats.executions >= n => break,
            Budget::Time(t) if start.elapsed() >= t => break,
            _ => {}
        }
        let base: &[u8] = if corpus.is_empty() {
            &[]
        } else {
            &corpus[rng.below(corpus.len())]
        };
        let input = mutate(base, corpus, &mut rng, max_len);
        run_one(name, target, &input)?;
        stats.executions += 1;
    }
    Ok(stats)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Panics on any input longer than 3 bytes that contains a `#`.
    fn fragile(data: &[u8]) {
        assert!(!(data.len() > 3 && data.contains(&b'#')), "fragile broke");
    }

    fn panics_on_x(data: &[u8]) {
        if data.first() == Some(&b'x') {
            panic!("deliberate panic on {} bytes", data.len());
        }
    }

    #[test]
    fn mutation_is_deterministic_and_bounded() {
        let corpus = vec![b"points: [[1, 2, 3]]".to_vec(), b"v 0 0 0\n".to_vec()];
        let run = |seed| {
            let mut rng = Rng::new(seed);
            (0..500)
                .map(|i| mutate(&corpus[i % 2], &corpus, &mut rng, 64))
                .collect::<Vec<_>>()
        };
        let a = run(7);
        assert_eq!(a, run(7));
        assert_ne!(a, run(8));
        assert!(a.iter().all(|m| m.len() <= 64));
        // Mutations change the input most of the time, and sometimes the length.
        assert!(
            a.iter()
                .filter(|m| **m != corpus[0] && **m != corpus[1])
                .count()
                > 400
        );
        assert!(a.iter().any(|m| m.len() > corpus[0].len()));
        assert!(a.iter().any(|m| m.is_empty() || m.len() < corpus[1].len()));
        // Empty inputs can be mutated too.
        let mut rng = Rng::new(1);
        assert!((0..50).any(|_| !mutate(&[], &[], &mut rng, 16).is_empty()));
    }

    #[test]
    fn a_panicking_corpus_file_is_reported_and_saved() {
        let corpus = vec![b"ok".to_vec(), b"x marks the spot".to_vec()];
        let err = fuzz(
            "panics_on_x",
            panics_on_x,
            &corpus,
            1,
            Budget::Iterations(0),
        )
        .unwrap_err();
        assert_eq!(err.target, "panics_on_x");
        assert!(
            err.message.contains("deliberate panic on 16 bytes"),
            "{err}"
        );
        assert_eq!(err.input, corpus[1]);
        let saved = err.saved.as_ref().expect("saved");
        assert_eq!(std::fs::read(saved).unwrap(), corpus[1]);
        let shown = err.to_string();
        assert!(shown.contains("panics_on_x") && shown.contains(&saved.display().to_string()));
        std::fs::remove_file(saved).ok();
    }

    #[test]
    fn mutation_finds_a_deliberate_bug_and_the_saved_input_reproduces_it() {
        let corpus = vec![b"abcd".to_vec(), b"a: 1".to_vec()];
        // The corpus itself is fine.
        fuzz("fragile", fragile, &corpus, 3, Budget::Iterations(0)).unwrap();
        let err = fuzz("fragile", fragile, &corpus, 3, Budget::Iterations(10_000)).unwrap_err();
        assert!(err.message.contains("fragile broke"), "{err}");
        let saved = err.saved.as_ref().expect("saved");
        let input = std::fs::read(saved).unwrap();
        assert!(run_one("fragile", fragile, &input).is_err());
        std::fs::remove_file(saved).ok();
    }

    #[test]
    fn a_clean_target_runs_the_whole_budget() {
        fn nothing(_: &[u8]) {}
        let stats = fuzz(
            "nothing",
            nothing,
            &[b"a".to_vec()],
            9,
            Budget::Iterations(123),
        )
        .unwrap();
        assert_eq!(
            stats,
            Stats {
                replayed: 1,
                executions: 123
            }
        );
    }
}
