//! What can go wrong in the job stage: [`JobError`], a candidate without its settings or a new job
//! that cannot be written from its template (every variant is an input error, exit code 2).
//! Reading a job reports through [`crate::Error::Parse`] and [`crate::Error::Input`], with the
//! file, line and column.

/// A job that cannot be written from its template (`wiperlab init`), or whose candidate lacks
/// its settings.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum JobError {
    /// The shoulder candidate without its bounds.
    #[error("the shoulder candidate needs [fit.shoulder] bounds")]
    ShoulderBounds,
    /// `init`: a value that cannot be written as TOML.
    #[error("init: cannot write a TOML value: {0}")]
    TomlValue(#[source] toml::ser::Error),
    /// `init`: a recording path that is not UTF-8 (a job file is UTF-8).
    #[error("init: the recording's path is not UTF-8")]
    PathNotUtf8 { path: std::path::PathBuf },
    /// `init`: the job template does not render.
    #[error("init: the job template does not render: {0}")]
    Template(#[source] minijinja::Error),
}

impl From<JobError> for crate::Error {
    fn from(e: JobError) -> Self {
        crate::Error::stage(e, true)
    }
}

impl JobError {
    /// The job stage's error inside `e`, if it is one.
    pub fn of(e: &crate::Error) -> Option<&JobError> {
        e.stage_error()
    }
}
