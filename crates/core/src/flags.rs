//! How both binaries answer their command line: a bad flag ends the program with exit code
//! 2 and one line on stderr naming it; `--help` and `--version` print in full.

/// Parses the command line; a bad flag ends the program with exit code 2 and one line
/// on stderr (`--help` and `--version` print as usual and exit 0). Shared by both
/// binaries.
pub fn parse_or_exit<P: clap::Parser>(program: &str) -> P {
    match P::try_parse() {
        Ok(args) => args,
        Err(e) => exit_on_clap_error(program, &e),
    }
}

/// Prints a clap error as one line (help and version in full), then exits.
pub fn exit_on_clap_error(program: &str, e: &clap::Error) -> ! {
    use clap::error::ErrorKind;
    use std::io::Write;
    if matches!(
        e.kind(),
        ErrorKind::DisplayHelp
            | ErrorKind::DisplayVersion
            | ErrorKind::DisplayHelpOnMissingArgumentOrSubcommand
    ) {
        // Help goes to stdout; a closed pipe there is not an error.
        let _ = e.print();
        std::process::exit(e.exit_code());
    }
    let _ = writeln!(std::io::stderr(), "{program}: {}", one_line(e));
    std::process::exit(2);
}

/// The first line of a clap error, without its "error: " prefix, plus a pointer to
/// `--help`.
pub fn one_line(e: &clap::Error) -> String {
    let text = e.render().to_string();
    let mut lines = text.lines().map(str::trim).filter(|l| !l.is_empty());
    let first = lines.next().unwrap_or("bad command line");
    let first = first.strip_prefix("error: ").unwrap_or(first);
    // A message that ends in a colon lists what it names on the lines below (the flags a
    // flag requires): they join it.
    let named: Vec<&str> = if first.ends_with(':') {
        lines.take_while(|l| l.starts_with('-')).collect()
    } else {
        Vec::new()
    };
    let first = if named.is_empty() {
        first.to_string()
    } else {
        format!("{first} {}", named.join(", "))
    };
    format!("{first} (--help lists the options)")
}
