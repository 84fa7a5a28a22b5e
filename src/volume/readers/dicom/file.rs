//! One DICOM file: opened behind [`super::guard`], its attributes read by tag, its pixel
//! data decoded and normalised.

use std::borrow::Cow;
use std::path::Path;

use dicom_dictionary_std::tags;
use dicom_dictionary_std::uids::RLE_LOSSLESS;

/// Explicit VR Big Endian (retired from the standard, still found in archives).
const EXPLICIT_VR_BIG_ENDIAN: &str = "1.2.840.10008.1.2.2";
use dicom_object::file::ReadPreamble;
use dicom_object::mem::InMemElement;
use dicom_object::{DefaultDicomObject, InMemDicomObject, OpenFileOptions, Tag};
use glam::Vec3;

use super::guard;
use crate::volume::readers::common::{Problem, ReadError, ReadOptions, file_len};

/// Reads and checks one file, then parses it.
pub fn open(path: &Path, options: &ReadOptions) -> Result<DefaultDicomObject, ReadError> {
    let fail = |p: Problem| ReadError::new(path, p);
    let len = file_len(path)?;
    if len > options.max_bytes + (64 << 20) {
        return Err(fail(Problem::TooLarge(format!("a {len}-byte DICOM file"))));
    }
    let bytes = std::fs::read(path).map_err(|e| fail(Problem::Io(e)))?;
    options.count_whole(len);
    guard::check(&bytes, options.max_bytes + (64 << 20)).map_err(fail)?;
    let (start, _) = guard::meta_start(&bytes).map_err(fail)?;
    let from = &bytes[start - 4..];
    // The guard bounds every allocation; a parser panic on some other inconsistency is
    // still turned into an error rather than taking the application down.
    crate::volume::caught::caught(|| OpenFileOptions::new().read_preamble(ReadPreamble::Never).from_reader(from))
        .map_err(|_| fail(Problem::Malformed("the DICOM parser failed on this file".into())))?
        .map_err(|e| fail(Problem::Malformed(format!("DICOM parser: {e}"))))
}

// --- attribute access -------------------------------------------------------

/// Whether an element's value representation is UN (unknown): some converters write
/// text attributes so (GDCM's RLE files); their bytes are the text, as pydicom reads
/// them by the dictionary.
fn unknown(e: &InMemElement) -> bool {
    e.vr().to_string() == "UN"
}

/// The text of an attribute written with VR UN.
fn unknown_text(e: &InMemElement) -> Option<String> {
    unknown(e).then(|| e.to_bytes().ok().map(|b| String::from_utf8_lossy(&b).into_owned())).flatten()
}

pub(super) fn string(o: &InMemDicomObject, t: Tag) -> Option<String> {
    let e = o.get(t)?;
    let text = match unknown_text(e) {
        Some(text) => text,
        None => e.to_str().ok()?.into_owned(),
    };
    Some(text.trim().trim_end_matches('\0').trim().to_string()).filter(|s| !s.is_empty())
}

pub(super) fn floats(o: &InMemDicomObject, t: Tag) -> Option<Vec<f64>> {
    let e = o.get(t)?;
    let values = match unknown_text(e) {
        Some(text) => text.trim_end_matches('\0').split('\\').map(|v| v.trim().parse::<f64>()).collect::<Result<Vec<_>, _>>().ok()?,
        None => e.to_multi_float64().ok()?,
    };
    Some(values).filter(|v| v.iter().all(|x| x.is_finite()))
}

pub(super) fn float(o: &InMemDicomObject, t: Tag) -> Option<f64> {
    if o.get(t).is_some_and(unknown) {
        return floats(o, t).and_then(|v| v.first().copied());
    }
    o.get(t)?.to_float64().ok().filter(|x| x.is_finite())
}

pub(super) fn int(o: &InMemDicomObject, t: Tag) -> Option<u32> {
    let e = o.get(t)?;
    match unknown_text(e) {
        // (Integer strings; binary integers written as UN stay unread.)
        Some(text) => text.trim_end_matches('\0').trim().parse().ok(),
        None => e.to_int::<u32>().ok(),
    }
}

fn first_item(o: &InMemDicomObject, seq: Tag) -> Option<&InMemDicomObject> {
    o.get(seq)?.items()?.first()
}

/// An attribute of a functional-group macro: per-frame first, then shared.
pub(super) fn group_value(o: &InMemDicomObject, frame: usize, macro_seq: Tag, tag: Tag) -> Option<&InMemElement> {
    o.get(tags::PER_FRAME_FUNCTIONAL_GROUPS_SEQUENCE)
        .and_then(|e| e.items())
        .and_then(|v| v.get(frame))
        .and_then(|it| first_item(it, macro_seq))
        .and_then(|m| m.get(tag))
        .or_else(|| {
            first_item(o, tags::SHARED_FUNCTIONAL_GROUPS_SEQUENCE).and_then(|sh| first_item(sh, macro_seq)).and_then(|m| m.get(tag))
        })
}

pub(super) fn vec3(v: &[f64]) -> Vec3 {
    Vec3::new(v[0] as f32, v[1] as f32, v[2] as f32)
}

/// Pixel layout of an image object.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) struct PixelFormat {
    pub(super) rows: u32,
    pub(super) cols: u32,
    pub(super) bits_allocated: u16,
    pub(super) bits_stored: u16,
    pub(super) signed: bool,
}

impl PixelFormat {
    pub(super) fn of(o: &InMemDicomObject) -> Result<Self, Problem> {
        let need = |t: Tag, name: &str| int(o, t).ok_or_else(|| Problem::Malformed(format!("{name} is missing")));
        let samples = int(o, tags::SAMPLES_PER_PIXEL).unwrap_or(1);
        if samples != 1 {
            return Err(Problem::Unsupported(format!("{samples} samples per pixel (colour images); Focal reads grey-scale volumes")));
        }
        let f = PixelFormat {
            rows: need(tags::ROWS, "Rows")?,
            cols: need(tags::COLUMNS, "Columns")?,
            bits_allocated: need(tags::BITS_ALLOCATED, "Bits Allocated")? as u16,
            bits_stored: int(o, tags::BITS_STORED).unwrap_or(0) as u16,
            signed: int(o, tags::PIXEL_REPRESENTATION).unwrap_or(0) == 1,
        };
        let f = PixelFormat { bits_stored: if f.bits_stored == 0 { f.bits_allocated } else { f.bits_stored }, ..f };
        if !matches!(f.bits_allocated, 8 | 16 | 32) || f.bits_stored > f.bits_allocated {
            return Err(Problem::Unsupported(format!("Bits Allocated {} / Bits Stored {}", f.bits_allocated, f.bits_stored)));
        }
        if f.rows == 0 || f.cols == 0 {
            return Err(Problem::Malformed(format!("image size {}×{}", f.cols, f.rows)));
        }
        Ok(f)
    }

    pub(super) fn frame_bytes(&self) -> usize {
        self.rows as usize * self.cols as usize * (self.bits_allocated as usize / 8)
    }

    pub(super) fn sample_type(&self) -> crate::volume::SampleType {
        use crate::volume::SampleType::*;
        match (self.bits_allocated, self.signed) {
            (8, false) => U8,
            (8, true) => I8,
            (16, false) => U16,
            (16, true) => I16,
            (_, false) => U32,
            (_, true) => I32,
        }
    }

    /// Masks samples to Bits Stored and sign-extends them (little-endian bytes, in place).
    pub(super) fn normalise(&self, bytes: &mut [u8]) {
        let (bits, stored) = (self.bits_allocated as u32, self.bits_stored as u32);
        if stored >= bits {
            return;
        }
        let size = bits as usize / 8;
        let mask = (1u64 << stored) - 1;
        let sign = 1u64 << (stored - 1);
        for s in bytes.chunks_exact_mut(size) {
            let mut a = [0u8; 8];
            a[..size].copy_from_slice(s);
            let mut v = u64::from_le_bytes(a) & mask;
            if self.signed && v & sign != 0 {
                v |= !mask;
            }
            s.copy_from_slice(&v.to_le_bytes()[..size]);
        }
    }
}

/// The pixel bytes of all frames of an object (little-endian samples).
pub(super) fn pixel_bytes<'a>(object: &'a DefaultDicomObject, format: &PixelFormat, frames: usize) -> Result<Cow<'a, [u8]>, Problem> {
    let need = format.frame_bytes() * frames;
    let element = object.element(tags::PIXEL_DATA).map_err(|_| Problem::Malformed("no Pixel Data".into()))?;
    let bytes = match element.to_bytes() {
        // Explicit VR big endian: 32-bit samples in an OW element come as 16-bit words,
        // each in native order, the sample's high word first: swap the words.
        Ok(b)
            if format.bits_allocated == 32
                && element.vr().to_string() == "OW"
                && object.meta().transfer_syntax().trim_end_matches('\0') == EXPLICIT_VR_BIG_ENDIAN =>
        {
            Cow::Owned(b.chunks_exact(4).flat_map(|w| [w[2], w[3], w[0], w[1]]).collect())
        }
        Ok(b) => b,
        Err(_) if format.bits_allocated == 32 && object.meta().transfer_syntax().trim_end_matches('\0') == RLE_LOSSLESS => {
            // (dicom-pixeldata's RLE takes 8 and 16 bits; RT Dose grids are 32.)
            let fragments = element.fragments().ok_or_else(|| Problem::Malformed("RLE pixel data without fragments".into()))?;
            if fragments.len() < frames {
                return Err(Problem::Truncated(format!("{} RLE fragment(s) for {frames} frame(s)", fragments.len())));
            }
            let samples = format.rows as usize * format.cols as usize;
            let mut all = Vec::with_capacity(need);
            for (k, f) in fragments[..frames].iter().enumerate() {
                all.extend(super::rle::decode_frame(f, samples, 4).map_err(|e| Problem::Corrupt(format!("frame {k}: {e}")))?);
            }
            Cow::Owned(all)
        }
        Err(_) => {
            // Encapsulated (compressed) pixel data: let dicom-pixeldata decode it.
            use dicom_pixeldata::PixelDecoder;
            let decoded = crate::volume::caught::caught(|| object.decode_pixel_data())
                .map_err(|_| Problem::Corrupt("the pixel data decoder failed on this data".into()))?
                .map_err(|e| Problem::Unsupported(format!("pixel data in transfer syntax {}: {}", transfer_syntax(object), chain(&e))))?;
            Cow::Owned(decoded.data().to_vec())
        }
    };
    if bytes.len() < need {
        return Err(Problem::Truncated(format!(
            "Pixel Data holds {} bytes, {} frame(s) of {}×{} need {need}",
            bytes.len(),
            frames,
            format.cols,
            format.rows
        )));
    }
    Ok(match bytes {
        Cow::Borrowed(b) => Cow::Borrowed(&b[..need]),
        Cow::Owned(mut b) => {
            b.truncate(need);
            Cow::Owned(b)
        }
    })
}

/// An object's transfer syntax: its UID and, where the registry knows it, its name.
fn transfer_syntax(object: &DefaultDicomObject) -> String {
    let uid = object.meta().transfer_syntax().trim_end_matches('\0');
    use dicom_transfer_syntax_registry::TransferSyntaxIndex;
    match dicom_transfer_syntax_registry::TransferSyntaxRegistry.get(uid) {
        Some(ts) => format!("{uid} ({})", ts.name()),
        None => uid.to_string(),
    }
}

/// An error with the errors under it (the decoders say what failed only there).
fn chain(e: &dyn std::error::Error) -> String {
    let mut text = e.to_string();
    let mut source = e.source();
    while let Some(s) = source {
        let next = s.to_string();
        if !text.contains(&next) {
            text += &format!(": {next}");
        }
        source = s.source();
    }
    text
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn samples_are_masked_and_sign_extended() {
        // 12 bits stored in 16: 0x0FFF is −1 when signed; bits above 12 are garbage.
        let f = PixelFormat { rows: 1, cols: 3, bits_allocated: 16, bits_stored: 12, signed: true };
        let mut b: Vec<u8> = [0xFFFFu16, 0xF800, 0x07FF].iter().flat_map(|v| v.to_le_bytes()).collect();
        f.normalise(&mut b);
        let v: Vec<i16> = b.chunks_exact(2).map(|c| i16::from_le_bytes([c[0], c[1]])).collect();
        assert_eq!(v, vec![-1, -2048, 2047]);
        let u = PixelFormat { signed: false, ..f };
        let mut b: Vec<u8> = [0xF0FFu16].iter().flat_map(|v| v.to_le_bytes()).collect();
        u.normalise(&mut b);
        assert_eq!(u16::from_le_bytes([b[0], b[1]]), 0x00FF);
        assert_eq!(u.sample_type(), crate::volume::SampleType::U16);
    }
}
