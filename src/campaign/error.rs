//! What can go wrong setting up a campaign run: [`CampaignError`], naming the command and flag.

/// Campaign settings that cannot be run. Always an input error (exit code 2).
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum CampaignError {
    /// A campaign without recordings.
    #[error("campaign slurm: the campaign has no recordings")]
    NoRecordings,
    /// A count flag (`flags`, as typed) of `command` that is 0.
    #[error("{command}: {flags} must be at least 1")]
    AtLeastOne {
        command: &'static str,
        flags: &'static str,
    },
    /// A Slurm setting that would break the batch script's `#SBATCH` line.
    #[error("campaign slurm: {flag} {value:?} must be one word without quotes")]
    NotOneWord { flag: &'static str, value: String },
}

impl From<CampaignError> for crate::Error {
    fn from(e: CampaignError) -> Self {
        crate::Error::stage(e, true)
    }
}

impl CampaignError {
    /// The campaign stage's error inside `e`, if it is one.
    pub fn of(e: &crate::Error) -> Option<&CampaignError> {
        e.stage_error()
    }
}
