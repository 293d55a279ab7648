//! Cost of planning one batch of the streaming mode (issue 29, item 5): the
//! executor's request thread plans a batch when the robot rests, so this is
//! the delay a full queue adds before the robot moves.
//!
//! Six joints with the IRB 6660's velocity limits and its limits file's
//! acceleration and jerk (`urdf/irb6660_limits.yaml`), a smooth joint path
//! with 0.01 rad between points, precision 1e-4 rad, period 4 ms (250 Hz);
//! batches of 1, 16, 64 and 256 points (the default queue).
//!
//! Run: `cargo bench -p kerf_stepping --bench stream_batch` (release).
#![allow(clippy::unwrap_used, clippy::expect_used)]

use std::time::Instant;

use kerf_stepping::{
    stream::{Stream, StreamPoint, StreamSettings},
    Controller, Course, Limits, Rpro, RproSettings, StepError,
};

fn rpro(course: &Course) -> Result<Box<dyn Controller>, StepError> {
    Ok(Box::new(Rpro::new(course, RproSettings::default())?))
}

fn main() {
    let v = [1.9199, 2.2689, 2.2689, 2.618, 2.0944, 4.1888];
    let a = [3.5, 4.0, 4.0, 5.0, 4.0, 8.0];
    let limits: Vec<Limits> = (0..6)
        .map(|j| Limits::new(v[j], a[j], 5.0 * a[j]))
        .collect();
    let ranges = vec![(-3.0, 3.0); 6];
    println!("| points in the batch | planning mean ms | max ms | batch duration s | steps |");
    println!("|---|---|---|---|---|");
    for n in [1usize, 16, 64, 256] {
        let mut times = Vec::new();
        let (mut duration, mut steps) = (0.0, 0);
        for trial in 0..5 {
            let mut s =
                Stream::new(limits.clone(), ranges.clone(), StreamSettings::new(0.004)).unwrap();
            let at = |k: usize| -> Vec<f64> {
                let t = k as f64 * 0.01 + trial as f64 * 1e-3;
                vec![
                    t,
                    0.2 * t.sin(),
                    -0.1 * t,
                    0.3 * (2.0 * t).sin(),
                    0.05 * t,
                    -0.2 * t,
                ]
            };
            s.push(StreamPoint {
                id: 0,
                positions: at(0),
                precision: 1e-4,
            })
            .unwrap();
            for k in 1..=n {
                // Points 0.01 rad apart along joint 1, the others following smoothly.
                s.push(StreamPoint {
                    id: k as u32,
                    positions: at(k),
                    precision: 1e-4,
                })
                .unwrap();
            }
            let started = Instant::now();
            let batch = s.take_batch(&rpro).unwrap().unwrap();
            times.push(started.elapsed().as_secs_f64() * 1e3);
            steps = batch.samples.len() - 1;
            duration = steps as f64 * 0.004;
        }
        let mean = times.iter().sum::<f64>() / times.len() as f64;
        let max = times.iter().cloned().fold(0.0, f64::max);
        println!("| {n} | {mean:.2} | {max:.2} | {duration:.3} | {steps} |");
    }
}
