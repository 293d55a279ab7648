//! Where the |μ|max values of a plan come from ([`IndicatorSource`]) and
//! how they were obtained ([`IndicatorProvenance`], part of the planner's
//! answer).

/// Where the |μ|max of a plan's segments comes from.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum IndicatorSource {
    /// Every segment evaluated directly with the chatter model (the
    /// default; about 1.25 ms per segment in release).
    #[default]
    Direct,
    /// The indicator cache's interpolation where it applies, with its
    /// stated error bound reported ([`Plan::evaluate`] stays direct; see
    /// [`crate::planner::MillPlanner::with_indicator_source`]).
    Cache,
}

impl IndicatorSource {
    /// `direct` or `cache`.
    pub fn name(self) -> &'static str {
        match self {
            Self::Direct => "direct",
            Self::Cache => "cache",
        }
    }
}

/// How the |μ|max values of a plan were obtained (part of the planner's
/// answer, [`crate::planner::MillPlanOutput::indicator`]).
#[derive(Debug, Clone, PartialEq)]
pub struct IndicatorProvenance {
    /// The source asked for.
    pub requested: IndicatorSource,
    /// Segments whose |μ|max is the cache's interpolation (ascending);
    /// empty for a direct evaluation.
    pub cached_segments: Vec<usize>,
    /// Segments in the plan.
    pub segments: usize,
    /// The cache's stated bound on |cached − direct| |μ|max when some
    /// segment is cached (the largest that applies: the bound for g on a
    /// g node where every cached g is a node and the cache states one, else
    /// the general bound), else `None`.
    pub error_bound: Option<f64>,
    /// One sentence for the answer's message: how many segments are
    /// cached, the bound, and why the cache was not used where it was not.
    pub note: String,
}

impl IndicatorProvenance {
    /// Every segment evaluated directly, `requested` having been asked for
    /// (`reason`: why the cache was not used, when it was asked for).
    ///
    /// # Arguments
    /// * `requested` — the source asked for; `segments` — plan length;
    /// * `reason` — appended to the note when not empty.
    ///
    /// # Returns
    /// A provenance with no cached segment.
    pub fn direct(requested: IndicatorSource, segments: usize, reason: &str) -> Self {
        let mut note = format!("|mu|max evaluated directly for all {segments} segments");
        if !reason.is_empty() {
            note.push_str(&format!(" ({reason})"));
        }
        Self {
            requested,
            cached_segments: Vec::new(),
            segments,
            error_bound: None,
            note,
        }
    }

    /// Whether every |μ|max of the plan is a direct evaluation.
    pub fn all_direct(&self) -> bool {
        self.cached_segments.is_empty()
    }
}
