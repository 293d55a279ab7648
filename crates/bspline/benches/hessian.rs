//! Cost of the QP building blocks of seed 001 section 2.2: the jerk Hessian
//! (eq. 17-18) and the collocation matrix (eq. 35) for n + 1 = 64 and 628
//! coefficients (the paper reports 9.5 s in Python for 628).
#![allow(clippy::unwrap_used, clippy::expect_used)] // tests report failures by panicking

use criterion::{criterion_group, criterion_main, Criterion};
use kerf_bspline::{collocation, derivative_operator, jerk_hessian, KnotVector};
use std::hint::black_box;

fn bench(c: &mut Criterion) {
    for n1 in [64usize, 628] {
        let kv = KnotVector::clamped_uniform(5, n1).expect("valid knot vector");
        let params: Vec<f64> = (0..n1).map(|i| i as f64 / (n1 - 1) as f64).collect();
        c.bench_function(&format!("jerk_hessian n+1={n1}"), |b| {
            b.iter(|| jerk_hessian(black_box(&kv)).expect("hessian"))
        });
        c.bench_function(&format!("collocation n+1={n1}"), |b| {
            b.iter(|| collocation(black_box(&kv), black_box(&params)).expect("collocation"))
        });
        c.bench_function(&format!("hessian+collocation+D1..D3 n+1={n1}"), |b| {
            b.iter(|| {
                let h = jerk_hessian(black_box(&kv)).expect("hessian");
                let n = collocation(black_box(&kv), black_box(&params)).expect("collocation");
                let d: Vec<_> = (1..=3)
                    .map(|r| derivative_operator(&kv, r).expect("operator"))
                    .collect();
                (h, n, d)
            })
        });
    }
}

criterion_group!(benches, bench);
criterion_main!(benches);
