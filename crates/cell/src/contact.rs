//! Contacts decided by distance: a robot shape nearer than the threshold to a scene object.
//!
//! rapier's own contact events are not used: with speculative contacts they start about 2 cm
//! before the shapes touch. Each (robot shape, scene object) pair is tested with parry's
//! `contact` query, after a bounding-box test; the reported distance is signed (negative =
//! penetration depth).
//!
//! Every test leaves a lower bound on the pair's distance (the box gap, the query's distance,
//! or its prediction distance when it finds nothing). Until the shape has moved far enough to
//! close that margin ([`crate::motion`]), the pair cannot be a contact and is not tested again:
//! the contacts found are those of testing every pair at every call.

use parry3d_f64::bounding_volume::Aabb;
use parry3d_f64::math::Pose;
use parry3d_f64::query;

use crate::config::{Allow, CellFile, ObjectKind};
use crate::geometry::{to_vector3, RobotShape, SceneObject};
use crate::mesh_contact::{mesh_contact, Candidates};
use crate::motion::{aabb_gap, ShapeBound};
use crate::CellError;

/// How much farther than its threshold a pair's query looks (m): the query then returns the
/// pair's distance (or that it is beyond `threshold + MARGIN`), a clearance the shape may use
/// up by moving before the pair is tested again. Larger margins test more triangles per query
/// and fewer queries; BENCHMARKS.md, "Simulated cell", compares 0.5 to 4 mm.
pub const MARGIN: f64 = 0.001;

/// Allowance for the queries' own error (m) when a clearance decides to skip a test (GJK
/// converges to about 1e-10 m at these scales; this keeps the skip conservative).
const SLACK: f64 = 1e-6;

/// What the last test of a pair proved: its distance was at least `lower` with the shape at
/// `pose`.
#[derive(Debug, Clone, Copy)]
struct Clearance {
    lower: f64,
    pose: Pose,
}

/// One contact between a robot shape and a scene object.
#[derive(Debug, Clone, PartialEq)]
pub struct Contact {
    /// The robot link (URDF name).
    pub link: String,
    /// The robot shape: `<link>/<collision index>` or a tool shape's name.
    pub shape: String,
    /// The scene object.
    pub object: String,
    /// Signed distance (m): > 0 a gap below the threshold, < 0 a penetration.
    pub distance: f64,
    /// Penetration depth `max(0, -distance)` (m).
    pub depth: f64,
    /// The point of the robot shape nearest to (or deepest in) the object, base frame (m).
    pub position: [f64; 3],
    /// The object's point nearest to the robot shape, base frame (m).
    pub object_point: [f64; 3],
    /// Simulated time of the physics sub-step where this pair was nearest (s).
    pub time: f64,
}

/// A pair to test and its threshold.
#[derive(Debug, Clone, Copy)]
struct Pair {
    shape: usize,
    object: usize,
    threshold: f64,
}

/// The pairs to test and their thresholds (allowances applied).
#[derive(Clone)]
pub struct ContactChecker {
    shapes: Vec<RobotShape>,
    objects: Vec<SceneObject>,
    pairs: Vec<Pair>,
    threshold: f64,
    /// Per shape: its bounding box in its own frame.
    local_aabbs: Vec<Aabb>,
    /// Per shape: the data of its displacement bound.
    bounds: Vec<ShapeBound>,
    /// Per pair: what its last test proved (`None` before the first).
    clearance: Vec<Option<Clearance>>,
    /// Queries run and skipped by [`ContactChecker::check`] since the checker was built.
    counts: QueryCounts,
    /// Scratch of the mesh queries.
    candidates: Candidates,
}

/// How many pair tests [`ContactChecker::check`] ran as parry queries, settled by bounding
/// boxes, or skipped by a clearance.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct QueryCounts {
    /// Parry `contact` queries.
    pub queries: u64,
    /// Pairs settled by their bounding-box gap.
    pub boxes: u64,
    /// Pairs skipped: the shape had not moved enough since the last test.
    pub skipped: u64,
    /// Mesh triangles in the grown boxes of the queried shapes.
    pub triangles: u64,
    /// Mesh triangles tested with GJK (and EPA) after the plane bounds
    /// ([`crate::mesh_contact`]).
    pub tested: u64,
}

impl std::fmt::Debug for ContactChecker {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("ContactChecker")
            .field(
                "shapes",
                &self.shapes.iter().map(|s| &s.name).collect::<Vec<_>>(),
            )
            .field(
                "objects",
                &self.objects.iter().map(|o| &o.name).collect::<Vec<_>>(),
            )
            .field("pairs", &self.pairs.len())
            .field("threshold", &self.threshold)
            .finish()
    }
}

impl ContactChecker {
    /// Builds the pair list from the cell file's contact rules.
    ///
    /// # Errors
    /// [`CellError::InvalidValue`] for a negative or non-finite threshold or standoff, or a
    /// standoff above the threshold; [`CellError::CellFile`] for an allowance naming an
    /// unknown shape or object, or a fixture (only workpieces may be engaged).
    pub fn new(
        cell: &CellFile,
        shapes: Vec<RobotShape>,
        objects: Vec<SceneObject>,
    ) -> Result<Self, CellError> {
        let threshold = cell.contact.threshold;
        if !(threshold.is_finite() && threshold >= 0.0) {
            return Err(CellError::InvalidValue {
                field: "contact.threshold".into(),
                value: threshold,
                requirement: "must be finite and >= 0",
            });
        }
        let mut pair_threshold: Vec<Vec<Option<f64>>> =
            vec![vec![Some(threshold); objects.len()]; shapes.len()];
        for a in &cell.contact.allowances {
            let s = shapes
                .iter()
                .position(|s| s.name == a.shape)
                .ok_or_else(|| {
                    cell.error(format!(
                        "allowance names robot shape '{}'; the shapes are {:?}",
                        a.shape,
                        shapes.iter().map(|s| &s.name).collect::<Vec<_>>()
                    ))
                })?;
            let o = objects
                .iter()
                .position(|o| o.name == a.object)
                .ok_or_else(|| {
                    cell.error(format!(
                        "allowance names unknown scene object '{}'",
                        a.object
                    ))
                })?;
            if objects[o].kind != ObjectKind::Workpiece {
                return Err(cell.error(format!(
                    "allowance for '{}' on '{}': only a workpiece may be approached or \
                     engaged by design, '{}' is a fixture",
                    a.shape, a.object, a.object
                )));
            }
            pair_threshold[s][o] = match a.allow()? {
                Allow::Engagement => None,
                Allow::Standoff { min_distance } => {
                    if !(min_distance.is_finite()
                        && min_distance >= 0.0
                        && min_distance <= threshold)
                    {
                        return Err(CellError::InvalidValue {
                            field: format!("contact.allowances[{}].min_distance", a.shape),
                            value: min_distance,
                            requirement: "must be finite, >= 0 and <= contact.threshold",
                        });
                    }
                    Some(min_distance)
                }
            };
        }
        let mut pairs = Vec::new();
        for (s, row) in pair_threshold.iter().enumerate() {
            for (o, t) in row.iter().enumerate() {
                if let Some(t) = *t {
                    pairs.push(Pair {
                        shape: s,
                        object: o,
                        threshold: t,
                    });
                }
            }
        }
        let local_aabbs = shapes
            .iter()
            .map(|s| s.shape.compute_local_aabb())
            .collect();
        let bounds = shapes
            .iter()
            .map(|s| ShapeBound::new(s.shape.as_ref()))
            .collect();
        let clearance = vec![None; pairs.len()];
        Ok(Self {
            shapes,
            objects,
            pairs,
            threshold,
            local_aabbs,
            bounds,
            clearance,
            counts: QueryCounts::default(),
            candidates: Candidates::default(),
        })
    }

    /// The robot shapes.
    pub fn shapes(&self) -> &[RobotShape] {
        &self.shapes
    }

    /// The scene objects.
    pub fn objects(&self) -> &[SceneObject] {
        &self.objects
    }

    /// The cell's contact threshold (m).
    pub fn threshold(&self) -> f64 {
        self.threshold
    }

    /// How many pair tests ran as queries, were settled by boxes, or were skipped.
    pub fn counts(&self) -> QueryCounts {
        QueryCounts {
            triangles: self.candidates.candidates,
            tested: self.candidates.tested,
            ..self.counts
        }
    }

    /// Tests every pair at the given body poses and merges the contacts into `out`: per
    /// (shape, object) pair, the nearest over the calls is kept.
    ///
    /// # Arguments
    /// * `bodies` - pose of every moving body in the base frame (parry convention).
    /// * `time` - simulated time of these poses (s), recorded in new contacts.
    /// * `out` - contacts so far in this control cycle.
    ///
    /// # Performance
    /// Per pair one displacement bound; when the shape has moved less than the clearance the
    /// last test left, nothing more. Otherwise a bounding-box gap, and a parry `contact` query
    /// (BVH traversal for meshes) with prediction `threshold + MARGIN` only when the gap is
    /// below the threshold.
    pub fn check(&mut self, bodies: &[Pose], time: f64, out: &mut Vec<Contact>) {
        let Self {
            shapes,
            objects,
            pairs,
            local_aabbs,
            bounds,
            clearance,
            counts,
            candidates,
            ..
        } = self;
        for (pair, known) in pairs.iter().zip(clearance.iter_mut()) {
            let s = &shapes[pair.shape];
            let o = &objects[pair.object];
            let pose = match s.body {
                Some(b) => bodies[b] * s.local,
                None => s.local,
            };
            if let Some(k) = known {
                let moved = bounds[pair.shape].displacement(&k.pose, &pose);
                if k.lower - moved - SLACK >= pair.threshold {
                    counts.skipped += 1;
                    continue;
                }
            }
            let gap = aabb_gap(&local_aabbs[pair.shape].transform_by(&pose), &o.aabb);
            if gap - SLACK >= pair.threshold {
                counts.boxes += 1;
                *known = Some(Clearance { lower: gap, pose });
                continue;
            }
            counts.queries += 1;
            // A pair found within its threshold is likely to stay there: the margin would only
            // add triangles to the query (10 % of the cycle with the nozzle in the part).
            let near = known.is_some_and(|k| k.lower < pair.threshold);
            let prediction = pair.threshold + if near { 0.0 } else { MARGIN };
            let c = match pair_contact(s, &pose, o, prediction, candidates) {
                Ok(Some(c)) => {
                    *known = Some(Clearance {
                        lower: c.dist,
                        pose,
                    });
                    if c.dist >= pair.threshold {
                        continue;
                    }
                    c
                }
                Ok(None) => {
                    *known = Some(Clearance {
                        lower: prediction,
                        pose,
                    });
                    continue;
                }
                Err(_) => {
                    // Every pair's support was checked when the cell was built.
                    log::error!("parry cannot test {} against {}", s.name, o.name);
                    *known = None;
                    continue;
                }
            };
            let found = Contact {
                link: s.link.clone(),
                shape: s.name.clone(),
                object: o.name.clone(),
                distance: c.dist,
                depth: (-c.dist).max(0.0),
                position: to_vector3(c.point1).into(),
                object_point: to_vector3(c.point2).into(),
                time,
            };
            match out
                .iter_mut()
                .find(|k| k.shape == found.shape && k.object == found.object)
            {
                Some(k) if k.distance > found.distance => *k = found,
                Some(_) => {}
                None => out.push(found),
            }
        }
    }

    /// Signed distance (m) of every robot shape to every scene object it is tested against
    /// (allowance-engaged pairs excluded), at the given body poses; `None` for a pair parry
    /// cannot measure.
    pub fn distances(&self, bodies: &[Pose]) -> Vec<(String, String, Option<f64>)> {
        self.pairs
            .iter()
            .map(|pair| {
                let s = &self.shapes[pair.shape];
                let o = &self.objects[pair.object];
                let pose = match s.body {
                    Some(b) => bodies[b] * s.local,
                    None => s.local,
                };
                let d = query::distance(&pose, s.shape.as_ref(), &o.pose, o.shape.as_ref())
                    .ok()
                    .map(|d| d.distance);
                // parry's distance is 0 for intersecting shapes: use the contact depth there.
                let d = match d {
                    Some(d) if d <= 0.0 => {
                        query::contact(&pose, s.shape.as_ref(), &o.pose, o.shape.as_ref(), 0.0)
                            .ok()
                            .flatten()
                            .map(|c| c.dist.min(0.0))
                    }
                    other => other,
                };
                (s.name.clone(), o.name.clone(), d)
            })
            .collect()
    }

    /// Checks that parry supports every pair (probes each once at the identity).
    ///
    /// # Errors
    /// [`CellError::InvalidValue`] naming the first unsupported pair.
    pub fn probe(&self) -> Result<(), CellError> {
        let mut scratch = Candidates::default();
        for pair in &self.pairs {
            let s = &self.shapes[pair.shape];
            let o = &self.objects[pair.object];
            if pair_contact(s, &Pose::IDENTITY, o, 0.0, &mut scratch).is_err() {
                return Err(CellError::InvalidValue {
                    field: format!("{} against {}", s.name, o.name),
                    value: f64::NAN,
                    requirement: "parry3d must support this shape pair",
                });
            }
        }
        Ok(())
    }
}

/// The contact query of one pair, as [`ContactChecker::check`] and
/// [`ContactChecker::probe`] run it: [`mesh_contact`] against a triangle mesh, parry's
/// `contact` against anything else.
fn pair_contact(
    s: &RobotShape,
    pose: &Pose,
    o: &SceneObject,
    prediction: f64,
    candidates: &mut Candidates,
) -> Result<Option<query::Contact>, query::Unsupported> {
    match o.shape.as_trimesh() {
        Some(mesh) => mesh_contact(
            mesh,
            &o.pose,
            s.shape.as_ref(),
            pose,
            prediction,
            candidates,
        ),
        None => query::contact(
            pose,
            s.shape.as_ref(),
            &o.pose,
            o.shape.as_ref(),
            prediction,
        ),
    }
}
