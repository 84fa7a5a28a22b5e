//! DICOM RLE Lossless (PS3.5 Annex G) for the sample sizes dicom-pixeldata's decoder
//! refuses: 32-bit samples, as RT Dose grids store them (its adapter takes 8 and 16).
//!
//! Each frame is one fragment. Its 64-byte header holds the number of segments (u32)
//! and fifteen segment offsets (u32, from the header's start); segment k is byte k of
//! every sample, the most significant byte first (G.2), each PackBits-coded (G.3.1): a
//! control byte n in 0…127 copies the next n + 1 bytes, −127…−1 repeats the next byte
//! 1 − n times, −128 is skipped. Output: little-endian samples, row by row.

/// Decodes one frame of `samples` samples of `bytes` bytes each.
pub fn decode_frame(fragment: &[u8], samples: usize, bytes: usize) -> Result<Vec<u8>, String> {
    let word = |i: usize| -> Result<usize, String> {
        fragment
            .get(i * 4..i * 4 + 4)
            .map(|b| u32::from_le_bytes([b[0], b[1], b[2], b[3]]) as usize)
            .ok_or_else(|| "RLE header cut short".to_string())
    };
    if fragment.len() < 64 {
        return Err(format!("RLE header cut short ({} of 64 bytes)", fragment.len()));
    }
    let segments = word(0)?;
    if segments != bytes {
        return Err(format!("RLE frame has {segments} segments, {bytes}-byte samples need {bytes}"));
    }
    let mut out = vec![0u8; samples * bytes];
    for k in 0..segments {
        let start = word(1 + k)?;
        let end = if k + 1 < segments { word(2 + k)? } else { fragment.len() };
        let segment = fragment
            .get(start..end)
            .ok_or_else(|| format!("RLE segment {k} lies outside its fragment ({start}…{end} of {})", fragment.len()))?;
        // Byte k of a sample (most significant first) is byte bytes − 1 − k little-endian.
        let lane = bytes - 1 - k;
        let mut n = 0usize;
        let mut put = |b: u8, n: &mut usize| -> Result<(), String> {
            if *n >= samples {
                return Err(format!("RLE segment {k} decodes to more than {samples} bytes"));
            }
            out[*n * bytes + lane] = b;
            *n += 1;
            Ok(())
        };
        let mut i = 0;
        while i < segment.len() && n < samples {
            let control = segment[i] as i8;
            i += 1;
            match control {
                0..=127 => {
                    let run = segment.get(i..i + control as usize + 1).ok_or_else(|| format!("RLE segment {k} cut short"))?;
                    for &b in run {
                        put(b, &mut n)?;
                    }
                    i += run.len();
                }
                -127..=-1 => {
                    let b = *segment.get(i).ok_or_else(|| format!("RLE segment {k} cut short"))?;
                    for _ in 0..(1 - control as isize) {
                        put(b, &mut n)?;
                    }
                    i += 1;
                }
                _ => {}
            }
        }
        if n < samples {
            return Err(format!("RLE segment {k} decodes to {n} bytes, the frame has {samples} samples"));
        }
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A frame of 32-bit samples coded by hand: header, then four PackBits segments.
    fn frame(segments: &[&[u8]]) -> Vec<u8> {
        let mut header = vec![0u8; 64];
        header[..4].copy_from_slice(&(segments.len() as u32).to_le_bytes());
        let mut offset = 64u32;
        let mut body = Vec::new();
        for (k, s) in segments.iter().enumerate() {
            header[4 + 4 * k..8 + 4 * k].copy_from_slice(&offset.to_le_bytes());
            offset += s.len() as u32;
            body.extend_from_slice(s);
        }
        header.extend(body);
        header
    }

    #[test]
    fn thirty_two_bit_samples_from_four_byte_planes() {
        // Samples 0x01020304, 0x01020305, 0x010203FF: the high three planes are runs
        // (−2: the next byte three times), the low one literal (2: three bytes).
        let f = frame(&[&[0xFE, 0x01], &[0xFE, 0x02], &[0xFE, 0x03], &[0x02, 0x04, 0x05, 0xFF]]);
        let out = decode_frame(&f, 3, 4).unwrap();
        let v: Vec<u32> = out.chunks_exact(4).map(|c| u32::from_le_bytes([c[0], c[1], c[2], c[3]])).collect();
        assert_eq!(v, vec![0x01020304, 0x01020305, 0x010203FF]);
        // −128 is no operation.
        let f = frame(&[&[0x80, 0xFE, 0x01], &[0xFE, 0x02], &[0xFE, 0x03], &[0x02, 0x04, 0x05, 0xFF]]);
        assert_eq!(decode_frame(&f, 3, 4).unwrap(), out);
    }

    #[test]
    fn damaged_frames_are_errors() {
        let good = frame(&[&[0xFE, 0x01], &[0xFE, 0x02], &[0xFE, 0x03], &[0x02, 0x04, 0x05, 0xFF]]);
        assert!(decode_frame(&good[..40], 3, 4).unwrap_err().contains("header"));
        assert!(decode_frame(&good[..good.len() - 1], 3, 4).unwrap_err().contains("cut short"));
        assert!(decode_frame(&good, 4, 4).unwrap_err().contains("decodes to 3"));
        assert!(decode_frame(&good, 2, 4).unwrap_err().contains("more than"));
        assert!(decode_frame(&good, 3, 2).unwrap_err().contains("segments"));
        let mut far = good.clone();
        far[8..12].copy_from_slice(&9999u32.to_le_bytes());
        assert!(decode_frame(&far, 3, 4).unwrap_err().contains("outside"));
    }
}
