//! PLY scans (ascii, and binary in either byte order) through `ply-rs-bw`.
//!
//! The `vertex` element's properties are read by name:
//!
//! | what | properties | scaling |
//! | --- | --- | --- |
//! | position | `x`, `y`, `z` (any scalar type) | metres, as is |
//! | normal | `nx`, `ny`, `nz` | as is (must be unit) |
//! | intensity | `intensity`, `scalar_intensity`, `reflectance`, `scalar_reflectance` (any case) | integer types over their maximum (uchar 255, ushort 65535, …); floats as is |
//! | colour | `red`, `green`, `blue` (or `r`, `g`, `b`, `diffuse_red`, …) | integer types over their maximum (a signed `char` read as its byte); floats as is |
//! | grid | `row`, `col` (or `column`): integer types | the organised scan's cell |
//!
//! Other properties are ignored, and so is every other element: a mesh's
//! `face` element still reads as its vertices. A comment
//! `campanile scanner_pose ox oy oz qw qx qy qz`, which our writer puts in
//! ([`crate::write::ply`]), gives the scan its [`ScannerPose`].

use std::fs::File;
use std::io::{BufRead, BufReader};
use std::path::Path;

use nalgebra::{Quaternion, UnitQuaternion, Vector3};
use ply_rs_bw::parser::{Parser, Reader};
use ply_rs_bw::ply::{
    ElementDef, Encoding, Header, Property, PropertyAccess, PropertyAccessResult, PropertyType, ScalarType,
};

use super::{ReadError, checked, grid_from_indices, stem};
use crate::cloud::{Scan, ScannerPose};

/// The comment that carries a scan's pose in our PLY files.
pub(crate) const POSE_COMMENT: &str = "campanile scanner_pose";

/// The comment that carries an organised scan's grid size (rows, columns)
/// in our PLY files, so that empty last rows and columns survive.
pub(crate) const GRID_COMMENT: &str = "campanile grid";

/// What a truncated file's error says it found.
const END: &str = "the end of the file";

/// Names a PLY file may give the intensity, compared case-insensitively.
const INTENSITY_NAMES: [&str; 4] = ["intensity", "scalar_intensity", "reflectance", "scalar_reflectance"];

/// Which attribute a vertex property carries.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Field {
    Position(usize),
    Normal(usize),
    Intensity,
    Colour(usize),
    Row,
    Col,
}

fn field(name: &str) -> Option<Field> {
    let lower = name.to_ascii_lowercase();
    Some(match lower.as_str() {
        "x" => Field::Position(0),
        "y" => Field::Position(1),
        "z" => Field::Position(2),
        "nx" => Field::Normal(0),
        "ny" => Field::Normal(1),
        "nz" => Field::Normal(2),
        "red" | "r" | "diffuse_red" => Field::Colour(0),
        "green" | "g" | "diffuse_green" => Field::Colour(1),
        "blue" | "b" | "diffuse_blue" => Field::Colour(2),
        "row" => Field::Row,
        "col" | "column" => Field::Col,
        n if INTENSITY_NAMES.contains(&n) => Field::Intensity,
        _ => return None,
    })
}

/// One vertex as read (and as our writer writes it).
#[derive(Debug, Clone, Default)]
pub(crate) struct PlyVertex {
    pub(crate) position: [f64; 3],
    pub(crate) normal: [f64; 3],
    pub(crate) intensity: f32,
    pub(crate) colour: [f32; 3],
    /// Raw colour bytes for writing.
    pub(crate) colour_u8: [u8; 3],
    pub(crate) row: i64,
    pub(crate) col: i64,
}

/// A scalar's value and, for integer types, the scale that maps the type's
/// maximum to 1 (floats: 1).
fn scalar(property: &Property) -> Option<(f64, f64)> {
    Some(match *property {
        Property::Char(v) => (f64::from(v as u8), 255.0),
        Property::UChar(v) => (f64::from(v), 255.0),
        Property::Short(v) => (f64::from(v), f64::from(i16::MAX)),
        Property::UShort(v) => (f64::from(v), f64::from(u16::MAX)),
        Property::Int(v) => (f64::from(v), f64::from(i32::MAX)),
        Property::UInt(v) => (f64::from(v), f64::from(u32::MAX)),
        Property::Float(v) => (f64::from(v), 1.0),
        Property::Double(v) => (v, 1.0),
        _ => return None,
    })
}

impl PropertyAccess for PlyVertex {
    fn new() -> Self {
        PlyVertex::default()
    }

    fn set_property(&mut self, name: &str, property: Property) -> PropertyAccessResult {
        let (Some(f), Some((value, max))) = (field(name), scalar(&property)) else {
            return PropertyAccessResult::Ignored;
        };
        match f {
            Field::Position(i) => self.position[i] = value,
            Field::Normal(i) => self.normal[i] = value,
            Field::Intensity => self.intensity = (value / max) as f32,
            Field::Colour(i) => self.colour[i] = (value / max) as f32,
            // Signed `char` rows are read as their value, not their byte.
            Field::Row | Field::Col => {
                let v = match property {
                    Property::Char(c) => i64::from(c),
                    _ => value as i64,
                };
                if f == Field::Row {
                    self.row = v;
                } else {
                    self.col = v;
                }
            }
        }
        PropertyAccessResult::Set
    }

    fn get_double(&self, name: &str) -> Option<f64> {
        match field(name)? {
            Field::Position(i) => Some(self.position[i]),
            _ => None,
        }
    }

    fn get_float(&self, name: &str) -> Option<f32> {
        match field(name)? {
            Field::Normal(i) => Some(self.normal[i] as f32),
            Field::Intensity => Some(self.intensity),
            _ => None,
        }
    }

    fn get_uchar(&self, name: &str) -> Option<u8> {
        match field(name)? {
            Field::Colour(i) => Some(self.colour_u8[i]),
            _ => None,
        }
    }

    fn get_int(&self, name: &str) -> Option<i32> {
        match field(name)? {
            Field::Row => i32::try_from(self.row).ok(),
            Field::Col => i32::try_from(self.col).ok(),
            _ => None,
        }
    }
}

/// An element read only to get past it (an element before `vertex`).
struct Skipped;

impl PropertyAccess for Skipped {
    fn new() -> Self {
        Skipped
    }
}

/// Which attributes the vertex element declares, checked against what each
/// needs.
struct Declared {
    normals: bool,
    intensity: bool,
    colour: bool,
    grid: bool,
}

fn declared(path: &Path, vertex: &ElementDef) -> Result<Declared, ReadError> {
    let element = "element vertex";
    let mut seen: Vec<Field> = Vec::new();
    for (name, def) in &vertex.properties {
        let Some(f) = field(name) else { continue };
        let scalar = match &def.data_type {
            PropertyType::Scalar(s) => s,
            PropertyType::List(index, item) => {
                return Err(ReadError::malformed(
                    path,
                    element,
                    format!("property {name}"),
                    format!("a list ({index:?} count, {item:?} items)"),
                    "a scalar",
                ));
            }
        };
        if matches!(f, Field::Row | Field::Col) && matches!(scalar, ScalarType::Float | ScalarType::Double) {
            return Err(ReadError::malformed(
                path,
                element,
                format!("property {name}"),
                format!("{scalar:?}"),
                "an integer type (a grid index)",
            ));
        }
        seen.push(f);
    }
    let all = |fs: &[Field]| fs.iter().all(|f| seen.contains(f));
    let any = |fs: &[Field]| fs.iter().any(|f| seen.contains(f));
    let position = [Field::Position(0), Field::Position(1), Field::Position(2)];
    if !all(&position) {
        return Err(ReadError::malformed(
            path,
            element,
            "properties",
            names(vertex),
            "x, y and z",
        ));
    }
    let normal = [Field::Normal(0), Field::Normal(1), Field::Normal(2)];
    let colour = [Field::Colour(0), Field::Colour(1), Field::Colour(2)];
    let grid = [Field::Row, Field::Col];
    for (what, fs) in [
        ("nx, ny and nz", &normal[..]),
        ("red, green and blue", &colour[..]),
        ("row and col", &grid[..]),
    ] {
        if any(fs) && !all(fs) {
            return Err(ReadError::malformed(
                path,
                element,
                "properties",
                names(vertex),
                format!("all of {what} or none"),
            ));
        }
    }
    Ok(Declared {
        normals: all(&normal),
        intensity: seen.contains(&Field::Intensity),
        colour: all(&colour),
        grid: all(&grid),
    })
}

fn names(element: &ElementDef) -> String {
    element.properties.keys().cloned().collect::<Vec<_>>().join(", ")
}

fn pose_from_comments(path: &Path, header: &Header) -> Result<Option<ScannerPose>, ReadError> {
    let Some(rest) = header.comments.iter().find_map(|c| c.trim().strip_prefix(POSE_COMMENT)) else {
        return Ok(None);
    };
    let values: Vec<f64> = rest.split_whitespace().filter_map(|v| v.parse().ok()).collect();
    let bad = || {
        ReadError::malformed(
            path,
            "header",
            "comment scanner_pose",
            rest.trim(),
            "7 finite numbers: ox oy oz qw qx qy qz",
        )
    };
    let [ox, oy, oz, w, x, y, z] = values[..] else {
        return Err(bad());
    };
    let q = Quaternion::new(w, x, y, z);
    if !values.iter().all(|v| v.is_finite()) || q.norm() < 1e-9 {
        return Err(bad());
    }
    Ok(Some(ScannerPose {
        origin: Vector3::new(ox, oy, oz),
        rotation: UnitQuaternion::from_quaternion(q).to_rotation_matrix(),
    }))
}

/// The grid size our writer records, or (0, 0).
fn grid_size_from_comments(header: &Header) -> (usize, usize) {
    header
        .comments
        .iter()
        .find_map(|c| c.trim().strip_prefix(GRID_COMMENT))
        .and_then(|rest| {
            let mut it = rest.split_whitespace().map(|v| v.parse::<usize>().ok());
            Some((it.next()??, it.next()??))
        })
        .unwrap_or((0, 0))
}

/// The scan in the PLY file at `path`: its `vertex` element.
pub fn read(path: &Path) -> Result<Scan, ReadError> {
    let file = File::open(path).map_err(|e| ReadError::io(path, &e))?;
    let mut reader = Reader::new(BufReader::new(file));
    let format_error = |e: &dyn std::fmt::Display| ReadError::Format {
        path: path.to_path_buf(),
        format: "PLY",
        message: e.to_string(),
    };
    let vertex_parser = Parser::<PlyVertex>::new();
    let header = vertex_parser.read_header(&mut reader).map_err(|e| format_error(&e))?;
    let Some(vertex_def) = header.elements.get("vertex") else {
        return Err(ReadError::malformed(
            path,
            "header",
            "elements",
            header.elements.keys().cloned().collect::<Vec<_>>().join(", "),
            "a vertex element",
        ));
    };
    let declared = declared(path, vertex_def)?;
    let pose = pose_from_comments(path, &header)?;
    // Elements come in header order: get past any before `vertex`.
    let skip_parser = Parser::<Skipped>::new();
    for (name, def) in &header.elements {
        if name == "vertex" {
            break;
        }
        skip_parser
            .read_payload_for_element(&mut reader, def, &header)
            .map_err(|e| format_error(&e))?;
    }
    // The vertices one at a time, straight into the scan's columns (no
    // intermediate vector of vertices: a 10⁷-point file needs only its scan).
    let count = vertex_def.count;
    let capacity = count.min(1 << 24);
    let mut positions = Vec::with_capacity(capacity);
    let mut normals = Vec::with_capacity(if declared.normals { capacity } else { 0 });
    let mut intensity = Vec::with_capacity(if declared.intensity { capacity } else { 0 });
    let mut colour = Vec::with_capacity(if declared.colour { capacity } else { 0 });
    let mut indices = Vec::with_capacity(if declared.grid { capacity } else { 0 });
    let mut line = String::new();
    for i in 0..count {
        let bad = |found: String| {
            ReadError::malformed(
                path,
                "element vertex",
                format!("entry {i} of {count}"),
                found,
                "each of the header's properties",
            )
        };
        let inner = reader.get_mut();
        let v = match header.encoding {
            Encoding::Ascii => {
                line.clear();
                if inner.read_line(&mut line).map_err(|e| ReadError::io(path, &e))? == 0 {
                    return Err(bad(END.into()));
                }
                vertex_parser.read_ascii_element(&line, vertex_def)
            }
            Encoding::BinaryLittleEndian => vertex_parser.read_little_endian_element(inner, vertex_def),
            Encoding::BinaryBigEndian => vertex_parser.read_big_endian_element(inner, vertex_def),
        }
        .map_err(|e| match e.kind() {
            std::io::ErrorKind::UnexpectedEof => bad(END.into()),
            _ => bad(e.to_string()),
        })?;
        positions.push(Vector3::from(v.position));
        if declared.normals {
            normals.push(Vector3::from(v.normal));
        }
        if declared.intensity {
            intensity.push(v.intensity);
        }
        if declared.colour {
            colour.push(v.colour);
        }
        if declared.grid {
            let (Ok(r), Ok(c)) = (u32::try_from(v.row), u32::try_from(v.col)) else {
                return Err(ReadError::malformed(
                    path,
                    format!("vertex {i}"),
                    "row/col",
                    format!("({}, {})", v.row, v.col),
                    "indices from 0",
                ));
            };
            indices.push((r, c));
        }
    }
    let mut scan = Scan::from_positions(stem(path), positions);
    scan.pose = pose;
    scan.normals = declared.normals.then_some(normals);
    scan.intensity = declared.intensity.then_some(intensity);
    scan.colour = declared.colour.then_some(colour);
    if declared.grid {
        let (rows, cols) = grid_size_from_comments(&header);
        scan.grid = Some(grid_from_indices(path, "element vertex", &indices, rows, cols)?);
    }
    checked(path, scan)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::read::{read_scan, validation_file};

    fn ply_file(dir: &tempfile::TempDir, name: &str, text: &str) -> std::path::PathBuf {
        let path = dir.path().join(name);
        std::fs::write(&path, text).unwrap();
        path
    }

    // PDAL's test data (validation/scans/README.md). The expected values
    // are the files' own headers and payload lines, and PDAL's
    // PlyReaderTest (ReadBinary, ReadTextExtraDims).
    #[test]
    fn cloudcompare_binary_ply_reads_its_three_points() {
        let scan = read(&validation_file("pdal-simple_binary.ply")).unwrap();
        // "element vertex 3"; PDAL's test: (-1, 0, 0), (0, 1, 0), (1, 0, 0).
        assert_eq!(
            scan.positions,
            vec![
                Vector3::new(-1.0, 0.0, 0.0),
                Vector3::new(0.0, 1.0, 0.0),
                Vector3::new(1.0, 0.0, 0.0)
            ]
        );
        assert!(scan.normals.is_none() && scan.colour.is_none() && scan.intensity.is_none() && scan.grid.is_none());
    }

    #[test]
    fn vcglib_ascii_ply_reads_position_normal_and_colour() {
        let scan = read(&validation_file("pdal-text_extradim.ply")).unwrap();
        assert_eq!(scan.len(), 1);
        // Payload: -2.64944 -13.0955 0.00640115 -0.0237552 -0.00902114 0.999665 63 200 64 255 1234
        // (float properties: compare at f32 precision).
        let p = scan.positions[0];
        assert!((p - Vector3::new(-2.64944, -13.0955, 0.00640115)).norm() < 1e-6, "{p}");
        let n = scan.normals.as_ref().unwrap()[0];
        assert!(
            (n - Vector3::new(-0.0237552, -0.00902114, 0.999665)).norm() < 1e-6,
            "{n}"
        );
        // uchar red, uchar green, and a signed `char` blue of 64.
        let c = scan.colour.as_ref().unwrap()[0];
        assert_eq!(c, [63.0 / 255.0, 200.0 / 255.0, 64.0 / 255.0]);
    }

    #[test]
    fn a_pdal_mesh_reads_as_its_vertices() {
        // "element vertex 4" then "element face 2": the faces are skipped.
        let scan = read(&validation_file("pdal-mesh.ply")).unwrap();
        assert_eq!(scan.len(), 4);
        assert_eq!(scan.positions[3], Vector3::new(2.0, 2.0, 2.0));
    }

    #[test]
    fn a_file_with_no_vertex_element_is_refused_naming_what_it_has() {
        let e = read_scan(&validation_file("pdal-no_vertex.ply")).unwrap_err();
        assert!(
            matches!(&e, ReadError::Malformed { element, expected, .. } if element == "header" && expected == "a vertex element"),
            "{e}"
        );
    }

    #[test]
    fn faces_before_the_vertices_are_skipped() {
        let dir = tempfile::tempdir().unwrap();
        let path = ply_file(
            &dir,
            "faces-first.ply",
            "ply\nformat ascii 1.0\nelement face 1\nproperty list uchar int vertex_indices\n\
             element vertex 3\nproperty float x\nproperty float y\nproperty float z\nproperty uchar intensity\nend_header\n\
             3 0 1 2\n0 0 0 0\n1 0 0 255\n0 1 0 51\n",
        );
        let scan = read(&path).unwrap();
        assert_eq!(scan.len(), 3);
        assert_eq!(scan.positions[2], Vector3::new(0.0, 1.0, 0.0));
        // uchar intensity over 255.
        assert_eq!(scan.intensity.unwrap(), vec![0.0, 1.0, 0.2]);
    }

    #[test]
    fn hard_inputs_are_clear_errors() {
        let dir = tempfile::tempdir().unwrap();
        let header = "ply\nformat ascii 1.0\nelement vertex 2\n";
        // A position declared as a list.
        let path = ply_file(
            &dir,
            "list-x.ply",
            &format!(
                "{header}property list uchar float x\nproperty float y\nproperty float z\nend_header\n1 0 0 0\n1 1 1 1\n"
            ),
        );
        let e = read(&path).unwrap_err();
        assert!(
            matches!(&e, ReadError::Malformed { field, expected, .. } if field == "property x" && expected == "a scalar"),
            "{e}"
        );
        // A face list whose count is declared float, before the vertices
        // (ply-rs refuses it while skipping the faces).
        let path = ply_file(
            &dir,
            "float-count.ply",
            "ply\nformat binary_little_endian 1.0\nelement face 1\nproperty list float int vertex_indices\n\
             element vertex 1\nproperty float x\nproperty float y\nproperty float z\nend_header\n\0\0\x40\x40\0\0\0\0",
        );
        let e = read(&path).unwrap_err();
        assert!(matches!(e, ReadError::Format { .. }), "{e}");
        // A grid index far beyond the points: refused, not allocated.
        let path = ply_file(
            &dir,
            "huge-grid.ply",
            &format!(
                "{header}property float x\nproperty float y\nproperty float z\nproperty int row\nproperty int col\nend_header\n0 0 0 0 0\n1 1 1 2000000000 2000000000\n"
            ),
        );
        let e = read(&path).unwrap_err();
        assert!(
            matches!(&e, ReadError::Malformed { field, .. } if field == "row/column"),
            "{e}"
        );
        // A float grid index.
        let path = ply_file(
            &dir,
            "float-row.ply",
            &format!(
                "{header}property float x\nproperty float y\nproperty float z\nproperty float row\nproperty float col\nend_header\n0 0 0 0 0\n1 1 1 0 1\n"
            ),
        );
        let e = read(&path).unwrap_err();
        assert!(
            matches!(&e, ReadError::Malformed { field, .. } if field == "property row"),
            "{e}"
        );
        // Two points in one grid cell.
        let path = ply_file(
            &dir,
            "same-cell.ply",
            &format!(
                "{header}property float x\nproperty float y\nproperty float z\nproperty int row\nproperty int col\nend_header\n0 0 0 1 1\n1 1 1 1 1\n"
            ),
        );
        let e = read(&path).unwrap_err();
        assert!(
            matches!(&e, ReadError::Malformed { element, .. } if element == "point 1"),
            "{e}"
        );
        // A negative grid index.
        let path = ply_file(
            &dir,
            "negative-row.ply",
            &format!(
                "{header}property float x\nproperty float y\nproperty float z\nproperty int row\nproperty int col\nend_header\n0 0 0 -1 0\n1 1 1 1 1\n"
            ),
        );
        let e = read(&path).unwrap_err();
        assert!(
            matches!(&e, ReadError::Malformed { element, .. } if element == "vertex 0"),
            "{e}"
        );
        // No z.
        let path = ply_file(
            &dir,
            "no-z.ply",
            &format!("{header}property float x\nproperty float y\nend_header\n0 0\n1 1\n"),
        );
        let e = read(&path).unwrap_err();
        assert!(
            matches!(&e, ReadError::Malformed { expected, .. } if expected == "x, y and z"),
            "{e}"
        );
        // A NaN coordinate: ascii "nan" is refused by the grammar, a
        // binary NaN by the scan's check, naming the point.
        let path = ply_file(
            &dir,
            "nan.ply",
            &format!("{header}property float x\nproperty float y\nproperty float z\nend_header\n0 0 0\n1 nan 1\n"),
        );
        let e = read(&path).unwrap_err();
        assert!(
            matches!(&e, ReadError::Malformed { field, .. } if field == "entry 1 of 2"),
            "{e}"
        );
        let path = dir.path().join("nan-binary.ply");
        let mut bytes =
            b"ply\nformat binary_big_endian 1.0\nelement vertex 2\nproperty float x\nproperty float y\nproperty float z\nend_header\n"
                .to_vec();
        for v in [0.0f32, 0.0, 0.0, 1.0, f32::NAN, 1.0] {
            bytes.extend(v.to_be_bytes());
        }
        std::fs::write(&path, bytes).unwrap();
        let e = read(&path).unwrap_err();
        assert!(
            matches!(
                &e,
                ReadError::Invalid {
                    source: crate::cloud::ScanError::NotFinite { point: 1, .. },
                    ..
                }
            ),
            "{e}"
        );
        // Fewer lines than the header promises.
        let path = ply_file(
            &dir,
            "short.ply",
            &format!("{header}property float x\nproperty float y\nproperty float z\nend_header\n0 0 0\n"),
        );
        let e = read(&path).unwrap_err();
        assert!(
            matches!(&e, ReadError::Malformed { field, found, .. } if field == "entry 1 of 2" && found == END),
            "{e}"
        );
        // A bad pose comment.
        let path = ply_file(
            &dir,
            "pose.ply",
            "ply\nformat ascii 1.0\ncomment campanile scanner_pose 1 2 3\nelement vertex 0\nproperty float x\nproperty float y\nproperty float z\nend_header\n",
        );
        let e = read(&path).unwrap_err();
        assert!(
            matches!(&e, ReadError::Malformed { field, .. } if field == "comment scanner_pose"),
            "{e}"
        );
        // A header and no points: an empty scan.
        let path = ply_file(
            &dir,
            "none.ply",
            "ply\nformat binary_little_endian 1.0\nelement vertex 0\nproperty float x\nproperty float y\nproperty float z\nend_header\n",
        );
        assert!(read(&path).unwrap().is_empty());
    }
}
