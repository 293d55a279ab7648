//! Collision queries per second and GFD build time (seed 001 section 2.4).
//!
//! Workpiece: a hat-section sheet (a B-pillar-like profile: flanges, two
//! inclined walls, a top) generated here, and `urdf/meshes/bpillar.obj`
//! when it exists. Configurations: the head cutting on the surface (C on
//! a triangle centroid, tool axis along the face normal, q6 from -0.1 to
//! -0.07 m, leans of 0 and +-0.1 rad). Near the hat's walls the head
//! collides (steep walls, the fork over the flanges), elsewhere it is
//! free: queries are timed over the mix and over the free ones alone
//! (every link tested, the most expensive case).
//!
//! Run: `cargo bench -p kerf_mjto --bench collision`.
#![allow(clippy::unwrap_used, clippy::expect_used)] // tests report failures by panicking

use kerf_budget::Budget;
use std::hint::black_box;

use criterion::{criterion_group, criterion_main, Criterion, Throughput};
use kerf_mjto::collision::{CollisionWorld, HeadModel};
use kerf_mjto::gfd::Gfd;
use kerf_mjto::mesh::{self, MeshData};
use kerf_mjto::request::{GfdGrid, Weights};
use kerf_mjto::selection::{select_rtos, select_rtos_eager};
use kerf_mjto::LaserMachine;
use nalgebra::{Isometry3, Vector3};

/// A hat section extruded along x over 1 m: profile (y, z) flange, wall,
/// top, wall, flange; every profile segment split in 6, 200 stations.
fn hat_section() -> MeshData {
    let corners = [
        (-0.16, 0.0),
        (-0.09, 0.0),
        (-0.06, 0.09),
        (0.06, 0.09),
        (0.09, 0.0),
        (0.16, 0.0),
    ];
    let mut profile = Vec::new();
    for w in corners.windows(2) {
        let ((y0, z0), (y1, z1)) = (w[0], w[1]);
        for k in 0..6 {
            let t = k as f64 / 6.0;
            profile.push((y0 + t * (y1 - y0), z0 + t * (z1 - z0)));
        }
    }
    profile.push(corners[corners.len() - 1]);
    let stations = 200;
    let np = profile.len() as u32;
    let mut m = MeshData::default();
    for s in 0..=stations {
        let x = s as f64 / stations as f64;
        m.vertices.extend(profile.iter().map(|&(y, z)| [x, y, z]));
    }
    for s in 0..stations as u32 {
        for j in 0..np - 1 {
            let a = s * np + j;
            let b = a + np;
            m.triangles.push([a, b, a + 1]);
            m.triangles.push([a + 1, b, b + 1]);
        }
    }
    m
}

/// Places the mesh's bounding box centre at (0.8, 0.7, 0.35) in the
/// machine frame.
fn placement(m: &MeshData) -> Isometry3<f64> {
    let (lo, hi) = m.bounds().expect("mesh has vertices");
    Isometry3::translation(
        0.8 - (lo[0] + hi[0]) / 2.0,
        0.7 - (lo[1] + hi[1]) / 2.0,
        0.35 - (lo[2] + hi[2]) / 2.0,
    )
}

/// Cutting configurations on the surface: C at centroids of upward faces,
/// O along the normal (plus leans), M = C - q6 O (seed 001 eq. 3).
fn surface_configs(m: &MeshData, pose: &Isometry3<f64>, n: usize) -> Vec<[f64; 6]> {
    let up: Vec<(Vector3<f64>, Vector3<f64>)> = m
        .triangles
        .iter()
        .filter_map(|t| {
            let p = t.map(|k| pose * nalgebra::Point3::from(m.vertices[k as usize]));
            let nrm = (p[1] - p[0]).cross(&(p[2] - p[0])).try_normalize(1e-12)?;
            let nrm = if nrm.z < 0.0 { -nrm } else { nrm };
            (nrm.z > 0.3).then(|| ((p[0].coords + p[1].coords + p[2].coords) / 3.0, nrm))
        })
        .collect();
    let step = (up.len() / n).max(1);
    up.iter()
        .step_by(step)
        .enumerate()
        .map(|(i, (c, o))| {
            let q6 = [-0.1, -0.085, -0.07][i % 3];
            let q5 = o.z.clamp(-1.0, 1.0).acos() + [0.0, 0.1, -0.1][(i / 3) % 3];
            let q4 = o.y.atan2(o.x);
            let axis = Vector3::new(q4.cos() * q5.sin(), q4.sin() * q5.sin(), q5.cos());
            let mp = c - q6 * axis;
            [mp.x, mp.y, mp.z, q4, q5, q6]
        })
        .collect()
}

fn head() -> HeadModel {
    let machine = LaserMachine::default_machine().expect("machine");
    HeadModel::from_urdf(machine.robot().urdf()).expect("head")
}

fn world(m: &MeshData, pose: &Isometry3<f64>) -> CollisionWorld {
    CollisionWorld::new(head(), m, pose, 0.0).expect("world")
}

fn bench_queries(c: &mut Criterion, name: &str, m: &MeshData) {
    let pose = placement(m);
    let w = world(m, &pose);
    let configs = surface_configs(m, &pose, 1000);
    let free = configs.iter().filter(|q| w.is_free(q)).count();
    eprintln!(
        "{name}: {} triangles, {} configurations, {free} free",
        w.triangles(),
        configs.len()
    );
    let free_only: Vec<[f64; 6]> = configs.iter().copied().filter(|q| w.is_free(q)).collect();
    let mut g = c.benchmark_group(format!("collision/{name}"));
    g.throughput(Throughput::Elements(configs.len() as u64));
    g.bench_function("is_free (mixed)", |b| {
        b.iter(|| configs.iter().filter(|q| w.is_free(black_box(q))).count())
    });
    // Free configurations test every link: the most expensive queries.
    g.throughput(Throughput::Elements(free_only.len() as u64));
    g.bench_function("is_free (free only)", |b| {
        b.iter(|| free_only.iter().filter(|q| w.is_free(black_box(q))).count())
    });
    g.throughput(Throughput::Elements(configs.len() as u64));
    g.bench_function("colliding_links", |b| {
        b.iter(|| {
            configs
                .iter()
                .map(|q| w.colliding_links(black_box(q)).len())
                .sum::<usize>()
        })
    });
    g.throughput(Throughput::Elements(1));
    let h = head();
    g.bench_function("world build (BVH)", |b| {
        b.iter(|| CollisionWorld::new(h.clone(), black_box(m), &pose, 0.0).expect("world"))
    });
    g.finish();
}

fn bench_gfd(c: &mut Criterion, m: &MeshData) {
    let machine = LaserMachine::default_machine().expect("machine");
    let pose = placement(m);
    let w = world(m, &pose);
    // On the top of the hat, 2 cm from the wall edge: vertical reference.
    let top = pose * nalgebra::Point3::new(0.5, 0.04, 0.09);
    let point = top.coords;
    // Path frame of a cut along +x: t = x, n = z, b = y.
    let lead_tilt = |o: &Vector3<f64>| (o.x.atan2(o.z), o.y.atan2(o.z));
    let build = || {
        Gfd::build(
            0,
            0.5,
            &point,
            [0.0, 0.0, -0.07],
            &GfdGrid::default(),
            &Weights::default(),
            15f64.to_radians(),
            10f64.to_radians(),
            &lead_tilt,
            machine.limits(),
        )
    };
    let sample = build();
    eprintln!(
        "GFD: {} samples, {} candidates, {} angle-rejected",
        sample.total,
        sample.candidates.len(),
        sample.angle_rejected
    );
    let mut g = c.benchmark_group("gfd/hat_section");
    g.bench_function("build (default grid, lazy)", |b| {
        b.iter(|| black_box(build()))
    });
    g.bench_function("build + check every candidate", |b| {
        b.iter(|| {
            let mut gfd = build();
            (0..gfd.candidates.len())
                .filter(|&p| gfd.is_free(p, &w))
                .count()
        })
    });
    g.bench_function("build + nearest_free(reference)", |b| {
        b.iter(|| {
            let mut gfd = build();
            gfd.nearest_free(gfd.reference, &Weights::default(), &w, &Budget::unlimited())
        })
    });
    g.finish();
}

/// Eq. 56 over 6 RTOs along the top of the hat, 1 cm from its edge, with a
/// colliding reference standoff (q6 = -0.05: the fork arms reach the
/// sheet), so the lazy selection needs several rounds.
fn bench_selection(c: &mut Criterion, m: &MeshData) {
    let machine = LaserMachine::default_machine().expect("machine");
    let pose = placement(m);
    let w = world(m, &pose);
    let lead_tilt = |o: &Vector3<f64>| (o.x.atan2(o.z), o.y.atan2(o.z));
    let xs = [0.1, 0.25, 0.4, 0.55, 0.7, 0.85];
    let gfds: Vec<Gfd> = xs
        .iter()
        .enumerate()
        .map(|(i, &x)| {
            let p = (pose * nalgebra::Point3::new(x, 0.05, 0.09)).coords;
            Gfd::build(
                i,
                x,
                &p,
                [0.0, 0.0, -0.05],
                &GfdGrid::default(),
                &Weights::default(),
                15f64.to_radians(),
                10f64.to_radians(),
                &lead_tilt,
                machine.limits(),
            )
        })
        .collect();
    let sigma: Vec<f64> = xs.windows(2).map(|p| p[1] - p[0]).collect();
    let weights = Weights::default();
    let before = w.queries();
    let mut once = gfds.clone();
    let choice =
        select_rtos(&mut once, &sigma, &weights, &w, &Budget::unlimited()).expect("selection");
    eprintln!(
        "selection: {} layers of {} candidates, {} queries, choice {choice:?}",
        gfds.len(),
        gfds[0].candidates.len(),
        w.queries() - before
    );
    let mut g = c.benchmark_group("selection/hat_section");
    g.bench_function("lazy (6 RTOs, default grid)", |b| {
        b.iter(|| {
            let mut l = gfds.clone();
            select_rtos(&mut l, &sigma, &weights, &w, &Budget::unlimited()).expect("selection")
        })
    });
    g.bench_function("eager (6 RTOs, default grid)", |b| {
        b.iter(|| {
            let mut l = gfds.clone();
            select_rtos_eager(&mut l, &sigma, &weights, &w).expect("selection")
        })
    });
    g.finish();
}

fn benches(c: &mut Criterion) {
    let hat = hat_section();
    bench_queries(c, "hat_section", &hat);
    bench_gfd(c, &hat);
    bench_selection(c, &hat);
    let bpillar = mesh::package_root().join("urdf/meshes/bpillar.obj");
    if bpillar.is_file() {
        match mesh::load(&bpillar.to_string_lossy()) {
            Ok(m) => bench_queries(c, "bpillar", &m),
            Err(e) => eprintln!("skipping bpillar.obj: {e}"),
        }
    }
}

criterion_group!(collision, benches);
criterion_main!(collision);
