//! The `wiperlab` command: parses arguments and reports errors; `wiperlab::cli` does the work.

use clap::Parser;

fn main() {
    let cli = wiperlab::cli::Cli::parse();
    if let Err(e) = wiperlab::cli::run(cli) {
        eprintln!("error: {e}");
        std::process::exit(e.exit_code());
    }
}
