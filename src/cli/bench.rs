//! `wiperlab bench`: the work–precision study and the spectra against tolerance.

use crate::job::{parse_toml, read_text};
use crate::model::BladeParams;
use crate::{Error, Result};
use std::path::{Path, PathBuf};

/// Runs the study, writes its CSVs and figures under `out_dir`, and prints both tables. The
/// defaults are the source tree's blades and `reports/bench`, wherever the command runs; a blade
/// inside the source tree is labelled by its path relative to it.
pub(super) fn run(
    quick: bool,
    blade: Option<Vec<PathBuf>>,
    out_dir: Option<PathBuf>,
) -> Result<()> {
    let tree = Path::new(env!("CARGO_MANIFEST_DIR"));
    let blade = blade.unwrap_or_else(|| {
        ["blade_true.toml", "blade.toml"]
            .map(|f| tree.join("data/reversal").join(f))
            .to_vec()
    });
    let out_dir = &out_dir.unwrap_or_else(|| tree.join("reports/bench"));
    let mut blades = Vec::new();
    for path in &blade {
        let params: BladeParams = parse_toml(path, &read_text(path)?)?;
        params
            .validate()
            .map_err(|m| Error::input(path, m.to_string()))?;
        let label = path
            .strip_prefix(tree)
            .unwrap_or(path)
            .display()
            .to_string();
        blades.push((label, params));
    }
    let Some((_, params)) = blades.first() else {
        return Err(super::CliError::NoBladeFile.into());
    };
    let rows = crate::bench::run_bench(&crate::bench::BenchOptions {
        quick,
        blade: *params,
    })?;
    crate::bench::write_reports(out_dir, &rows)?;
    print_work_precision(&rows);
    println!("wrote {}", out_dir.join("work_precision.csv").display());
    let rtols: Vec<f64> = if quick {
        vec![1e-6, 1e-8, 1e-10, 1e-12]
    } else {
        (4..=13).map(|e| 10f64.powi(-e)).collect()
    };
    let mut spectra = Vec::new();
    for (name, p) in &blades {
        spectra.extend(crate::bench::spectra_vs_rtol(name, p, &rtols)?);
    }
    let loosest = crate::bench::write_spectra(out_dir, &spectra, 0.002, 0.05)?;
    println!(
        "\n{:<32} {:>8} {:>9} {:>6} {:>12} {:>12}",
        "blade", "rtol", "wall_s", "trans", "low_peak_hz", "high_peak_hz"
    );
    for r in &spectra {
        println!(
            "{:<32} {:>8.0e} {:>9.3} {:>6} {:>12.3} {:>12.3}",
            r.blade, r.rtol, r.wall_s, r.transitions, r.low_peak_hz, r.high_peak_hz
        );
    }
    match loosest {
        Some(r) => println!(
            "loosest rtol with both peaks of every blade within 0.2 % of its tightest run (and the transition count within 5 %): {r:e}"
        ),
        None => println!(
            "no rtol has both peaks within 0.2 % (and the transition count within 5 %) of the tightest"
        ),
    }
    println!("wrote {}", out_dir.join("spectra_vs_rtol.csv").display());
    Ok(())
}

/// The work–precision table on stdout.
fn print_work_precision(rows: &[crate::bench::BenchRow]) {
    println!(
        "{:<13} {:<44} {:>8} {:>10} {:>10} {:>10} {:>6} {:>10} {:>10}",
        "problem", "method", "setting", "value", "wall_s", "rhs", "trans", "t_err_s", "trace_err"
    );
    for r in rows {
        println!(
            "{:<13} {:<44} {:>8} {:>10.1e} {:>10.3e} {:>10} {:>6} {:>10.2e} {:>10.2e} {}",
            r.problem,
            r.method,
            r.setting_name,
            r.setting,
            r.wall_s,
            r.rhs_evals,
            r.transitions,
            r.transition_err_s,
            r.trace_err_m,
            r.note
        );
    }
}
