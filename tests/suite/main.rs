//! The integration tests, one module per file, built as one test binary (`cargo test --release
//! --test suite`; one file's tests: `cargo test --release --test suite <file>::`). One binary links
//! once and runs every file's tests on all cores; `tests/alloc_free.rs` stays a binary of its own
//! for its counting global allocator.

#[path = "../common/mod.rs"]
mod common;

mod architecture;
mod bad_input;
mod bench;
mod campaign;
mod cli;
mod comparison_methods;
mod docs;
mod dop853_work;
mod event_location;
mod explore;
mod fit_recovery;
mod fit_result;
mod geometry_fit;
mod goodness_of_fit;
mod hard_cases;
mod import;
mod import_cli;
mod import_fuzz;
mod import_realdata;
mod import_roundtrip;
mod init;
mod instfreq;
mod interval_coverage;
mod joint_fit;
mod joint_signals;
mod likelihood;
mod model;
mod model_choice;
mod modes;
mod necklip;
mod necklip_fit;
mod out_dir;
mod priors;
mod python;
mod report_browser;
mod results_doc;
mod shoulder;
mod shoulder_fit;
mod signals;
mod sim_trace;
mod spectrum;
mod spectrum_realdata;
mod stick_slip_benchmarks;
