//! A cheap pass over DICOM element headers before the real parser runs.
//!
//! `dicom-object` allocates the full declared length of an element before reading it
//! (up to 4 GiB for one corrupted length field; for strings a failed allocation aborts
//! the process), and builds nested sequences recursively. This walk reads only tags,
//! VRs and lengths and refuses a file where any defined length runs past the end of its
//! enclosing value or of the file, or where sequences nest absurdly deep. After it
//! passes, no allocation the parser makes can exceed the file's size.
//!
//! Layout (PS3.5 §7.1): tag (group, element as two u16), then for explicit VR two VR
//! characters and a 2-byte length, or for OB OD OF OL OV OW SQ SV UC UN UR UT UV two
//! reserved bytes and a 4-byte length; implicit VR has a 4-byte length. Items and
//! delimiters (group FFFE) have a 4-byte length and no VR. `0xFFFFFFFF` is an undefined
//! length (sequences, items, encapsulated pixel data), closed by a delimiter. The file
//! meta group is always explicit VR little endian. In the deflated transfer syntax
//! (1.2.840.10008.1.2.1.99, PS3.5 §A.5) the data set after it is a raw deflate stream
//! of explicit VR little endian: it is inflated (at most the reader's byte limit) and
//! walked so.

use super::super::common::Problem;

/// Deepest sequence nesting accepted (real files rarely exceed 4).
const MAX_DEPTH: usize = 24;

const UNDEFINED: u32 = 0xFFFF_FFFF;

/// The value representations of PS3.5 §6.2.
const KNOWN_VRS: [[u8; 2]; 34] = [
    *b"AE", *b"AS", *b"AT", *b"CS", *b"DA", *b"DS", *b"DT", *b"FD", *b"FL", *b"IS", *b"LO", *b"LT", *b"OB", *b"OD", *b"OF", *b"OL", *b"OV",
    *b"OW", *b"PN", *b"SH", *b"SL", *b"SQ", *b"SS", *b"ST", *b"SV", *b"TM", *b"UC", *b"UI", *b"UL", *b"UN", *b"UR", *b"US", *b"UT", *b"UV",
];

/// The Pixel Data element.
const PIXEL_DATA: Tag = (0x7FE0, 0x0010);

/// The deflated explicit VR little endian transfer syntax.
const DEFLATED: &str = "1.2.840.10008.1.2.1.99";

/// Encoding of the data set after the meta group.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Encoding {
    pub explicit: bool,
    pub big_endian: bool,
}

/// Where the meta group starts and whether a preamble precedes it.
pub fn meta_start(bytes: &[u8]) -> Result<(usize, bool), Problem> {
    if bytes.len() >= 132 && &bytes[128..132] == b"DICM" {
        Ok((132, true))
    } else if bytes.len() >= 4 && &bytes[..4] == b"DICM" {
        Ok((4, false))
    } else {
        Err(Problem::NotFormat { format: "DICOM", detail: "no 'DICM' marker at byte 128 (or 0)".into() })
    }
}

/// One element header: tag, VR (if explicit), length (`None`: undefined) and where the
/// value starts.
struct Header {
    tag: Tag,
    vr: Option<[u8; 2]>,
    len: Option<u32>,
    value_at: usize,
}

/// Checks the whole file (a deflated data set inflating to at most `max_inflated`
/// bytes); returns the transfer syntax UID.
pub fn check(bytes: &[u8], max_inflated: u64) -> Result<String, Problem> {
    let (start, _) = meta_start(bytes)?;
    let meta = Encoding { explicit: true, big_endian: false };
    let mut w = Walker { bytes, pos: start, enc: meta, fragments: false };
    // Meta group: group 0002 elements.
    let mut ts = None;
    while w.pos + 4 <= bytes.len() && w.u16_at(w.pos) == 0x0002 {
        let Header { tag, len, value_at, .. } = w.header()?;
        let len = len.ok_or_else(|| Problem::Malformed("undefined length in the file meta group".into()))?;
        w.ensure(value_at, len as usize, tag)?;
        if tag == (0x0002, 0x0010) {
            ts = Some(String::from_utf8_lossy(&bytes[value_at..value_at + len as usize]).trim_end_matches(['\0', ' ']).to_string());
        }
        w.pos = value_at + len as usize;
    }
    let ts = ts.ok_or_else(|| Problem::Malformed("no Transfer Syntax UID in the file meta group".into()))?;
    w.enc = match ts.as_str() {
        "1.2.840.10008.1.2" => Encoding { explicit: false, big_endian: false },
        "1.2.840.10008.1.2.2" => Encoding { explicit: true, big_endian: true },
        _ => Encoding { explicit: true, big_endian: false },
    };
    if ts == DEFLATED {
        let inflated = inflate(&bytes[w.pos..], max_inflated)?;
        Walker { bytes: &inflated, pos: 0, enc: w.enc, fragments: false }.walk(inflated.len(), 0)?;
    } else {
        w.walk(bytes.len(), 0)?;
    }
    Ok(ts)
}

/// A raw deflate stream inflated, refused past `limit` bytes or where it is corrupt.
fn inflate(stream: &[u8], limit: u64) -> Result<Vec<u8>, Problem> {
    use std::io::Read;
    let mut out = Vec::new();
    flate2::read::DeflateDecoder::new(stream)
        .take(limit + 1)
        .read_to_end(&mut out)
        .map_err(|e| Problem::Corrupt(format!("the deflated data set does not inflate: {e}")))?;
    if out.len() as u64 > limit {
        return Err(Problem::TooLarge(format!("a deflated data set inflating to more than {limit} bytes")));
    }
    Ok(out)
}

struct Walker<'a> {
    bytes: &'a [u8],
    pos: usize,
    enc: Encoding,
    /// Whether the items of the level walked are pixel-data fragments (inside
    /// encapsulated Pixel Data: compressed bytes, not walked) rather than data sets.
    fragments: bool,
}

type Tag = (u16, u16);

impl Walker<'_> {
    fn u16_at(&self, at: usize) -> u16 {
        let b = [self.bytes[at], self.bytes[at + 1]];
        if self.enc.big_endian { u16::from_be_bytes(b) } else { u16::from_le_bytes(b) }
    }

    fn u32_at(&self, at: usize) -> u32 {
        let b = [self.bytes[at], self.bytes[at + 1], self.bytes[at + 2], self.bytes[at + 3]];
        if self.enc.big_endian { u32::from_be_bytes(b) } else { u32::from_le_bytes(b) }
    }

    fn need(&self, at: usize, n: usize) -> Result<(), Problem> {
        if at.checked_add(n).is_none_or(|e| e > self.bytes.len()) {
            return Err(Problem::Truncated(format!("element header at byte {at} runs past the end of the file")));
        }
        Ok(())
    }

    fn ensure(&self, at: usize, len: usize, tag: Tag) -> Result<(), Problem> {
        if at.checked_add(len).is_none_or(|e| e > self.bytes.len()) {
            return Err(Problem::Truncated(format!(
                "element ({:04X},{:04X}) declares {len} bytes at byte {at}, but the file has {}",
                tag.0,
                tag.1,
                self.bytes.len()
            )));
        }
        Ok(())
    }

    /// Reads the element header at `pos`.
    fn header(&self) -> Result<Header, Problem> {
        let p = self.pos;
        self.need(p, 8)?;
        let group = self.u16_at(p);
        let tag = (group, self.u16_at(p + 2));
        let (vr, len, value_at) = if group == 0xFFFE {
            (None, self.u32_at(p + 4), p + 8)
        } else if self.enc.explicit {
            let vr = [self.bytes[p + 4], self.bytes[p + 5]];
            // (An unknown VR is read by the parser with a 4-byte length: a corrupted one
            // made it allocate 1.4 GB.)
            if !KNOWN_VRS.contains(&vr) {
                return Err(Problem::Malformed(format!(
                    "element ({:04X},{:04X}) has an unknown VR '{}' at byte {p}",
                    tag.0,
                    tag.1,
                    String::from_utf8_lossy(&vr)
                )));
            }
            if matches!(&vr, b"OB" | b"OD" | b"OF" | b"OL" | b"OV" | b"OW" | b"SQ" | b"SV" | b"UC" | b"UN" | b"UR" | b"UT" | b"UV") {
                self.need(p, 12)?;
                (Some(vr), self.u32_at(p + 8), p + 12)
            } else {
                (Some(vr), self.u16_at(p + 6) as u32, p + 8)
            }
        } else {
            (None, self.u32_at(p + 4), p + 8)
        };
        Ok(Header { tag, vr, len: (len != UNDEFINED).then_some(len), value_at })
    }

    /// Walks elements until `end` (exclusive) or a delimiter at this level.
    fn walk(&mut self, end: usize, depth: usize) -> Result<(), Problem> {
        if depth > MAX_DEPTH {
            return Err(Problem::Malformed(format!("sequences nest deeper than {MAX_DEPTH} levels")));
        }
        while self.pos < end {
            if end - self.pos < 8 {
                // Trailing padding shorter than an element header.
                if self.bytes[self.pos..end].iter().all(|&b| b == 0) {
                    self.pos = end;
                    return Ok(());
                }
                return Err(Problem::Truncated(format!("{} stray bytes at the end of a data set", end - self.pos)));
            }
            let Header { tag, vr, len, value_at } = self.header()?;
            match (tag, len) {
                // Item / sequence delimiters end the current undefined-length level.
                ((0xFFFE, 0xE00D), _) | ((0xFFFE, 0xE0DD), _) => {
                    self.pos = value_at;
                    return Ok(());
                }
                (_, None) => {
                    // Undefined length: a sequence, an item, or encapsulated pixel data
                    // (OB or OW: its items are fragments). An explicit-VR UN of undefined
                    // length holds an implicit-VR sequence.
                    let (outer, outer_fragments) = (self.enc, self.fragments);
                    if vr == Some(*b"UN") {
                        self.enc = Encoding { explicit: false, big_endian: false };
                    }
                    self.fragments = tag == PIXEL_DATA || matches!(vr, Some([b'O', b'B' | b'W']));
                    self.pos = value_at;
                    self.walk(end, depth + 1)?;
                    (self.enc, self.fragments) = (outer, outer_fragments);
                }
                (_, Some(len)) => {
                    let len = len as usize;
                    self.ensure(value_at, len, tag)?;
                    if value_at.checked_add(len).is_some_and(|e| e > end) {
                        return Err(Problem::Malformed(format!("element ({:04X},{:04X}) overruns its enclosing item", tag.0, tag.1)));
                    }
                    // (An item of a sequence is a data set; a sequence's content, items.)
                    let inside = if tag == (0xFFFE, 0xE000) {
                        !self.fragments
                    } else {
                        vr == Some(*b"SQ") || (vr.is_none() && tag != PIXEL_DATA && self.starts_with_item(value_at, len))
                    };
                    if inside {
                        let outer_fragments = std::mem::replace(&mut self.fragments, false);
                        self.pos = value_at;
                        self.walk(value_at + len, depth + 1)?;
                        self.fragments = outer_fragments;
                    }
                    self.pos = value_at + len;
                }
            }
        }
        Ok(())
    }

    fn starts_with_item(&self, at: usize, len: usize) -> bool {
        len >= 8 && self.u16_at(at) == 0xFFFE && self.u16_at(at + 2) == 0xE000
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn element_explicit(group: u16, elem: u16, vr: &[u8; 2], value: &[u8]) -> Vec<u8> {
        let mut v = Vec::new();
        v.extend_from_slice(&group.to_le_bytes());
        v.extend_from_slice(&elem.to_le_bytes());
        v.extend_from_slice(vr);
        if matches!(vr, b"OB" | b"OW" | b"SQ" | b"UN") {
            v.extend_from_slice(&[0, 0]);
            v.extend_from_slice(&(value.len() as u32).to_le_bytes());
        } else {
            v.extend_from_slice(&(value.len() as u16).to_le_bytes());
        }
        v.extend_from_slice(value);
        v
    }

    fn file(ts: &str, body: &[u8]) -> Vec<u8> {
        let mut f = vec![0u8; 128];
        f.extend_from_slice(b"DICM");
        let mut uid = ts.as_bytes().to_vec();
        if uid.len() % 2 == 1 {
            uid.push(0);
        }
        f.extend(element_explicit(0x0002, 0x0010, b"UI", &uid));
        f.extend_from_slice(body);
        f
    }

    #[test]
    fn accepts_consistent_and_refuses_overlong_lengths() {
        let good = file("1.2.840.10008.1.2.1", &element_explicit(0x0010, 0x0010, b"PN", b"DOE^J "));
        assert_eq!(check(&good, 1 << 20).unwrap(), "1.2.840.10008.1.2.1");
        let mut bad = file("1.2.840.10008.1.2.1", &element_explicit(0x7FE0, 0x0010, b"OW", &[0u8; 16]));
        let n = bad.len();
        bad[n - 20..n - 16].copy_from_slice(&0xFFFF_FFF0u32.to_le_bytes());
        assert!(matches!(check(&bad, 1 << 20), Err(Problem::Truncated(_))), "{:?}", check(&bad, 1 << 20));
        assert!(matches!(check(&[0u8; 64], 1 << 20), Err(Problem::NotFormat { .. })));
    }

    #[test]
    fn refuses_absurd_nesting() {
        // Implicit VR: sequences of undefined length nested 100 deep.
        let mut body = Vec::new();
        for _ in 0..100 {
            body.extend_from_slice(&0x0008u16.to_le_bytes());
            body.extend_from_slice(&0x1115u16.to_le_bytes());
            body.extend_from_slice(&UNDEFINED.to_le_bytes());
        }
        let f = file("1.2.840.10008.1.2", &body);
        assert!(matches!(check(&f, 1 << 20), Err(Problem::Malformed(_))));
    }

    #[test]
    fn deflated_data_sets_are_walked_inflated() {
        use std::io::Write;
        let deflate = |body: &[u8]| {
            let mut e = flate2::write::DeflateEncoder::new(Vec::new(), flate2::Compression::default());
            e.write_all(body).unwrap();
            e.finish().unwrap()
        };
        let name = element_explicit(0x0010, 0x0010, b"PN", b"DOE^J ");
        assert_eq!(check(&file(DEFLATED, &deflate(&name)), 1 << 20).unwrap(), DEFLATED);
        // An overlong length inside the deflated set is found as in a plain one.
        let mut overlong = element_explicit(0x7FE0, 0x0010, b"OW", &[0u8; 16]);
        overlong[8..12].copy_from_slice(&0xFFFF_FFF0u32.to_le_bytes());
        assert!(matches!(check(&file(DEFLATED, &deflate(&overlong)), 1 << 20), Err(Problem::Truncated(_))));
        // Not a deflate stream; one that inflates past the limit.
        assert!(matches!(check(&file(DEFLATED, &[0xFF; 40]), 1 << 20), Err(Problem::Corrupt(_))));
        assert!(matches!(inflate(&deflate(&[0u8; 5000]), 4096), Err(Problem::TooLarge(_))));
        assert_eq!(inflate(&deflate(&[7u8; 4096]), 4096).unwrap(), vec![7u8; 4096]);
    }

    /// An item of a sequence is a data set, walked whatever its first bytes look like
    /// (a corrupted VR there made the parser read a length of hundreds of megabytes);
    /// the fragments of encapsulated pixel data are not.
    #[test]
    fn sequence_items_are_walked_and_fragments_are_not() {
        let item = |content: &[u8]| {
            let mut v = vec![0xFE, 0xFF, 0x00, 0xE0];
            v.extend_from_slice(&(content.len() as u32).to_le_bytes());
            v.extend_from_slice(content);
            v
        };
        let mut bad_vr = element_explicit(0x0018, 0x0050, b"DS", b"2.5 ");
        bad_vr[4] = b'9';
        let sequence = element_explicit(0x0028, 0x9110, b"SQ", &item(&bad_vr));
        assert!(matches!(check(&file("1.2.840.10008.1.2.1", &sequence), 1 << 20), Err(Problem::Malformed(_))));
        // Encapsulated pixel data: an empty offset table, then a fragment of any bytes.
        let mut pixels = vec![0xE0, 0x7F, 0x10, 0x00, b'O', b'B', 0, 0, 0xFF, 0xFF, 0xFF, 0xFF];
        pixels.extend(item(&[]));
        pixels.extend(item(&bad_vr));
        pixels.extend_from_slice(&[0xFE, 0xFF, 0xDD, 0xE0, 0, 0, 0, 0]);
        assert!(
            check(&file("1.2.840.10008.1.2.4.50", &pixels), 1 << 20).is_ok(),
            "{:?}",
            check(&file("1.2.840.10008.1.2.4.50", &pixels), 1 << 20)
        );
    }
}
