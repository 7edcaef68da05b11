//! The time series as an Apache Parquet file (`sky-series.parquet`), beside
//! the CSV: the same rows and columns ([`super::SERIES_COLUMNS`]), typed —
//! `time_utc` a UTC timestamp in milliseconds, numbers as nullable
//! doubles, text as nullable UTF-8 — so that a year of scans can be read
//! by column (pyarrow, polars, DuckDB, Spark) without parsing text.
//!
//! Units and meanings go in the file's key–value metadata, one entry per
//! column: key `campanile.unit.<column>`, value the column's line of the
//! CSV header ("W·m⁻² (full-well gauge): direct normal solar irradiance,
//! channel r"); `campanile.format` names the layout and its version.
//! Snappy-compressed, one row group; the bytes depend only on the rows, so
//! a merged day is byte-equal to the same day processed in one piece.

use std::sync::Arc;

use parquet::basic::{Compression, LogicalType, Repetition, TimeUnit, Type as PhysicalType};
use parquet::data_type::{ByteArray, ByteArrayType, DoubleType, Int64Type};
use parquet::errors::ParquetError;
use parquet::file::metadata::KeyValue;
use parquet::file::properties::WriterProperties;
use parquet::file::writer::SerializedFileWriter;
use parquet::schema::types::Type;

use super::day::SkySeries;
use super::series_csv::{Cell, SERIES_COLUMNS, cells, expand};

/// The value of the `campanile.format` metadata entry.
pub const PARQUET_FORMAT: &str = "campanile sky-series 1";

/// The metadata key holding a column's unit and meaning.
pub fn unit_key(column: &str) -> String {
    format!("campanile.unit.{column}")
}

/// What a column holds, in Parquet terms.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Kind {
    Text,
    Number,
    Time,
}

fn kinds() -> Vec<Kind> {
    // Columns are text when their unit line says so, the time column by
    // name; every other column is a number.
    expand(SERIES_COLUMNS)
        .iter()
        .map(|(name, doc)| {
            if name == "time_utc" {
                Kind::Time
            } else if doc.starts_with("text") {
                Kind::Text
            } else {
                Kind::Number
            }
        })
        .collect()
}

fn schema(kinds: &[Kind]) -> Result<Type, ParquetError> {
    let mut fields = Vec::new();
    for ((name, _), kind) in expand(SERIES_COLUMNS).iter().zip(kinds) {
        let field = match kind {
            Kind::Time => Type::primitive_type_builder(name, PhysicalType::INT64)
                .with_logical_type(Some(LogicalType::timestamp(true, TimeUnit::MILLIS)))
                .with_repetition(Repetition::REQUIRED),
            Kind::Text => Type::primitive_type_builder(name, PhysicalType::BYTE_ARRAY)
                .with_logical_type(Some(LogicalType::String))
                .with_repetition(Repetition::OPTIONAL),
            Kind::Number => {
                Type::primitive_type_builder(name, PhysicalType::DOUBLE).with_repetition(Repetition::OPTIONAL)
            }
        };
        fields.push(Arc::new(field.build()?));
    }
    Type::group_type_builder("sky_series").with_fields(fields).build()
}

/// The series as Parquet bytes (module doc).
pub fn series_parquet(series: &SkySeries) -> Result<Vec<u8>, ParquetError> {
    let columns = expand(SERIES_COLUMNS);
    let mut metadata = vec![KeyValue::new("campanile.format".to_owned(), PARQUET_FORMAT.to_owned())];
    metadata.extend(
        columns
            .iter()
            .map(|(name, doc)| KeyValue::new(unit_key(name), doc.clone())),
    );
    let props = WriterProperties::builder()
        .set_compression(Compression::SNAPPY)
        .set_key_value_metadata(Some(metadata))
        .set_created_by(format!("campanile {}", env!("CARGO_PKG_VERSION")))
        .build();
    let rows: Vec<Vec<Cell>> = series
        .scans
        .iter()
        .zip(&series.conditions)
        .map(|(s, c)| cells(s, c))
        .collect();
    let kinds = kinds();
    let mut writer = SerializedFileWriter::new(Vec::new(), Arc::new(schema(&kinds)?), Arc::new(props))?;
    let mut group = writer.next_row_group()?;
    let mut index = 0;
    while let Some(mut column) = group.next_column()? {
        let cells = rows.iter().map(|r| &r[index]);
        match kinds[index] {
            Kind::Time => {
                let values: Vec<i64> = cells
                    .map(|c| match c {
                        Cell::Time(t) => t.timestamp_millis(),
                        _ => 0,
                    })
                    .collect();
                column.typed::<Int64Type>().write_batch(&values, None, None)?;
            }
            Kind::Text => {
                let texts: Vec<Option<&str>> = cells
                    .map(|c| match c {
                        Cell::Text(t) => t.as_deref(),
                        _ => None,
                    })
                    .collect();
                let levels: Vec<i16> = texts.iter().map(|t| i16::from(t.is_some())).collect();
                let values: Vec<ByteArray> = texts.iter().flatten().map(|t| ByteArray::from(*t)).collect();
                column
                    .typed::<ByteArrayType>()
                    .write_batch(&values, Some(&levels), None)?;
            }
            Kind::Number => {
                let numbers: Vec<Option<f64>> = cells
                    .map(|c| match c {
                        Cell::Number(v) => v.filter(|v| v.is_finite()),
                        _ => None,
                    })
                    .collect();
                let levels: Vec<i16> = numbers.iter().map(|v| i16::from(v.is_some())).collect();
                let values: Vec<f64> = numbers.iter().flatten().copied().collect();
                column.typed::<DoubleType>().write_batch(&values, Some(&levels), None)?;
            }
        }
        column.close()?;
        index += 1;
    }
    group.close()?;
    writer.into_inner()
}

#[cfg(test)]
mod tests {
    use super::*;
    use parquet::file::reader::{FileReader, SerializedFileReader};

    #[test]
    fn an_empty_series_has_every_column_with_its_unit() {
        let bytes = series_parquet(&SkySeries::new(Vec::new())).unwrap();
        let file = tempfile::tempfile().unwrap();
        std::io::Write::write_all(&mut &file, &bytes).unwrap();
        let reader = SerializedFileReader::new(file).unwrap();
        let meta = reader.metadata().file_metadata();
        assert_eq!(meta.num_rows(), 0);
        let names: Vec<String> = meta
            .schema_descr()
            .columns()
            .iter()
            .map(|c| c.name().to_owned())
            .collect();
        let expected: Vec<String> = expand(SERIES_COLUMNS).into_iter().map(|(n, _)| n).collect();
        assert_eq!(names, expected);
        assert_eq!(names.len(), 51);
        let kv = meta.key_value_metadata().unwrap();
        let get = |k: &str| kv.iter().find(|e| e.key == k).and_then(|e| e.value.clone());
        assert_eq!(get("campanile.format").as_deref(), Some(PARQUET_FORMAT));
        assert_eq!(
            get(&unit_key("sun_e_g_w_m2")).as_deref(),
            Some("W·m⁻² (full-well gauge): direct normal solar irradiance, channel g")
        );
    }
}
