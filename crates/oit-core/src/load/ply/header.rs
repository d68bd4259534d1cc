//! A PLY header: the format, and each element with its count and properties (scalars of every
//! type, lists of any count and item type).

use std::io::Read;

use crate::load::text::Text;

#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Scalar {
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
    pub fn from_name(name: &[u8]) -> Option<Self> {
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

    pub fn size(self) -> u64 {
        match self {
            Self::I8 | Self::U8 => 1,
            Self::I16 | Self::U16 => 2,
            Self::I32 | Self::U32 | Self::F32 => 4,
            Self::F64 => 8,
        }
    }

    /// The largest value of an integer type (colors scale by it); None for floats.
    pub fn unit(self) -> Option<f64> {
        match self {
            Self::I8 => Some(127.0),
            Self::U8 => Some(255.0),
            Self::I16 => Some(32767.0),
            Self::U16 => Some(65535.0),
            Self::I32 => Some(i32::MAX as f64),
            Self::U32 => Some(u32::MAX as f64),
            Self::F32 | Self::F64 => None,
        }
    }
}

#[derive(Clone, Copy, Debug, PartialEq)]
pub enum PropertyKind {
    Scalar(Scalar),
    List { count: Scalar, item: Scalar },
}

pub struct Element {
    pub name: String,
    pub count: u64,
    pub props: Vec<(String, PropertyKind)>,
}

impl Element {
    pub fn find(&self, names: &[&str]) -> Option<usize> {
        names.iter().find_map(|n| self.props.iter().position(|(p, k)| p == n && matches!(k, PropertyKind::Scalar(_))))
    }

    pub fn scalar(&self, i: usize) -> Scalar {
        match self.props[i].1 {
            PropertyKind::Scalar(s) => s,
            PropertyKind::List { item, .. } => item,
        }
    }

    /// The fewest bytes an item takes: binary, its scalars and list counts; ASCII, one a value.
    pub fn min_bytes(&self, format: Format) -> u64 {
        self.props
            .iter()
            .map(|(_, k)| match (format, k) {
                (Format::Ascii, _) => 1,
                (_, PropertyKind::Scalar(s)) => s.size(),
                (_, PropertyKind::List { count, .. }) => count.size(),
            })
            .sum()
    }
}

#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Format {
    Ascii,
    Little,
    Big,
}

/// The header, read up to its `end_header` line.
pub fn header<R: Read>(input: &mut Text<R>) -> Result<(Format, Vec<Element>), String> {
    let bad = |line: usize, e: &str| format!("header line {line}: {e}");
    match header_line(input)? {
        Some(b"ply") => {}
        _ => return Err("not a PLY file: it does not start with 'ply'".into()),
    }
    let mut format = None;
    let mut elements: Vec<Element> = Vec::new();
    loop {
        let n = input.line_number;
        let Some(line) = header_line(input)? else { return Err("the header has no 'end_header'".into()) };
        let mut t = line.split(|b| b.is_ascii_whitespace()).filter(|w| !w.is_empty());
        match t.next() {
            None | Some(b"comment" | b"obj_info") => {}
            Some(b"format") => {
                format = Some(match t.next() {
                    Some(b"ascii") => Format::Ascii,
                    Some(b"binary_little_endian") => Format::Little,
                    Some(b"binary_big_endian") => Format::Big,
                    _ => return Err(bad(n, "the format is none of ascii, binary_little_endian, binary_big_endian")),
                })
            }
            Some(b"element") => {
                let name = t.next().ok_or_else(|| bad(n, "an element needs a name and a count"))?;
                let count = t.next().and_then(|c| std::str::from_utf8(c).ok()?.parse::<u64>().ok());
                let count = count.ok_or_else(|| bad(n, "an element's count must be a whole number >= 0"))?;
                elements.push(Element { name: String::from_utf8_lossy(name).into_owned(), count, props: Vec::new() });
            }
            Some(b"property") => {
                let e = elements.last_mut().ok_or_else(|| bad(n, "a property comes before any element"))?;
                let ty = t.next().ok_or_else(|| bad(n, "a property needs a type and a name"))?;
                let kind = if ty == b"list" {
                    let count = t.next().and_then(Scalar::from_name);
                    let item = t.next().and_then(Scalar::from_name);
                    match (count, item) {
                        (Some(count), Some(item)) if !matches!(count, Scalar::F32 | Scalar::F64) => PropertyKind::List { count, item },
                        _ => return Err(bad(n, "a list property needs an integer count type and an item type")),
                    }
                } else {
                    let name = String::from_utf8_lossy(ty).chars().take(20).collect::<String>();
                    PropertyKind::Scalar(Scalar::from_name(ty).ok_or_else(|| bad(n, &format!("unknown property type '{name}'")))?)
                };
                let name = t.next().ok_or_else(|| bad(n, "a property needs a name"))?;
                e.props.push((String::from_utf8_lossy(name).into_owned(), kind));
            }
            Some(b"end_header") => break,
            Some(w) => {
                let w: String = String::from_utf8_lossy(w).chars().take(20).collect();
                return Err(bad(n, &format!("'{w}' is not a PLY header keyword")));
            }
        }
    }
    Ok((format.ok_or("the header has no 'format' line")?, elements))
}

/// A header line without its end: its LF and a CR before it (None at the end of the file).
fn header_line<R: Read>(input: &mut Text<R>) -> Result<Option<&[u8]>, String> {
    let line = input.line().map_err(|e| format!("cannot read it ({e})"))?;
    Ok(line.map(|l| match l.strip_suffix(b"\n") {
        Some(l) => l.strip_suffix(b"\r").unwrap_or(l),
        None => l,
    }))
}
