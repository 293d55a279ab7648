//! The generic dynamic program of [`crate::dp`] on a 3-D grid: stages,
//! moves of −1/0/+1 grid steps per axis (27 moves), a stage reward per
//! node ([`solve_grid`]) and optionally a filter on moves
//! ([`solve_grid_with_moves`]).

use kerf_budget::Budget;

use crate::error::MillPlanError;

/// Result of the generic DP.
#[derive(Debug, Clone, PartialEq)]
pub struct GridPath {
    /// The value (Σ stage rewards, f64 re-summed along the path).
    pub value: f64,
    /// Node indices (i, j, k) per stage.
    pub nodes: Vec<[usize; 3]>,
}

/// The generic DP on a 3-D grid (module documentation): `stages` stages,
/// grid `dims`, start node `start`, moves of −1/0/+1 per axis, stage
/// reward `stage(t, [i, j, k])` (`None` = forbidden state).
///
/// # Returns
/// `Ok(None)` when no feasible sequence exists (the start is forbidden or
/// every continuation dies).
///
/// # Errors
/// [`MillPlanError::InvalidConfig`] for zero stages, empty dimensions, a
/// start outside the grid, or a grid too large (> 2^31 nodes × stages).
pub fn solve_grid<F>(
    stages: usize,
    dims: [usize; 3],
    start: [usize; 3],
    stage: F,
) -> Result<Option<GridPath>, MillPlanError>
where
    F: FnMut(usize, [usize; 3]) -> Option<f64>,
{
    solve_grid_with_moves(
        stages,
        dims,
        start,
        stage,
        |_, _, _| true,
        &Budget::unlimited(),
    )
}

/// As [`solve_grid`], with a filter on moves: `allowed(t, x, y)` says
/// whether the move from node x at stage t to node y at stage t + 1 is
/// allowed (e.g. joint speeds, [`crate::joint_speed`]), under a time budget
/// checked per row of the grid (`dims[1] × dims[2]` nodes) of every stage.
///
/// # Errors
/// As [`solve_grid`], and [`MillPlanError::Interrupted`].
pub fn solve_grid_with_moves<F, M>(
    stages: usize,
    dims: [usize; 3],
    start: [usize; 3],
    mut stage: F,
    allowed: M,
    budget: &Budget,
) -> Result<Option<GridPath>, MillPlanError>
where
    F: FnMut(usize, [usize; 3]) -> Option<f64>,
    M: Fn(usize, [usize; 3], [usize; 3]) -> bool,
{
    let nodes = check_grid(stages, dims, start, 1)?;
    let index = |i: usize, j: usize, k: usize| (i * dims[1] + j) * dims[2] + k;
    let stage_table = |t: usize, stage: &mut F| stage_rewards(t, dims, &mut *stage, budget);
    // Backward pass.
    let mut next = stage_table(stages - 1, &mut stage)?;
    let mut back: Vec<u8> = vec![u8::MAX; nodes * (stages - 1)];
    for t in (0..stages - 1).rev() {
        let r = stage_table(t, &mut stage)?;
        let mut value = vec![f32::NEG_INFINITY; nodes];
        let bt = &mut back[t * nodes..(t + 1) * nodes];
        for i in 0..dims[0] {
            budget.check("the DP")?;
            for j in 0..dims[1] {
                for k in 0..dims[2] {
                    let here = index(i, j, k);
                    let rv = r[here];
                    if rv == f32::NEG_INFINITY {
                        continue;
                    }
                    let mut best = f32::NEG_INFINITY;
                    let mut best_m = u8::MAX;
                    for di in 0..3usize {
                        let Some(ni) = (i + di).checked_sub(1).filter(|v| *v < dims[0]) else {
                            continue;
                        };
                        for dj in 0..3usize {
                            let Some(nj) = (j + dj).checked_sub(1).filter(|v| *v < dims[1]) else {
                                continue;
                            };
                            for dk in 0..3usize {
                                let Some(nk) = (k + dk).checked_sub(1).filter(|v| *v < dims[2])
                                else {
                                    continue;
                                };
                                let v = next[index(ni, nj, nk)];
                                if v > best && allowed(t, [i, j, k], [ni, nj, nk]) {
                                    best = v;
                                    best_m = (di * 9 + dj * 3 + dk) as u8;
                                }
                            }
                        }
                    }
                    if best > f32::NEG_INFINITY {
                        value[here] = rv + best;
                        bt[here] = best_m;
                    }
                }
            }
        }
        next = value;
    }
    let s0 = index(start[0], start[1], start[2]);
    if next.get(s0).is_none_or(|v| *v == f32::NEG_INFINITY) {
        return Ok(None);
    }
    // Forward pass, re-summing the stage rewards in f64.
    let mut path = Vec::with_capacity(stages);
    let mut x = start;
    let mut total = 0.0;
    for t in 0..stages {
        path.push(x);
        total += stage(t, x).unwrap_or(f64::NEG_INFINITY);
        if t + 1 == stages {
            break;
        }
        let m = back[t * nodes + index(x[0], x[1], x[2])];
        if m == u8::MAX {
            return Ok(None);
        }
        let m = m as usize;
        x = [x[0] + m / 9 - 1, x[1] + (m / 3) % 3 - 1, x[2] + m % 3 - 1];
    }
    Ok(Some(GridPath {
        value: total,
        nodes: path,
    }))
}

/// As [`solve_grid_with_moves`], with the previous move on the third axis
/// (−1/0/+1 steps, coded 0/1/2) in the state, so that a move can be judged
/// by three consecutive nodes (e.g. a second difference: joint
/// accelerations, [`crate::dp`]'s `joint_acceleration_limits`):
/// `allowed3(t, p, x, y)` says whether the move x → y at stage t is allowed
/// after a move coded p on axis 2 into x (p = 1, no move, at stage 0).
/// Three times the states of [`solve_grid_with_moves`] (value layers of
/// 3 × nodes f32, one u8 backpointer per (stage, node, p)).
///
/// # Errors
/// As [`solve_grid_with_moves`] (the state count includes the factor 3).
pub fn solve_grid_with_history<F, M, A>(
    stages: usize,
    dims: [usize; 3],
    start: [usize; 3],
    mut stage: F,
    allowed: M,
    allowed3: A,
    budget: &Budget,
) -> Result<Option<GridPath>, MillPlanError>
where
    F: FnMut(usize, [usize; 3]) -> Option<f64>,
    M: Fn(usize, [usize; 3], [usize; 3]) -> bool,
    A: Fn(usize, usize, [usize; 3], [usize; 3]) -> bool,
{
    let nodes = check_grid(stages, dims, start, 3)?;
    let index = |i: usize, j: usize, k: usize| (i * dims[1] + j) * dims[2] + k;
    let mut stage_table = |t: usize| stage_rewards(t, dims, &mut stage, budget);
    // V_{N-1}(x, p) = r(N-1, x) for every p.
    let last = stage_table(stages - 1)?;
    let mut next: Vec<f32> = last.iter().flat_map(|v| [*v; 3]).collect();
    let mut back: Vec<u8> = vec![u8::MAX; nodes * 3 * (stages - 1)];
    for t in (0..stages - 1).rev() {
        let r = stage_table(t)?;
        let mut value = vec![f32::NEG_INFINITY; nodes * 3];
        let bt = &mut back[t * nodes * 3..(t + 1) * nodes * 3];
        for i in 0..dims[0] {
            budget.check("the DP")?;
            for j in 0..dims[1] {
                for k in 0..dims[2] {
                    let here = index(i, j, k);
                    let rv = r[here];
                    if rv == f32::NEG_INFINITY {
                        continue;
                    }
                    let x = [i, j, k];
                    let mut best = [f32::NEG_INFINITY; 3];
                    let mut best_m = [u8::MAX; 3];
                    for di in 0..3usize {
                        let Some(ni) = (i + di).checked_sub(1).filter(|v| *v < dims[0]) else {
                            continue;
                        };
                        for dj in 0..3usize {
                            let Some(nj) = (j + dj).checked_sub(1).filter(|v| *v < dims[1]) else {
                                continue;
                            };
                            for dk in 0..3usize {
                                let Some(nk) = (k + dk).checked_sub(1).filter(|v| *v < dims[2])
                                else {
                                    continue;
                                };
                                let v = next[index(ni, nj, nk) * 3 + dk];
                                // Better than the best so far of some p, or skip.
                                if v <= best[0] && v <= best[1] && v <= best[2] {
                                    continue;
                                }
                                let y = [ni, nj, nk];
                                if !allowed(t, x, y) {
                                    continue;
                                }
                                for p in 0..3usize {
                                    if v > best[p] && allowed3(t, p, x, y) {
                                        best[p] = v;
                                        best_m[p] = (di * 9 + dj * 3 + dk) as u8;
                                    }
                                }
                            }
                        }
                    }
                    for p in 0..3usize {
                        if best[p] > f32::NEG_INFINITY {
                            value[here * 3 + p] = rv + best[p];
                            bt[here * 3 + p] = best_m[p];
                        }
                    }
                }
            }
        }
        next = value;
    }
    let s0 = index(start[0], start[1], start[2]) * 3 + 1;
    if next.get(s0).is_none_or(|v| *v == f32::NEG_INFINITY) {
        return Ok(None);
    }
    // Forward pass from (start, p = 1), re-summing the stage rewards in f64.
    let mut path = Vec::with_capacity(stages);
    let mut x = start;
    let mut p = 1usize;
    let mut total = 0.0;
    for t in 0..stages {
        path.push(x);
        total += stage(t, x).unwrap_or(f64::NEG_INFINITY);
        if t + 1 == stages {
            break;
        }
        let m = back[t * nodes * 3 + index(x[0], x[1], x[2]) * 3 + p];
        if m == u8::MAX {
            return Ok(None);
        }
        let m = m as usize;
        x = [x[0] + m / 9 - 1, x[1] + (m / 3) % 3 - 1, x[2] + m % 3 - 1];
        p = m % 3;
    }
    Ok(Some(GridPath {
        value: total,
        nodes: path,
    }))
}

/// Checks a DP grid: at least one stage, a non-empty grid, the start inside it, and at most
/// 2^31 states (`layers` value layers per node and stage).
///
/// # Returns
/// The nodes per stage.
///
/// # Errors
/// [`MillPlanError::InvalidConfig`] naming what is wrong.
fn check_grid(
    stages: usize,
    dims: [usize; 3],
    start: [usize; 3],
    layers: usize,
) -> Result<usize, MillPlanError> {
    let nodes = dims[0] * dims[1] * dims[2];
    if stages == 0 || nodes == 0 || (0..3).any(|a| start[a] >= dims[a]) {
        return Err(MillPlanError::InvalidConfig {
            name: "DP grid".to_string(),
            reason: format!("stages {stages}, dims {dims:?}, start {start:?}"),
        });
    }
    if nodes
        .checked_mul(layers * stages)
        .is_none_or(|v| v > (1usize << 31))
    {
        return Err(MillPlanError::InvalidConfig {
            name: "DP grid".to_string(),
            reason: "too many states".to_string(),
        });
    }
    Ok(nodes)
}

/// The rewards of stage `t` at every node (f32; −∞ where `stage` gives none or a non-finite
/// value), the budget checked per row of the first axis.
///
/// # Errors
/// [`MillPlanError::Interrupted`] when the budget runs out.
fn stage_rewards<F>(
    t: usize,
    dims: [usize; 3],
    mut stage: F,
    budget: &Budget,
) -> Result<Vec<f32>, MillPlanError>
where
    F: FnMut(usize, [usize; 3]) -> Option<f64>,
{
    let index = |i: usize, j: usize, k: usize| (i * dims[1] + j) * dims[2] + k;
    let mut out = vec![f32::NEG_INFINITY; dims[0] * dims[1] * dims[2]];
    for i in 0..dims[0] {
        budget.check("the DP")?;
        for j in 0..dims[1] {
            for k in 0..dims[2] {
                if let Some(r) = stage(t, [i, j, k]) {
                    if r.is_finite() {
                        out[index(i, j, k)] = r as f32;
                    }
                }
            }
        }
    }
    Ok(out)
}
