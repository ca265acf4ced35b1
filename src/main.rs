//! The pendant binary. Until the desktop window lands it runs headless (`headless::run`):
//! flags and line set-up live in `cli`, so the window can share them.

use std::process::ExitCode;

use xsel_pendant::{cli, headless};

fn main() -> ExitCode {
    let args: cli::Args = cli::parse_or_exit("xsel-pendant");
    headless::run(&args)
}
