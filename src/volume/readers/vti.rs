//! VTK XML ImageData (`.vti`).
//!
//! The XML part is parsed with `quick-xml`; raw appended data (after `<AppendedData
//! encoding="raw">` and its `_` marker) is binary and is located by byte offset before the
//! XML parser sees the file. Supported: data arrays in `format="binary"` (inline base64),
//! `"appended"` (raw or base64) and `"ascii"`; `header_type` UInt32 or UInt64; no
//! compressor or `vtkZLibDataCompressor`. A compressed array starts with the block header
//! `[n_blocks, block_size, last_block_size, compressed_size_0 … n-1]` and the zlib blocks
//! are inflated in parallel straight into their place in the output. Several pieces are
//! assembled into the whole extent. VTK has no patient frame: positions are taken as
//! Focal world coordinates as they are (`Origin + Direction · (Spacing ⊙ index)`).

use std::path::Path;

use base64::Engine;
use base64::engine::general_purpose::STANDARD;
use glam::{Mat3, UVec3, Vec3};
use quick_xml::Reader;
use quick_xml::events::{BytesStart, Event};
use rayon::prelude::*;

use super::common::{
    Problem, ReadError, ReadOptions, encode, file_len, first_component, inflate_zlib, parse_n, parse_numbers, volume_name,
};
use crate::volume::encode::{ByteOrder, SampleType, encode_values};
use crate::volume::{Grid, Source, Volume};

#[derive(Debug, Default)]
struct Array {
    ty: String,
    name: String,
    format: String,
    components: usize,
    offset: Option<usize>,
    text: String,
}

#[derive(Debug)]
struct Piece {
    extent: [i64; 6],
    /// The scalar array of the piece's point data.
    array: Option<Array>,
    scalars: Option<String>,
    others: Vec<Array>,
}

#[derive(Debug, Default)]
struct Document {
    byte_order: Option<String>,
    header_type: Option<String>,
    compressor: Option<String>,
    kind: Option<String>,
    whole_extent: Option<[i64; 6]>,
    origin: Option<Vec3>,
    spacing: Option<Vec3>,
    direction: Option<Mat3>,
    pieces: Vec<Piece>,
    appended_encoding: Option<String>,
}

fn attr(e: &BytesStart, name: &str) -> Option<String> {
    e.attributes().flatten().find(|a| a.key.as_ref() == name.as_bytes()).map(|a| String::from_utf8_lossy(&a.value).into_owned())
}

fn extent(text: &str) -> Result<[i64; 6], Problem> {
    let v: Vec<i64> = parse_n("Extent", text, 6)?;
    let e = [v[0], v[1], v[2], v[3], v[4], v[5]];
    if e[1] < e[0] || e[3] < e[2] || e[5] < e[4] {
        return Err(Problem::Malformed(format!("extent {text} is empty")));
    }
    Ok(e)
}

fn vec3(field: &str, text: &str) -> Result<Vec3, Problem> {
    let v: Vec<f32> = parse_n(field, text, 3)?;
    if v.iter().any(|x| !x.is_finite()) {
        return Err(Problem::Malformed(format!("{field} '{text}' is not finite")));
    }
    Ok(Vec3::new(v[0], v[1], v[2]))
}

fn parse_document(xml: &str) -> Result<Document, Problem> {
    let mut reader = Reader::from_str(xml);
    let mut doc = Document::default();
    let mut in_point_data = false;
    let mut current: Option<Array> = None;
    let mut saw_root = false;
    loop {
        let event = reader.read_event().map_err(|e| Problem::Malformed(format!("XML: {e}")))?;
        let (start, empty) = match &event {
            Event::Start(e) => (Some(e), false),
            Event::Empty(e) => (Some(e), true),
            _ => (None, false),
        };
        if let Some(e) = start {
            let name = e.name();
            {
                match name.as_ref() {
                    b"VTKFile" => {
                        saw_root = true;
                        doc.kind = attr(e, "type");
                        doc.byte_order = attr(e, "byte_order");
                        doc.header_type = attr(e, "header_type");
                        doc.compressor = attr(e, "compressor");
                    }
                    b"ImageData" => {
                        doc.whole_extent = attr(e, "WholeExtent").map(|t| extent(&t)).transpose()?;
                        doc.origin = attr(e, "Origin").map(|t| vec3("Origin", &t)).transpose()?;
                        doc.spacing = attr(e, "Spacing").map(|t| vec3("Spacing", &t)).transpose()?;
                        doc.direction = attr(e, "Direction")
                            .map(|t| parse_n::<f32>("Direction", &t, 9).map(|m| Mat3::from_cols_slice(&m).transpose()))
                            .transpose()?;
                    }
                    b"Piece" => {
                        let ext = attr(e, "Extent").ok_or_else(|| Problem::Malformed("Piece has no Extent".into()))?;
                        doc.pieces.push(Piece { extent: extent(&ext)?, array: None, scalars: None, others: Vec::new() });
                    }
                    b"PointData" => {
                        in_point_data = true;
                        if let Some(p) = doc.pieces.last_mut() {
                            p.scalars = attr(e, "Scalars");
                        }
                    }
                    b"DataArray" if in_point_data => {
                        let array = Array {
                            ty: attr(e, "type").unwrap_or_default(),
                            name: attr(e, "Name").unwrap_or_default(),
                            format: attr(e, "format").unwrap_or_else(|| "ascii".into()),
                            components: attr(e, "NumberOfComponents").and_then(|c| c.trim().parse().ok()).unwrap_or(1),
                            offset: attr(e, "offset").and_then(|o| o.trim().parse().ok()),
                            text: String::new(),
                        };
                        if empty {
                            store(&mut doc, array);
                        } else {
                            current = Some(array);
                        }
                    }
                    b"AppendedData" => doc.appended_encoding = attr(e, "encoding"),
                    _ => {}
                }
            }
            continue;
        }
        match event {
            Event::Text(t) => {
                if let Some(a) = current.as_mut() {
                    a.text.push_str(&String::from_utf8_lossy(&t));
                }
            }
            Event::End(e) => match e.name().as_ref() {
                b"DataArray" => {
                    if let Some(a) = current.take() {
                        store(&mut doc, a);
                    }
                }
                b"PointData" => in_point_data = false,
                _ => {}
            },
            Event::Eof => break,
            _ => {}
        }
    }
    if !saw_root {
        return Err(Problem::NotFormat { format: "VTK XML", detail: "no <VTKFile> element".into() });
    }
    Ok(doc)
}

fn store(doc: &mut Document, array: Array) {
    if let Some(p) = doc.pieces.last_mut() {
        if p.array.is_none() && p.scalars.as_deref().is_none_or(|s| s == array.name) {
            p.array = Some(array);
        } else {
            p.others.push(array);
        }
    }
}

fn sample_type(name: &str) -> Result<SampleType, Problem> {
    Ok(match name {
        "Int8" | "Char" => SampleType::I8,
        "UInt8" | "UnsignedChar" => SampleType::U8,
        "Int16" | "Short" => SampleType::I16,
        "UInt16" | "UnsignedShort" => SampleType::U16,
        "Int32" | "Int" => SampleType::I32,
        "UInt32" | "UnsignedInt" => SampleType::U32,
        "Int64" | "Long" | "LongLong" => SampleType::I64,
        "UInt64" | "UnsignedLong" | "UnsignedLongLong" => SampleType::U64,
        "Float32" | "Float" => SampleType::F32,
        "Float64" | "Double" => SampleType::F64,
        "" => return Err(Problem::Malformed("DataArray has no type".into())),
        other => return Err(Problem::Unsupported(format!("DataArray type {other}"))),
    })
}

/// Reads a `.vti` file.
pub fn read(path: &Path, options: &ReadOptions) -> Result<Volume, ReadError> {
    let fail = |p: Problem| ReadError::new(path, p);
    let size = file_len(path)?;
    if size > options.max_bytes.saturating_mul(2).saturating_add(1 << 20) {
        return Err(fail(Problem::TooLarge(format!("a {size}-byte file"))));
    }
    let bytes = std::fs::read(path).map_err(|e| fail(Problem::Io(e)))?;
    options.count_whole(size);
    // The XML part ends where raw appended data begins.
    let appended_at = find(&bytes, b"<AppendedData");
    let xml_end = appended_at.map(|a| find(&bytes[a..], b">").map(|e| a + e + 1).unwrap_or(bytes.len())).unwrap_or(bytes.len());
    let xml = String::from_utf8_lossy(&bytes[..xml_end]);
    let doc = parse_document(&xml).map_err(fail)?;
    let appended = appended_at.map(|_| {
        let rest = &bytes[xml_end..];
        let start = find(rest, b"_").map(|u| xml_end + u + 1).unwrap_or(bytes.len());
        &bytes[start..]
    });

    if doc.kind.as_deref() != Some("ImageData") {
        return Err(fail(Problem::Unsupported(format!("VTK file type {:?} (only ImageData)", doc.kind.unwrap_or_default()))));
    }
    let order = match doc.byte_order.as_deref() {
        Some("BigEndian") => ByteOrder::Big,
        _ => ByteOrder::Little,
    };
    let header_size = match doc.header_type.as_deref() {
        None | Some("UInt32") => 4,
        Some("UInt64") => 8,
        Some(other) => return Err(fail(Problem::Unsupported(format!("header_type {other}")))),
    };
    let compressed = match doc.compressor.as_deref() {
        None | Some("") => false,
        Some("vtkZLibDataCompressor") => true,
        Some(other) => return Err(fail(Problem::Unsupported(format!("compressor {other} (only zlib)")))),
    };
    let whole = doc.whole_extent.ok_or_else(|| fail(Problem::Malformed("ImageData has no WholeExtent".into())))?;
    let wdims = [whole[1] - whole[0] + 1, whole[3] - whole[2] + 1, whole[5] - whole[4] + 1].map(|d| d as u64);
    if doc.pieces.is_empty() {
        return Err(fail(Problem::Malformed("no Piece".into())));
    }
    let first = doc.pieces[0].array.as_ref().ok_or_else(|| fail(Problem::Malformed("no point data array".into())))?;
    let ty = sample_type(&first.ty).map_err(fail)?;
    let components = first.components.max(1);
    let (dims, _) = options.check_size(wdims, ty.size()).map_err(fail)?;
    let (_, whole_len) = options.check_size([wdims[0] * components as u64, wdims[1], wdims[2]], ty.size()).map_err(fail)?;
    let ctx = Decode { order, header_size, compressed, appended, appended_base64: doc.appended_encoding.as_deref() == Some("base64") };

    let mut data = if doc.pieces.len() == 1 { Vec::new() } else { vec![0u8; whole_len] };
    for piece in &doc.pieces {
        let array = piece.array.as_ref().ok_or_else(|| fail(Problem::Malformed("a Piece has no point data array".into())))?;
        if array.ty != first.ty || array.components != first.components {
            return Err(fail(Problem::Malformed("pieces disagree on the array type".into())));
        }
        let e = piece.extent;
        if e[0] < whole[0] || e[1] > whole[1] || e[2] < whole[2] || e[3] > whole[3] || e[4] < whole[4] || e[5] > whole[5] {
            return Err(fail(Problem::Malformed("a Piece extent lies outside the WholeExtent".into())));
        }
        let pdims = [e[1] - e[0] + 1, e[3] - e[2] + 1, e[5] - e[4] + 1].map(|d| d as usize);
        let sample = ty.size() * components;
        let plen = pdims[0] * pdims[1] * pdims[2] * sample;
        let bytes = ctx.decode(array, plen, ty).map_err(fail)?;
        if doc.pieces.len() == 1 {
            data = bytes;
            break;
        }
        let row = pdims[0] * sample;
        for z in 0..pdims[2] {
            for y in 0..pdims[1] {
                let src = (z * pdims[1] + y) * row;
                let (wx, wy, wz) = ((e[0] - whole[0]) as usize, (e[2] - whole[2]) as usize + y, (e[4] - whole[4]) as usize + z);
                let dst = ((wz * wdims[1] as usize + wy) * wdims[0] as usize + wx) * sample;
                data[dst..dst + row].copy_from_slice(&bytes[src..src + row]);
            }
        }
    }
    let encoded = if first.format == "ascii" {
        let values: Vec<f64> = parse_numbers("ascii DataArray", &String::from_utf8_lossy(&data)).map_err(fail)?;
        encode_values(&values, ty).map_err(|e| fail(Problem::Values(e)))?
    } else {
        encode(data, ty, order).map_err(fail)?
    };
    let encoded = if components > 1 { first_component(encoded, components) } else { encoded };

    let spacing = doc.spacing.unwrap_or(Vec3::ONE);
    let direction = doc.direction.unwrap_or(Mat3::IDENTITY);
    let axes = direction * Mat3::from_diagonal(spacing);
    let lo = Vec3::new(whole[0] as f32, whole[2] as f32, whole[4] as f32);
    let origin = doc.origin.unwrap_or(Vec3::ZERO) + axes * lo;
    let grid = Grid::from_axes(UVec3::new(dims.x, dims.y, dims.z), axes, origin)
        .map_err(|e| fail(Problem::Malformed(format!("geometry: {e}"))))?;
    let mut details = vec![("array".to_string(), first.name.clone()), ("format".to_string(), first.format.clone())];
    if compressed {
        details.push(("compression".into(), "zlib".into()));
    }
    if components > 1 {
        details.push(("note".into(), format!("{components} components per point: showing the first")));
    }
    let source = Source { format: "VTK ImageData".into(), path: Some(path.to_path_buf()), sample_type: ty.name().into(), details };
    Volume::new(volume_name(path), grid, encoded.voxels, encoded.map, source).map_err(|e| fail(Problem::Malformed(e)))
}

fn find(hay: &[u8], needle: &[u8]) -> Option<usize> {
    hay.windows(needle.len()).position(|w| w == needle)
}

/// How arrays are stored in this file.
struct Decode<'a> {
    order: ByteOrder,
    header_size: usize,
    compressed: bool,
    appended: Option<&'a [u8]>,
    appended_base64: bool,
}

impl Decode<'_> {
    fn uint(&self, b: &[u8]) -> u64 {
        let mut a = [0u8; 8];
        a[..b.len()].copy_from_slice(b);
        if self.order == ByteOrder::Big {
            a[..b.len()].reverse();
        }
        u64::from_le_bytes(a)
    }

    /// Decodes one array to exactly `len` bytes (or, for ascii, its text).
    fn decode(&self, array: &Array, len: usize, ty: SampleType) -> Result<Vec<u8>, Problem> {
        match array.format.as_str() {
            "ascii" => {
                let _ = ty;
                Ok(array.text.clone().into_bytes())
            }
            "binary" => {
                let text: String = array.text.chars().filter(|c| !c.is_whitespace()).collect();
                self.decode_base64(text.as_bytes(), len)
            }
            "appended" => {
                let data = self.appended.ok_or_else(|| Problem::Malformed("appended array but no AppendedData".into()))?;
                let offset = array.offset.ok_or_else(|| Problem::Malformed("appended array has no offset".into()))?;
                let data = data.get(offset..).ok_or_else(|| Problem::Truncated(format!("appended data ends before offset {offset}")))?;
                if self.appended_base64 { self.decode_base64(data, len) } else { self.decode_binary(data, len) }
            }
            other => Err(Problem::Unsupported(format!("DataArray format '{other}'"))),
        }
    }

    /// Header and data in raw bytes.
    fn decode_binary(&self, data: &[u8], len: usize) -> Result<Vec<u8>, Problem> {
        let hs = self.header_size;
        let need = |n: usize| data.get(..n).ok_or_else(|| Problem::Truncated("data ends inside an array header".into()));
        if !self.compressed {
            let n = self.uint(need(hs)?) as usize;
            if n != len {
                return Err(Problem::Malformed(format!("array holds {n} bytes, the extent needs {len}")));
            }
            return data
                .get(hs..hs + len)
                .map(<[u8]>::to_vec)
                .ok_or_else(|| Problem::Truncated(format!("array needs {len} bytes, fewer present")));
        }
        let head = need(3 * hs)?;
        let blocks = self.uint(&head[..hs]) as usize;
        if blocks > len.max(1) {
            return Err(Problem::Malformed(format!("{blocks} compressed blocks for {len} bytes")));
        }
        let header = need((3 + blocks) * hs)?;
        let sizes: Vec<usize> = (0..blocks).map(|i| self.uint(&header[(3 + i) * hs..(4 + i) * hs]) as usize).collect();
        self.inflate_blocks(&header[..3 * hs], &sizes, &data[(3 + blocks) * hs..], len)
    }

    /// Header and data in base64 (VTK encodes the header and the data separately).
    fn decode_base64(&self, text: &[u8], len: usize) -> Result<Vec<u8>, Problem> {
        let hs = self.header_size;
        let b64 = |t: &[u8]| STANDARD.decode(t).map_err(|e| Problem::Corrupt(format!("base64: {e}")));
        let chars = |bytes: usize| bytes.div_ceil(3) * 4;
        let prefix = |n: usize| text.get(..n).ok_or_else(|| Problem::Truncated("base64 data ends inside an array header".into()));
        let header_len = if self.compressed {
            let first = b64(prefix(chars(3 * hs))?)?;
            (3 + self.uint(&first[..hs]).min(len as u64 + 1) as usize) * hs
        } else {
            hs
        };
        let hchars = chars(header_len);
        let head_text = prefix(hchars)?;
        // Separately encoded header: its last group is padded (or it is a whole number of groups).
        let (header, body) = if header_len % 3 == 0 || head_text.ends_with(b"=") {
            (b64(head_text)?, b64(&text[hchars..])?)
        } else {
            let all = b64(text)?;
            if all.len() < header_len {
                return Err(Problem::Truncated("base64 data ends inside an array header".into()));
            }
            let body = all[header_len..].to_vec();
            (all[..header_len].to_vec(), body)
        };
        if !self.compressed {
            let n = self.uint(&header[..hs]) as usize;
            if n != len || body.len() < len {
                return Err(Problem::Truncated(format!("array holds {} bytes (header says {n}), the extent needs {len}", body.len())));
            }
            return Ok(body[..len].to_vec());
        }
        let blocks = (header_len / hs) - 3;
        let sizes: Vec<usize> = (0..blocks).map(|i| self.uint(&header[(3 + i) * hs..(4 + i) * hs]) as usize).collect();
        self.inflate_blocks(&header[..3 * hs], &sizes, &body, len)
    }

    /// Inflates zlib blocks in parallel into one buffer of `len` bytes.
    fn inflate_blocks(&self, head: &[u8], sizes: &[usize], body: &[u8], len: usize) -> Result<Vec<u8>, Problem> {
        let hs = self.header_size;
        let block = self.uint(&head[hs..2 * hs]) as usize;
        let last = match self.uint(&head[2 * hs..3 * hs]) as usize {
            0 => block,
            l => l,
        };
        let n = sizes.len();
        let total = if n == 0 { 0 } else { block.saturating_mul(n - 1).saturating_add(last) };
        if total != len || block == 0 && n > 0 {
            return Err(Problem::Malformed(format!("compressed blocks hold {total} bytes, the extent needs {len}")));
        }
        let mut starts = Vec::with_capacity(n);
        let mut at = 0usize;
        for &s in sizes {
            let end = at
                .checked_add(s)
                .filter(|&e| e <= body.len())
                .ok_or_else(|| Problem::Truncated(format!("compressed block ends past the data ({} bytes)", body.len())))?;
            starts.push(at..end);
            at = end;
        }
        let mut out = vec![0u8; len];
        out.par_chunks_mut(block.max(1)).zip(starts.par_iter()).try_for_each(|(dst, range)| -> Result<(), Problem> {
            let plain = inflate_zlib(&body[range.clone()], dst.len())?;
            dst.copy_from_slice(&plain);
            Ok(())
        })?;
        Ok(out)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn direction_is_read_row_major() {
        let doc = parse_document(
            r#"<VTKFile type="ImageData"><ImageData WholeExtent="0 1 0 1 0 1" Direction="0 -1 0 1 0 0 0 0 1"><Piece Extent="0 1 0 1 0 1"><PointData><DataArray type="UInt8" format="ascii">1 2 3 4 5 6 7 8</DataArray></PointData></Piece></ImageData></VTKFile>"#,
        )
        .unwrap();
        let d = doc.direction.unwrap();
        // Column 0 (the i axis) is (0, 1, 0): rows are "0 -1 0", "1 0 0", "0 0 1".
        assert_eq!(d.x_axis, Vec3::Y);
        assert_eq!(d.y_axis, -Vec3::X);
        assert_eq!(doc.pieces[0].array.as_ref().unwrap().text.trim(), "1 2 3 4 5 6 7 8");
    }
}
