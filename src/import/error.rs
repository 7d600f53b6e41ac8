//! What can go wrong in the import settings: [`ImportError`], each variant with the field as the
//! user typed it (a job key under `[recording.import]` or the matching flag) and its value.
//!
//! Every variant is an input error (exit code 2). Errors about a file's content are
//! [`crate::Error::Parse`] / [`crate::Error::Input`], which name the file and line.

use super::Format;

/// An import setting out of range, or one that contradicts another or the file's format.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum ImportError {
    /// A scale, rate or factor that must be finite and positive.
    #[error("import: {field} must be finite and > 0, got {value}")]
    NotPositive { field: &'static str, value: f64 },
    /// A value that must be finite.
    #[error("import: {field} must be finite, got {value}")]
    NotFinite { field: &'static str, value: f64 },
    /// `origin_px` with a non-finite coordinate.
    #[error("import: origin_px must be finite, got {origin_px:?}")]
    OriginNotFinite { origin_px: [f64; 2] },
    /// Two settings that say the same thing in different ways: set one.
    #[error("import: set {first} or {second}, not both")]
    Exclusive {
        first: &'static str,
        second: &'static str,
    },
    /// `scale_points_px` without `scale_distance_m` or the other way round.
    #[error(
        "import: scale_points_px and scale_distance_m go together (two image points a known distance apart)"
    )]
    ScaleIncomplete,
    /// The two scale points coincide or are not finite.
    #[error(
        "import: scale_points_px must be two distinct finite points, got [[{}, {}], [{}, {}]]",
        points_px[0][0], points_px[0][1], points_px[1][0], points_px[1][1]
    )]
    ScalePoints { points_px: [[f64; 2]; 2] },
    /// A likelihood cut-off outside [0, 1].
    #[error("import: min_likelihood must be in [0, 1], got {value}")]
    MinLikelihood { value: f64 },
    /// `n_cameras` of 0, or fewer cameras than the camera asked for.
    #[error(
        "import: n_cameras must be ≥ 1 and ≥ camera, got n_cameras = {n_cameras} with camera = {camera}"
    )]
    Cameras { n_cameras: usize, camera: usize },
    /// DLTdv camera 0 (cameras count from 1).
    #[error("import: camera is 1-based (cam1, cam2, ...), got 0")]
    CameraZero,
    /// A role or point name that is empty.
    #[error("import: points: role and point name must not be empty (got {role:?} = {point:?})")]
    EmptyRole { role: String, point: String },
    /// Two roles mapped to the same point.
    #[error("import: points: roles {first:?} and {second:?} both map to point {point:?}")]
    SharedPoint {
        first: String,
        second: String,
        point: String,
    },
    /// A setting that does not apply to the file's format; `hint` says what to do instead.
    #[error("import: {field} does not apply to {format} files; {hint}")]
    NotForFormat {
        field: &'static str,
        format: Format,
        hint: &'static str,
    },
    /// Generic format without a `[generic]` mapping.
    #[error(
        "import: format \"generic\" needs a [generic] column mapping (time or frame column, and [generic.points] name = [x column, y column])"
    )]
    GenericUnmapped,
    /// `[generic.points]` empty.
    #[error("import: [generic.points] is empty: map at least one point to [x column, y column]")]
    GenericNoPoints,
    /// A `[generic.points]` entry that is not one or two column names.
    #[error(
        "import: [generic.points] {point} = {columns:?}: expected [x column, y column] or [column]"
    )]
    GenericColumns { point: String, columns: Vec<String> },
    /// The sparse DLTdv writer got tracks of different lengths (`lengths`: x and y per track).
    #[error("DLTdv sparse writer: tracks differ in length ({lengths:?} samples)")]
    TrackLengths { lengths: Vec<(usize, usize)> },
}

impl From<ImportError> for crate::Error {
    fn from(e: ImportError) -> Self {
        crate::Error::stage(e, true)
    }
}

impl ImportError {
    /// The import stage's error inside `e`, if it is one.
    pub fn of(e: &crate::Error) -> Option<&ImportError> {
        e.stage_error()
    }
}
