//! Reading CSV tables cell by cell, with errors that name the row, the
//! column, the value found and what was expected.

/// A cell that cannot be read as what its column holds.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("row {row}, column `{column}`: found {value:?}; expected {expected}")]
pub struct CellError {
    /// Row, counting the header as row 1.
    pub row: u64,
    /// Column name.
    pub column: String,
    /// The cell as written.
    pub value: String,
    /// What it should be.
    pub expected: &'static str,
}

/// The number in column `col` of `record` (row `row`), finite and within
/// `[lo, hi]`.
pub fn number(
    record: &csv::StringRecord,
    header: &csv::StringRecord,
    col: usize,
    row: u64,
    (lo, hi): (f64, f64),
    expected: &'static str,
) -> Result<f64, CellError> {
    let cell = record.get(col).unwrap_or("");
    cell.parse::<f64>()
        .ok()
        .filter(|x| x.is_finite() && (lo..=hi).contains(x))
        .ok_or_else(|| CellError {
            row,
            column: header.get(col).unwrap_or("?").to_owned(),
            value: cell.to_owned(),
            expected,
        })
}

/// A problem with a CSV table as a whole or one of its cells.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum TableError {
    /// The CSV is malformed.
    #[error("row {row}: {message}")]
    Csv {
        /// Row (the header is row 1).
        row: u64,
        /// What the parser said.
        message: String,
    },
    /// A required column is absent.
    #[error("the header has no `{column}` column (it has: {found})")]
    MissingColumn {
        /// The column.
        column: &'static str,
        /// The header as read.
        found: String,
    },
    /// A cell cannot be read.
    #[error(transparent)]
    Cell(#[from] CellError),
}

impl TableError {
    /// The parser's error at `row`.
    pub fn csv(row: u64, e: &csv::Error) -> TableError {
        TableError::Csv {
            row,
            message: e.to_string(),
        }
    }
}

/// The index of column `name` in `header`.
pub fn column(header: &csv::StringRecord, name: &'static str) -> Result<usize, TableError> {
    header
        .iter()
        .position(|h| h == name)
        .ok_or_else(|| TableError::MissingColumn {
            column: name,
            found: header.iter().collect::<Vec<_>>().join(","),
        })
}
