//! Collecting a campaign: one row per recording with its conditions, fitted values and intervals,
//! peaks, chosen model, cost, failures and wall time, written as `campaign.csv`.

use super::run::{EntryPaths, State, read_status, write_atomic};
use super::{Campaign, Override};
use crate::fit::result::FitResult;
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
/// [`Error::Numerics`] if the CSV writer fails (it writes to memory).
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
    let err = |e: csv::Error| Error::Numerics(format!("writing campaign.csv: {e}"));
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
        .map_err(|e| Error::Numerics(format!("writing campaign.csv: {e}")))?;
    String::from_utf8(bytes).map_err(|e| Error::Numerics(e.to_string()))
}

/// Gathers the campaign and writes `<out dir>/campaign.csv`; returns the table and the path.
///
/// # Errors
/// Those of [`gather`] and [`to_csv`]; [`Error::Io`] when the file cannot be written.
pub fn collect(campaign: &Campaign) -> Result<(Table, PathBuf)> {
    let table = gather(campaign)?;
    let path = campaign.out_dir().join("campaign.csv");
    write_atomic(&path, to_csv(&table)?.as_bytes())?;
    Ok((table, path))
}
