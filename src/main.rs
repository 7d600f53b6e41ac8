//! The `wiperlab` command: parses arguments and reports errors; `wiperlab::cli` does the work.

use clap::Parser;

fn main() {
    restore_sigpipe();
    let cli = wiperlab::cli::Cli::parse();
    if let Err(e) = wiperlab::cli::run(cli) {
        eprintln!("error: {e}");
        std::process::exit(e.exit_code());
    }
}

/// Rust ignores SIGPIPE, so a closed pipe (`wiperlab modes ... | head`) makes `println!` panic.
/// A command-line tool should end quietly instead, as `cat` does: the default action is restored.
#[cfg(unix)]
fn restore_sigpipe() {
    // SAFETY: called once at start, before any thread exists; SIG_DFL is a valid disposition.
    unsafe {
        libc::signal(libc::SIGPIPE, libc::SIG_DFL);
    }
}

#[cfg(not(unix))]
fn restore_sigpipe() {}
