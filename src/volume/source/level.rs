//! A whole level of a source as a [`Volume`] in memory: what `focal info`, the
//! reference renderer and the one-texture GPU path use until a source is drawn brick by
//! brick. Slabs one chunk deep are read in parallel.

use glam::UVec3;
use rayon::prelude::*;

use super::{Fault, FaultKind, SourceError, SourceInfo, VoxelSource};
use crate::volume::grid::fmt_dims;
use crate::volume::{Volume, Voxels};

/// Largest level [`load_finest_within`] loads whole by default (codes).
pub const WHOLE_LEVEL_BYTES: u64 = 256 << 20;

/// The finest level whose codes take at most `max_bytes` (the coarsest if none does).
pub fn finest_within(info: &SourceInfo, max_bytes: u64) -> usize {
    let bytes = |k: usize| info.levels[k].grid.voxel_count() as u64 * (info.bits as u64 / 8);
    (0..info.levels.len()).find(|&k| bytes(k) <= max_bytes).unwrap_or(info.levels.len().saturating_sub(1))
}

/// Reads level `level` whole; `done(voxels)` is called as slabs arrive. The faults of
/// every slab come back beside the volume.
pub fn read_level(source: &dyn VoxelSource, level: usize, done: &(dyn Fn(u64) + Sync)) -> Result<(Volume, Vec<Fault>), SourceError> {
    let info = source.info();
    let Some(l) = info.levels.get(level) else {
        return Err(SourceError::new(info.location(), format!("level {level} asked for, the pyramid has {}", info.levels.len())));
    };
    let dims = l.grid.dims;
    let depth = l.chunk.z.clamp(1, dims.z);
    let slabs: Vec<u32> = (0..dims.z).step_by(depth as usize).collect();
    let blocks: Vec<_> = slabs
        .par_iter()
        .map(|&z| {
            let size = UVec3::new(dims.x, dims.y, depth.min(dims.z - z));
            let block = source.read_box(level, UVec3::new(0, 0, z), size);
            done(size.x as u64 * size.y as u64 * size.z as u64);
            block
        })
        .collect();
    let mut faults = Vec::new();
    let mut voxels = info.zeros(0);
    for block in blocks {
        let block = block?;
        faults.extend(block.faults);
        match (&mut voxels, block.voxels) {
            (Voxels::U8(all), Voxels::U8(part)) => all.extend(part),
            (Voxels::U16(all), Voxels::U16(part)) => all.extend(part),
            _ => return Err(SourceError::new(info.location(), "a slab came back with codes of another width")),
        }
    }
    let mut source_facts = info.source.clone();
    if info.levels.len() > 1 {
        source_facts.details.push(("level shown".into(), format!("{level} of {}", info.levels.len())));
    }
    let volume = Volume::new(info.name.clone(), l.grid.clone(), voxels, info.values.clone(), source_facts)
        .map_err(|e| SourceError::new(info.location(), e))?;
    // (Opacities hold for level 0's voxels at every level: Volume::opacity_reference.)
    let finest = info.levels.first().map_or(l.grid.min_spacing(), |l0| l0.grid.min_spacing());
    Ok((volume.with_opacity_reference(finest), faults))
}

/// The finest level of `source` within `max_bytes`, read whole, with the opening's
/// warnings, why a coarser level was taken and the read's faults as notes (`details`).
pub fn load_finest_within(source: &dyn VoxelSource, max_bytes: u64, done: &(dyn Fn(u64) + Sync)) -> Result<Volume, SourceError> {
    let info = source.info();
    let level = finest_within(info, max_bytes);
    let (mut volume, faults) = read_level(source, level, done)?;
    let notes = &mut volume.source.details;
    notes.extend(info.warnings.iter().map(|w| ("note".to_owned(), w.clone())));
    if level > 0 {
        let finest = &info.levels[0].grid;
        let mib = (finest.voxel_count() as u64 * (info.bits as u64 / 8)) >> 20;
        notes.push((
            "note".into(),
            format!(
                "level {level} ({}) shown whole: level 0 ({}, {mib} MiB) is larger than a level read whole may be ({} MiB)",
                fmt_dims(info.levels[level].grid.dims),
                fmt_dims(finest.dims),
                max_bytes >> 20
            ),
        ));
    }
    if let Some(line) = summarize(&faults) {
        notes.push(("note".into(), line));
    }
    Ok(volume)
}

/// One line for a list of faults: the unreadable chunks (each named, up to five), the
/// samples that were not finite and how many chunks were absent.
pub fn summarize(faults: &[Fault]) -> Option<String> {
    let bad: Vec<&Fault> = faults.iter().filter(|f| f.kind == FaultKind::Unreadable).collect();
    let absent = faults.iter().filter(|f| f.kind == FaultKind::Absent).count();
    let not_finite: Vec<&Fault> = faults.iter().filter(|f| f.kind == FaultKind::NotFinite).collect();
    let mut parts = Vec::new();
    if !not_finite.is_empty() {
        let first = not_finite[0];
        parts.push(format!("NaN or infinite samples in {} chunk(s) (chunk {}: {})", not_finite.len(), first.chunk, first.problem));
    }
    if !bad.is_empty() {
        let named: Vec<String> = bad.iter().take(5).map(|f| format!("chunk {}: {}", f.chunk, f.problem)).collect();
        let more = if bad.len() > 5 { format!(" (and {} more)", bad.len() - 5) } else { String::new() };
        parts.push(format!("{} unreadable chunk(s) drawn at the fill value: {}{more}", bad.len(), named.join("; ")));
    }
    if absent > 0 {
        parts.push(format!("{absent} chunk(s) absent from the store (fill value)"));
    }
    (!parts.is_empty()).then(|| parts.join("; "))
}

#[cfg(test)]
mod tests {
    use std::sync::Arc;
    use std::sync::atomic::{AtomicU64, Ordering};

    use glam::Vec3;

    use super::*;
    use crate::volume::source::memory::MemorySource;
    use crate::volume::source::procedural::ProceduralSource;
    use crate::volume::{Grid, Source, ValueMap};

    #[test]
    fn a_level_read_whole_is_the_level() {
        let s = ProceduralSource::new(UVec3::new(200, 100, 150), Vec3::splat(0.5)).expect("source");
        let count = AtomicU64::new(0);
        let (v, faults) = read_level(&s, 1, &|n| {
            count.fetch_add(n, Ordering::Relaxed);
        })
        .expect("level");
        assert!(faults.is_empty());
        assert_eq!(v.dims(), UVec3::new(100, 50, 75));
        assert_eq!(count.load(Ordering::Relaxed), 100 * 50 * 75);
        assert_eq!(v.grid, s.info().levels[1].grid);
        let b = s.read_box(1, UVec3::new(40, 20, 70), UVec3::ONE).expect("box");
        assert_eq!(v.code(40, 20, 70), b.voxels.code(0));
        // Round trip through a memory source.
        let m = MemorySource::new(Arc::new(v), 8);
        assert_eq!(m.read_box(0, UVec3::new(40, 20, 70), UVec3::ONE).expect("box").voxels.code(0), b.voxels.code(0));
    }

    #[test]
    fn the_finest_level_within_a_budget() {
        let v = Volume::new(
            "v",
            Grid::new(UVec3::splat(64), Vec3::ONE),
            Voxels::U16(vec![0; 64 * 64 * 64]),
            ValueMap::IDENTITY,
            Source::default(),
        )
        .expect("volume");
        let m = MemorySource::new(Arc::new(v), 8);
        assert_eq!(finest_within(m.info(), 64 * 64 * 64 * 2), 0);
        assert_eq!(finest_within(m.info(), 64 * 64 * 64 * 2 - 1), 1);
        assert_eq!(finest_within(m.info(), 1), 3);
        let f = |kind, chunk: &str| Fault { chunk: chunk.into(), kind, problem: "crc mismatch".into() };
        let line =
            summarize(&[f(FaultKind::Unreadable, "0/1/2"), f(FaultKind::Absent, "0/0/0"), f(FaultKind::NotFinite, "0/0/1")]).expect("line");
        assert!(line.contains("chunk 0/1/2: crc mismatch") && line.contains("1 chunk(s) absent"), "{line}");
        assert!(line.contains("NaN or infinite samples in 1 chunk(s) (chunk 0/0/1"), "{line}");
        assert_eq!(summarize(&[]), None);
    }
}
