//! IK with the redundancy angle plus the condition number (seed 004 eq. 13
//! and 14) per path segment, and the full cell evaluation (IK, condition
//! number, tool-tip dynamics).

use criterion::{criterion_group, criterion_main, Criterion};
use kerf_mill::{condition_number, MillCell};

fn bench(c: &mut Criterion) {
    let cell = MillCell::default_cell().expect("default cell");
    let kin = cell.kinematics();
    let path = cell.path();
    let l = cell.characteristic_length();
    let reference = *cell.reference_joints();
    let n = path.segments().len();
    c.bench_function("ik(g) + condition number, one segment", |b| {
        let mut s = 0usize;
        b.iter(|| {
            s = (s + 1) % n;
            let pose = path.tool_pose(s, 1.0).expect("pose");
            let q = kin.ik_nearest(&pose, &reference).expect("ik");
            let j = kin.jacobian(&q).expect("J");
            condition_number(&j, l).expect("K")
        })
    });
    c.bench_function("cell.evaluate (ik + K + Modal2), one segment", |b| {
        let mut s = 0usize;
        b.iter(|| {
            s = (s + 1) % n;
            cell.evaluate(s, 1.0, None).expect("state")
        })
    });
}

criterion_group!(benches, bench);
criterion_main!(benches);
