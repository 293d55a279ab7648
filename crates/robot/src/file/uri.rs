//! [`resolve_uri`]: the one place a file reference a request gives (a mesh, a policy, a
//! G-code program) becomes a path: a plain path, a local `file://` URI or
//! `package://kerf/<path>`; every other form is refused naming the reference.

use std::path::PathBuf;

use crate::RobotError;

/// The URIs that are read, for the messages of refused ones.
const ACCEPTED: &str = "use a path, file:///absolute/path or package://kerf/<path>";

/// Resolves a file reference from a request to the path to read.
///
/// Surrounding white space is ignored. The path is not checked against the file system
/// (whether it exists, or lies under the allowed roots, is the reader's and
/// [`crate::roots::AllowedRoots`]' concern).
///
/// # Arguments
/// * `uri` - one of
///   * a plain path, absolute or relative (relative paths are relative to the process's
///     working directory);
///   * a local `file://` URI, `file:///abs/path` or `file://localhost/abs/path` (`%XX`
///     escapes are decoded);
///   * `package://kerf/<relative path>`, below the kerf data root
///     ([`crate::data::resolve_package_uri`]).
///
/// # Returns
/// The path the reference names.
///
/// # Errors
/// * [`RobotError::FileUri`], naming the reference: it is empty or holds a NUL byte, it is a
///   URI of another scheme (`http://`, ...), a `file://` URI of another host or without an
///   absolute path, or its `%XX` escapes are malformed, decode to a NUL byte or to text that
///   is not UTF-8.
/// * [`RobotError::PackageUri`] for a `package://` URI of another package or whose path is
///   empty or leaves the data root; [`RobotError::DataNotFound`] when no data root is found.
pub fn resolve_uri(uri: &str) -> Result<PathBuf, RobotError> {
    let refuse = |reason: String| RobotError::FileUri {
        uri: uri.to_owned(),
        reason,
    };
    let reference = uri.trim();
    if reference.is_empty() {
        return Err(refuse("empty file reference".to_owned()));
    }
    if reference.contains('\0') {
        return Err(refuse("holds a NUL byte".to_owned()));
    }
    if reference.starts_with("package://") {
        return crate::data::resolve_package_uri(reference);
    }
    if let Some(rest) = reference.strip_prefix("file://") {
        return file_uri_path(rest).map_err(refuse);
    }
    match uri_scheme(reference) {
        Some(scheme) => Err(refuse(format!(
            "URI scheme '{scheme}://' is not supported ({ACCEPTED})"
        ))),
        None => Ok(PathBuf::from(reference)),
    }
}

impl RobotError {
    /// The message without the reference, for a caller whose own message names it (a mesh,
    /// a policy): the reason of [`RobotError::FileUri`] and [`RobotError::PackageUri`], the
    /// whole message of every other error.
    ///
    /// # Returns
    /// The reason the reference was refused.
    pub fn uri_reason(&self) -> String {
        match self {
            RobotError::FileUri { reason, .. } | RobotError::PackageUri { reason, .. } => {
                reason.clone()
            }
            other => other.to_string(),
        }
    }
}

/// The path of a `file://` URI, given what follows `file://`: `/abs` or `localhost/abs`.
fn file_uri_path(rest: &str) -> Result<PathBuf, String> {
    let path = rest.strip_prefix("localhost").unwrap_or(rest);
    if !path.starts_with('/') {
        return Err(
            "a file:// URI must name a local absolute path: file:///path or \
             file://localhost/path"
                .to_owned(),
        );
    }
    percent_decode(path).map(PathBuf::from)
}

/// The scheme of `reference` when it starts with `scheme://` (RFC 3986: a letter, then
/// letters, digits, `+`, `-` and `.`), else `None` (a plain path).
fn uri_scheme(reference: &str) -> Option<&str> {
    let (scheme, _) = reference.split_once("://")?;
    let mut chars = scheme.chars();
    let first = chars.next()?;
    let valid = first.is_ascii_alphabetic()
        && chars.all(|c| c.is_ascii_alphanumeric() || matches!(c, '+' | '-' | '.'));
    valid.then_some(scheme)
}

/// Decodes the `%XX` escapes of a URI path.
fn percent_decode(s: &str) -> Result<String, String> {
    let bytes = s.as_bytes();
    let mut out = Vec::with_capacity(bytes.len());
    let mut i = 0;
    while let Some(&b) = bytes.get(i) {
        if b == b'%' {
            let hex = bytes
                .get(i + 1..i + 3)
                .and_then(|h| std::str::from_utf8(h).ok())
                .and_then(|h| u8::from_str_radix(h, 16).ok())
                .ok_or_else(|| format!("bad percent escape at byte {i} of the URI path"))?;
            if hex == 0 {
                return Err(format!(
                    "%00 at byte {i} of the URI path decodes to a NUL byte"
                ));
            }
            out.push(hex);
            i += 3;
        } else {
            out.push(b);
            i += 1;
        }
    }
    String::from_utf8(out).map_err(|_| "the URI path is not UTF-8 after decoding".to_owned())
}

#[cfg(test)]
mod tests {
    use super::resolve_uri;
    use crate::RobotError;
    use std::path::Path;

    /// The message of a refused reference, which must be a [`RobotError::FileUri`] naming it.
    fn refused(uri: &str) -> String {
        match resolve_uri(uri) {
            Err(e @ RobotError::FileUri { .. }) => {
                let msg = e.to_string();
                assert!(msg.contains(&format!("{uri:?}")), "{msg}");
                msg
            }
            other => panic!("{uri:?} should be refused, got {other:?}"),
        }
    }

    #[test]
    fn plain_paths_are_kept_as_given() {
        assert_eq!(resolve_uri("/abs/x.stl").unwrap(), Path::new("/abs/x.stl"));
        assert_eq!(
            resolve_uri("parts/x.obj").unwrap(),
            Path::new("parts/x.obj")
        );
        assert_eq!(resolve_uri("  ./x.ngc\n").unwrap(), Path::new("./x.ngc"));
        // "://" after something that is not a scheme is part of a path.
        assert_eq!(resolve_uri("dir/a://b").unwrap(), Path::new("dir/a://b"));
        assert_eq!(resolve_uri("1x://b").unwrap(), Path::new("1x://b"));
    }

    #[test]
    fn local_file_uris_resolve_to_their_absolute_path() {
        assert_eq!(
            resolve_uri("file:///abs/x.safetensors").unwrap(),
            Path::new("/abs/x.safetensors")
        );
        assert_eq!(
            resolve_uri("file://localhost/abs/x.obj").unwrap(),
            Path::new("/abs/x.obj")
        );
        assert_eq!(
            resolve_uri("file:///tmp/a%20b%2Fc.stl").unwrap(),
            Path::new("/tmp/a b/c.stl")
        );
    }

    #[test]
    fn package_uris_resolve_below_the_data_root() {
        let root = crate::data::root().unwrap();
        assert_eq!(
            resolve_uri("package://kerf/urdf/irb6660.urdf").unwrap(),
            root.join("urdf/irb6660.urdf")
        );
        for bad in ["package://kerf_msgs/x.stl", "package://kerf/../etc/passwd"] {
            assert!(
                matches!(resolve_uri(bad), Err(RobotError::PackageUri { .. })),
                "{bad}"
            );
        }
    }

    #[test]
    fn other_schemes_hosts_and_malformed_references_are_refused_naming_them() {
        for uri in ["http://example.com/x.stl", "s3://bucket/x", "git+ssh://h/x"] {
            assert!(refused(uri).contains("is not supported"), "{uri}");
        }
        for uri in [
            "file://otherhost/x.stl",
            "file://localhost",
            "file://",
            "file://x",
        ] {
            assert!(refused(uri).contains("local absolute path"), "{uri}");
        }
        assert!(refused("").contains("empty"));
        assert!(refused(" \t\n").contains("empty"));
        assert!(refused("/tmp/a\0b").contains("NUL"));
        assert!(refused("file:///tmp/a%00b").contains("NUL"));
        assert!(refused("file:///tmp/a%2").contains("bad percent escape"));
        assert!(refused("file:///tmp/a%zz").contains("bad percent escape"));
        assert!(refused("file:///tmp/%ff").contains("not UTF-8"));
        // The NUL byte is shown escaped, never written into the message.
        assert!(!refused("/tmp/a\0b").contains('\0'));
    }

    #[test]
    fn uri_reason_drops_the_reference_the_caller_names() {
        let e = resolve_uri("http://h/x").unwrap_err();
        assert!(e.uri_reason().starts_with("URI scheme 'http://'"), "{e}");
        let e = resolve_uri("package://other/x").unwrap_err();
        assert!(e.uri_reason().starts_with("package 'other'"), "{e}");
    }
}
