//! Value range, histogram and summary statistics of a volume.
//!
//! One parallel pass counts every code (256 or 65 536 counters); everything else —
//! range, mean, standard deviation, percentiles and a histogram binned over the real
//! value range — is derived from those counts exactly.

use rayon::prelude::*;

use super::voxels::{ValueMap, Voxels};

/// Number of bins of the display histogram.
pub const HISTOGRAM_BINS: usize = 256;

/// Summary of the values in a volume, in real units.
#[derive(Clone, Debug, PartialEq)]
pub struct ValueStats {
    pub code_min: u16,
    pub code_max: u16,
    /// Smallest and largest real value present.
    pub min: f64,
    pub max: f64,
    pub mean: f64,
    pub std_dev: f64,
    /// 1st, 50th and 99th percentile.
    pub p01: f64,
    pub median: f64,
    pub p99: f64,
    /// Number of voxels whose code is not the minimum (useful for masks and labels).
    pub above_min: u64,
    /// Voxels with no value (`ValueMap::no_data`), left out of everything above.
    pub no_data: u64,
    pub histogram: Histogram,
}

/// Counts of voxels in equal-width bins over `[min, max]` (real units).
#[derive(Clone, Debug, PartialEq)]
pub struct Histogram {
    pub min: f64,
    pub max: f64,
    pub counts: Vec<u64>,
}

impl Histogram {
    /// Real value at the centre of bin `i`.
    pub fn bin_center(&self, i: usize) -> f64 {
        let w = (self.max - self.min) / self.counts.len() as f64;
        self.min + (i as f64 + 0.5) * w
    }

    pub fn total(&self) -> u64 {
        self.counts.iter().sum()
    }
}

/// Counts of every code from 0 to the largest present (in parallel for large volumes).
pub fn code_counts(voxels: &Voxels) -> Vec<u64> {
    // Tallies only span the codes in use (cache-friendly for 16-bit data with a narrow
    // range), in u32 per chunk (a chunk never holds 2³² voxels).
    fn count<T: Copy + Into<usize> + Ord + Sync>(v: &[T]) -> Vec<u64> {
        let n = v.iter().copied().max().map_or(0, Into::into) + 1;
        let tally = |chunk: &[T]| {
            let mut acc = vec![0u32; n];
            for &c in chunk {
                acc[c.into()] += 1;
            }
            acc.into_iter().map(u64::from).collect::<Vec<u64>>()
        };
        if v.len() < 1 << 20 {
            return tally(v);
        }
        let chunk = v.len().div_ceil(rayon::current_num_threads().max(1)).min(u32::MAX as usize);
        v.par_chunks(chunk).map(tally).reduce(
            || vec![0u64; n],
            |mut a, b| {
                a.iter_mut().zip(b).for_each(|(x, y)| *x += y);
                a
            },
        )
    }
    match voxels {
        Voxels::U8(v) => count(v),
        Voxels::U16(v) => count(v),
    }
}

/// Computes the statistics of `voxels` under `map`.
pub fn compute(voxels: &Voxels, map: &ValueMap) -> ValueStats {
    let mut counts = code_counts(voxels);
    let no_data = map.no_data.and_then(|c| counts.get_mut(c as usize)).map_or(0, std::mem::take);
    ValueStats { no_data, ..from_counts(&counts, map) }
}

/// Derives the statistics from per-code counts (at least one count must be non-zero),
/// in one pass over the codes present.
pub fn from_counts(counts: &[u64], map: &ValueMap) -> ValueStats {
    let total: u64 = counts.iter().sum();
    let code_min = counts.iter().position(|&c| c > 0).unwrap_or(0);
    let code_max = counts.iter().rposition(|&c| c > 0).unwrap_or(0);
    let (lo, hi) = (map.to_real(code_min as f64), map.to_real(code_max as f64));
    let (min, max) = (lo.min(hi), lo.max(hi));
    let width = (max - min).max(f64::MIN_POSITIVE);
    let targets = [0.01, 0.5, 0.99].map(|q: f64| (q * total as f64).ceil().max(1.0) as u64);
    let mut percentiles = [map.to_real(code_max as f64); 3];
    let mut bins = vec![0u64; HISTOGRAM_BINS];
    let (mut sum, mut sum2, mut acc) = (0.0f64, 0.0f64, 0u64);
    for (code, &c) in counts.iter().enumerate().take(code_max + 1).skip(code_min) {
        if c == 0 {
            continue;
        }
        let v = map.to_real(code as f64);
        sum += v * c as f64;
        sum2 += v * v * c as f64;
        for (p, &t) in percentiles.iter_mut().zip(&targets) {
            if acc < t && acc + c >= t {
                *p = v;
            }
        }
        acc += c;
        let b = (((v - min) / width) * HISTOGRAM_BINS as f64) as usize;
        bins[b.min(HISTOGRAM_BINS - 1)] += c;
    }
    let n = total.max(1) as f64;
    let mean = sum / n;
    ValueStats {
        code_min: code_min as u16,
        code_max: code_max as u16,
        min,
        max,
        mean,
        std_dev: (sum2 / n - mean * mean).max(0.0).sqrt(),
        p01: percentiles[0],
        median: percentiles[1],
        p99: percentiles[2],
        above_min: total - counts.get(code_min).copied().unwrap_or(0),
        no_data: 0,
        histogram: Histogram { min, max, counts: bins },
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn statistics_match_a_direct_computation() {
        let values: Vec<u8> = (0..1000u32).map(|i| ((i * 37) % 200) as u8).collect();
        let map = ValueMap::new(0.5, -10.0);
        let s = compute(&Voxels::U8(values.clone()), &map);
        let real: Vec<f64> = values.iter().map(|&v| v as f64 * 0.5 - 10.0).collect();
        let mean = real.iter().sum::<f64>() / real.len() as f64;
        let var = real.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / real.len() as f64;
        assert!((s.mean - mean).abs() < 1e-9);
        assert!((s.std_dev - var.sqrt()).abs() < 1e-9);
        assert_eq!(s.min, -10.0);
        assert_eq!(s.max, 199.0 * 0.5 - 10.0);
        let mut sorted = real.clone();
        sorted.sort_by(f64::total_cmp);
        assert_eq!(s.median, sorted[499]);
        assert_eq!(s.histogram.total(), 1000);
        assert_eq!(s.histogram.counts.len(), HISTOGRAM_BINS);
    }

    #[test]
    fn negative_slope_keeps_min_below_max() {
        let s = compute(&Voxels::U16(vec![0, 10]), &ValueMap::new(-1.0, 0.0));
        assert_eq!((s.min, s.max), (-10.0, 0.0));
        assert_eq!(s.above_min, 1);
    }
}
