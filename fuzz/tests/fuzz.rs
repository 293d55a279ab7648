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
                replay_and_fuzz(stringify!($name), $iterations);
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
}
