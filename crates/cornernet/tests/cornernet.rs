//! The DRLS crate's fast tests: a small swarm, a tiny network.
#![allow(clippy::unwrap_used, clippy::expect_used)]

use std::path::PathBuf;

use kerf_cornernet::file::{sidecar_path, FORMAT};
use kerf_cornernet::train::train;
use kerf_cornernet::{
    Architecture, CornerNetError, Dataset, Distribution, DrlsNet, Model, Sidecar, Source,
    TrainSettings,
};
use kerf_toolpath::vec3::{distance_to_segment, scale};
use kerf_toolpath::NurbsSettings;

/// A swarm small enough for the dev profile.
fn small_swarm() -> NurbsSettings {
    NurbsSettings {
        particles: 8,
        iterations: 10,
        ..NurbsSettings::default()
    }
}

fn tmp(name: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join(name)
}

/// A tiny trained model on 40 corners (34 training, 6 held out).
fn tiny_model() -> (Dataset, Model) {
    let swarm = small_swarm();
    let data = Dataset::generate(Distribution::default(), &swarm, 11, 40, 2).unwrap();
    let (tr, ho) = data.split(0.15);
    let settings = TrainSettings {
        epochs: 30,
        batch: 8,
        ..TrainSettings::default()
    };
    let arch = Architecture::fdls(8, 4);
    let (net, normalization, report) = train(arch, tr, ho, &settings).unwrap();
    let sidecar = Sidecar {
        format: FORMAT.to_string(),
        architecture: arch,
        normalization,
        distribution: data.distribution,
        swarm,
        dataset_seed: data.seed,
        dataset_size: data.samples.len(),
        train: settings,
        report,
    };
    (data, Model { net, sidecar })
}

#[test]
fn dataset_is_deterministic_for_a_seed_and_any_thread_count() {
    let swarm = small_swarm();
    let d = Distribution::default();
    let a = Dataset::generate(d, &swarm, 5, 9, 1).unwrap();
    let b = Dataset::generate(d, &swarm, 5, 9, 2).unwrap();
    let c = Dataset::generate(d, &swarm, 6, 9, 2).unwrap();
    assert_eq!(a, b);
    assert_ne!(a.samples, c.samples);
    for s in &a.samples {
        let deg = s.turn.to_degrees();
        assert!((5.0..=175.0).contains(&deg), "{deg}");
        assert!((2.0..=500.0).contains(&s.ratio), "{}", s.ratio);
        assert!(s.curvature.is_finite() && s.curvature > 0.0);
    }
}

#[test]
fn dataset_and_model_round_trip() {
    let (data, model) = tiny_model();
    let p = tmp("round_trip_dataset.json");
    data.save(&p).unwrap();
    // serde_json's default float parser may differ in the last bit.
    let back = Dataset::load(&p).unwrap();
    assert_eq!(
        (back.distribution, back.swarm, back.seed, back.samples.len()),
        (data.distribution, data.swarm, data.seed, data.samples.len())
    );
    let close = |a: f64, b: f64| (a - b).abs() <= 1e-14 * a.abs().max(1.0);
    for (a, b) in back.samples.iter().zip(&data.samples) {
        assert!(
            close(a.turn, b.turn) && close(a.ratio, b.ratio) && close(a.curvature, b.curvature)
        );
        assert!(
            a.x.iter().zip(&b.x).all(|(p, q)| close(*p, *q)),
            "{a:?} {b:?}"
        );
    }
    let w = tmp("round_trip.safetensors");
    model.save(&w).unwrap();
    let back = Model::load(&w, &Distribution::default()).unwrap();
    assert_eq!(back, model);
}

#[test]
fn wrong_size_or_distribution_is_refused() {
    let (_, model) = tiny_model();
    let w = tmp("wrong.safetensors");
    model.save(&w).unwrap();
    // Another distribution.
    let other = Distribution {
        ratio_max: 1000.0,
        ..Distribution::default()
    };
    let e = Model::load(&w, &other).unwrap_err();
    assert!(matches!(e, CornerNetError::Mismatch { .. }), "{e}");
    assert!(e.to_string().contains("trained for"), "{e}");
    // A sidecar claiming width 16 for width-8 tensors.
    let side = sidecar_path(&w);
    let mut sidecar = model.sidecar.clone();
    sidecar.architecture.width = 16;
    std::fs::write(&side, serde_json::to_string(&sidecar).unwrap()).unwrap();
    let e = Model::load(&w, &Distribution::default()).unwrap_err();
    assert!(matches!(e, CornerNetError::Mismatch { .. }), "{e}");
    assert!(e.to_string().contains("shape"), "{e}");
    // A sidecar claiming more layers than the file holds.
    sidecar.architecture.width = 8;
    sidecar.architecture.layers = 6;
    std::fs::write(&side, serde_json::to_string(&sidecar).unwrap()).unwrap();
    let e = Model::load(&w, &Distribution::default()).unwrap_err();
    assert!(e.to_string().contains("missing"), "{e}");
}

/// The largest sampled distance of a transition from the two segments.
fn sampled_deviation(t: &kerf_toolpath::CornerTransition, prev: [f64; 3], next: [f64; 3]) -> f64 {
    (0..=200)
        .map(|k| {
            let p = t.curve.point(k as f64 / 200.0);
            distance_to_segment(p, prev, t.vertex).min(distance_to_segment(p, t.vertex, next))
        })
        .fold(0.0, f64::max)
}

#[test]
fn held_out_predictions_stay_within_tolerance_or_fall_back() {
    let (data, model) = tiny_model();
    let (_, held) = data.split(0.15);
    let mut drls = DrlsNet::new(model);
    let delta = 1e-5;
    for s in held {
        let available = s.ratio * delta;
        let v = [0.1, 0.2, 0.0];
        let (t1, t2) = s.corner().directions();
        let prev = kerf_toolpath::vec3::sub(v, scale(t1, 2.0 * available));
        let next = kerf_toolpath::vec3::add(v, scale(t2, 2.0 * available));
        let r = drls.transition(prev, v, next, delta, available).unwrap();
        let t = r.transition.unwrap();
        assert!(t.deviation <= delta * (1.0 + 1e-9));
        assert!(sampled_deviation(&t, prev, next) <= delta * (1.0 + 1e-6));
        assert!(t.tangent_length <= available * (1.0 + 1e-12));
    }
    let c = drls.counts();
    assert_eq!(c.network + c.fallback, held.len());
}

#[test]
fn out_of_distribution_corner_falls_back_with_the_reason() {
    let (_, model) = tiny_model();
    let mut drls = DrlsNet::new(model);
    let delta = 1e-5;
    // 2° turn: below the trained 5°.
    let turn = 2f64.to_radians();
    let r = drls
        .transition(
            [-1e-3, 0.0, 0.0],
            [0.0; 3],
            [1e-3 * turn.cos(), 1e-3 * turn.sin(), 0.0],
            delta,
            1e-4,
        )
        .unwrap();
    match &r.source {
        Source::Fallback(why) => assert!(why.contains("turning angle"), "{why}"),
        Source::Network => panic!("a 2° corner was predicted"),
    }
    assert!(r.transition.unwrap().deviation <= delta * (1.0 + 1e-9));
    // A / δ = 10⁴: above the trained 500.
    let r = drls
        .transition([-1.0, 0.0, 0.0], [0.0; 3], [0.0, 1.0, 0.0], delta, 0.1)
        .unwrap();
    match &r.source {
        Source::Fallback(why) => assert!(why.contains("available / tolerance"), "{why}"),
        Source::Network => panic!("A / δ = 10⁴ was predicted"),
    }
    assert_eq!(drls.counts().fallback, 2);
}
