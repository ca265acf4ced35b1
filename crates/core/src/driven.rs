//! The pendant model on a line with no window: one session, its events in, the model's
//! requests out, until what was asked is done (`xsel-pendant --snapshot`). The window's
//! lines hand their requests to the session through [`forward`] too.

use std::io::Write as _;
use std::path::Path;
use std::process::ExitCode;
use std::sync::Arc;
use std::time::{Duration, Instant};

use crate::cli::Args;
use crate::pendant::snapshot::{Part, SnapshotIntent};
use crate::pendant::{Intent, Pendant, Request, Settings};
use crate::protocol::CoordKind;
use crate::session::{LineOwner, Session};

/// Hands `request` to the session's link. What only a window carries out (lines opened
/// or closed, the RMC151, the built-in simulator's panel, STOP of every line) comes
/// back to the caller.
pub fn forward(
    session: &Session,
    request: Request,
    table_records: impl FnOnce(CoordKind) -> std::ops::Range<u16>,
) -> Option<Request> {
    match request {
        Request::Submit(command) => session.submit(command),
        Request::Background(command) => session.submit_background(command),
        Request::Spare(command) => session.submit_spare(command),
        Request::RenewJogLease => session.renew_jog_lease(),
        Request::ReadTable(kind) => session.read_table(kind, table_records(kind)),
        Request::ReadRecords(kind, range) => session.read_table(kind, range),
        Request::CancelTableRead => session.cancel_table_read(),
        other => return Some(other),
    }
    None
}

/// How long the line may take to answer its first status poll.
const FIRST_ANSWER: Duration = Duration::from_secs(10);
/// The longest a snapshot may take (20000 positions at 9600 baud take about 10 minutes).
const SNAPSHOT_LIMIT: Duration = Duration::from_secs(30 * 60);
/// How often the model is ticked while no event comes.
const TICK: Duration = Duration::from_millis(20);

/// `--snapshot FILE`: takes a controller snapshot on the line the flags name and writes
/// it as a new JSON file; 0 when written, 1 when the line or the snapshot failed, 2 for
/// a bad flag.
pub fn snapshot(args: &Args) -> ExitCode {
    let Some(path) = args.snapshot.clone() else {
        return ExitCode::from(2);
    };
    if let Err(e) = args.line_settings() {
        return fail(2, &e.to_string());
    }
    let model = match args.model() {
        Ok(m) => m,
        Err(e) => return fail(2, &e.to_string()),
    };
    let settings = args.connection_settings();
    let mut pendant = Pendant::new(
        Settings {
            connection: settings.clone(),
            ..Settings::default()
        },
        model.clone(),
    );
    pendant.set_model(model.clone());
    let polls = crate::pendant::controller::poll_commands();
    let session = match Session::open(
        &settings,
        &model,
        polls,
        Arc::new(|_: &crate::link::LinkEvent| {}),
        &LineOwner::InProcess,
    ) {
        Ok(s) => s,
        Err(e) => return fail(1, &e),
    };
    let result = take(&mut pendant, &session, &path);
    let Session { link, sim, .. } = session;
    let report = link.shutdown();
    drop(sim);
    if !report.is_clean() {
        let _ = writeln!(std::io::stderr(), "xsel-pendant: {report}");
    }
    match result {
        Ok(said) => {
            let _ = writeln!(std::io::stdout(), "{said}");
            ExitCode::SUCCESS
        }
        Err(e) => fail(1, &e),
    }
}

/// Runs the model until the line is up and its first reads are done, takes the
/// snapshot and writes it.
fn take(pendant: &mut Pendant, session: &Session, path: &Path) -> Result<String, String> {
    let start = Instant::now();
    let settled = |p: &Pendant| {
        p.line.is_up()
            && p.controller.system.is_some()
            && p.alarms.reading().is_none()
            && p.coords.reading().is_none()
    };
    run_until(pendant, session, start + FIRST_ANSWER, settled).map_err(|e| {
        format!(
            "{e}: {}",
            last_words(pendant).unwrap_or_else(|| "the controller did not answer".into())
        )
    })?;
    pendant.apply(Intent::Snapshot(SnapshotIntent::Take), Instant::now());
    let mut shown: Option<Part> = None;
    run_until(pendant, session, start + SNAPSHOT_LIMIT, |p| {
        let part = p.snapshots.part();
        if part != shown {
            if let Some(part) = part {
                let _ = writeln!(std::io::stderr(), "snapshot: reading {}", part.name());
            }
            shown = part;
        }
        part.is_none()
    })?;
    let Some(snapshot) = pendant.snapshots.latest.clone() else {
        return Err(format!(
            "no snapshot: {}",
            last_words(pendant).unwrap_or_else(|| "the line was lost".into())
        ));
    };
    crate::first_contact::write_new(path, &String::from_utf8_lossy(&snapshot.to_json()))
        .map_err(|e| format!("--snapshot {e}"))?;
    Ok(format!(
        "snapshot written: {} ({})",
        path.display(),
        snapshot.summary()
    ))
}

/// Feeds the session's events to the model and its requests to the session until
/// `done` holds, or fails at `deadline`.
fn run_until(
    pendant: &mut Pendant,
    session: &Session,
    deadline: Instant,
    mut done: impl FnMut(&Pendant) -> bool,
) -> Result<(), String> {
    loop {
        if done(pendant) {
            return Ok(());
        }
        let now = Instant::now();
        if now >= deadline {
            return Err("timed out".into());
        }
        if let Ok(event) = session.events.recv_timeout(TICK.min(deadline - now)) {
            pendant.handle_event(Instant::now(), event);
            while let Ok(event) = session.events.try_recv() {
                pendant.handle_event(Instant::now(), event);
            }
        }
        pendant.tick(Instant::now());
        for request in pendant.take_requests() {
            let rest = forward(session, request, |kind| pendant.table_records(kind));
            if let Some(Request::Stop) = rest {
                session.stop_all();
            }
        }
    }
}

/// The model's last warning or error, for a failure's message.
fn last_words(pendant: &Pendant) -> Option<String> {
    pendant
        .messages
        .iter()
        .rev()
        .find(|m| m.level != crate::pendant::Level::Info)
        .map(|m| m.text.clone())
}

fn fail(code: u8, msg: &str) -> ExitCode {
    let _ = writeln!(std::io::stderr(), "xsel-pendant: {msg}");
    ExitCode::from(code)
}
