//! The experience replay buffer B of DDPG (seed 004 Algorithm 1; Lillicrap
//! et al., "Continuous control with deep reinforcement learning", ICLR 2016,
//! Algorithm 1): a ring buffer of transitions (s_t, a_t, r_{t+1}, s_{t+1},
//! terminal) from which minibatches are drawn uniformly.
//!
//! Storage is flat `f32` arrays (one row per transition), so a minibatch is
//! gathered into row-major matrices ready to become candle tensors without
//! further copies.

use crate::error::MillPlanError;
use crate::rng::Rng;

/// A ring buffer of transitions with fixed observation and action sizes.
///
/// When full, the oldest transition is overwritten (first in, first out), as
/// in Lillicrap et al. 2016 ("when the replay buffer was full the oldest
/// samples were discarded").
#[derive(Debug, Clone)]
pub struct ReplayBuffer {
    capacity: usize,
    observation_dim: usize,
    action_dim: usize,
    observations: Vec<f32>,
    actions: Vec<f32>,
    rewards: Vec<f32>,
    next_observations: Vec<f32>,
    terminals: Vec<f32>,
    len: usize,
    next: usize,
}

/// A minibatch gathered from a [`ReplayBuffer`], row-major.
#[derive(Debug, Clone, PartialEq)]
pub struct Batch {
    /// Number of rows.
    pub size: usize,
    /// `size × observation_dim` observations s_t.
    pub observations: Vec<f32>,
    /// `size × action_dim` actions a_t (with the exploration noise that was
    /// actually applied).
    pub actions: Vec<f32>,
    /// `size` rewards r_{t+1}.
    pub rewards: Vec<f32>,
    /// `size × observation_dim` next observations s_{t+1}.
    pub next_observations: Vec<f32>,
    /// `size` values 1 − terminal: 0 when s_{t+1} is terminal (no bootstrap),
    /// 1 otherwise.
    pub not_done: Vec<f32>,
}

impl ReplayBuffer {
    /// An empty buffer.
    ///
    /// # Errors
    /// [`MillPlanError::InvalidParameter`] when `capacity`, `observation_dim`
    /// or `action_dim` is zero.
    pub fn new(
        capacity: usize,
        observation_dim: usize,
        action_dim: usize,
    ) -> Result<Self, MillPlanError> {
        for (name, value) in [
            ("replay buffer capacity", capacity),
            ("observation dimension", observation_dim),
            ("action dimension", action_dim),
        ] {
            if value == 0 {
                return Err(MillPlanError::InvalidParameter {
                    name: name.to_string(),
                    value: 0.0,
                    reason: "must be at least 1".to_string(),
                });
            }
        }
        Ok(Self {
            capacity,
            observation_dim,
            action_dim,
            observations: Vec::with_capacity(capacity * observation_dim),
            actions: Vec::with_capacity(capacity * action_dim),
            rewards: Vec::with_capacity(capacity),
            next_observations: Vec::with_capacity(capacity * observation_dim),
            terminals: Vec::with_capacity(capacity),
            len: 0,
            next: 0,
        })
    }

    /// Number of stored transitions (at most the capacity).
    pub fn len(&self) -> usize {
        self.len
    }

    /// Whether nothing is stored yet.
    pub fn is_empty(&self) -> bool {
        self.len == 0
    }

    /// Largest number of stored transitions.
    pub fn capacity(&self) -> usize {
        self.capacity
    }

    /// Stores one transition, overwriting the oldest when full.
    ///
    /// # Arguments
    /// * `observation`, `next_observation` — `observation_dim` finite values.
    /// * `action` — `action_dim` finite values.
    /// * `reward` — finite.
    /// * `terminal` — s_{t+1} is terminal (no bootstrapping from it). A time
    ///   limit that cuts an episode short is *not* terminal.
    ///
    /// # Errors
    /// [`MillPlanError::InvalidConfig`] for a wrong length, and
    /// [`MillPlanError::InvalidParameter`] for a non-finite value; the buffer
    /// is unchanged then.
    pub fn push(
        &mut self,
        observation: &[f32],
        action: &[f32],
        reward: f64,
        next_observation: &[f32],
        terminal: bool,
    ) -> Result<(), MillPlanError> {
        check_row("observation", observation, self.observation_dim)?;
        check_row("action", action, self.action_dim)?;
        check_row("next observation", next_observation, self.observation_dim)?;
        if !reward.is_finite() {
            return Err(MillPlanError::InvalidParameter {
                name: "reward".to_string(),
                value: reward,
                reason: "must be finite".to_string(),
            });
        }
        let terminal = if terminal { 1.0 } else { 0.0 };
        if self.len < self.capacity {
            self.observations.extend_from_slice(observation);
            self.actions.extend_from_slice(action);
            self.rewards.push(reward as f32);
            self.next_observations.extend_from_slice(next_observation);
            self.terminals.push(terminal);
            self.len += 1;
        } else {
            let i = self.next;
            let (o, a) = (self.observation_dim, self.action_dim);
            self.observations[i * o..(i + 1) * o].copy_from_slice(observation);
            self.actions[i * a..(i + 1) * a].copy_from_slice(action);
            self.rewards[i] = reward as f32;
            self.next_observations[i * o..(i + 1) * o].copy_from_slice(next_observation);
            self.terminals[i] = terminal;
        }
        self.next = (self.next + 1) % self.capacity;
        Ok(())
    }

    /// Draws `size` transitions uniformly, with replacement (each row an
    /// independent uniform index, as e.g. Stable-Baselines3's `ReplayBuffer`;
    /// for batch 64 out of ≥ 64 stored transitions the difference from
    /// sampling without replacement is immaterial to the gradient estimate).
    ///
    /// # Errors
    /// [`MillPlanError::InvalidParameter`] when `size` is zero or the buffer
    /// is empty.
    pub fn sample(&self, size: usize, rng: &mut Rng) -> Result<Batch, MillPlanError> {
        if size == 0 {
            return Err(MillPlanError::InvalidParameter {
                name: "batch size".to_string(),
                value: 0.0,
                reason: "must be at least 1".to_string(),
            });
        }
        let (o, a) = (self.observation_dim, self.action_dim);
        let mut batch = Batch {
            size,
            observations: Vec::with_capacity(size * o),
            actions: Vec::with_capacity(size * a),
            rewards: Vec::with_capacity(size),
            next_observations: Vec::with_capacity(size * o),
            not_done: Vec::with_capacity(size),
        };
        for _ in 0..size {
            let i = rng
                .below(self.len)
                .ok_or_else(|| MillPlanError::InvalidParameter {
                    name: "replay buffer length".to_string(),
                    value: 0.0,
                    reason: "cannot sample from an empty replay buffer".to_string(),
                })?;
            batch
                .observations
                .extend_from_slice(&self.observations[i * o..(i + 1) * o]);
            batch
                .actions
                .extend_from_slice(&self.actions[i * a..(i + 1) * a]);
            batch.rewards.push(self.rewards[i]);
            batch
                .next_observations
                .extend_from_slice(&self.next_observations[i * o..(i + 1) * o]);
            batch.not_done.push(1.0 - self.terminals[i]);
        }
        Ok(batch)
    }
}

/// Length and finiteness check of one row.
fn check_row(name: &str, row: &[f32], dim: usize) -> Result<(), MillPlanError> {
    if row.len() != dim {
        return Err(MillPlanError::InvalidConfig {
            name: name.to_string(),
            reason: format!("has {} entries, expected {dim}", row.len()),
        });
    }
    if let Some(v) = row.iter().find(|v| !v.is_finite()) {
        return Err(MillPlanError::InvalidParameter {
            name: name.to_string(),
            value: f64::from(*v),
            reason: "every entry must be finite".to_string(),
        });
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ring_overwrites_oldest_and_sampling_sees_only_stored_rows() {
        let mut b = ReplayBuffer::new(3, 2, 1).expect("valid sizes");
        assert!(b.is_empty());
        for k in 0..5 {
            let x = k as f32;
            b.push(&[x, -x], &[x / 10.0], f64::from(x), &[x + 1.0, 0.0], k == 4)
                .expect("valid row");
        }
        assert_eq!(b.len(), 3);
        assert_eq!(b.capacity(), 3);
        // Rows 0 and 1 were overwritten by 3 and 4: slots hold 3, 4, 2.
        assert_eq!(b.rewards, vec![3.0, 4.0, 2.0]);
        assert_eq!(b.observations, vec![3.0, -3.0, 4.0, -4.0, 2.0, -2.0]);
        assert_eq!(b.terminals, vec![0.0, 1.0, 0.0]);
        let mut rng = Rng::new(1);
        let batch = b.sample(300, &mut rng).expect("nonempty");
        assert_eq!(batch.observations.len(), 600);
        let mut seen = [false; 3];
        for r in 0..batch.size {
            let reward = batch.rewards[r];
            assert!([2.0, 3.0, 4.0].contains(&reward));
            // The row is consistent across the arrays.
            assert_eq!(batch.observations[2 * r], reward);
            assert_eq!(batch.observations[2 * r + 1], -reward);
            assert_eq!(batch.actions[r], reward / 10.0);
            assert_eq!(batch.next_observations[2 * r], reward + 1.0);
            assert_eq!(batch.not_done[r], if reward == 4.0 { 0.0 } else { 1.0 });
            seen[reward as usize - 2] = true;
        }
        assert_eq!(seen, [true; 3]);
    }

    #[test]
    fn bad_rows_are_refused_and_leave_the_buffer_unchanged() {
        let mut b = ReplayBuffer::new(4, 2, 1).expect("valid sizes");
        assert!(b.push(&[0.0], &[0.0], 0.0, &[0.0, 0.0], false).is_err());
        assert!(b
            .push(&[0.0, f32::NAN], &[0.0], 0.0, &[0.0, 0.0], false)
            .is_err());
        assert!(b
            .push(&[0.0, 0.0], &[0.0], f64::INFINITY, &[0.0, 0.0], false)
            .is_err());
        assert!(b.is_empty());
        let mut rng = Rng::new(0);
        assert!(b.sample(4, &mut rng).is_err());
        b.push(&[0.0, 0.0], &[0.0], 1.0, &[0.0, 0.0], false)
            .expect("valid row");
        assert!(b.sample(0, &mut rng).is_err());
        assert!(ReplayBuffer::new(0, 1, 1).is_err());
        assert!(ReplayBuffer::new(1, 0, 1).is_err());
        assert!(ReplayBuffer::new(1, 1, 0).is_err());
    }
}
