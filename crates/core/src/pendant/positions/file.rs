//! Position table files: CSV (Excel-friendly) and JSON, read whole or refused.
