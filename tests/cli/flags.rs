//! The pendant's command line checked whole on every path: addresses with a port out of
//! range, output files in missing folders, and flags that do nothing in the mode chosen
//! end it at once with exit code 2 and one line naming the flag; the text mode says it
//! shows no RMC151.

use std::path::PathBuf;

use crate::bin_common::*;
use crate::wait::PROCESS;

/// Runs the pendant, which must end by itself with exit code 2 and one line on stderr
/// that names `flag` and says `says`; nothing may have started (no line, no window).
fn refused(args: &[&str], flag: &str, says: &str) {
    let run = run(PENDANT, args, PROCESS);
    let status = run
        .status
        .unwrap_or_else(|| panic!("{args:?}: still running"));
    assert_eq!(status.code(), Some(2), "{args:?}: {}", run.stderr);
    let err: Vec<&str> = run.stderr.lines().collect();
    assert_eq!(err.len(), 1, "{args:?}: {}", run.stderr);
    assert!(
        err[0].starts_with("xsel-pendant: ") && err[0].contains(flag) && err[0].contains(says),
        "{args:?}: {}",
        run.stderr
    );
    assert!(
        !err[0].contains("display"),
        "{args:?}: the window was tried"
    );
    assert_no_panic(&run.stderr);
    assert!(run.stdout.is_empty(), "{args:?}: {}", run.stdout);
}

#[test]
fn an_address_with_a_port_out_of_range_or_no_address_is_refused_on_every_path() {
    for mode in [&[][..], &["--headless"], &["--watch"]] {
        for (flag, value, says) in [
            ("--tcp", "127.0.0.1:99999", "port 99999 is out of range"),
            ("--tcp", "127.0.0.1:0", "port 0 is out of range"),
            ("--tcp", "nonsense", "names no port"),
            ("--tcp", "127.0.0.1:http", "not a port number"),
            ("--rmc", "127.0.0.1:99999", "port 99999 is out of range"),
            ("--rmc", "127.0.0.1:99999:502", "not an address"),
            ("--rmc", "::1", "in brackets"),
        ] {
            let mut args = mode.to_vec();
            args.extend([flag, value]);
            refused(&args, flag, says);
        }
    }
}

/// A folder under the temporary one that does not exist, unique to this test.
fn missing_folder(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("xsel-no-folder-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    dir
}

#[test]
fn an_output_file_in_a_missing_folder_is_refused_and_no_folder_is_made() {
    let root = missing_folder("png");
    let file = root.join("sub").join("view.png");
    let file = file.to_str().expect("a UTF-8 temporary folder");
    let capture = std::env::temp_dir().join("xsel-no-such-capture.csv");
    let capture = capture.to_str().expect("a UTF-8 temporary folder");
    for (args, flag) in [
        (vec!["--render-png", file], "--render-png"),
        (vec!["--plot-png", file, "--capture", capture], "--plot-png"),
    ] {
        refused(&args, flag, "does not exist");
        refused(&args, "sub", "no folder is created");
        assert!(!root.exists(), "{args:?} made {}", root.display());
    }
}

#[test]
fn a_flag_that_does_nothing_in_the_mode_chosen_is_refused_with_the_reason() {
    let dir = std::env::temp_dir();
    let png = dir.join(format!("xsel-flags-{}.png", std::process::id()));
    let png = png.to_str().expect("a UTF-8 temporary folder");
    let plot = ["--plot-png", png, "--capture", "capture.csv"];
    let render = ["--render-png", png];
    for (mode, extra, flag, says) in [
        (
            &plot[..],
            &["--arm", "left"][..],
            "--arm",
            "for --render-png only",
        ),
        (
            &plot,
            &["--joints", "1,2,3,4"],
            "--joints",
            "for --render-png only",
        ),
        (
            &plot,
            &["--pose", "1,2,3,4"],
            "--pose",
            "for --render-png only",
        ),
        (&plot, &["--tcp", "127.0.0.1:5099"], "--tcp", "X-SEL's line"),
        (&render, &["--rmc", "10.0.0.5"], "--rmc", "only the window"),
        (&render, &["--watch"], "--watch", "chooses the text mode"),
        (
            &["--headless"],
            &["--rmc", "10.0.0.5"],
            "--rmc",
            "only the window connects the RMC151",
        ),
        (
            &["--watch"],
            &["--rmc", "sim"],
            "--rmc",
            "only the window connects the RMC151",
        ),
        (
            &["--headless"],
            &["--no-rmc"],
            "--no-rmc",
            "only the window",
        ),
        (
            &["--headless"],
            &["--size", "800x600"],
            "--size",
            "for --render-png and --plot-png",
        ),
        (
            &["--headless"],
            &["--renderer", "wgpu"],
            "--renderer",
            "for the window only",
        ),
        (
            &["--headless"],
            &["--no-guardian"],
            "--no-guardian",
            "only the window",
        ),
    ] {
        let mut args = mode.to_vec();
        args.extend(extra);
        refused(&args, flag, says);
        refused(&args, flag, "does nothing");
    }
    assert!(!std::path::Path::new(png).exists(), "nothing was drawn");
}

#[test]
fn the_text_mode_says_it_shows_no_rmc151_and_names_the_installed_simulator() {
    let run = run(PENDANT, &["--headless"], PROCESS);
    assert_eq!(run.status.and_then(|s| s.code()), Some(0), "{}", run.stderr);
    let first: Vec<&str> = run.stdout.lines().take(2).collect();
    assert!(
        first
            .iter()
            .any(|l| l.contains("RMC151") && l.contains("window")),
        "said at start: {first:?}"
    );
    assert!(
        run.stdout.contains("`xsel-sim --help`"),
        "the installed name: {}",
        run.stdout
    );
    let help = crate::bin_common::run(PENDANT, &["--help"], PROCESS);
    let help = help.stdout.replace(char::is_whitespace, " ");
    for flag in ["--headless", "--watch"] {
        let at = help
            .find(&format!("      {flag}"))
            .unwrap_or_else(|| panic!("{flag} in --help"));
        let text = &help[at..(at + 300).min(help.len())];
        assert!(text.contains("RMC151"), "{flag}: {text}");
    }
}
