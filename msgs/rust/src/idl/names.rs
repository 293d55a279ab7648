//! Name rules of `rosidl_adapter.parser` (`VALID_*_PATTERN`).

/// Package and field names: `^(?!.*__)(?!.*_$)[a-z][a-z0-9_]*$`.
pub(crate) fn is_valid_field_name(name: &str) -> bool {
    let mut chars = name.chars();
    matches!(chars.next(), Some('a'..='z'))
        && chars.all(|c| matches!(c, 'a'..='z' | '0'..='9' | '_'))
        && !name.contains("__")
        && !name.ends_with('_')
}

/// Package names follow the field-name rule.
pub(crate) fn is_valid_package_name(name: &str) -> bool {
    is_valid_field_name(name)
}

/// Message names: `^[A-Z][A-Za-z0-9]*$`.
pub(crate) fn is_valid_message_name(name: &str) -> bool {
    let mut chars = name.chars();
    matches!(chars.next(), Some('A'..='Z')) && chars.all(|c| c.is_ascii_alphanumeric())
}

/// Constant names: `^[A-Z]([A-Z0-9_]?[A-Z0-9]+)*$`, i.e. upper-case letters,
/// digits and single inner underscores, starting with a letter.
pub(crate) fn is_valid_constant_name(name: &str) -> bool {
    let mut chars = name.chars();
    matches!(chars.next(), Some('A'..='Z'))
        && chars.all(|c| matches!(c, 'A'..='Z' | '0'..='9' | '_'))
        && !name.contains("__")
        && !name.ends_with('_')
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn field_names() {
        for ok in ["a", "joint_names", "x1", "multi_dof_error"] {
            assert!(is_valid_field_name(ok), "{ok}");
        }
        for bad in ["", "A", "1a", "_a", "a_", "a__b", "jointNames", "a-b"] {
            assert!(!is_valid_field_name(bad), "{bad}");
        }
    }

    #[test]
    fn message_and_constant_names() {
        assert!(is_valid_message_name("JointTrajectory"));
        assert!(is_valid_message_name("MultiDOFJointTrajectoryPoint"));
        assert!(!is_valid_message_name("jointTrajectory"));
        assert!(!is_valid_message_name("Joint_Trajectory"));
        for ok in ["X", "X_AXIS", "OLD_HEADER_TIMESTAMP", "A1"] {
            assert!(is_valid_constant_name(ok), "{ok}");
        }
        for bad in ["", "x_axis", "_X", "X_", "X__Y", "1X"] {
            assert!(!is_valid_constant_name(bad), "{bad}");
        }
    }
}
