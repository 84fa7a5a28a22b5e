//! DICOM Segmentation objects (PS3.3 §C.8.20) and other 1-bit images, read as label
//! volumes.
//!
//! A segmentation is a multi-frame object whose frames are masks: each frame belongs to
//! one segment (Segment Identification Sequence → Referenced Segment Number, per frame)
//! and lies where its Plane Position Sequence says. BINARY segmentations store one bit
//! a pixel (Bits Allocated 1), packed across the frames without padding, the first
//! pixel in the lowest bit of its byte (PS3.5 §8.1.1); FRACTIONAL ones store 8 bits, a
//! pixel belonging to its segment from half the Maximum Fractional Value up.
//!
//! The frames' positions, projected on the normal `n = row × column`, give the slices:
//! their distances `d = p · n` are placed on a regular grid of step Spacing Between
//! Slices (else the smallest gap between distinct distances), slice `k = round((d −
//! d₀) / step)`; slices no frame covers (segmentations leave out empty ones) are
//! background. A voxel takes the segment number of the frame that marks it (where
//! segments overlap, the higher number, with a note). The Segment Sequence names the
//! segments and gives their colours (Recommended Display CIELab Value →
//! [`cielab_to_srgb`]); the volume carries that table, so it is shown as labels.

use std::path::Path;

use dicom_dictionary_std::tags;
use dicom_object::{DefaultDicomObject, InMemDicomObject};
use glam::Vec3;

use super::file::{PixelFormat, float, floats, group_value, int, string};
use super::series::{Plane, assemble, frame_geometry};
use crate::volume::readers::common::{MAX_AXIS, Problem, ReadError, ReadOptions, volume_name};
use crate::volume::{Label, LabelTable, Volume};

/// SOP Class UID of Segmentation Storage.
const SEGMENTATION_STORAGE: &str = "1.2.840.10008.5.1.4.1.1.66.4";

/// Whether an object is read here: a segmentation, or any 1-bit image.
pub fn applies(o: &InMemDicomObject) -> bool {
    string(o, tags::SOP_CLASS_UID).as_deref() == Some(SEGMENTATION_STORAGE) || int(o, tags::BITS_ALLOCATED) == Some(1)
}

/// Reads a segmentation (or 1-bit image) as a label volume with its segments' table.
pub fn read(path: &Path, object: DefaultDicomObject, options: &ReadOptions) -> Result<Volume, ReadError> {
    let fail = |p: Problem| ReadError::new(path, p);
    let (rows, cols) = (int(&object, tags::ROWS).unwrap_or(0), int(&object, tags::COLUMNS).unwrap_or(0));
    let frames = int(&object, tags::NUMBER_OF_FRAMES).unwrap_or(1) as usize;
    let bits = int(&object, tags::BITS_ALLOCATED).unwrap_or(0);
    if rows == 0 || cols == 0 {
        return Err(fail(Problem::Malformed(format!("image size {cols}×{rows}"))));
    }
    if !matches!(bits, 1 | 8) {
        return Err(fail(Problem::Unsupported(format!("a segmentation with Bits Allocated {bits} (1 or 8 are defined)"))));
    }
    options.check_size([cols as u64, rows as u64, frames as u64], 1).map_err(fail)?;
    let fractional = string(&object, tags::SEGMENTATION_TYPE).is_some_and(|t| t.eq_ignore_ascii_case("FRACTIONAL"));
    let threshold = match (bits, fractional) {
        (1, _) => 1,
        (_, true) => (int(&object, tags::MAXIMUM_FRACTIONAL_VALUE).unwrap_or(255).clamp(1, 255) as u8).div_ceil(2),
        // (An 8-bit BINARY mask, or a grey image with 8 bits: any non-zero pixel.)
        _ => 1,
    };
    let masks = Masks::read(&object, bits, (rows, cols), frames).map_err(fail)?;
    let (table, numbers) = segments(&object);
    let mut notes = Vec::new();

    // Each frame's segment and where it lies.
    let mut placed = Vec::with_capacity(frames);
    for f in 0..frames {
        let segment = group_value(&object, f, tags::SEGMENT_IDENTIFICATION_SEQUENCE, tags::REFERENCED_SEGMENT_NUMBER)
            .and_then(|e| e.to_int::<u32>().ok())
            .or_else(|| (numbers.len() <= 1).then(|| numbers.first().copied().unwrap_or(1)))
            .ok_or_else(|| fail(Problem::Malformed(format!("frame {} names no segment (Referenced Segment Number)", f + 1))))?;
        if !(1..=65535).contains(&segment) {
            return Err(fail(Problem::Malformed(format!("frame {} names segment {segment} (1 … 65535)", f + 1))));
        }
        placed.push((segment, frame_geometry(&object, Some(f))));
    }
    let g0 = placed[0].1.clone();
    let [row, col] = g0.orientation.unwrap_or([Vec3::X, Vec3::Y]);
    let normal = row.cross(col).normalize();
    let positions: Option<Vec<Vec3>> = placed.iter().map(|(_, g)| g.position).collect();
    let step_given = group_value(&object, 0, tags::PIXEL_MEASURES_SEQUENCE, tags::SPACING_BETWEEN_SLICES)
        .and_then(|e| e.to_float64().ok())
        .or_else(|| float(&object, tags::SPACING_BETWEEN_SLICES))
        .filter(|s| s.is_finite() && *s > 0.0)
        .map(|s| s as f32);
    // (One position for every frame, a 1-bit image's own: stacked as without positions.)
    let positions = positions.filter(|p| p.iter().any(|q| (*q - p[0]).length() > 1e-3) || p.len() == 1);
    let (slice_of, origin, step): (Vec<usize>, Vec3, f32) = match positions {
        Some(p) => {
            let d: Vec<f32> = p.iter().map(|p| p.dot(normal)).collect();
            let (k, first, step, note) = slice_indices(&d, step_given).map_err(fail)?;
            notes.extend(note);
            (k, p[first], step)
        }
        None => {
            // (No positions: one slice a segment's frame, in frame order per segment.)
            notes.push("frames have no positions of their own: each segment's frames stacked in order".into());
            let mut seen = std::collections::BTreeMap::<u32, usize>::new();
            let k = placed
                .iter()
                .map(|(s, _)| {
                    let n = seen.entry(*s).or_default();
                    *n += 1;
                    *n - 1
                })
                .collect();
            let origin = g0.position.or_else(|| floats(&object, tags::IMAGE_POSITION_PATIENT).map(|v| super::file::vec3(&v)));
            (k, origin.unwrap_or(Vec3::ZERO), step_given.unwrap_or(1.0))
        }
    };
    let slices = slice_of.iter().max().map_or(1, |m| m + 1);
    let wide = placed.iter().any(|(s, _)| *s > 255);
    options.check_size([cols as u64, rows as u64, slices as u64], if wide { 2 } else { 1 }).map_err(fail)?;

    // The label of every voxel.
    let per = rows as usize * cols as usize;
    let mut labels = vec![0u16; per * slices];
    let mut overlaps = 0u64;
    for (f, ((segment, _), &k)) in placed.iter().zip(&slice_of).enumerate() {
        let slice = &mut labels[k * per..(k + 1) * per];
        for (i, v) in slice.iter_mut().enumerate() {
            if masks.value(f * per + i) >= threshold {
                if *v != 0 && *v != *segment as u16 {
                    overlaps += 1;
                }
                *v = (*v).max(*segment as u16);
            }
        }
    }
    if overlaps > 0 {
        notes.push(format!("{overlaps} voxel(s) in more than one segment: shown as the highest-numbered"));
    }
    if fractional {
        notes.push(format!("FRACTIONAL segmentation: voxels from {threshold} (half the Maximum Fractional Value) up"));
    }
    let format =
        PixelFormat { rows, cols, bits_allocated: if wide { 16 } else { 8 }, bits_stored: if wide { 16 } else { 8 }, signed: false };
    let planes = (0..slices)
        .map(|k| {
            let geometry = super::series::FrameGeometry {
                position: Some(origin + normal * step * k as f32),
                slope: 1.0,
                intercept: 0.0,
                ..g0.clone()
            };
            let ids = &labels[k * per..(k + 1) * per];
            let bytes = if wide { ids.iter().flat_map(|v| v.to_le_bytes()).collect() } else { ids.iter().map(|&v| v as u8).collect() };
            Plane { geometry, instance: k as i64, bytes }
        })
        .collect();
    let name = string(&object, tags::SERIES_DESCRIPTION).unwrap_or_else(|| volume_name(path));
    notes.push(format!("{} segment(s), {frames} frame(s)", table.len().max(numbers.len())));
    let volume = assemble(path, &object, format, planes, name, "DICOM segmentation", notes)?;
    Ok(volume.with_label_table(table))
}

/// The pixel data of all frames, read pixel by pixel (packed bits or bytes).
struct Masks<'a> {
    bytes: std::borrow::Cow<'a, [u8]>,
    bits: u32,
}

impl<'a> Masks<'a> {
    fn read(object: &'a DefaultDicomObject, bits: u32, (rows, cols): (u32, u32), frames: usize) -> Result<Masks<'a>, Problem> {
        let pixels = rows as usize * cols as usize * frames;
        let need = if bits == 1 { pixels.div_ceil(8) } else { pixels };
        let element = object.element(tags::PIXEL_DATA).map_err(|_| Problem::Malformed("no Pixel Data".into()))?;
        let bytes = element.to_bytes().map_err(|_| {
            Problem::Unsupported(format!(
                "compressed segmentation pixel data (transfer syntax {}); Focal reads native ones",
                object.meta().transfer_syntax().trim_end_matches('\0')
            ))
        })?;
        if bytes.len() < need {
            return Err(Problem::Truncated(format!(
                "Pixel Data holds {} bytes, {frames} frame(s) of {cols}×{rows} need {need}",
                bytes.len()
            )));
        }
        Ok(Masks { bytes, bits })
    }

    /// Pixel `i` of the frames one after the other (0 or 1 for packed bits).
    fn value(&self, i: usize) -> u8 {
        if self.bits == 1 { (self.bytes[i / 8] >> (i % 8)) & 1 } else { self.bytes[i] }
    }
}

/// The Segment Sequence as a label table, and the segment numbers it lists.
fn segments(o: &InMemDicomObject) -> (LabelTable, Vec<u32>) {
    let mut table = LabelTable::default();
    let mut numbers = Vec::new();
    for item in o.get(tags::SEGMENT_SEQUENCE).and_then(|e| e.items()).into_iter().flatten() {
        let Some(number) = int(item, tags::SEGMENT_NUMBER).filter(|n| (1..=65535).contains(n)) else { continue };
        numbers.push(number);
        let name = string(item, tags::SEGMENT_LABEL).unwrap_or_else(|| format!("segment {number}"));
        let color = floats(item, tags::RECOMMENDED_DISPLAY_CIE_LAB_VALUE)
            .filter(|v| v.len() == 3)
            .map(|v| cielab_to_srgb([v[0], v[1], v[2]]))
            .unwrap_or_else(|| crate::volume::labels::generated_color(number));
        table.labels.insert(number, Label { name, color });
    }
    (table, numbers)
}

/// The slice index of each distance along the normal, the index of a frame on slice 0,
/// the step and a note where the given step did not fit: `step` if given and every
/// frame falls on its grid, else the smallest gap between distinct distances.
fn slice_indices(d: &[f32], step: Option<f32>) -> Result<(Vec<usize>, usize, f32, Option<String>), Problem> {
    let (first, lo) = d.iter().copied().enumerate().fold((0, f32::INFINITY), |(i, lo), (j, x)| if x < lo { (j, x) } else { (i, lo) });
    let mut distinct: Vec<f32> = d.to_vec();
    distinct.sort_by(f32::total_cmp);
    distinct.dedup_by(|b, a| (*b - *a).abs() < 1e-3);
    let gap = distinct.windows(2).map(|w| w[1] - w[0]).fold(f32::INFINITY, f32::min);
    let gap = if gap.is_finite() { gap } else { 1.0 };
    // Each frame's slice on the grid of `step`, unless one is off it or beyond an axis.
    let on_grid = |step: f32| -> Option<Vec<usize>> {
        d.iter()
            .map(|x| {
                let k = ((x - lo) / step).round();
                let fits = k <= MAX_AXIS as f32 && ((x - lo) - k * step).abs() <= 0.1 * step;
                fits.then_some(k as usize)
            })
            .collect()
    };
    if let Some(k) = step.and_then(on_grid) {
        return Ok((k, first, step.unwrap_or(gap), None));
    }
    let k = on_grid(gap).ok_or_else(|| {
        Problem::Malformed(format!("the frames' positions along the normal lie on no regular grid (smallest gap {gap:.3} mm)"))
    })?;
    let note =
        step.map(|s| format!("Spacing Between Slices {s} mm does not fit the frames' positions: {gap:.3} mm, their smallest gap, is used"));
    Ok((k, first, gap, note))
}

/// A DICOM Recommended Display CIELab Value (PS3.3 §C.10.7.1.1: L*, a*, b* scaled to
/// 0 … 65535, a* and b* offset by 128) as sRGB: CIELab → XYZ (D65 white, as the
/// segmentation viewers do) → linear sRGB (IEC 61966-2-1 matrix) → gamma-encoded.
pub fn cielab_to_srgb(v: [f64; 3]) -> [u8; 3] {
    let l = v[0] * 100.0 / 65535.0;
    let a = v[1] * 255.0 / 65535.0 - 128.0;
    let b = v[2] * 255.0 / 65535.0 - 128.0;
    let fy = (l + 16.0) / 116.0;
    let (fx, fz) = (fy + a / 500.0, fy - b / 200.0);
    let inv = |t: f64| if t > 6.0 / 29.0 { t * t * t } else { 3.0 * (6.0f64 / 29.0).powi(2) * (t - 4.0 / 29.0) };
    let (x, y, z) = (0.950_47 * inv(fx), inv(fy), 1.088_83 * inv(fz));
    let r = 3.240_454_2 * x - 1.537_138_5 * y - 0.498_531_4 * z;
    let g = -0.969_266 * x + 1.876_010_8 * y + 0.041_556 * z;
    let bl = 0.055_643_4 * x - 0.204_025_9 * y + 1.057_225_2 * z;
    let encode = |c: f64| {
        let c = c.clamp(0.0, 1.0);
        let s = if c <= 0.003_130_8 { 12.92 * c } else { 1.055 * c.powf(1.0 / 2.4) - 0.055 };
        (s * 255.0).round() as u8
    };
    [encode(r), encode(g), encode(bl)]
}

#[cfg(test)]
mod tests {
    use super::*;

    /// DICOM's scaled values of L*, a*, b*.
    fn scaled(l: f64, a: f64, b: f64) -> [f64; 3] {
        [l * 65535.0 / 100.0, (a + 128.0) * 65535.0 / 255.0, (b + 128.0) * 65535.0 / 255.0]
    }

    #[test]
    fn cielab_colours_convert_to_srgb() {
        // White and black; sRGB red, green and blue have L*a*b* (D65) 53.24/80.09/67.20,
        // 87.73/−86.18/83.18, 32.30/79.19/−107.86 (Lindbloom's calculator).
        assert_eq!(cielab_to_srgb(scaled(100.0, 0.0, 0.0)), [255, 255, 255]);
        assert_eq!(cielab_to_srgb(scaled(0.0, 0.0, 0.0)), [0, 0, 0]);
        for (lab, rgb) in
            [((53.24, 80.09, 67.20), [255, 0, 0]), ((87.73, -86.18, 83.18), [0, 255, 0]), ((32.30, 79.19, -107.86), [0, 0, 255])]
        {
            let got = cielab_to_srgb(scaled(lab.0, lab.1, lab.2));
            assert!(got.iter().zip(rgb).all(|(g, e)| g.abs_diff(e) <= 2), "{lab:?}: {got:?} for {rgb:?}");
        }
    }

    #[test]
    fn frames_fall_on_slices_of_the_grid_and_gaps_stay_empty() {
        // Distances 10, 14, 12, 20 with step 2: slices 0, 2, 1, 5 (3 and 4 empty).
        let (k, first, step, note) = slice_indices(&[10.0, 14.0, 12.0, 20.0], None).unwrap();
        assert_eq!((k, first, step, note), (vec![0, 2, 1, 5], 0, 2.0, None));
        // Two segments on one slice; the given step wins over the gaps.
        let (k, first, step, note) = slice_indices(&[-3.0, -3.0, 3.0], Some(1.5)).unwrap();
        assert_eq!((k, first, step, note), (vec![0, 0, 4], 0, 1.5, None));
        // A given step the frames do not fit (one between its slices, or a step so small
        // the slices would run past an axis): their smallest gap, with a note.
        let (k, _, step, note) = slice_indices(&[0.0, 1.0, 2.0], Some(0.8)).unwrap();
        assert_eq!((k, step), (vec![0, 1, 2], 1.0));
        assert!(note.is_some_and(|n| n.contains("0.8 mm does not fit")));
        let (k, _, step, _) = slice_indices(&[0.0, 1.0], Some(f32::MIN_POSITIVE)).unwrap();
        assert_eq!((k, step), (vec![0, 1], 1.0));
        // Positions on no grid at all.
        assert!(matches!(slice_indices(&[0.0, 1.0, 2.5], None), Err(Problem::Malformed(_))));
    }
}
