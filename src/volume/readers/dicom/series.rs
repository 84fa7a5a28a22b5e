//! Assembling DICOM slices or frames into one volume: grouping, sorting and geometry.

use std::path::{Path, PathBuf};

use dicom_dictionary_std::tags;
use dicom_object::{DefaultDicomObject, InMemDicomObject};
use glam::{Mat3, Vec3};

use super::file::{PixelFormat, float, floats, group_value, int, open, pixel_bytes, string, vec3};
use crate::volume::encode::{ByteOrder, encode_samples, encode_values};
use crate::volume::grid::{lps_axes_to_ras, lps_to_ras};
use crate::volume::readers::common::{Problem, ReadError, ReadOptions, volume_name};
use crate::volume::{Grid, Source, ValueMap, Volume};

/// Where one frame (or slice) lies, in LPS millimetres, and how to rescale its values.
#[derive(Clone, Debug, PartialEq)]
pub struct FrameGeometry {
    pub position: Option<Vec3>,
    /// Row direction (along a row: increasing column index) and column direction.
    pub orientation: Option<[Vec3; 2]>,
    /// Pixel Spacing: (between rows, between columns).
    pub pixel_spacing: Option<[f32; 2]>,
    pub slope: f64,
    pub intercept: f64,
}

pub(super) fn frame_geometry(o: &InMemDicomObject, frame: Option<usize>) -> FrameGeometry {
    let get = |seq, tag| match frame {
        Some(f) => group_value(o, f, seq, tag).and_then(|e| e.to_multi_float64().ok()).filter(|v| v.iter().all(|x| x.is_finite())),
        None => floats(o, tag),
    };
    let position = get(tags::PLANE_POSITION_SEQUENCE, tags::IMAGE_POSITION_PATIENT)
        .or_else(|| floats(o, tags::IMAGE_POSITION_PATIENT))
        .filter(|v| v.len() == 3)
        .map(|v| vec3(&v));
    let orientation = get(tags::PLANE_ORIENTATION_SEQUENCE, tags::IMAGE_ORIENTATION_PATIENT)
        .or_else(|| floats(o, tags::IMAGE_ORIENTATION_PATIENT))
        .filter(|v| v.len() == 6)
        .map(|v| [vec3(&v[..3]), vec3(&v[3..])])
        .filter(|[r, c]| r.length() > 0.5 && c.length() > 0.5 && r.cross(*c).length() > 0.5);
    let pixel_spacing = get(tags::PIXEL_MEASURES_SEQUENCE, tags::PIXEL_SPACING)
        .or_else(|| floats(o, tags::PIXEL_SPACING))
        .or_else(|| floats(o, tags::IMAGER_PIXEL_SPACING))
        .filter(|v| v.len() == 2 && v[0] > 0.0 && v[1] > 0.0)
        .map(|v| [v[0] as f32, v[1] as f32]);
    let rescale = |tag| match frame {
        Some(f) => {
            group_value(o, f, tags::PIXEL_VALUE_TRANSFORMATION_SEQUENCE, tag).and_then(|e| e.to_float64().ok()).or_else(|| float(o, tag))
        }
        None => float(o, tag),
    };
    // (RT Dose: Dose Grid Scaling turns stored values into dose.)
    let slope = rescale(tags::RESCALE_SLOPE).or_else(|| float(o, tags::DOSE_GRID_SCALING)).filter(|s| *s != 0.0).unwrap_or(1.0);
    let intercept = rescale(tags::RESCALE_INTERCEPT).unwrap_or(0.0);
    FrameGeometry { position, orientation, pixel_spacing, slope, intercept }
}

/// One slice (file) or frame with its pixels.
pub(super) struct Plane {
    pub(super) geometry: FrameGeometry,
    pub(super) instance: i64,
    pub(super) bytes: Vec<u8>,
}

/// Reads every DICOM file in `files` and assembles the largest series.
pub fn read_series(dir: &Path, files: &[PathBuf], options: &ReadOptions) -> Result<Volume, ReadError> {
    read_series_of(dir, files, None, options)
}

/// Like [`read_series`], restricted to one Series Instance UID when given. Where `at`
/// is one of `files` (the user opened that slice), the group read is the one holding
/// it, and its pixel format is the series's. Files of the group that cannot be read as
/// that format (another format, pixel data that does not decode) are skipped and named
/// in the volume's notes, as are files that do not parse; only the opened file's own
/// failure is an error.
pub fn read_series_of(at: &Path, files: &[PathBuf], uid: Option<&str>, options: &ReadOptions) -> Result<Volume, ReadError> {
    // (The folder's listing may name the opened file otherwise: `./a.dcm` for `a.dcm`.)
    let at_canonical = std::fs::canonicalize(at).ok();
    let is_opened =
        |p: &Path| p == at || p.file_name() == at.file_name() && at_canonical.is_some() && std::fs::canonicalize(p).ok() == at_canonical;
    let mut objects: Vec<(PathBuf, DefaultDicomObject)> = Vec::new();
    let mut first_error: Option<ReadError> = None;
    let mut skipped: Vec<String> = Vec::new();
    for f in files {
        match open(f, options) {
            Ok(o) => objects.push((f.clone(), o)),
            // The opened file's own failure is the answer.
            Err(e) if is_opened(f) => return Err(e),
            Err(e) => {
                // Non-DICOM files (DICOMDIR, notes) are common in exported folders.
                if !matches!(e.problem, Problem::NotFormat { .. }) {
                    skipped.push(format!("{} ({})", file_name(f), e.problem));
                    first_error.get_or_insert(e);
                }
            }
        }
    }
    if objects.is_empty() {
        return Err(first_error
            .unwrap_or_else(|| ReadError::new(at, Problem::NotFormat { format: "DICOM", detail: "no DICOM files found".into() })));
    }
    // Group by series, image size and orientation.
    let key = |o: &DefaultDicomObject| {
        let g = frame_geometry(o, None);
        let orient = g.orientation.map(|[r, c]| [r, c].map(|v| (v * 100.0).round().as_ivec3().to_array()));
        (string(o, tags::SERIES_INSTANCE_UID), int(o, tags::ROWS), int(o, tags::COLUMNS), orient)
    };
    let mut groups: Vec<(_, Vec<usize>)> = Vec::new();
    let mut other_series: Vec<Option<String>> = Vec::new();
    for (i, (_, o)) in objects.iter().enumerate() {
        if let Some(u) = uid
            && string(o, tags::SERIES_INSTANCE_UID).as_deref() != Some(u)
        {
            let theirs = string(o, tags::SERIES_INSTANCE_UID);
            if !other_series.contains(&theirs) {
                other_series.push(theirs);
            }
            continue;
        }
        let k = key(o);
        match groups.iter_mut().find(|(g, _)| *g == k) {
            Some((_, v)) => v.push(i),
            None => groups.push((k, vec![i])),
        }
    }
    let opened = objects.iter().position(|(p, _)| is_opened(p));
    let chosen = match opened {
        Some(i) => groups.iter().find(|(_, v)| v.contains(&i)),
        None => groups.iter().max_by_key(|(_, v)| v.len()),
    };
    let Some((_, chosen)) = chosen else {
        return Err(ReadError::new(at, Problem::Malformed("no slice of the series was readable".into())));
    };
    let others = groups.len() - 1 + other_series.len();
    // The series's pixel format: the opened file's, else the most common one.
    let formats: Vec<Result<PixelFormat, Problem>> = chosen.iter().map(|&i| PixelFormat::of(&objects[i].1)).collect();
    let reference = match opened.filter(|o| chosen.contains(o)) {
        Some(o) => PixelFormat::of(&objects[o].1).map_err(|p| ReadError::new(at, p))?,
        None => {
            let ok: Vec<PixelFormat> = formats.iter().filter_map(|f| f.as_ref().ok()).copied().collect();
            match ok.iter().max_by_key(|f| ok.iter().filter(|g| g == f).count()) {
                Some(common) => *common,
                None => {
                    let (p, o) = &objects[chosen[0]];
                    return Err(ReadError::new(p, PixelFormat::of(o).err().unwrap_or(Problem::Malformed("no pixel format".into()))));
                }
            }
        }
    };
    let format = reference;
    options
        .check_size([format.cols as u64, format.rows as u64, chosen.len() as u64], format.bits_allocated as usize / 8)
        .map_err(|p| ReadError::new(at, p))?;
    let mut planes = Vec::with_capacity(chosen.len());
    let mut first = None;
    for (&i, f) in chosen.iter().zip(formats) {
        let (p, o) = &objects[i];
        let bytes = match f {
            Ok(f) if f == format => pixel_bytes(o, &format, 1).map(|b| b.into_owned()),
            Ok(_) => Err(Problem::Malformed("pixel format differs from the rest of the series".into())),
            Err(e) => Err(e),
        };
        match bytes {
            Ok(bytes) => {
                first.get_or_insert(i);
                planes.push(Plane {
                    geometry: frame_geometry(o, None),
                    instance: int(o, tags::INSTANCE_NUMBER).map(i64::from).unwrap_or(i as i64),
                    bytes,
                });
            }
            Err(e) if Some(i) == opened => return Err(ReadError::new(p, e)),
            Err(e) => skipped.push(format!("{} ({e})", file_name(p))),
        }
    }
    let Some(first) = first else {
        return Err(ReadError::new(at, Problem::Malformed(format!("no slice of the series was readable: {}", skipped.join("; ")))));
    };
    let first = &objects[first].1;
    let mut notes = Vec::new();
    if others > 0 {
        notes.push(format!("{others} other series (or image sizes) in the folder were not loaded"));
    }
    if !skipped.is_empty() {
        const LISTED: usize = 5;
        let more = skipped.len().saturating_sub(LISTED);
        let mut listed = skipped[..skipped.len().min(LISTED)].join("; ");
        if more > 0 {
            listed.push_str(&format!("; and {more} more"));
        }
        notes.push(format!("{} file(s) skipped: {listed}", skipped.len()));
    }
    let name = string(first, tags::SERIES_DESCRIPTION)
        .unwrap_or_else(|| at.file_name().map(|n| n.to_string_lossy().into_owned()).unwrap_or_else(|| "DICOM".into()));
    assemble(at, first, format, planes, name, "DICOM series", notes)
}

fn file_name(p: &Path) -> String {
    p.file_name().map(|n| n.to_string_lossy().into_owned()).unwrap_or_else(|| p.display().to_string())
}

/// Reads a multi-frame object.
pub fn read_multiframe(path: &Path, object: DefaultDicomObject, options: &ReadOptions) -> Result<Volume, ReadError> {
    let fail = |p: Problem| ReadError::new(path, p);
    let format = PixelFormat::of(&object).map_err(fail)?;
    let frames = int(&object, tags::NUMBER_OF_FRAMES).unwrap_or(1) as usize;
    options.check_size([format.cols as u64, format.rows as u64, frames as u64], format.bits_allocated as usize / 8).map_err(fail)?;
    let all = pixel_bytes(&object, &format, frames).map_err(fail)?;
    let fb = format.frame_bytes();
    let mut planes: Vec<Plane> = (0..frames)
        .map(|f| Plane { geometry: frame_geometry(&object, Some(f)), instance: f as i64, bytes: all[f * fb..(f + 1) * fb].to_vec() })
        .collect();
    // RT Dose: the frames' offsets along the normal from the first (Grid Frame Offset
    // Vector; relative when its first element is 0, else absolute: the differences from
    // the first element serve both).
    let offsets = floats(&object, tags::GRID_FRAME_OFFSET_VECTOR).filter(|o| o.len() == frames && o.iter().all(|x| x.is_finite()));
    let one_position = planes.iter().all(|p| p.geometry.position == planes[0].geometry.position);
    if let (Some(offsets), true, Some(p0), Some([r, c])) =
        (offsets, one_position, planes[0].geometry.position, planes[0].geometry.orientation)
    {
        let n = r.cross(c).normalize();
        for (p, o) in planes.iter_mut().zip(&offsets) {
            p.geometry.position = Some(p0 + n * (o - offsets[0]) as f32);
        }
    }
    // Frames without their own position: stack them along the normal from the first.
    if planes.iter().any(|p| p.geometry.position.is_none())
        && let (Some(p0), Some([r, c])) = (
            planes[0].geometry.position.or_else(|| floats(&object, tags::IMAGE_POSITION_PATIENT).map(|v| vec3(&v))),
            planes[0].geometry.orientation,
        )
    {
        let step = float(&object, tags::SPACING_BETWEEN_SLICES).or_else(|| float(&object, tags::SLICE_THICKNESS)).unwrap_or(1.0) as f32;
        let n = r.cross(c).normalize();
        for (k, p) in planes.iter_mut().enumerate() {
            p.geometry.position = Some(p0 + n * step * k as f32);
        }
    }
    drop(all);
    let name = string(&object, tags::SERIES_DESCRIPTION).unwrap_or_else(|| volume_name(path));
    assemble(path, &object, format, std::mem::take(&mut planes), name, "DICOM multi-frame", Vec::new())
}

/// Sorts planes along the slice normal, derives the grid and encodes the voxels.
pub(super) fn assemble(
    at: &Path,
    first: &DefaultDicomObject,
    format: PixelFormat,
    mut planes: Vec<Plane>,
    name: String,
    kind: &str,
    mut notes: Vec<String>,
) -> Result<Volume, ReadError> {
    let fail = |p: Problem| ReadError::new(at, p);
    let g0 = planes[0].geometry.clone();
    let [row, col] = g0.orientation.unwrap_or([Vec3::X, Vec3::Y]);
    if g0.orientation.is_none() {
        notes.push("no Image Orientation (Patient): assumed axial".into());
    }
    let normal = row.cross(col).normalize();
    let positioned = planes.iter().all(|p| p.geometry.position.is_some());
    if positioned {
        planes.sort_by(|a, b| {
            let da = a.geometry.position.map(|p| p.dot(normal)).unwrap_or(0.0);
            let db = b.geometry.position.map(|p| p.dot(normal)).unwrap_or(0.0);
            da.total_cmp(&db)
        });
        let before = planes.len();
        planes.dedup_by(|b, a| match (a.geometry.position, b.geometry.position) {
            (Some(pa), Some(pb)) => (pa - pb).length() < 1e-3,
            _ => false,
        });
        if planes.len() < before {
            notes.push(format!(
                "{} frame(s) at repeated positions skipped (several stacks or time points: showing the first)",
                before - planes.len()
            ));
        }
    } else {
        planes.sort_by_key(|p| p.instance);
        notes.push("slices have no Image Position (Patient): ordered by Instance Number".into());
    }
    let [ps_row, ps_col] = g0.pixel_spacing.unwrap_or_else(|| {
        notes.push("no Pixel Spacing: 1 mm assumed".into());
        [1.0, 1.0]
    });
    let n = planes.len();
    let slice_axis = match (positioned, n) {
        (true, n) if n >= 2 => {
            let p0 = planes[0].geometry.position.unwrap_or(Vec3::ZERO);
            let pn = planes[n - 1].geometry.position.unwrap_or(Vec3::ZERO);
            let step = (pn - p0) / (n - 1) as f32;
            let gaps: Vec<f32> =
                planes.windows(2).filter_map(|w| Some((w[1].geometry.position? - w[0].geometry.position?).length())).collect();
            let (lo, hi) = gaps.iter().fold((f32::INFINITY, 0.0f32), |(lo, hi), &g| (lo.min(g), hi.max(g)));
            if hi - lo > 0.01 * step.length().max(1e-6) {
                notes.push(format!("irregular slice spacing ({lo:.3}–{hi:.3} mm): using the mean {:.3} mm", step.length()));
            }
            step
        }
        _ => {
            normal
                * float(first, tags::SPACING_BETWEEN_SLICES)
                    .or_else(|| float(first, tags::SLICE_THICKNESS))
                    .filter(|s| *s > 0.0)
                    .unwrap_or(1.0) as f32
        }
    };
    let axes_lps = Mat3::from_cols(row.normalize() * ps_col, col.normalize() * ps_row, slice_axis);
    let origin = planes[0].geometry.position.unwrap_or(Vec3::ZERO);
    let dims = glam::UVec3::new(format.cols, format.rows, n as u32);
    let grid = Grid::from_axes(dims, lps_axes_to_ras(axes_lps), lps_to_ras(origin))
        .map_err(|e| fail(Problem::Malformed(format!("slice geometry: {e}"))))?;

    let mut bytes = Vec::with_capacity(format.frame_bytes() * n);
    for p in &planes {
        bytes.extend_from_slice(&p.bytes);
    }
    format.normalise(&mut bytes);
    let ty = format.sample_type();
    let uniform = planes.iter().all(|p| p.geometry.slope == g0.slope && p.geometry.intercept == g0.intercept);
    let encoded = if uniform {
        let mut e = encode_samples(bytes, ty, ByteOrder::Little).map_err(|e| fail(Problem::Values(e)))?;
        e.map = e.map.then(g0.slope, g0.intercept);
        e
    } else {
        // Rescale differs per frame: apply it to every value, then quantise once.
        let raw = encode_samples(bytes, ty, ByteOrder::Little).map_err(|e| fail(Problem::Values(e)))?;
        let per = format.rows as usize * format.cols as usize;
        let real: Vec<f64> = (0..raw.voxels.len())
            .map(|i| {
                let g = &planes[i / per].geometry;
                raw.map.to_real(raw.voxels.code(i) as f64) * g.slope + g.intercept
            })
            .collect();
        notes.push("rescale differs between frames: values quantised to 16 bits".into());
        encode_values(&real, crate::volume::SampleType::F64).map_err(|e| fail(Problem::Values(e)))?
    };
    let modality = string(first, tags::MODALITY);
    let units = string(first, tags::RESCALE_TYPE)
        .filter(|t| t != "US")
        .or_else(|| (modality.as_deref() == Some("CT")).then(|| "HU".to_string()))
        .or_else(|| {
            string(first, tags::DOSE_UNITS).map(|u| if u.eq_ignore_ascii_case("GY") { "Gy".into() } else { u.to_ascii_lowercase() })
        });
    let values = ValueMap { units, ..encoded.map };

    let mut details: Vec<(String, String)> = Vec::new();
    let mut add = |k: &str, v: Option<String>| {
        if let Some(v) = v {
            details.push((k.to_string(), v));
        }
    };
    add("modality", modality);
    add("series", string(first, tags::SERIES_DESCRIPTION));
    add("transfer syntax", Some(first.meta().transfer_syntax().to_string()));
    add(
        "window",
        floats(first, tags::WINDOW_CENTER).zip(floats(first, tags::WINDOW_WIDTH)).map(|(c, w)| format!("centre {} width {}", c[0], w[0])),
    );
    add("slices", Some(n.to_string()));
    for note in notes {
        details.push(("note".into(), note));
    }
    let source = Source { format: kind.into(), path: Some(at.to_path_buf()), sample_type: ty.name().into(), details };
    Volume::new(name, grid, encoded.voxels, values, source).map_err(|e| fail(Problem::Malformed(e)))
}
