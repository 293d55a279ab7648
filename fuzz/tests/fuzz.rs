//! Every fuzz target replays its committed corpus (`fuzz/corpus/<target>/`), then runs a short
//! deterministic mutation fuzz (fixed seed, fixed number of inputs). A failure names the target
//! and the file the input was written to.
//!
//! `KERF_FUZZ_SCALE` multiplies the number of inputs (e.g. 10 for a longer run); `KERF_FUZZ_SEED`
//! changes the seed. For runs of minutes, `kerf-fuzz run` or libFuzzer (BENCHMARKS.md).

#![allow(clippy::unwrap_used, clippy::expect_used)]

use kerf_fuzz::{
    corpus_dir,
    mutate::{self, Budget},
    target, TARGETS,
};

fn env_u64(name: &str, default: u64) -> u64 {
    std::env::var(name)
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(default)
}

/// Replays the corpus of `name`, then fuzzes it with `iterations` mutated inputs.
fn replay_and_fuzz(name: &str, iterations: u64) {
    let t = target(name).expect("a target of TARGETS");
    let corpus: Vec<Vec<u8>> = mutate::load_corpus(&corpus_dir().join(name))
        .expect("readable corpus")
        .into_iter()
        .map(|(_, data)| data)
        .collect();
    assert!(!corpus.is_empty(), "fuzz/corpus/{name}/ has no seed files");
    // The seed differs per target but not per run.
    let seed = env_u64("KERF_FUZZ_SEED", 0)
        ^ name.bytes().fold(0xcbf2_9ce4_8422_2325u64, |h, b| {
            (h ^ u64::from(b)).wrapping_mul(0x100_0000_01b3)
        });
    let n = iterations * env_u64("KERF_FUZZ_SCALE", 1);
    let start = std::time::Instant::now();
    match mutate::fuzz(name, t, &corpus, seed, Budget::Iterations(n)) {
        Ok(stats) => {
            assert_eq!(stats.replayed, corpus.len());
            assert_eq!(stats.executions, n);
            println!(
                "{name}: {} corpus files, {} mutated inputs in {:.2?}",
                stats.replayed,
                stats.executions,
                start.elapsed()
            );
        }
        Err(failure) => panic!("{failure}"),
    }
}

/// One test per target (libtest runs them in parallel), with its number of mutated inputs:
/// at most about two seconds each in a debug build on one core (mill_msg's validation builds
/// the path's spline: 3 ms an input; a mesh input takes microseconds).
macro_rules! fuzz_tests {
    ($($name:ident: $iterations:expr),* $(,)?) => {
        $(
            #[test]
            fn $name() {
                before(stringify!($name));
                replay_and_fuzz(stringify!($name), $iterations);
                after(stringify!($name));
            }
        )*

        /// Every target of `TARGETS` has a test here.
        #[test]
        fn every_target_is_fuzzed() {
            let tested = [$(stringify!($name)),*];
            for (name, _) in TARGETS {
                assert!(tested.contains(name), "no fuzz test for target {name}");
            }
            assert_eq!(tested.len(), TARGETS.len());
        }
    };
}

fuzz_tests! {
    cut_text: 10000,
    cut_lines: 30000,
    cut_yaml: 10000,
    cut_json: 10000,
    mill_text: 5000,
    mill_yaml: 8000,
    mill_json: 20000,
    document: 20000,
    mesh_stl: 50000,
    mesh_obj: 50000,
    cut_msg: 50000,
    mill_msg: 700,
    trajectory_msg: 50000,
    cdr: 3000,
    gcode_program: 20000,
    gcode_text: 300,
    cut_numbers: 4000,
    mill_numbers: 1000,
    gcode_msg: 4000,
    file_uri: 5000,
    capped_reader: 10000,
}

/// What a target needs before its test: `file_uri`'s tree of roots must build (else the
/// target would check nothing), and accept a file in a root but not a link out of it.
fn before(name: &str) {
    if name == "file_uri" {
        let s = kerf_fuzz::files::scratch().expect("the file_uri tree under the temp directory");
        assert!(s.allowed.check(&s.dir.join("a/part.ngc")).is_ok());
        assert!(s.allowed.check(&s.dir.join("a/link-out")).is_err());
    }
}

/// What a target leaves behind, removed after its test: `file_uri`'s tree of roots.
fn after(name: &str) {
    if name == "file_uri" {
        kerf_fuzz::files::remove_scratch();
    }
}

/// Every named seed of the numbers targets is in the corpus and still gives the message its
/// name says (a change of `kerf_fuzz::gen` that moves them is caught here; `kerf-fuzz seeds`
/// writes them again).
#[test]
fn named_seeds_give_their_messages() {
    for (target, file, gives) in kerf_fuzz::numbers::SEEDS {
        let path = corpus_dir().join(target).join(file);
        let data = std::fs::read(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
        assert!(
            gives(&data),
            "{} no longer gives its message",
            path.display()
        );
    }
}
