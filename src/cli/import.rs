//! `wiperlab import`: a tracking-tool export to the canonical trace CSV; and the import options
//! that `spectrum` shares.

use super::CliError;
use super::ImportArgs;
use crate::Result;
use crate::import::{Format, ImportSpec};
use crate::job::{parse_toml, read_text};
use crate::trace::Role;
use std::path::{Path, PathBuf};

/// Converts `file` (or only describes it) and writes `output` (default `<stem>.trace.csv` in
/// `out_dir`, itself by default the input's directory).
pub(super) fn run(
    file: &Path,
    import: &ImportArgs,
    describe: bool,
    output: Option<PathBuf>,
    out_dir: Option<PathBuf>,
) -> Result<()> {
    let output = output.or_else(|| {
        let name = format!("{}.trace.csv", super::stem(file));
        out_dir
            .as_deref()
            .map(|d| super::single_output(file, Some(d), &name))
    });
    if let Some(out) = output.as_deref().filter(|o| *o != Path::new("-")) {
        crate::io::refuse_overwriting_input(file, out)?;
    }
    let spec = import_spec(import)?;
    if describe {
        // Described without a calibration if need be: frames and pixels are said as such.
        let (_, summary) = crate::import::describe_file(file, &spec)?;
        println!("{summary}");
        return Ok(());
    }
    let (trace, summary) = crate::import::read_trace_with_summary(file, &spec)?;
    let out = output.unwrap_or_else(|| file.with_extension("trace.csv"));
    // `--out-dir` is created if need be; an `-o` into a missing directory is refused.
    if let Some(d) = &out_dir {
        crate::io::create_dir(d)?;
    }
    if out == Path::new("-") {
        // `-o -`: the CSV on stdout, the summary on stderr.
        let mut stdout = std::io::BufWriter::new(std::io::stdout().lock());
        crate::import::canonical::write_trace_csv_to(
            &mut stdout,
            Path::new("<stdout>"),
            &trace,
            &[],
        )?;
        super::esay!("{summary}");
        return Ok(());
    }
    crate::import::canonical::write_trace_csv(&out, &trace)?;
    super::esay!("{summary}");
    println!("wrote {}", out.display());
    Ok(())
}

pub(super) fn import_spec(a: &ImportArgs) -> Result<ImportSpec> {
    let mut spec = match &a.spec {
        Some(p) => parse_toml::<ImportSpec>(p, &read_text(p)?)?,
        None => ImportSpec::default(),
    };
    if let Some(f) = &a.format {
        spec.format = Format::from_name(f);
    }
    if let Some(p) = &a.scale_points_px {
        let &[x1, y1, x2, y2] = p.as_slice() else {
            return Err(CliError::ValueCount {
                flag: "--scale-points-px",
                expected: "X1,Y1,X2,Y2 in pixels",
                got: p.len(),
            }
            .into());
        };
        spec.scale_points_px = Some([[x1, y1], [x2, y2]]);
    }
    if a.scale_distance_m.is_some() {
        spec.scale_distance_m = a.scale_distance_m;
    }
    if a.units_to_m.is_some() {
        spec.units_to_m = a.units_to_m;
    }
    if a.y_down.is_some() {
        spec.y_down = a.y_down;
    }
    if a.sweep_angle_deg.is_some() {
        spec.sweep_angle_deg = a.sweep_angle_deg;
    }
    if a.sweep_from_head {
        spec.sweep_from_head = true;
    }
    if a.time_to_s.is_some() {
        spec.time_to_s = a.time_to_s;
    }
    if a.min_likelihood.is_some() {
        spec.min_likelihood = a.min_likelihood;
    }
    if let Some(c) = a.camera {
        spec.camera = c;
    }
    if let Some(n) = a.n_cameras {
        spec.n_cameras = n;
    }
    if a.fps.is_some() {
        spec.fps_hz = a.fps;
    }
    if a.m_per_px.is_some() {
        spec.m_per_px = a.m_per_px;
    }
    if let Some(o) = &a.origin_px {
        let &[x, y] = o.as_slice() else {
            return Err(CliError::ValueCount {
                flag: "--origin-px",
                expected: "X,Y in pixels, e.g. 200,300",
                got: o.len(),
            }
            .into());
        };
        spec.origin_px = [x, y];
    }
    if let Some(h) = &a.head {
        spec.points.insert(Role::Head.name().into(), h.clone());
    }
    if let Some(t) = &a.tip {
        spec.points.insert(Role::Tip.name().into(), t.clone());
    }
    Ok(spec)
}

pub(super) fn read_any(file: &Path, a: &ImportArgs) -> Result<crate::trace::Trace> {
    crate::import::read_trace(file, &import_spec(a)?)
}
