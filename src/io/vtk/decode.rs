//! Decoding of `<DataArray>` contents: ASCII, base64 (inline or appended),
//! raw appended bytes, zlib blocks, either byte order and header width.

use super::xml::Element;
use crate::io::IoError;
use base64::Engine;
use std::io::Read;
use std::path::Path;

/// Decoded values of a data array.
pub(super) enum Values {
    /// Integer values.
    Ints(Vec<i64>),
    /// Floating-point values.
    Floats(Vec<f64>),
}

impl Values {
    pub(super) fn len(&self) -> usize {
        match self {
            Values::Ints(v) => v.len(),
            Values::Floats(v) => v.len(),
        }
    }
}

/// How the binary parts of the file are laid out.
pub(super) struct Layout<'a> {
    pub(super) path: &'a Path,
    pub(super) big_endian: bool,
    pub(super) header64: bool,
    pub(super) compressed: bool,
    pub(super) appended: Option<&'a [u8]>,
    pub(super) appended_base64: bool,
}

#[derive(Clone, Copy, PartialEq)]
enum Scalar {
    I8,
    U8,
    I16,
    U16,
    I32,
    U32,
    I64,
    U64,
    F32,
    F64,
}

impl Scalar {
    fn parse(s: &str) -> Option<Scalar> {
        Some(match s {
            "Int8" | "Char" => Scalar::I8,
            "UInt8" | "UnsignedChar" => Scalar::U8,
            "Int16" | "Short" => Scalar::I16,
            "UInt16" | "UnsignedShort" => Scalar::U16,
            "Int32" | "Int" => Scalar::I32,
            "UInt32" | "UnsignedInt" => Scalar::U32,
            "Int64" | "Long" | "LongLong" | "IdType" => Scalar::I64,
            "UInt64" | "UnsignedLong" | "UnsignedLongLong" => Scalar::U64,
            "Float32" | "Float" => Scalar::F32,
            "Float64" | "Double" => Scalar::F64,
            _ => return None,
        })
    }

    fn size(self) -> usize {
        match self {
            Scalar::I8 | Scalar::U8 => 1,
            Scalar::I16 | Scalar::U16 => 2,
            Scalar::I32 | Scalar::U32 | Scalar::F32 => 4,
            Scalar::I64 | Scalar::U64 | Scalar::F64 => 8,
        }
    }

    fn is_float(self) -> bool {
        matches!(self, Scalar::F32 | Scalar::F64)
    }
}

/// Decodes base64 that may be several independently padded pieces.
fn base64_pieces(text: &[u8]) -> Option<Vec<u8>> {
    let clean: Vec<u8> = text
        .iter()
        .copied()
        .filter(|c| !c.is_ascii_whitespace())
        .collect();
    let b64 = base64::engine::general_purpose::STANDARD;
    let mut out = Vec::with_capacity(clean.len() / 4 * 3);
    let mut start = 0;
    let mut i = 0;
    while i < clean.len() {
        if clean[i] == b'=' {
            while i < clean.len() && clean[i] == b'=' {
                i += 1;
            }
            out.extend(b64.decode(&clean[start..i]).ok()?);
            start = i;
        } else {
            i += 1;
        }
    }
    if start < clean.len() {
        out.extend(b64.decode(&clean[start..]).ok()?);
    }
    Some(out)
}

impl Layout<'_> {
    fn uint(&self, b: &[u8]) -> u64 {
        let mut a = [0u8; 8];
        let n = b.len();
        a[..n].copy_from_slice(b);
        if self.big_endian {
            a[..n].reverse();
        }
        u64::from_le_bytes(a)
    }

    /// The array bytes after the header (decompressed), from a stream that
    /// starts with the header, and the number of stream bytes the array
    /// takes (header included).
    fn unpack(&self, s: &[u8], err: &dyn Fn(&str) -> IoError) -> Result<(Vec<u8>, usize), IoError> {
        let h = if self.header64 { 8 } else { 4 };
        let word = |i: usize| -> Result<u64, IoError> {
            s.get(i * h..(i + 1) * h)
                .map(|w| self.uint(w))
                .ok_or_else(|| err("data ends inside the array header (truncated?)"))
        };
        if !self.compressed {
            let n = word(0)? as usize;
            return s
                .get(h..h.saturating_add(n))
                .map(|d| (d.to_vec(), h + n))
                .ok_or_else(|| {
                    err(&format!(
                        "array announces {n} bytes but fewer follow (truncated?)"
                    ))
                });
        }
        let blocks = word(0)? as usize;
        let block = word(1)? as usize;
        let last = word(2)? as usize;
        if blocks > 0 && (block == 0 || last > block) {
            return Err(err(&format!(
                "compressed array header gives blocks of {block} bytes and a last block of {last} (corrupt header)"
            )));
        }
        if blocks > s.len() / h {
            return Err(err(&format!(
                "{blocks} compressed blocks cannot fit the data (corrupt header)"
            )));
        }
        let mut sizes = Vec::with_capacity(blocks);
        for i in 0..blocks {
            sizes.push(word(3 + i)? as usize);
        }
        let mut at = (3 + blocks) * h;
        let total = if blocks == 0 {
            0
        } else {
            block
                .saturating_mul(blocks - 1)
                .saturating_add(if last == 0 { block } else { last })
        };
        if total > s.len().saturating_mul(1100).saturating_add(1 << 20) {
            return Err(err(
                "compressed array header announces an impossible size (corrupt)",
            ));
        }
        let mut out = Vec::with_capacity(total.min(s.len().saturating_mul(8)));
        for (i, &cs) in sizes.iter().enumerate() {
            let want = if i + 1 == blocks && last != 0 {
                last
            } else {
                block
            };
            let src = s.get(at..at.saturating_add(cs)).ok_or_else(|| {
                err("compressed block runs past the end of the data (truncated?)")
            })?;
            let before = out.len();
            flate2::read::ZlibDecoder::new(src)
                .take(want as u64 + 1)
                .read_to_end(&mut out)
                .map_err(|e| err(&format!("cannot decompress block {}: {e}", i + 1)))?;
            if out.len() - before != want {
                return Err(err(&format!(
                    "compressed block {} holds {} bytes, not {want}",
                    i + 1,
                    out.len() - before
                )));
            }
            at += cs;
        }
        Ok((out, at))
    }

    /// The number of bytes the raw appended array at the start of `s` takes,
    /// header included, from its header alone.
    pub(super) fn raw_extent(&self, s: &[u8]) -> Result<usize, String> {
        let h = if self.header64 { 8 } else { 4 };
        let word = |i: usize| -> Result<u64, String> {
            s.get(i * h..(i + 1) * h)
                .map(|w| self.uint(w))
                .ok_or_else(|| "the appended data ends inside its header (truncated?)".to_string())
        };
        let total = if self.compressed {
            let blocks = word(0)?;
            if blocks > (s.len() / h) as u64 {
                return Err(format!(
                    "its header announces {blocks} compressed blocks, more than the data can hold"
                ));
            }
            let mut t = (3 + blocks) * h as u64;
            for i in 0..blocks as usize {
                t = t.saturating_add(word(3 + i)?);
            }
            t
        } else {
            (h as u64).saturating_add(word(0)?)
        };
        if total > s.len() as u64 {
            return Err(format!(
                "its header announces {total} bytes but only {} are left in the appended data (truncated or corrupt)",
                s.len()
            ));
        }
        Ok(total as usize)
    }

    /// Values of a DataArray element.
    pub(super) fn values(&self, e: &Element) -> Result<(Values, usize), IoError> {
        let err = |m: &str| match e.attr("Name") {
            Some(n) => IoError::at(self.path, e.line, format!("DataArray '{n}': {m}")),
            None => IoError::at(self.path, e.line, format!("DataArray: {m}")),
        };
        let ty = e.attr("type").ok_or_else(|| err("no type attribute"))?;
        let scalar = Scalar::parse(ty).ok_or_else(|| err(&format!("unsupported type '{ty}'")))?;
        let comps = match e.attr("NumberOfComponents") {
            Some(s) => s
                .trim()
                .parse::<usize>()
                .ok()
                .filter(|&c| c >= 1)
                .ok_or_else(|| err(&format!("bad NumberOfComponents '{s}'")))?,
            None => 1,
        };
        let format = e.attr("format").unwrap_or("ascii");
        if format == "ascii" {
            let toks = e.text.split_ascii_whitespace();
            let v = if scalar.is_float() {
                Values::Floats(
                    toks.map(|t| {
                        t.parse::<f64>().map_err(|_| {
                            err(&format!(
                                "'{}' is not a number",
                                t.chars().take(24).collect::<String>()
                            ))
                        })
                    })
                    .collect::<Result<_, _>>()?,
                )
            } else {
                Values::Ints(
                    toks.map(|t| {
                        t.parse::<i64>().map_err(|_| {
                            err(&format!(
                                "'{}' is not an integer",
                                t.chars().take(24).collect::<String>()
                            ))
                        })
                    })
                    .collect::<Result<_, _>>()?,
                )
            };
            return Ok((v, comps));
        }
        let raw = match format {
            "binary" => {
                let bytes =
                    base64_pieces(e.text.as_bytes()).ok_or_else(|| err("invalid base64 data"))?;
                let (raw, used) = self.unpack(&bytes, &err)?;
                if used != bytes.len() {
                    return Err(err(&format!(
                        "its header announces {used} bytes but the element holds {} (corrupt header or data)",
                        bytes.len()
                    )));
                }
                raw
            }
            "appended" => {
                let app = self
                    .appended
                    .ok_or_else(|| err("format 'appended' but the file has no AppendedData"))?;
                let off: usize = e
                    .attr("offset")
                    .and_then(|s| s.trim().parse().ok())
                    .ok_or_else(|| err("appended array without a valid offset"))?;
                let s = app.get(off..).ok_or_else(|| {
                    err(&format!(
                        "offset {off} is past the end of the appended data (truncated?)"
                    ))
                })?;
                if self.appended_base64 {
                    let end = s.iter().position(|&c| c == b'<').unwrap_or(s.len());
                    let bytes =
                        base64_pieces(&s[..end]).ok_or_else(|| err("invalid base64 data"))?;
                    self.unpack(&bytes, &err)?.0
                } else {
                    self.unpack(s, &err)?.0
                }
            }
            other => return Err(err(&format!("unknown format '{other}'"))),
        };
        let size = scalar.size();
        if raw.len() % size != 0 {
            return Err(err(&format!(
                "{} bytes is not a whole number of {ty} values",
                raw.len()
            )));
        }
        let word = |c: &[u8]| {
            let mut a = [0u8; 8];
            a[..size].copy_from_slice(c);
            if self.big_endian {
                a[..size].reverse();
            }
            a
        };
        let chunks = raw.chunks_exact(size);
        let v = match scalar {
            Scalar::F32 => Values::Floats(
                chunks
                    .map(|c| f32::from_le_bytes(word(c)[..4].try_into().unwrap_or([0; 4])) as f64)
                    .collect(),
            ),
            Scalar::F64 => Values::Floats(chunks.map(|c| f64::from_le_bytes(word(c))).collect()),
            Scalar::I8 => Values::Ints(chunks.map(|c| c[0] as i8 as i64).collect()),
            Scalar::U8 => Values::Ints(chunks.map(|c| c[0] as i64).collect()),
            Scalar::I16 => Values::Ints(
                chunks
                    .map(|c| i16::from_le_bytes([word(c)[0], word(c)[1]]) as i64)
                    .collect(),
            ),
            Scalar::U16 => Values::Ints(
                chunks
                    .map(|c| u16::from_le_bytes([word(c)[0], word(c)[1]]) as i64)
                    .collect(),
            ),
            Scalar::I32 => Values::Ints(
                chunks
                    .map(|c| i32::from_le_bytes(word(c)[..4].try_into().unwrap_or([0; 4])) as i64)
                    .collect(),
            ),
            Scalar::U32 => Values::Ints(
                chunks
                    .map(|c| u32::from_le_bytes(word(c)[..4].try_into().unwrap_or([0; 4])) as i64)
                    .collect(),
            ),
            Scalar::I64 => Values::Ints(chunks.map(|c| i64::from_le_bytes(word(c))).collect()),
            Scalar::U64 => {
                let v: Vec<u64> = chunks.map(|c| u64::from_le_bytes(word(c))).collect();
                if v.iter().any(|&x| x > i64::MAX as u64) {
                    return Err(err("UInt64 value too large"));
                }
                Values::Ints(v.into_iter().map(|x| x as i64).collect())
            }
        };
        Ok((v, comps))
    }
}
