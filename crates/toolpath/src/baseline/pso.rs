//! A deterministic particle swarm (seed 003 eq. 8, after Kennedy and
//! Eberhart, "Particle swarm optimization", Proc. ICNN 1995) with a fixed
//! seed: the same settings give bit-identical results.

use kerf_budget::{bytes_of, Budget, Interrupt};

/// SplitMix64 (Steele, Lea and Flood, "Fast splittable pseudorandom number
/// generators", OOPSLA 2014; the constants of its reference
/// implementation): a tiny generator, enough for a swarm's draws.
#[derive(Debug, Clone)]
pub struct SplitMix64 {
    state: u64,
}

impl SplitMix64 {
    /// A generator from a seed.
    pub fn new(seed: u64) -> Self {
        SplitMix64 { state: seed }
    }

    /// The next 64 random bits.
    pub fn next_u64(&mut self) -> u64 {
        self.state = self.state.wrapping_add(0x9e37_79b9_7f4a_7c15);
        let mut z = self.state;
        z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        z ^ (z >> 31)
    }

    /// A uniform draw in [0, 1) (the top 53 bits).
    pub fn next_f64(&mut self) -> f64 {
        (self.next_u64() >> 11) as f64 * (1.0 / (1u64 << 53) as f64)
    }
}

/// The swarm's coefficients (seed 003 eq. 8).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Swarm {
    /// Particles.
    pub particles: usize,
    /// Iterations after the initial draw.
    pub iterations: usize,
    /// Inertia w.
    pub inertia: f64,
    /// c₁: pull towards the particle's own best.
    pub c1: f64,
    /// c₂: pull towards the swarm's best.
    pub c2: f64,
    /// c₃: the term c₃ r₃ (pbest − gbest) of seed 003 eq. 8.
    pub c3: f64,
}

/// Minimizes `f` over the box [`lo`, `hi`] by the swarm of seed 003 eq. 8:
/// v ← w v + c₁r₁(pbest − x) + c₂r₂(gbest − x) + c₃r₃(pbest − gbest),
/// x ← x + v clamped to the box (r drawn per particle and coordinate).
/// Positions start uniform in the box with zero velocity; infeasible points
/// are those where `f` is +∞.
///
/// # Returns
/// The best point and its value (+∞ when no point drawn was feasible).
pub fn minimize<const D: usize>(
    f: impl Fn(&[f64; D]) -> f64,
    lo: [f64; D],
    hi: [f64; D],
    swarm: &Swarm,
    seed: u64,
) -> ([f64; D], f64) {
    match run(f, lo, hi, swarm, seed, || {
        Ok::<(), std::convert::Infallible>(())
    }) {
        Ok(best) => best,
        Err(never) => match never {},
    }
}

/// [`minimize`] under a budget: the swarm's memory (positions, velocities and bests of every
/// particle) is checked before it is drawn, the deadline at every particle's move.
///
/// # Errors
/// [`Interrupt`] when the budget runs out.
pub fn minimize_within<const D: usize>(
    f: impl Fn(&[f64; D]) -> f64,
    lo: [f64; D],
    hi: [f64; D],
    swarm: &Swarm,
    seed: u64,
    budget: &Budget,
) -> Result<([f64; D], f64), Interrupt> {
    let n = swarm.particles.max(1) as u64;
    budget.check_memory(
        bytes_of::<[f64; D]>(n.saturating_mul(4)),
        &format!("corner swarm: {n} particles"),
    )?;
    run(f, lo, hi, swarm, seed, || {
        budget.check("NURBS corner swarm")
    })
}

/// The swarm of [`minimize`], `check` called before every particle's move.
fn run<const D: usize, E>(
    f: impl Fn(&[f64; D]) -> f64,
    lo: [f64; D],
    hi: [f64; D],
    swarm: &Swarm,
    seed: u64,
    mut check: impl FnMut() -> Result<(), E>,
) -> Result<([f64; D], f64), E> {
    let mut rng = SplitMix64::new(seed);
    let n = swarm.particles.max(1);
    let mut x: Vec<[f64; D]> = (0..n)
        .map(|_| std::array::from_fn(|d| lo[d] + rng.next_f64() * (hi[d] - lo[d])))
        .collect();
    let mut v = vec![[0.0; D]; n];
    let mut best: Vec<([f64; D], f64)> = x.iter().map(|p| (*p, f(p))).collect();
    let mut global = best[0];
    for b in &best {
        if b.1 < global.1 {
            global = *b;
        }
    }
    for _ in 0..swarm.iterations {
        for i in 0..n {
            check()?;
            for d in 0..D {
                let (r1, r2, r3) = (rng.next_f64(), rng.next_f64(), rng.next_f64());
                let pb = best[i].0[d];
                v[i][d] = swarm.inertia * v[i][d]
                    + swarm.c1 * r1 * (pb - x[i][d])
                    + swarm.c2 * r2 * (global.0[d] - x[i][d])
                    + swarm.c3 * r3 * (pb - global.0[d]);
                x[i][d] = (x[i][d] + v[i][d]).clamp(lo[d], hi[d]);
            }
            let value = f(&x[i]);
            if value < best[i].1 {
                best[i] = (x[i], value);
                if value < global.1 {
                    global = best[i];
                }
            }
        }
    }
    Ok(global)
}
