//! The `rt` command: see `rt --help`, or the crate docs of `rt_cli`.
#![allow(clippy::std_instead_of_core, clippy::std_instead_of_alloc, clippy::alloc_instead_of_core)]

use std::process::ExitCode;

use clap::Parser;

fn main() -> ExitCode {
    // A bug must not print a backtrace at a user: one line, then exit 101.
    std::panic::set_hook(Box::new(|info| {
        let what = info
            .payload()
            .downcast_ref::<&str>()
            .map(ToString::to_string)
            .or_else(|| info.payload().downcast_ref::<String>().cloned())
            .unwrap_or_default();
        let line = what.lines().next().unwrap_or_default();
        let at = info.location().map(|l| format!(" at {}:{}", l.file(), l.line()));
        eprintln!("rt: error: internal error{}: {line} (please report it)", at.unwrap_or_default());
    }));
    // SAFETY: the first thing the program does: no other thread runs yet.
    unsafe { rt_gpu::quiet_without_session() };
    let cli = rt_cli::Cli::parse();
    match rt_cli::run(cli) {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("rt: error: {}", rt_cli::one_line(&e));
            ExitCode::FAILURE
        }
    }
}
