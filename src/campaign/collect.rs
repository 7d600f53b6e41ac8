//! Collecting a campaign: one row per recording with its conditions, fitted values and intervals,
//! peaks, chosen model, cost, failures and wall time, written as `campaign.csv`.

use super::run::{EntryPaths, State, read_status};
use super::{Campaign, Override};
use crate::fit::result::FitResult;
use crate::io::write_atomic;
use crate::model::{BladeParams, FrictionLaw, ParamId};
use crate::{Error, Result};
use std::path::PathBuf;

/// One fitted parameter of one recording.
#[derive(Debug, Clone, PartialEq)]
pub struct ParamValue {
    pub value: f64,
    /// Interval ends (NaN without an interval).
    pub lo: f64,
    pub hi: f64,
    /// ±1σ from the curvature (NaN when not available).
    pub std_error: f64,
}

/// One recording's row.
#[derive(Debug, Clone, PartialEq)]
pub struct Row {
    pub id: String,
    pub recording: PathBuf,
    /// Condition labels, in the campaign's label-column order.
    pub labels: Vec<String>,
    /// Per-recording settings (NaN: the template's).
    pub overrides: Vec<f64>,
    /// `done`, `failed` or `missing` (never run or still running).
    pub state: String,
    pub reason: String,
    pub model: String,
    pub cost: f64,
    /// Fitted values by parameter name.
    pub params: Vec<(String, ParamValue)>,
    /// Measured and model peak (Hz) by band name.
    pub peaks: Vec<(String, f64, f64)>,
    pub model_evaluations: usize,
    pub failed_evaluations: usize,
    pub wall_time_s: f64,
    /// The fitted friction law: the recording's blade file with the fitted friction coefficients in place
    /// (`None` until the recording is done).
    pub friction: Option<FrictionLaw>,
}

/// The collected campaign.
#[derive(Debug, Clone, PartialEq)]
pub struct Table {
    pub label_columns: Vec<String>,
    /// Parameter names in first-seen order.
    pub param_names: Vec<String>,
    /// Band names in first-seen order.
    pub band_names: Vec<String>,
    pub rows: Vec<Row>,
}

/// Reads every recording's status and result.
///
/// # Errors
/// [`Error::Io`]/[`Error::Parse`] for a result file that exists but cannot be read.
pub fn gather(campaign: &Campaign) -> Result<Table> {
    let out = campaign.out_dir();
    let mut table = Table {
        label_columns: campaign.label_columns.clone(),
        param_names: Vec::new(),
        band_names: Vec::new(),
        rows: Vec::new(),
    };
    for e in &campaign.entries {
        let paths = EntryPaths::new(&out, e);
        let status = read_status(&paths);
        let mut row = Row {
            id: e.id.clone(),
            recording: e.recording.clone(),
            labels: campaign
                .label_columns
                .iter()
                .map(|c| {
                    e.labels
                        .iter()
                        .find(|(k, _)| k == c)
                        .map(|(_, v)| v.clone())
                        .unwrap_or_default()
                })
                .collect(),
            overrides: Override::ALL
                .iter()
                .map(|o| e.overrides.get(o).copied().unwrap_or(f64::NAN))
                .collect(),
            state: "missing".into(),
            reason: String::new(),
            model: String::new(),
            cost: f64::NAN,
            params: Vec::new(),
            peaks: Vec::new(),
            model_evaluations: 0,
            failed_evaluations: 0,
            wall_time_s: f64::NAN,
            friction: None,
        };
        if let Some(s) = status {
            row.wall_time_s = s.wall_time_s;
            row.reason = s.reason.unwrap_or_default();
            row.state = match s.state {
                State::Done => "done".into(),
                State::Failed => "failed".into(),
            };
            if s.state == State::Done {
                fill_from_result(&mut row, &FitResult::read(&paths.result)?, &mut table);
                row.friction = fitted_law(&paths.blade, &row.params)?;
            }
        }
        table.rows.push(row);
    }
    Ok(table)
}

fn fill_from_result(row: &mut Row, r: &FitResult, table: &mut Table) {
    row.model = r.model.to_string();
    row.cost = r.cost;
    row.model_evaluations = r.model_evaluations;
    row.failed_evaluations = r.failed_evaluations;
    for p in &r.parameters {
        let name = p.name.to_string();
        if !table.param_names.contains(&name) {
            table.param_names.push(name.clone());
        }
        let (lo, hi) = p
            .interval
            .as_ref()
            .map_or((f64::NAN, f64::NAN), |i| (i.lo, i.hi));
        row.params.push((
            name,
            ParamValue {
                value: p.value,
                lo,
                hi,
                std_error: p.std_error,
            },
        ));
    }
    for pk in &r.peaks {
        let band = pk.band.to_string();
        if !table.band_names.contains(&band) {
            table.band_names.push(band.clone());
        }
        row.peaks.push((band, pk.measured_hz, pk.model_hz));
    }
}

/// The blade file's friction law with the fitted coefficients (A, B, C, D, v_s, δ, as many as the
/// law has and the fit freed) in place of its own values.
fn fitted_law(
    blade: &std::path::Path,
    params: &[(String, ParamValue)],
) -> Result<Option<FrictionLaw>> {
    let text = std::fs::read_to_string(blade).map_err(|e| Error::io(blade, "cannot read", e))?;
    let mut p: BladeParams =
        toml::from_str(&text).map_err(|e| Error::input(blade, format!("blade file: {e}")))?;
    for (name, v) in params {
        if let Some(id) = ParamId::from_name(name).filter(|id| id.is_friction()) {
            id.set(&mut p, v.value);
        }
    }
    Ok(Some(p.friction))
}

fn num(x: f64) -> String {
    if x.is_finite() {
        format!("{x:e}")
    } else {
        String::new()
    }
}

/// The table as CSV: `id, recording, <labels>, <overrides>, state, reason, model, cost,` then per
/// parameter `<p>, <p>_lo, <p>_hi, <p>_std`, per band `peak_<band>_measured_hz,
/// peak_<band>_model_hz`, then `model_evaluations, failed_evaluations, wall_time_s`. Missing values
/// are empty cells; parameters in SI units as in the result files.
///
/// # Errors
/// [`Error::Write`] if the CSV writer fails (it writes to memory).
pub fn to_csv(t: &Table) -> Result<String> {
    let mut w = csv::Writer::from_writer(Vec::new());
    let mut header: Vec<String> = vec!["id".into(), "recording".into()];
    header.extend(t.label_columns.iter().cloned());
    header.extend(Override::ALL.iter().map(|o| o.column().to_string()));
    header.extend(["state", "reason", "model", "cost"].map(String::from));
    for p in &t.param_names {
        header.extend([
            p.clone(),
            format!("{p}_lo"),
            format!("{p}_hi"),
            format!("{p}_std"),
        ]);
    }
    for b in &t.band_names {
        header.push(format!("peak_{b}_measured_hz"));
        header.push(format!("peak_{b}_model_hz"));
    }
    header.extend(["model_evaluations", "failed_evaluations", "wall_time_s"].map(String::from));
    let err = |e: csv::Error| Error::write("campaign.csv", "CSV", e);
    w.write_record(&header).map_err(err)?;
    for r in &t.rows {
        let mut rec: Vec<String> = vec![r.id.clone(), r.recording.display().to_string()];
        rec.extend(r.labels.iter().cloned());
        rec.extend(r.overrides.iter().map(|x| num(*x)));
        rec.extend([
            r.state.clone(),
            r.reason.clone(),
            r.model.clone(),
            num(r.cost),
        ]);
        for p in &t.param_names {
            match r.params.iter().find(|(n, _)| n == p) {
                Some((_, v)) => rec.extend([v.value, v.lo, v.hi, v.std_error].map(num)),
                None => rec.extend(std::iter::repeat_n(String::new(), 4)),
            }
        }
        for b in &t.band_names {
            match r.peaks.iter().find(|(n, _, _)| n == b) {
                Some((_, m, f)) => rec.extend([num(*m), num(*f)]),
                None => rec.extend([String::new(), String::new()]),
            }
        }
        rec.push(r.model_evaluations.to_string());
        rec.push(r.failed_evaluations.to_string());
        rec.push(num(r.wall_time_s));
        w.write_record(&rec).map_err(err)?;
    }
    let bytes = w
        .into_inner()
        .map_err(|e| Error::write("campaign.csv", "CSV", e.into_error()))?;
    String::from_utf8(bytes).map_err(|e| Error::write("campaign.csv", "CSV", e))
}

/// Gathers the campaign and writes `<out dir>/campaign.csv`; returns the table and the path.
///
/// # Errors
/// Those of [`gather`] and [`to_csv`]; [`Error::Io`] when the file cannot be written.
pub fn collect(campaign: &Campaign) -> Result<(Table, PathBuf)> {
    let table = gather(campaign)?;
    crate::io::create_dir(&campaign.out_dir())?;
    let path = campaign.out_dir().join("campaign.csv");
    write_atomic(&path, to_csv(&table)?.as_bytes())?;
    Ok((table, path))
}

/// A fitted value far from the campaign's others: robust z-score `|x − median| / (1.4826·MAD)`
/// above [`OUTLIER_Z`] (Iglewicz & Hoaglin 1993, *How to Detect and Handle Outliers*, §3.3, with
/// the MAD scaled to σ for normal data).
#[derive(Debug, Clone, PartialEq)]
pub struct Outlier {
    pub id: String,
    pub param: String,
    pub value: f64,
    pub robust_z: f64,
}

/// Robust z-score above which a fitted value is listed as an outlier.
pub const OUTLIER_Z: f64 = 3.5;

/// The outliers of each parameter among the done recordings (at least 4 values needed).
pub fn outliers(t: &Table) -> Vec<Outlier> {
    let mut out = Vec::new();
    for p in &t.param_names {
        let vals: Vec<(&str, f64)> = t
            .rows
            .iter()
            .filter_map(|r| {
                r.params
                    .iter()
                    .find(|(n, _)| n == p)
                    .map(|(_, v)| (r.id.as_str(), v.value))
            })
            .filter(|(_, v)| v.is_finite())
            .collect();
        if vals.len() < 4 {
            continue;
        }
        let med = median(vals.iter().map(|(_, v)| *v).collect());
        let mad = median(vals.iter().map(|(_, v)| (v - med).abs()).collect());
        if mad <= 0.0 {
            continue;
        }
        for (id, v) in vals {
            let z = (v - med).abs() / (1.4826 * mad);
            if z > OUTLIER_Z {
                out.push(Outlier {
                    id: id.to_string(),
                    param: p.clone(),
                    value: v,
                    robust_z: z,
                });
            }
        }
    }
    out
}

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    let n = v.len();
    if n % 2 == 1 {
        v[n / 2]
    } else {
        0.5 * (v[n / 2 - 1] + v[n / 2])
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn row(id: &str, c: f64) -> Row {
        Row {
            id: id.into(),
            recording: PathBuf::from(id),
            labels: Vec::new(),
            overrides: Vec::new(),
            state: "done".into(),
            reason: String::new(),
            model: "blade2dof".into(),
            cost: 0.1,
            params: vec![(
                "C".into(),
                ParamValue {
                    value: c,
                    lo: f64::NAN,
                    hi: f64::NAN,
                    std_error: f64::NAN,
                },
            )],
            peaks: Vec::new(),
            model_evaluations: 1,
            failed_evaluations: 0,
            wall_time_s: 1.0,
            friction: None,
        }
    }

    /// Five values near 0.56 and one at 0.9: only the last is listed (its robust z is about 200).
    #[test]
    fn one_far_value_is_an_outlier() {
        let t = Table {
            label_columns: Vec::new(),
            param_names: vec!["C".into()],
            band_names: Vec::new(),
            rows: [0.558, 0.56, 0.561, 0.559, 0.562, 0.9]
                .iter()
                .enumerate()
                .map(|(i, c)| row(&format!("r{i}"), *c))
                .collect(),
        };
        let o = outliers(&t);
        assert_eq!(o.len(), 1, "{o:?}");
        assert_eq!(o[0].id, "r5");
        assert!(o[0].robust_z > 100.0);
    }

    /// The CSV has one row per recording and a column per parameter value and interval end.
    #[test]
    fn csv_columns() {
        let t = Table {
            label_columns: vec!["compound".into()],
            param_names: vec!["C".into()],
            band_names: Vec::new(),
            rows: vec![Row {
                labels: vec!["soft".into()],
                overrides: vec![f64::NAN; 5],
                ..row("a", 0.5)
            }],
        };
        let text = to_csv(&t).unwrap();
        let mut lines = text.lines();
        let header = lines.next().unwrap();
        assert!(
            header.starts_with("id,recording,compound,t0_s,"),
            "{header}"
        );
        assert!(header.contains(",C,C_lo,C_hi,C_std,"), "{header}");
        assert!(
            lines
                .next()
                .unwrap()
                .starts_with("a,a,soft,,,,,,done,,blade2dof,1e-1,5e-1,")
        );
    }
}
