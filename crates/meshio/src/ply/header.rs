//! PLY header: format, elements and their properties, and the size check that runs before
//! anything is allocated.
//!
//! Reference: Greg Turk, "The PLY Polygon File Format" (1994), plus the common type aliases
//! (`int8` … `float64`) written by later tools.

use std::path::Path;

use crate::MeshIoError;
use crate::text::{Lines, tokens};

/// How the body is encoded.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Encoding {
    Ascii,
    BinaryLittleEndian,
    BinaryBigEndian,
}

/// A PLY scalar type.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Scalar {
    I8,
    U8,
    I16,
    U16,
    I32,
    U32,
    F32,
    F64,
}

impl Scalar {
    fn from_name(name: &[u8]) -> Option<Self> {
        Some(match name {
            b"char" | b"int8" => Self::I8,
            b"uchar" | b"uint8" => Self::U8,
            b"short" | b"int16" => Self::I16,
            b"ushort" | b"uint16" => Self::U16,
            b"int" | b"int32" => Self::I32,
            b"uint" | b"uint32" => Self::U32,
            b"float" | b"float32" => Self::F32,
            b"double" | b"float64" => Self::F64,
            _ => return None,
        })
    }

    /// Size in bytes in a binary body.
    pub(crate) fn size(self) -> usize {
        match self {
            Self::I8 | Self::U8 => 1,
            Self::I16 | Self::U16 => 2,
            Self::I32 | Self::U32 | Self::F32 => 4,
            Self::F64 => 8,
        }
    }

    pub(crate) fn is_integer(self) -> bool {
        !matches!(self, Self::F32 | Self::F64)
    }
}

/// A property: one scalar, or a list with a count type and an item type.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Kind {
    Scalar(Scalar),
    List { count: Scalar, item: Scalar },
}

#[derive(Clone, Debug)]
pub(crate) struct Property {
    pub name: String,
    pub kind: Kind,
}

#[derive(Clone, Debug)]
pub(crate) struct Element {
    pub name: String,
    pub count: u64,
    pub properties: Vec<Property>,
}

#[derive(Clone, Debug)]
pub(crate) struct Header {
    pub encoding: Encoding,
    pub elements: Vec<Element>,
    /// Byte offset of the body.
    pub body_start: usize,
    /// Line number of the body's first line (ASCII error messages).
    pub body_first_line: usize,
}

fn header_error(path: &Path, line: usize, message: impl Into<String>) -> MeshIoError {
    MeshIoError::InvalidHeader {
        path: path.to_path_buf(),
        line: Some(line),
        message: message.into(),
    }
}

fn text(bytes: &[u8]) -> String {
    crate::error::token_text(bytes)
}

/// Parses the header at the start of `data`.
pub(crate) fn parse_header(path: &Path, data: &[u8]) -> Result<Header, MeshIoError> {
    let mut lines = Lines::new(data, 1);
    let mut offset = 0usize;
    let mut next_line = |offset: &mut usize| {
        let (number, line) = lines.next()?;
        // Advance past the line and its terminator ("\n", or nothing at the end of data).
        let cr = usize::from(data.get(*offset + line.len()) == Some(&b'\r'));
        let after = *offset + line.len() + cr;
        *offset = after + usize::from(after < data.len());
        Some((number, line))
    };
    match next_line(&mut offset) {
        Some((_, b"ply")) => {}
        _ => {
            return Err(header_error(
                path,
                1,
                "the file does not start with the line \"ply\"; it is not a PLY file",
            ));
        }
    }
    let mut encoding = None;
    let mut elements: Vec<Element> = Vec::new();
    loop {
        let Some((number, line)) = next_line(&mut offset) else {
            return Err(MeshIoError::InvalidHeader {
                path: path.to_path_buf(),
                line: None,
                message: "no \"end_header\" line; the header is cut or the file is not PLY".into(),
            });
        };
        let words: Vec<&[u8]> = tokens(line).collect();
        match words.as_slice() {
            [] => {}
            [b"comment" | b"obj_info", ..] => {}
            [b"format", format, version] => {
                if *version != b"1.0" {
                    return Err(header_error(
                        path,
                        number,
                        format!("unsupported PLY version {}", text(version)),
                    ));
                }
                encoding = Some(match *format {
                    b"ascii" => Encoding::Ascii,
                    b"binary_little_endian" => Encoding::BinaryLittleEndian,
                    b"binary_big_endian" => Encoding::BinaryBigEndian,
                    other => {
                        return Err(header_error(
                            path,
                            number,
                            format!(
                                "unknown format {}; expected ascii, binary_little_endian or binary_big_endian",
                                text(other)
                            ),
                        ));
                    }
                });
            }
            [b"element", name, count] => {
                let count = crate::text::parse_u64(count).ok_or_else(|| {
                    header_error(
                        path,
                        number,
                        format!(
                            "element count {} is not a non-negative integer",
                            text(count)
                        ),
                    )
                })?;
                let name = text(name);
                if elements.iter().any(|e| e.name == name) {
                    return Err(header_error(
                        path,
                        number,
                        format!("element {name} is declared twice"),
                    ));
                }
                elements.push(Element {
                    name,
                    count,
                    properties: Vec::new(),
                });
            }
            [b"property", rest @ ..] => {
                let Some(element) = elements.last_mut() else {
                    return Err(header_error(path, number, "property before any element"));
                };
                let (kind, name) = parse_property(rest).ok_or_else(|| {
                    header_error(
                        path,
                        number,
                        format!("malformed property line {:?}", text(line)),
                    )
                })?;
                if element.properties.iter().any(|p| p.name == name) {
                    return Err(header_error(
                        path,
                        number,
                        format!(
                            "property {name} of element {} is declared twice",
                            element.name
                        ),
                    ));
                }
                element.properties.push(Property { name, kind });
            }
            [b"end_header"] => {
                let encoding = encoding.ok_or_else(|| {
                    header_error(path, number, "no \"format\" line before end_header")
                })?;
                return Ok(Header {
                    encoding,
                    elements,
                    body_start: offset,
                    body_first_line: number + 1,
                });
            }
            _ => {
                return Err(header_error(
                    path,
                    number,
                    format!("unrecognised header line {:?}", text(line)),
                ));
            }
        }
    }
}

fn parse_property(words: &[&[u8]]) -> Option<(Kind, String)> {
    match words {
        [b"list", count, item, name] => {
            let count = Scalar::from_name(count)?;
            let item = Scalar::from_name(item)?;
            count
                .is_integer()
                .then(|| (Kind::List { count, item }, text(name)))
        }
        [ty, name] => Some((Kind::Scalar(Scalar::from_name(ty)?), text(name))),
        _ => None,
    }
}

/// Minimum bytes one row of `element` occupies: binary, the fixed parts (a list counts only
/// its count); ASCII, one character plus one separator per property.
fn min_row_bytes(element: &Element, encoding: Encoding) -> u64 {
    match encoding {
        Encoding::Ascii => 2 * element.properties.len() as u64,
        _ => element
            .properties
            .iter()
            .map(|p| match p.kind {
                Kind::Scalar(s) => s.size() as u64,
                Kind::List { count, .. } => count.size() as u64,
            })
            .sum(),
    }
}

/// Checks that the declared element counts fit into `body_len` bytes, before any allocation:
/// a header that claims 2⁴⁰ vertices fails here instead of in the allocator.
pub(crate) fn check_sizes(
    path: &Path,
    header: &Header,
    body_len: usize,
) -> Result<(), MeshIoError> {
    let available = body_len as u64;
    // The last ASCII row may lack its final separator.
    let slack = u64::from(header.encoding == Encoding::Ascii);
    let mut needed_total: u64 = 0;
    for element in &header.elements {
        let row = min_row_bytes(element, header.encoding);
        let needed = element.count.saturating_mul(row);
        needed_total = needed_total.saturating_add(needed);
        if needed_total > available.saturating_add(slack) {
            return Err(MeshIoError::CountTooLarge {
                path: path.to_path_buf(),
                element: format!("element {}", element.name),
                count: element.count,
                bytes_needed: needed_total.saturating_sub(slack),
                bytes_available: available,
            });
        }
    }
    Ok(())
}
