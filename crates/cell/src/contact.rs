//! Contacts decided by distance: a robot shape nearer than the threshold to a scene object.
//!
//! rapier's own contact events are not used: with speculative contacts they start about 2 cm
//! before the shapes touch. Each (robot shape, scene object) pair is tested with parry's
//! `contact` query with the pair's threshold as prediction distance, after a bounding-box
//! test; the reported distance is signed (negative = penetration depth).

use parry3d_f64::bounding_volume::BoundingVolume;
use parry3d_f64::math::Pose;
use parry3d_f64::query;

use crate::config::{Allow, CellFile, ObjectKind};
use crate::geometry::{to_vector3, RobotShape, SceneObject};
use crate::CellError;

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
pub struct ContactChecker {
    shapes: Vec<RobotShape>,
    objects: Vec<SceneObject>,
    pairs: Vec<Pair>,
    threshold: f64,
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
        Ok(Self {
            shapes,
            objects,
            pairs,
            threshold,
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

    /// Tests every pair at the given body poses and merges the contacts into `out`: per
    /// (shape, object) pair, the nearest over the calls is kept.
    ///
    /// # Arguments
    /// * `bodies` - pose of every moving body in the base frame (parry convention).
    /// * `time` - simulated time of these poses (s), recorded in new contacts.
    /// * `out` - contacts so far in this control cycle.
    ///
    /// # Performance
    /// One bounding-box test per pair; a parry `contact` query (BVH traversal for meshes)
    /// only for pairs whose boxes, grown by the threshold, overlap.
    pub fn check(&self, bodies: &[Pose], time: f64, out: &mut Vec<Contact>) {
        for pair in &self.pairs {
            let s = &self.shapes[pair.shape];
            let o = &self.objects[pair.object];
            let pose = match s.body {
                Some(b) => bodies[b] * s.local,
                None => s.local,
            };
            let aabb = s.shape.compute_aabb(&pose).loosened(pair.threshold);
            if !aabb.intersects(&o.aabb) {
                continue;
            }
            let c = match query::contact(
                &pose,
                s.shape.as_ref(),
                &o.pose,
                o.shape.as_ref(),
                pair.threshold,
            ) {
                Ok(Some(c)) if c.dist < pair.threshold => c,
                Ok(_) => continue,
                Err(_) => {
                    // Every pair's support was checked when the cell was built.
                    log::error!("parry cannot test {} against {}", s.name, o.name);
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
        for pair in &self.pairs {
            let s = &self.shapes[pair.shape];
            let o = &self.objects[pair.object];
            if query::contact(
                &Pose::IDENTITY,
                s.shape.as_ref(),
                &o.pose,
                o.shape.as_ref(),
                0.0,
            )
            .is_err()
            {
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
