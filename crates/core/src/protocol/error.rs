//! Message-level errors: what was expected, in which field, at which columns.

use std::fmt;

use super::ids::{Header, MessageId, Role};

/// A 1-based, inclusive range of frame columns (as in the spec's "cumulative" counts).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct Columns {
    /// First column.
    pub first: usize,
    /// Last column (equal to `first` for a 1-character field).
    pub last: usize,
}

impl Columns {
    /// Columns `first..=last`.
    pub const fn new(first: usize, last: usize) -> Columns {
        Columns { first, last }
    }
}

impl fmt::Display for Columns {
    /// `column 7` or `columns 17-20`.
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        if self.last <= self.first {
            write!(f, "column {}", self.first)
        } else {
            write!(f, "columns {}-{}", self.first, self.last)
        }
    }
}

/// A frame that is well formed but does not carry a valid message of its kind.
#[derive(Clone, Debug, PartialEq, Eq, Hash)]
pub struct MessageError {
    /// The message ID; `None` for an error reply (`&`).
    pub message: Option<MessageId>,
    /// Command or reply.
    pub role: Role,
    /// What is wrong.
    pub kind: MessageErrorKind,
}

/// What is wrong with a message.
#[derive(Clone, Debug, PartialEq, Eq, Hash)]
pub enum MessageErrorKind {
    /// A field's characters are not what its format allows (e.g. not hex digits).
    BadCharacters {
        /// Field name, e.g. `speed` or `axis 2 position`.
        field: String,
        /// Where the field is.
        columns: Columns,
        /// The characters found (escaped).
        raw: String,
        /// What the format allows, e.g. `4 hex digits`.
        expected: String,
    },
    /// The data ends before a field.
    Missing {
        /// Field name.
        field: String,
        /// Where the field should be.
        columns: Columns,
        /// Number of data characters present.
        data_len: usize,
    },
    /// Characters left after the last field.
    Trailing {
        /// Where the extra characters are.
        columns: Columns,
        /// The extra characters (escaped, shortened if long).
        raw: String,
    },
    /// A field holds a value the message does not allow (reserved code, bad count, ...).
    Invalid {
        /// Field name.
        field: String,
        /// Where the field is.
        columns: Columns,
        /// The characters found.
        raw: String,
        /// What is allowed, in words.
        expected: String,
    },
    /// A message ID this library has no layout for.
    UnknownMessage,
    /// A frame of the wrong kind for the decoder called (e.g. a reply given to
    /// `Command::decode`).
    WrongHeader {
        /// What the decoder handles.
        expected: &'static str,
        /// What the frame is.
        found: Header,
    },
}

impl MessageError {
    /// The 1-based column of the problem, if it has one.
    pub fn column(&self) -> Option<usize> {
        match &self.kind {
            MessageErrorKind::BadCharacters { columns, .. }
            | MessageErrorKind::Missing { columns, .. }
            | MessageErrorKind::Trailing { columns, .. }
            | MessageErrorKind::Invalid { columns, .. } => Some(columns.first),
            MessageErrorKind::UnknownMessage | MessageErrorKind::WrongHeader { .. } => Some(1),
        }
    }
}

impl fmt::Display for MessageError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self.message {
            Some(id) => write!(f, "{id} {}: ", self.role)?,
            None => f.write_str("error reply: ")?,
        }
        match &self.kind {
            MessageErrorKind::BadCharacters {
                field,
                columns,
                raw,
                expected,
            } => write!(
                f,
                "field '{field}' at {columns} is '{raw}' — expected {expected}"
            ),
            MessageErrorKind::Missing {
                field,
                columns,
                data_len,
            } => write!(
                f,
                "field '{field}' at {columns} is missing — the data has only {data_len} characters"
            ),
            MessageErrorKind::Trailing { columns, raw } => write!(
                f,
                "unexpected extra data '{raw}' at {columns} after the last field"
            ),
            MessageErrorKind::Invalid {
                field,
                columns,
                raw,
                expected,
            } => write!(
                f,
                "field '{field}' at {columns} is '{raw}' — expected {expected}"
            ),
            MessageErrorKind::UnknownMessage => {
                f.write_str("unknown message ID: no layout is known for it")
            }
            MessageErrorKind::WrongHeader { expected, found } => {
                write!(
                    f,
                    "expected {expected}, found a frame starting with {found}"
                )
            }
        }
    }
}

impl std::error::Error for MessageError {}

/// A typed message that cannot be put on the wire (a value does not fit its field, or a
/// block is inconsistent).
#[derive(Clone, Debug, PartialEq, Eq, Hash)]
pub struct EncodeError {
    /// The message being encoded.
    pub message: MessageId,
    /// The field at fault.
    pub field: String,
    /// Why, in words.
    pub reason: String,
}

impl fmt::Display for EncodeError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "cannot encode {}: field '{}' {}",
            self.message, self.field, self.reason
        )
    }
}

impl std::error::Error for EncodeError {}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn bad_characters_read_like_a_sentence() {
        let e = MessageError {
            message: Some(MessageId::SCARA_MOVE_RELATIVE),
            role: Role::Command,
            kind: MessageErrorKind::BadCharacters {
                field: "speed".into(),
                columns: Columns::new(17, 20),
                raw: "G0 1".into(),
                expected: "4 hex digits".into(),
            },
        };
        assert_eq!(
            e.to_string(),
            "2D5H command: field 'speed' at columns 17-20 is 'G0 1' — expected 4 hex digits"
        );
        assert_eq!(e.column(), Some(17));
    }

    #[test]
    fn single_column_fields_say_column() {
        assert_eq!(Columns::new(7, 7).to_string(), "column 7");
    }
}
