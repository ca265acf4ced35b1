//! SEL programs as text, the simulator's program file: a documented subset of IAI's SEL
//! language parsed into steps, every line that cannot be read named by line and column.
//!
//! One step is one row of SEL's grid (extension condition, condition, command, operand 1,
//! operand 2, output): the format is described in the README ("Programs in the
//! simulator"). The simulator runs what [`parse`] returns (only programs without errors);
//! the pendant shows it beside the step pointer (all programs, the errors marked).

mod parse;
#[cfg(test)]
mod tests;

use std::fmt;

pub use parse::{MAX_ERRORS, parse};

use crate::protocol::messages::signals::PROGRAMS;

/// The demo program of the built-in simulator: a pick and place between positions 1 and
/// 2, five cycles.
pub const DEMO: &str = include_str!("../../../../assets/programs/demo.sel");

/// The largest program file read (the simulator's `--programs`, the pendant's listing).
pub const MAX_FILE_BYTES: u64 = 4 * 1024 * 1024;

/// The most steps one program may have. IAI's X-SEL holds 9999 steps in all
/// `[inferred: recalled from the controller's specifications, not read on a page here]`.
pub const MAX_STEPS: usize = 9999;

/// Tags (TAG / GOTO) 1-256, as SEL numbers them `[inferred]`.
pub const TAGS: std::ops::RangeInclusive<u16> = 1..=256;

/// Program numbers a file may define: those Format B can name (1-64).
pub fn program_numbers() -> std::ops::Range<u8> {
    PROGRAMS
}

/// A parsed file: its programs (each with the steps that could be read) and the errors.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Parsed {
    pub programs: Vec<Program>,
    /// The first errors, in line order ([`parse::MAX_ERRORS`] at most).
    pub errors: Vec<SyntaxError>,
    /// Errors beyond those listed.
    pub unlisted: usize,
}

impl Parsed {
    /// The programs with no error: what the simulator loads.
    pub fn runnable(&self) -> impl Iterator<Item = &Program> {
        self.programs.iter().filter(|p| p.errors == 0)
    }

    /// What was read, in a few lines: the programs loaded, those not loaded and why, then
    /// every error listed (one a line).
    pub fn report(&self) -> Vec<String> {
        let name = |p: &Program| {
            if p.name.is_empty() {
                format!("{}", p.number)
            } else {
                format!("{} ({})", p.number, p.name)
            }
        };
        let loaded: Vec<String> = self.runnable().map(name).collect();
        let mut lines = vec![if loaded.is_empty() {
            "no program loaded".to_owned()
        } else {
            format!("program(s) loaded: {}", loaded.join(", "))
        }];
        for p in self.programs.iter().filter(|p| p.errors > 0) {
            lines.push(format!(
                "program {} not loaded: {} line(s) with errors",
                name(p),
                p.errors
            ));
        }
        lines.extend(self.errors.iter().map(|e| e.to_string()));
        if self.unlisted > 0 {
            lines.push(format!("{} more error(s) not listed", self.unlisted));
        }
        lines
    }
}

/// One program: its number, name and steps (step 1 first).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Program {
    pub number: u8,
    pub name: String,
    pub steps: Vec<Step>,
    /// Lines of this program that could not be read: a program with any is not run.
    pub errors: usize,
}

impl Program {
    /// Whether any step moves the arm (MOVP, MOVL): such a program takes the axes.
    pub fn moves(&self) -> bool {
        self.steps.iter().any(|s| {
            matches!(
                s.row.as_ref().and_then(|r| r.command.as_ref()),
                Some(Command::MoveP(_) | Command::MoveL(_))
            )
        })
    }

    /// The step index (0-based) of `TAG n`.
    pub fn tag(&self, n: u16) -> Option<usize> {
        self.steps.iter().position(|s| {
            matches!(s.row.as_ref().and_then(|r| r.command.as_ref()), Some(Command::Tag(t)) if *t == n)
        })
    }
}

/// One step as written: the source line, its text, and the row when it could be read.
#[derive(Clone, Debug, PartialEq)]
pub struct Step {
    /// 1-based line of the file.
    pub line: usize,
    /// The line's text, comment included, trailing space trimmed.
    pub text: String,
    /// `None` when the line has an error (named in [`Parsed::errors`]).
    pub row: Option<Row>,
}

/// A row of SEL's grid.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Row {
    pub condition: Option<Condition>,
    /// `None`: a condition alone, joined with the next rows' conditions.
    pub command: Option<Command>,
    /// The output column: an output port (300-599) or a flag (600-999).
    pub output: Option<u16>,
}

/// How a row's condition joins the conditions of the rows before it.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Join {
    /// `LD` or nothing: a new condition.
    #[default]
    Load,
    /// `A`: and.
    And,
    /// `O`: or.
    Or,
}

/// The condition column: an input (0-299), output (300-599) or flag (600-999), `N` for
/// "off".
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Condition {
    pub join: Join,
    pub negated: bool,
    pub number: u16,
}

/// An operand: a literal or, written `*n`, the value of integer variable n.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Value {
    Literal(f64),
    Variable(u16),
}

/// The comparisons of SEL's `CPxx` commands.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Compare {
    Eq,
    Ne,
    Gt,
    Ge,
    Lt,
    Le,
}

impl Compare {
    pub fn holds(self, a: i64, b: i64) -> bool {
        match self {
            Compare::Eq => a == b,
            Compare::Ne => a != b,
            Compare::Gt => a > b,
            Compare::Ge => a >= b,
            Compare::Lt => a < b,
            Compare::Le => a <= b,
        }
    }
}

/// The commands of the subset.
#[derive(Clone, Debug, PartialEq)]
pub enum Command {
    /// MOVP n: PTP move to position n.
    MoveP(Value),
    /// MOVL n: CP straight line to position n.
    MoveL(Value),
    /// VEL mm/s, ACC G, DCL G: the rates of the moves that follow.
    Vel(Value),
    Acc(Value),
    Dcl(Value),
    /// BTON / BTOF n [m]: outputs or flags n..=m on or off.
    Bits {
        on: bool,
        from: u16,
        to: u16,
    },
    /// WTON / WTOF n [s]: wait for input, output or flag n on or off, at most s seconds.
    WaitBit {
        on: bool,
        number: u16,
        timeout: Option<Value>,
    },
    /// TIMW s: wait s seconds.
    Wait(Value),
    Tag(u16),
    Goto(u16),
    /// LET / ADD / SUB v x: integer variable v set to, raised or lowered by x.
    Let {
        var: u16,
        value: Value,
    },
    Add {
        var: u16,
        value: Value,
    },
    Sub {
        var: u16,
        value: Value,
    },
    /// CPEQ / CPNE / CPGT / CPGE / CPLT / CPLE v x: the output column set to the result.
    Compare {
        op: Compare,
        var: u16,
        value: Value,
    },
    /// EXIT: the program ends.
    Exit,
}

/// A line that could not be read.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct SyntaxError {
    pub line: usize,
    /// 1-based character column.
    pub column: usize,
    /// The program the line belongs to, if any.
    pub program: Option<u8>,
    pub message: String,
}

impl fmt::Display for SyntaxError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "line {}, column {}: {}",
            self.line, self.column, self.message
        )
    }
}
