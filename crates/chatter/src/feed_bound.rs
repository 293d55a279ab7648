//! The feed lower bound of a row of a feed map: seed 004's observation (Fig. 4, 7) that
//! chatter can be left by feeding faster.

/// A feed lower bound ([`feed_lower_bound`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum FeedBound {
    /// Stable at every grid feed.
    All,
    /// Unstable at the highest grid feed.
    None,
    /// Stable from this feed \[m/s\] upward.
    Feed(f64),
}

impl std::fmt::Display for FeedBound {
    /// `all`, `none`, or the feed with 4 decimals.
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            FeedBound::All => write!(f, "all"),
            FeedBound::None => write!(f, "none"),
            FeedBound::Feed(v) => write!(f, "{v:.4}"),
        }
    }
}

/// The lowest grid feed from which every higher grid feed is stable (|μ| < 1) too.
///
/// # Arguments
/// * `feeds` – the grid feeds \[m/s\], ascending.
/// * `row` – |μ|max at each feed (`None` = undefined, counted as not stable).
///
/// # Returns
/// [`FeedBound::All`] if every feed is stable, [`FeedBound::None`] if the highest feed is
/// unstable (or the row is empty), else [`FeedBound::Feed`].
pub fn feed_lower_bound(feeds: &[f64], row: &[Option<f64>]) -> FeedBound {
    let stable = |mu: &Option<f64>| matches!(mu, Some(m) if *m < 1.0);
    let mut lowest = None;
    for (f, mu) in feeds.iter().zip(row).rev() {
        if stable(mu) {
            lowest = Some(*f);
        } else {
            break;
        }
    }
    match lowest {
        None => FeedBound::None,
        Some(_) if row.len() == feeds.len() && row.iter().all(stable) => FeedBound::All,
        Some(f) => FeedBound::Feed(f),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn feed_lower_bound_cases() {
        let f = [0.0, 0.02, 0.04, 0.06];
        let b = |row: [Option<f64>; 4]| feed_lower_bound(&f, &row);
        assert_eq!(
            b([Some(0.9), Some(0.9), Some(0.9), Some(0.9)]),
            FeedBound::All
        );
        assert_eq!(
            b([Some(1.2), Some(1.1), Some(0.99), Some(0.9)]),
            FeedBound::Feed(0.04)
        );
        // Stable, unstable, stable: the bound is the start of the stable tail.
        assert_eq!(
            b([Some(0.9), Some(1.1), Some(0.9), Some(0.9)]),
            FeedBound::Feed(0.04)
        );
        assert_eq!(
            b([Some(0.9), Some(0.9), Some(0.9), Some(1.0)]),
            FeedBound::None
        );
        // Undefined (f = 0, sublinear law) counts as not stable.
        assert_eq!(
            b([None, Some(0.9), Some(0.9), Some(0.9)]),
            FeedBound::Feed(0.02)
        );
        assert_eq!(feed_lower_bound(&f, &[]), FeedBound::None);
    }

    #[test]
    fn bounds_print_as_the_table_shows_them() {
        assert_eq!(FeedBound::All.to_string(), "all");
        assert_eq!(FeedBound::None.to_string(), "none");
        assert_eq!(FeedBound::Feed(0.04).to_string(), "0.0400");
    }
}
