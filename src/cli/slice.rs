//! `focal render INPUT --slice axial|coronal|sagittal[:INDEX]`: one slice view of a
//! dataset at its voxels' resolution (one pixel per voxel), through a window of values,
//! or in its label colours (`--labels`), as a PNG (`focal::slices`).

use focal::scene::load::LoadedDataset;
use focal::slices::{Orientation, Slice, SliceAxes, WindowLevel, to_image};

/// Largest slice read from a streamed pyramid, in pixels: a finer level's slice would be
/// larger than any screen (and its read slow); the finest level within it is taken.
pub const MAX_SLICE_PIXELS: u64 = 4096 * 4096;

/// `ORIENTATION[:INDEX]`.
pub fn parse_slice(text: &str) -> Result<(Orientation, Option<u32>), String> {
    let (name, index) = match text.split_once(':') {
        Some((n, i)) => (n, Some(i.trim().parse::<u32>().map_err(|e| format!("slice index '{i}' in '{text}': {e}"))?)),
        None => (text, None),
    };
    Ok((name.parse()?, index))
}

/// The window: `--window W --level L`, else a preset (`auto` or a CT one), else auto.
pub fn window_of(width: Option<f64>, level: Option<f64>, preset: Option<&str>, dataset: &LoadedDataset) -> Result<WindowLevel, String> {
    match (width, level, preset) {
        (Some(w), Some(l), _) if w.is_finite() && l.is_finite() && w > 0.0 => Ok(WindowLevel::new(w, l)),
        (Some(_), Some(_), _) => Err("--window must be a positive number and --level a number".into()),
        (Some(_), None, _) | (None, Some(_), _) => Err("give --window and --level together".into()),
        (None, None, Some(p)) if !p.eq_ignore_ascii_case("auto") => WindowLevel::preset(p),
        _ => Ok(WindowLevel::auto(&dataset.volume.stats)),
    }
}

/// The picture of slice `index` (level-0 voxels; the middle by default) of `dataset`
/// seen as `orientation`; says on stderr what it shows.
pub fn picture(
    dataset: &LoadedDataset,
    orientation: Orientation,
    index: Option<u32>,
    window: WindowLevel,
) -> Result<image::RgbaImage, String> {
    let slice = match &dataset.bricked {
        None => {
            let axes = SliceAxes::of(dataset.volume.grid.direction, orientation);
            let count = axes.count(dataset.volume.dims());
            Slice::of_volume(&dataset.volume, axes, index.unwrap_or(count / 2))
        }
        Some(b) => {
            let source = b.cache.source();
            let levels = &source.info().levels;
            let level = focal::slices::image::finest_level_within(levels, orientation, MAX_SLICE_PIXELS)
                .ok_or_else(|| format!("{}: the source has no levels", source.info().location()))?;
            let axes = SliceAxes::of(levels[level].grid.direction, orientation);
            let count0 = axes.count(levels[0].grid.dims);
            let index = index.unwrap_or(count0 / 2) >> level;
            if level > 0 {
                eprintln!("level 0's slices are larger than {MAX_SLICE_PIXELS} pixels: level {level} shown");
            }
            Slice::of_source(source.as_ref(), level, axes, index)?
        }
    };
    let pixels = match &dataset.table {
        Some(table) => slice.labels(table),
        None => slice.grey(&window),
    };
    let image = to_image(slice.width, slice.height, &pixels).ok_or("slice picture of the wrong size")?;
    let (medical, axis) = orientation.names();
    let (mm_x, mm_y) = slice.axes.pixel_mm(slice.grid.spacing);
    let shown =
        if dataset.table.is_some() { "label colours".to_string() } else { format!("window {} / level {}", window.width, window.level) };
    eprintln!(
        "{}: {medical} ({axis}) slice {} of {}, {}×{} pixels of {mm_x:.3}×{mm_y:.3} mm, {shown}",
        dataset.name,
        slice.index,
        slice.axes.count(slice.grid.dims),
        slice.width,
        slice.height
    );
    Ok(image)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn slice_arguments_parse() {
        assert_eq!(parse_slice("axial"), Ok((Orientation::Axial, None)));
        assert_eq!(parse_slice("Sagittal:12"), Ok((Orientation::Sagittal, Some(12))));
        assert!(parse_slice("axial:-1").unwrap_err().contains("slice index '-1'"));
        assert!(parse_slice("oblique").is_err());
    }
}
