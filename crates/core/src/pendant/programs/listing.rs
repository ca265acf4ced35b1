//! A program listing opened from a file in the simulator's SEL format, shown beside the
//! step pointer (Format B cannot read a controller's program text, PROTOCOL.md 3.44).

use crate::sel;

/// The longest listing file read.
pub const MAX_FILE_BYTES: u64 = sel::MAX_FILE_BYTES;

/// One step as the file writes it.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct ListedStep {
    pub number: u16,
    pub text: String,
    /// Why the line could not be read ("column 6: ..."), if it could not.
    pub error: Option<String>,
}

/// One program of a listing: its steps as written.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct ListedProgram {
    pub number: u8,
    pub name: String,
    pub steps: Vec<ListedStep>,
    /// Lines with errors (the simulator would not load this program).
    pub errors: usize,
}

/// The programs of one listing file, and the lines that could not be read.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct Listing {
    pub path: String,
    pub programs: Vec<ListedProgram>,
    /// "line 12, column 9: ..." for each line not read (the rest is shown).
    pub errors: Vec<String>,
}

impl Listing {
    /// The name the demo listing goes by where a file's path would be.
    pub const DEMO: &str = "the built-in simulator's demo";

    /// The built-in simulator's demo program ([`sel::DEMO`]).
    pub fn demo() -> Listing {
        Listing::from_parsed(Listing::DEMO, &sel::parse(sel::DEMO))
    }

    /// Reads a listing file's bytes (UTF-8 text in the simulator's format).
    pub fn from_bytes(path: &str, bytes: &[u8]) -> Result<Listing, String> {
        let text = std::str::from_utf8(bytes)
            .map_err(|e| format!("not UTF-8 text (byte {})", e.valid_up_to()))?;
        Ok(Listing::from_parsed(path, &sel::parse(text)))
    }

    fn from_parsed(path: &str, parsed: &sel::Parsed) -> Listing {
        let programs = parsed
            .programs
            .iter()
            .map(|p| ListedProgram {
                number: p.number,
                name: p.name.clone(),
                errors: p.errors,
                steps: p
                    .steps
                    .iter()
                    .enumerate()
                    .map(|(i, s)| ListedStep {
                        number: u16::try_from(i + 1).unwrap_or(u16::MAX),
                        text: s.text.clone(),
                        error: parsed
                            .errors
                            .iter()
                            .find(|e| e.line == s.line)
                            .map(|e| format!("column {}: {}", e.column, e.message)),
                    })
                    .collect(),
            })
            .collect();
        let mut errors: Vec<String> = parsed.errors.iter().map(|e| e.to_string()).collect();
        if parsed.unlisted > 0 {
            errors.push(format!("{} more error(s) not listed", parsed.unlisted));
        }
        Listing {
            path: path.to_owned(),
            programs,
            errors,
        }
    }

    /// What was read, for Messages.
    pub fn summary(&self) -> String {
        let mut s = format!("{}: {} program(s)", self.path, self.programs.len());
        if let Some(first) = self.errors.first() {
            s.push_str(&format!(
                "; {} line(s) not read, the first: {first}",
                self.errors.len()
            ));
        }
        s
    }

    /// Program `n` of the listing.
    pub fn program(&self, n: u8) -> Option<&ListedProgram> {
        self.programs.iter().find(|p| p.number == n)
    }

    /// Program `n`'s name, when it has one.
    pub fn name(&self, n: u8) -> Option<&str> {
        self.program(n)
            .map(|p| p.name.as_str())
            .filter(|s| !s.is_empty())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_listing_keeps_every_step_numbered_and_marks_the_lines_not_read() {
        let text = "PROGRAM 2 two\nVEL 100\nMOVP 1.5\nEXIT\nPROGRAM 3\nEXIT\n";
        let l = Listing::from_bytes("p.sel", text.as_bytes()).unwrap();
        let p = l.program(2).unwrap();
        let numbers: Vec<u16> = p.steps.iter().map(|s| s.number).collect();
        assert_eq!(numbers, [1, 2, 3]);
        assert_eq!(p.steps[1].text, "MOVP 1.5");
        assert!(p.steps[1].error.as_ref().unwrap().starts_with("column 6:"));
        assert_eq!((p.errors, l.program(3).unwrap().errors), (1, 0));
        assert_eq!(l.name(2), Some("two"));
        assert!(
            l.summary()
                .contains("1 line(s) not read, the first: line 3, column 6")
        );
        let demo = Listing::from_bytes("demo.sel", sel::DEMO.as_bytes()).unwrap();
        assert_eq!(demo.program(1).unwrap().steps.len(), 15);
        assert!(Listing::from_bytes("x", &[0xFF, 0xFE]).is_err());
    }
}
