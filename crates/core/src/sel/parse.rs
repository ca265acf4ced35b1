//! The SEL text parser: lines to programs and steps; a line it cannot read becomes an
//! error with its line and column, and its program is marked as not runnable.

use super::{
    Command, Compare, Condition, Join, MAX_STEPS, Parsed, Program, Row, Step, SyntaxError, TAGS,
    Value,
};
use crate::protocol::VarKind;
use crate::protocol::messages::signals::{INPUTS, LOCAL_FLAGS, OUTPUTS, PROGRAMS};

/// The most errors listed; the rest are counted in [`Parsed::unlisted`].
pub const MAX_ERRORS: usize = 200;

/// The commands of the subset, for the "unknown command" message.
const COMMANDS: &str = "MOVP, MOVL, VEL, ACC, DCL, BTON, BTOF, WTON, WTOF, TIMW, TAG, GOTO, \
                        LET, ADD, SUB, CPEQ, CPNE, CPGT, CPGE, CPLT, CPLE, EXIT";

/// A whitespace-separated word and its 1-based column.
#[derive(Clone, Copy)]
struct Token<'a> {
    text: &'a str,
    column: usize,
}

/// Why a line is not read: the column and the words.
struct LineError {
    column: usize,
    message: String,
}

fn err<T>(column: usize, message: impl Into<String>) -> Result<T, LineError> {
    Err(LineError {
        column,
        message: message.into(),
    })
}

/// Parses a whole file. Never fails: what cannot be read is in [`Parsed::errors`].
pub fn parse(text: &str) -> Parsed {
    let mut out = Parsed::default();
    let mut current: Option<usize> = None;
    for (i, raw) in text.lines().enumerate() {
        let line = i + 1;
        let code = raw.split('#').next().unwrap_or("");
        let tokens = tokenize(code);
        let Some(first) = tokens.first() else {
            continue;
        };
        if first.text.eq_ignore_ascii_case("PROGRAM") {
            match header(&tokens, raw, &out) {
                Ok((number, name)) => {
                    out.programs.push(Program {
                        number,
                        name,
                        ..Program::default()
                    });
                    current = Some(out.programs.len() - 1);
                }
                Err(e) => {
                    // The steps that follow belong to no program until the next header.
                    current = None;
                    push_error(&mut out, line, e, None);
                }
            }
            continue;
        }
        let Some(p) = current else {
            let e = LineError {
                column: first.column,
                message: "a step before any PROGRAM line (or after a PROGRAM line that \
                          could not be read)"
                    .into(),
            };
            push_error(&mut out, line, e, None);
            continue;
        };
        let program = &mut out.programs[p];
        if program.steps.len() >= MAX_STEPS {
            let number = program.number;
            program.errors += 1;
            let e = LineError {
                column: first.column,
                message: format!("program {number} has more than {MAX_STEPS} steps"),
            };
            push_error(&mut out, line, e, Some(number));
            continue;
        }
        let row = row(&tokens);
        let number = program.number;
        program.steps.push(Step {
            line,
            text: raw.trim_end().to_owned(),
            row: row.as_ref().ok().cloned(),
        });
        if let Err(e) = row {
            program.errors += 1;
            push_error(&mut out, line, e, Some(number));
        }
    }
    check_tags(&mut out);
    out
}

fn push_error(out: &mut Parsed, line: usize, e: LineError, program: Option<u8>) {
    if out.errors.len() >= MAX_ERRORS {
        out.unlisted += 1;
        return;
    }
    out.errors.push(SyntaxError {
        line,
        column: e.column,
        program,
        message: e.message,
    });
}

fn tokenize(code: &str) -> Vec<Token<'_>> {
    let mut tokens = Vec::new();
    let mut start: Option<usize> = None;
    // Columns count characters, not bytes.
    let mut column = 0;
    let mut start_column = 0;
    for (at, c) in code.char_indices() {
        column += 1;
        match (c.is_whitespace(), start) {
            (false, None) => {
                start = Some(at);
                start_column = column;
            }
            (true, Some(s)) => {
                tokens.push(Token {
                    text: &code[s..at],
                    column: start_column,
                });
                start = None;
            }
            _ => {}
        }
    }
    if let Some(s) = start {
        tokens.push(Token {
            text: &code[s..],
            column: start_column,
        });
    }
    tokens
}

/// `PROGRAM n [name]`.
fn header(tokens: &[Token], raw: &str, out: &Parsed) -> Result<(u8, String), LineError> {
    let Some(n) = tokens.get(1) else {
        return err(
            tokens[0].column + tokens[0].text.chars().count(),
            format!(
                "PROGRAM needs a number ({}-{})",
                PROGRAMS.start,
                PROGRAMS.end - 1
            ),
        );
    };
    let number = n.text.parse::<u8>().ok().filter(|v| PROGRAMS.contains(v));
    let Some(number) = number else {
        return err(
            n.column,
            format!(
                "program number {:?}: a number {}-{} is needed",
                n.text,
                PROGRAMS.start,
                PROGRAMS.end - 1
            ),
        );
    };
    if out.programs.iter().any(|p| p.number == number) {
        return err(n.column, format!("program {number} is defined twice"));
    }
    let name = match tokens.get(2) {
        Some(t) => {
            let code = raw.split('#').next().unwrap_or("");
            let from = code
                .char_indices()
                .nth(t.column - 1)
                .map_or(code.len(), |(at, _)| at);
            code[from..].trim().to_owned()
        }
        None => String::new(),
    };
    Ok((number, name))
}

/// A step's row: `[LD|A|O] [N]cnd`, then `COMMAND [op1 [op2 [output]]]`, `-` for an
/// empty field.
fn row(tokens: &[Token]) -> Result<Row, LineError> {
    let mut rest = tokens;
    let mut row = Row::default();
    let join = match rest.first().map(|t| t.text.to_ascii_uppercase()) {
        Some(j) if j == "AB" || j == "OB" => {
            return err(
                rest[0].column,
                format!("{j} (a block condition) is not in the simulator's SEL subset"),
            );
        }
        Some(j) if (j == "LD" || j == "A" || j == "O") && rest.len() > 1 => {
            let join = match j.as_str() {
                "LD" => Join::Load,
                "A" => Join::And,
                _ => Join::Or,
            };
            rest = &rest[1..];
            Some((join, tokens[0]))
        }
        _ => None,
    };
    if let Some(t) = rest.first()
        && looks_like_condition(t.text)
    {
        row.condition = Some(condition(*t, join.map_or(Join::Load, |(j, _)| j))?);
        rest = &rest[1..];
    } else if let Some((_, t)) = join {
        return err(
            t.column,
            format!(
                "{} needs a condition after it (an input, output or flag number)",
                t.text
            ),
        );
    }
    let Some((cmd, fields)) = rest.split_first() else {
        return Ok(row);
    };
    if fields.len() > 3 {
        return err(
            fields[3].column,
            format!(
                "too many fields after {}: operand 1, operand 2 and output at most",
                cmd.text
            ),
        );
    }
    let field = |k: usize| fields.get(k).copied().filter(|t| t.text != "-");
    // Where a missing field would go: one space after the last word.
    let after = |k: usize| match fields.get(k) {
        Some(t) => t.column,
        None => {
            let last = fields.last().unwrap_or(cmd);
            last.column + last.text.chars().count() + 1
        }
    };
    let name = cmd.text.to_ascii_uppercase();
    let none = |k: usize, what: &str| -> Result<(), LineError> {
        match field(k) {
            Some(t) => err(t.column, format!("{name} takes no {what}")),
            None => Ok(()),
        }
    };
    let need = |k: usize, what: &str| -> Result<Token, LineError> {
        field(k).ok_or_else(|| LineError {
            column: after(k),
            message: format!("{name} needs {what}"),
        })
    };
    let command = match name.as_str() {
        "MOVP" | "MOVL" => {
            let v = value(need(0, "a position number")?, 1.0, 20_000.0, true)?;
            none(1, "operand 2")?;
            if name == "MOVP" {
                Command::MoveP(v)
            } else {
                Command::MoveL(v)
            }
        }
        "VEL" | "ACC" | "DCL" => {
            let (what, max) = if name == "VEL" {
                ("a speed in mm/s", 10_000.0)
            } else {
                ("an acceleration in G", 10.0)
            };
            let v = value(need(0, what)?, f64::MIN_POSITIVE, max, false)?;
            none(1, "operand 2")?;
            match name.as_str() {
                "VEL" => Command::Vel(v),
                "ACC" => Command::Acc(v),
                _ => Command::Dcl(v),
            }
        }
        "BTON" | "BTOF" => {
            let from = settable(need(0, "an output or flag number")?)?;
            let to = match field(1) {
                Some(t) => {
                    let to = settable(t)?;
                    if to < from || category(to) != category(from) {
                        return err(
                            t.column,
                            format!("{to} does not end a range that starts at {from}"),
                        );
                    }
                    to
                }
                None => from,
            };
            Command::Bits {
                on: name == "BTON",
                from,
                to,
            }
        }
        "WTON" | "WTOF" => {
            let t = need(0, "an input, output or flag number")?;
            let number = integer(
                t,
                INPUTS.numbers.start,
                LOCAL_FLAGS.numbers.end - 1,
                "an input (0-299), output (300-599) or flag (600-999)",
            )?;
            let timeout = field(1)
                .map(|t| value(t, 0.0, 9_999.0, false))
                .transpose()?;
            Command::WaitBit {
                on: name == "WTON",
                number,
                timeout,
            }
        }
        "TIMW" => {
            let v = value(need(0, "a time in seconds")?, 0.0, 9_999.0, false)?;
            none(1, "operand 2")?;
            Command::Wait(v)
        }
        "TAG" | "GOTO" => {
            let t = need(0, "a tag number")?;
            let n = integer(t, *TAGS.start(), *TAGS.end(), "a tag number (1-256)")?;
            none(1, "operand 2")?;
            none(2, "output")?;
            if name == "TAG" {
                Command::Tag(n)
            } else {
                Command::Goto(n)
            }
        }
        "LET" | "ADD" | "SUB" | "CPEQ" | "CPNE" | "CPGT" | "CPGE" | "CPLT" | "CPLE" => {
            let var = variable(need(0, "an integer variable number")?)?;
            let v = value(need(1, "a value")?, -1e9, 1e9, true)?;
            match name.as_str() {
                "LET" => Command::Let { var, value: v },
                "ADD" => Command::Add { var, value: v },
                "SUB" => Command::Sub { var, value: v },
                cp => Command::Compare {
                    op: match &cp[2..] {
                        "EQ" => Compare::Eq,
                        "NE" => Compare::Ne,
                        "GT" => Compare::Gt,
                        "GE" => Compare::Ge,
                        "LT" => Compare::Lt,
                        _ => Compare::Le,
                    },
                    var,
                    value: v,
                },
            }
        }
        "EXIT" => {
            none(0, "operand 1")?;
            none(1, "operand 2")?;
            none(2, "output")?;
            Command::Exit
        }
        _ if cmd.text.chars().all(|c| c.is_ascii_alphabetic()) => {
            return err(
                cmd.column,
                format!(
                    "unknown command {}: the simulator's SEL subset is {COMMANDS}",
                    cmd.text
                ),
            );
        }
        _ => {
            return err(
                cmd.column,
                format!(
                    "{:?} is not a command (a condition is an input, output or flag \
                     number, N before it for \"off\")",
                    cmd.text
                ),
            );
        }
    };
    row.command = Some(command);
    row.output = field(2).map(settable).transpose()?;
    Ok(row)
}

fn looks_like_condition(text: &str) -> bool {
    let digits = text
        .strip_prefix('N')
        .or_else(|| text.strip_prefix('n'))
        .unwrap_or(text);
    !digits.is_empty() && digits.chars().all(|c| c.is_ascii_digit())
}

fn condition(t: Token, join: Join) -> Result<Condition, LineError> {
    let negated = t.text.starts_with(['N', 'n']);
    let digits = Token {
        text: &t.text[usize::from(negated)..],
        column: t.column + usize::from(negated),
    };
    let number = integer(
        digits,
        INPUTS.numbers.start,
        LOCAL_FLAGS.numbers.end - 1,
        "a condition (an input 0-299, output 300-599 or flag 600-999)",
    )?;
    Ok(Condition {
        join,
        negated,
        number,
    })
}

/// An output port or a flag: what a program may set.
fn settable(t: Token) -> Result<u16, LineError> {
    integer(
        t,
        OUTPUTS.numbers.start,
        LOCAL_FLAGS.numbers.end - 1,
        "an output (300-599) or flag (600-999)",
    )
}

/// 0 inputs, 1 outputs, 2 global flags, 3 local flags.
fn category(n: u16) -> u8 {
    match n {
        n if INPUTS.holds(n) => 0,
        n if OUTPUTS.holds(n) => 1,
        n if n < LOCAL_FLAGS.numbers.start => 2,
        _ => 3,
    }
}

/// An integer variable number: a program's local one or a global one.
fn variable(t: Token) -> Result<u16, LineError> {
    let n = t.text.parse::<u16>().ok();
    let (local, global) = (
        VarKind::Integer.numbers(false),
        VarKind::Integer.numbers(true),
    );
    match n {
        Some(n) if local.contains(&n) || global.contains(&n) => Ok(n),
        _ => err(
            t.column,
            format!(
                "{:?}: an integer variable number is {}-{} (the program's own) or {}-{} \
                 (global)",
                t.text,
                local.start,
                local.end - 1,
                global.start,
                global.end - 1
            ),
        ),
    }
}

fn integer(t: Token, lo: u16, hi: u16, what: &str) -> Result<u16, LineError> {
    match t.text.parse::<u16>() {
        Ok(n) if (lo..=hi).contains(&n) => Ok(n),
        _ => err(t.column, format!("{:?}: {what} is needed", t.text)),
    }
}

/// A literal in `lo..=hi` (a whole number when `whole`), or `*n`: integer variable n.
fn value(t: Token, lo: f64, hi: f64, whole: bool) -> Result<Value, LineError> {
    if let Some(rest) = t.text.strip_prefix('*') {
        let var = variable(Token {
            text: rest,
            column: t.column + 1,
        })?;
        return Ok(Value::Variable(var));
    }
    // Digits, one point and a sign only: no exponents, no "inf" or "nan".
    let plain = t
        .text
        .chars()
        .enumerate()
        .all(|(i, c)| c.is_ascii_digit() || c == '.' || (i == 0 && (c == '-' || c == '+')));
    let v = t.text.parse::<f64>().ok().filter(|_| plain);
    match v {
        Some(v) if whole && v.fract() != 0.0 => {
            err(t.column, format!("{}: a whole number is needed", t.text))
        }
        Some(v) if (lo..=hi).contains(&v) => Ok(Value::Literal(v)),
        Some(_) => err(
            t.column,
            format!("{} is out of range ({} to {hi})", t.text, lo.max(0.0)),
        ),
        None => err(
            t.column,
            format!(
                "{:?} is not a number (or *n for integer variable n)",
                t.text
            ),
        ),
    }
}

/// GOTO needs its TAG in the same program; a TAG is defined once.
fn check_tags(out: &mut Parsed) {
    let mut found = Vec::new();
    for p in &mut out.programs {
        let command = |s: &Step| s.row.as_ref().and_then(|r| r.command.clone());
        let mut tags = Vec::new();
        for s in &p.steps {
            if let Some(Command::Tag(n)) = command(s) {
                if tags.contains(&n) {
                    found.push((s, p.number, format!("TAG {n} is defined twice")));
                } else {
                    tags.push(n);
                }
            }
        }
        for s in &p.steps {
            if let Some(Command::Goto(n)) = command(s)
                && !tags.contains(&n)
            {
                let message = format!("GOTO {n}: program {} has no TAG {n}", p.number);
                found.push((s, p.number, message));
            }
        }
    }
    let found: Vec<_> = found
        .into_iter()
        .map(|(s, program, message)| (s.line, operand_column(&s.text), program, message))
        .collect();
    for (line, column, program, message) in found {
        if let Some(p) = out.programs.iter_mut().find(|p| p.number == program) {
            p.errors += 1;
        }
        push_error(out, line, LineError { column, message }, Some(program));
    }
}

/// The column of the first operand (the word after the command) of a step's text.
fn operand_column(text: &str) -> usize {
    let tokens = tokenize(text.split('#').next().unwrap_or(""));
    let command = tokens
        .iter()
        .position(|t| t.text.chars().all(|c| c.is_ascii_alphabetic()) && t.text.len() > 2);
    command
        .and_then(|k| tokens.get(k + 1))
        .map_or(1, |t| t.column)
}
