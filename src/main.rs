//! The pendant binary: the window (`ui::run_window`), or text mode with `--headless` /
//! `--watch` (`headless::run`), or the arm view or a saved capture to a PNG with
//! `--render-png` / `--plot-png` (`render_cli::run`), or the first-contact report with
//! `--first-contact` (`first_contact::command_line::run`), or a controller snapshot with
//! `--snapshot` (`driven::snapshot`). Flags, their checks and line set-up
//! live in `cli`, shared by all.

use std::io::Write;
use std::process::ExitCode;

use xsel_pendant::session::{self, LineOwner};
use xsel_pendant::ui::{BenchHooks, StartOptions, run_window};
use xsel_pendant::{cli, headless, render_cli};

fn main() -> ExitCode {
    // A guardian is started by the window itself; it reads its line from stdin.
    if std::env::args_os()
        .nth(1)
        .is_some_and(|a| a == session::guardian::GUARDIAN_FLAG)
    {
        return session::guardian::run();
    }
    // Every flag checked whole before any mode starts (values, addresses, output
    // folders, flags that do nothing in the mode chosen): exit code 2 and one line.
    let args = cli::parse_or_exit();
    if args.snapshot.is_some() {
        return xsel_pendant::driven::snapshot(&args);
    }
    if args.first_contact.is_some() {
        return xsel_pendant::first_contact::command_line::run(&args);
    }
    if args.render_png.is_some() || args.plot_png.is_some() {
        return render_cli::run(&args);
    }
    if args.is_headless() {
        return headless::run(&args);
    }
    // Flags name a connection that replaces the saved one; with none the window opens on
    // the built-in simulator and keeps the saved line settings for the panel.
    let named = cli::names_a_connection(std::env::args_os());
    if let Err(e) = args.line_settings().and_then(|_| args.model()) {
        let _ = writeln!(std::io::stderr(), "xsel-pendant: {e}");
        return ExitCode::from(2);
    }
    let options = StartOptions {
        connection: named.then(|| args.connection_settings()),
        rmc: match (&args.rmc, args.no_rmc) {
            (_, true) => Some(None),
            (Some(address), false) => Some(Some(address.clone())),
            (None, false) => None,
        },
        fresh: false,
        offline: false,
        data_dir: None,
        line_owner: if args.no_guardian {
            LineOwner::InProcess
        } else {
            LineOwner::guardian()
        },
        // The benches' opt-in hooks (benches/window_startup.sh sets them).
        bench: BenchHooks::from_env(),
    };
    match run_window(options, args.renderer) {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            let _ = writeln!(std::io::stderr(), "xsel-pendant: {e}");
            ExitCode::from(2)
        }
    }
}
