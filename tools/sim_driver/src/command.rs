//! Position commands: the messages of `<ns>/commands` turned into one position per joint.

use kerf_msgs::{sensor_msgs::JointState, std_msgs::Float64MultiArray};

fn finite(values: &[f64]) -> Result<(), String> {
    match values.iter().position(|x| !x.is_finite()) {
        Some(i) => Err(format!("value {i} is {}", values[i])),
        None => Ok(()),
    }
}

/// A `Float64MultiArray` command: one finite position per joint, in joint order.
///
/// # Errors
/// Why the command is ignored.
pub fn from_array(msg: &Float64MultiArray, joints: usize) -> Result<Vec<f64>, String> {
    if msg.data.len() != joints {
        return Err(format!("{} values for {joints} joints", msg.data.len()));
    }
    finite(&msg.data)?;
    Ok(msg.data.clone())
}

/// A `JointState` command: every joint named exactly once (any order), a finite position each.
///
/// # Errors
/// Why the command is ignored.
pub fn from_joint_state(msg: &JointState, joints: &[String]) -> Result<Vec<f64>, String> {
    if msg.name.len() != msg.position.len() {
        return Err(format!(
            "{} names but {} positions",
            msg.name.len(),
            msg.position.len()
        ));
    }
    finite(&msg.position)?;
    let mut out = vec![f64::NAN; joints.len()];
    for (name, p) in msg.name.iter().zip(&msg.position) {
        let Some(j) = joints.iter().position(|x| x == name) else {
            return Err(format!("unknown joint '{name}'"));
        };
        if !out[j].is_nan() {
            return Err(format!("joint '{name}' is named twice"));
        }
        out[j] = *p;
    }
    if let Some(j) = out.iter().position(|x| x.is_nan()) {
        return Err(format!("joint '{}' is missing", joints[j]));
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn arrays_and_joint_states() {
        let joints = vec!["a".to_string(), "b".to_string()];
        let arr = |d: Vec<f64>| Float64MultiArray {
            data: d,
            ..Default::default()
        };
        assert_eq!(from_array(&arr(vec![1.0, 2.0]), 2), Ok(vec![1.0, 2.0]));
        assert!(from_array(&arr(vec![1.0]), 2).is_err());
        assert!(from_array(&arr(vec![1.0, f64::NAN]), 2).is_err());
        let js = |n: &[&str], p: Vec<f64>| JointState {
            name: n.iter().map(|s| s.to_string()).collect(),
            position: p,
            ..Default::default()
        };
        assert_eq!(
            from_joint_state(&js(&["b", "a"], vec![2.0, 1.0]), &joints),
            Ok(vec![1.0, 2.0])
        );
        for (bad, needle) in [
            (js(&["a"], vec![1.0]), "missing"),
            (js(&["a", "a"], vec![1.0, 1.0]), "twice"),
            (js(&["a", "b", "c"], vec![1.0, 1.0, 1.0]), "unknown"),
            (js(&["a", "b"], vec![1.0]), "positions"),
            (js(&["a", "b"], vec![1.0, f64::INFINITY]), "inf"),
        ] {
            let e = from_joint_state(&bad, &joints).unwrap_err();
            assert!(e.contains(needle), "{e}");
        }
    }
}
