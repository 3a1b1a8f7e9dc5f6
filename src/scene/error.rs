//! What a reader says of a file it cannot read: the file, the line and what
//! was expected.

use std::fmt;
use std::path::{Path, PathBuf};

use crate::geometry::GeometryError;

/// A scene file that cannot be read: where and what was expected.
#[derive(Debug, Clone, PartialEq)]
pub struct SceneError {
    /// The file.
    pub path: PathBuf,
    /// 1-based line number, when the problem has one.
    pub line: Option<usize>,
    /// What was wrong or expected.
    pub message: String,
}

impl SceneError {
    /// An error at `line` of `path`.
    pub fn at(path: &Path, line: usize, message: impl Into<String>) -> Self {
        Self {
            path: path.to_path_buf(),
            line: Some(line),
            message: message.into(),
        }
    }

    /// An error about the whole file (cannot open it, unknown format…).
    pub fn file(path: &Path, message: impl Into<String>) -> Self {
        Self {
            path: path.to_path_buf(),
            line: None,
            message: message.into(),
        }
    }
}

impl fmt::Display for SceneError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self.line {
            Some(line) => write!(f, "{}:{}: {}", self.path.display(), line, self.message),
            None => write!(f, "{}: {}", self.path.display(), self.message),
        }
    }
}

impl std::error::Error for SceneError {}

/// A geometry error of an object read from a file, worded "expected …, found …".
pub fn geometry_message(e: &GeometryError) -> String {
    match e {
        GeometryError::CollinearVertices => "expected a polygon whose first three vertices span a plane \
                                             (they fix its normal), found them collinear"
            .into(),
        GeometryError::TooFewVertices(n) => format!("expected a polygon of at least 3 vertices, found {n}"),
        GeometryError::NegativeRadius(r) => format!("expected a radius ≥ 0, found {r}"),
        GeometryError::DegenerateCone => {
            "expected a cone with distinct base and apex centres and a radius > 0, \
                                          found a degenerate one"
                .into()
        }
        GeometryError::DegeneratePlane => {
            "expected a plane with a non-zero normal, found a zero normal (or parallel spanning vectors)"
                .into()
        }
        GeometryError::NotFinite => "expected finite coordinates, found NaN or infinity".into(),
        GeometryError::NotAffine => "expected an affine transform (bottom row 0 0 0 1), found another".into(),
        GeometryError::SingularTransform => "expected an invertible transform, found a singular one".into(),
    }
}
