//! `wiperlab modes`: the linearised blade's modes in stick and in steady slip.

use super::CliError;
use crate::job::{parse_toml, read_text};
use crate::model::modes::{BladeMode, ModesError, OperatingPoint};
use crate::model::{Blade, BladeParams, StickForm};
use crate::{Error, Result};
use std::path::Path;

/// Prints (or writes as JSON on stdout) the modes of the blade in `blade` at `speeds` (m/s;
/// default: the window's speeds).
pub(super) fn run(blade: &Path, speeds: Option<&[f64]>, json: bool) -> Result<()> {
    let params: BladeParams = parse_toml(blade, &read_text(blade)?)?;
    params
        .validate()
        .map_err(|m| Error::input(blade, m.to_string()))?;
    let model = Blade::new(params, StickForm::Reduced);
    let modes = match speeds {
        Some(v) => model.modes(v),
        None => model.window_modes(),
    }
    .map_err(|e| match e {
        ModesError::SpeedOutOfReach { .. } => CliError::Speeds(e),
        source => CliError::Modes {
            path: blade.to_path_buf(),
            source,
        },
    })?;
    if json {
        let text =
            serde_json::to_string_pretty(&modes).map_err(|e| Error::write("stdout", "JSON", e))?;
        println!("{text}");
        return Ok(());
    }
    print_table(blade, &modes);
    Ok(())
}

/// One row per mode: phase, frequency, damping ratio, participation.
fn print_table(blade: &Path, modes: &[BladeMode]) {
    println!(
        "{}: modes of the linearised 2-DOF blade (damping ratio < 0: self-excited in slip)",
        blade.display()
    );
    println!(
        "{:<22} {:>12} {:>10} {:>6} {:>10} {:>9}",
        "phase", "freq_hz", "damping", "head", "head-link", "neck-lip"
    );
    for m in modes {
        let phase = match m.phase {
            OperatingPoint::Stick => "stick".to_string(),
            OperatingPoint::Slip { speed_m_per_s } => format!("slip at {speed_m_per_s:.4} m/s"),
        };
        println!(
            "{phase:<22} {:>12.4} {:>10.4} {:>6.2} {:>10.2} {:>9.2}",
            m.freq_hz,
            m.damping_ratio,
            m.participation.head,
            m.participation.head_link,
            m.participation.neck_lip
        );
    }
}
