//! A store that refuses blosc frames claiming more decoded bytes than a chunk can hold.
//!
//! A blosc frame's 16-byte header gives its decoded size (`nbytes`, bytes 4–7) and its
//! compressed size (`cbytes`, bytes 12–15), and the blosc codec makes its output buffer
//! from `nbytes` before it decodes anything: one corrupted chunk (the fuzzer's first
//! find in `tests/fuzz_readers.rs`, `nbytes` 4 096 → 956 301 312) made a 912 MiB
//! allocation. Every value read from an array that uses blosc passes [`Guarded::check`]
//! first: a frame whose `nbytes` exceeds the array's largest chunk (its shape times 8
//! bytes, the widest sample type Focal reads) is an error that names the key, so the
//! chunk is drawn as unreadable and nothing is allocated for it. Arrays without blosc
//! pass untouched (their raw bytes may look like anything).
//!
//! A sharded array (`sharding_indexed`) whose inner chunks use blosc is guarded at its
//! inner chunks: those read by byte range are checked one by one against an inner
//! chunk's size, and a shard read whole (one `get`, when a box covers it) is walked
//! through its index ([`ShardIndex`]): every inner frame it lists is checked so.

use std::sync::RwLock;

use zarrs::storage::byte_range::ByteRangeIterator;
use zarrs::storage::{MaybeBytes, MaybeBytesIterator, ReadableStorage, ReadableStorageTraits, StorageError, StoreKey};

/// The store the reader sees.
pub struct Guarded {
    inner: ReadableStorage,
    /// Key prefix (an array's path and `/`) and the limit of each array whose codecs
    /// include blosc.
    blosc: RwLock<Vec<(String, Limit)>>,
}

/// What a blosc frame of one array may claim.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Limit {
    /// The largest decoded (inner) chunk, in bytes.
    pub chunk: u64,
    /// How a shard lists its inner chunks, for a sharded array.
    pub shard: Option<ShardIndex>,
}

/// A shard's index (Zarr v3 `sharding_indexed`): for each of its `chunks` inner chunks
/// an (offset, length) pair of little-endian u64 (both `u64::MAX`: an empty chunk), then
/// a CRC32C where `checksum`, at the shard's end or start.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct ShardIndex {
    pub chunks: u64,
    pub at_end: bool,
    pub checksum: bool,
}

impl ShardIndex {
    /// The index's length in bytes.
    pub fn bytes(&self) -> u64 {
        self.chunks.saturating_mul(16).saturating_add(if self.checksum { 4 } else { 0 })
    }

    /// The byte ranges of the inner chunks `shard` lists that lie within it (a shard too
    /// short for its index lists none: the reader reports it).
    pub fn frames(&self, shard: &[u8]) -> Vec<std::ops::Range<usize>> {
        let n = shard.len() as u64;
        if self.bytes() > n {
            return Vec::new();
        }
        let at = if self.at_end { n - self.bytes() } else { 0 } as usize;
        let word = |i: usize| u64::from_le_bytes(shard[i..i + 8].try_into().unwrap_or([0; 8]));
        (0..self.chunks as usize)
            .map(|k| (word(at + 16 * k), word(at + 16 * k + 8)))
            .filter(|&(offset, length)| offset != u64::MAX && offset.checked_add(length).is_some_and(|end| end <= n))
            .map(|(offset, length)| offset as usize..(offset + length) as usize)
            .collect()
    }
}

impl Guarded {
    pub fn new(inner: ReadableStorage) -> Self {
        Self { inner, blosc: RwLock::new(Vec::new()) }
    }

    /// From now on, values under `prefix` are checked against `limit`.
    pub fn guard(&self, prefix: String, limit: Limit) {
        if let Ok(mut b) = self.blosc.write() {
            b.push((prefix, limit));
        }
    }

    fn limit(&self, key: &StoreKey) -> Option<Limit> {
        let b = self.blosc.read().ok()?;
        b.iter().find(|(p, _)| key.as_str().starts_with(p.as_str())).map(|(_, l)| *l)
    }

    /// `bytes` if it is no blosc frame or one within `limit`.
    pub fn check(key: &StoreKey, limit: u64, bytes: zarrs::storage::Bytes) -> Result<zarrs::storage::Bytes, StorageError> {
        match blosc_claim(&bytes) {
            Some(n) if n > limit => Err(StorageError::Other(format!(
                "chunk {}: its blosc header claims {n} decoded bytes, more than a chunk of this array holds ({limit})",
                key.as_str()
            ))),
            _ => Ok(bytes),
        }
    }

    /// A value read whole: a shard's every inner frame, else the value as one frame.
    pub fn check_whole(key: &StoreKey, limit: Limit, bytes: zarrs::storage::Bytes) -> Result<zarrs::storage::Bytes, StorageError> {
        let Some(index) = limit.shard else { return Self::check(key, limit.chunk, bytes) };
        for frame in index.frames(&bytes) {
            if let Some(n) = blosc_claim(&bytes[frame.clone()]).filter(|&n| n > limit.chunk) {
                return Err(StorageError::Other(format!(
                    "shard {}: the blosc header of its chunk at byte {} claims {n} decoded bytes, more than a chunk of this array holds ({})",
                    key.as_str(),
                    frame.start,
                    limit.chunk
                )));
            }
        }
        Ok(bytes)
    }
}

/// The decoded size a blosc frame claims: a known format version, a compressed size
/// that fits in the bytes at hand.
pub fn blosc_claim(b: &[u8]) -> Option<u64> {
    if b.len() < 16 || !(1..=4).contains(&b[0]) {
        return None;
    }
    let word = |i: usize| u32::from_le_bytes([b[i], b[i + 1], b[i + 2], b[i + 3]]) as u64;
    let cbytes = word(12);
    (16..=b.len() as u64).contains(&cbytes).then(|| word(4))
}

impl ReadableStorageTraits for Guarded {
    fn get(&self, key: &StoreKey) -> Result<MaybeBytes, StorageError> {
        let value = self.inner.get(key)?;
        match (value, self.limit(key)) {
            (Some(b), Some(limit)) => Self::check_whole(key, limit, b).map(Some),
            (value, _) => Ok(value),
        }
    }

    fn get_partial_many<'a>(&'a self, key: &StoreKey, byte_ranges: ByteRangeIterator<'a>) -> Result<MaybeBytesIterator<'a>, StorageError> {
        let values = self.inner.get_partial_many(key, byte_ranges)?;
        // (Ranges of a shard are its inner chunks, or its index: no frame.)
        let Some(limit) = self.limit(key) else { return Ok(values) };
        let key = key.clone();
        Ok(values.map(|it| Box::new(it.map(move |b| b.and_then(|b| Self::check(&key, limit.chunk, b)))) as _))
    }

    fn size_key(&self, key: &StoreKey) -> Result<Option<u64>, StorageError> {
        self.inner.size_key(key)
    }

    fn supports_get_partial(&self) -> bool {
        self.inner.supports_get_partial()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_frame_claiming_more_than_a_chunk_is_refused() {
        // The header of a real 16³ uint8 chunk (blosc 2, zstd), then the fuzzer's change.
        let mut frame = vec![0x02, 0x01, 0x91, 0x01, 0x00, 0x10, 0x00, 0x00, 0x00, 0x10, 0x00, 0x00, 0x2f, 0x00, 0x00, 0x00];
        frame.resize(0x2f, 0);
        assert_eq!(blosc_claim(&frame), Some(4096));
        let key = StoreKey::new("0/1/2/0").unwrap();
        assert!(Guarded::check(&key, 4096 * 8, frame.clone().into()).is_ok());
        frame[7] = 0x39;
        assert_eq!(blosc_claim(&frame), Some(0x3900_1000));
        let e = Guarded::check(&key, 4096 * 8, frame.clone().into()).unwrap_err().to_string();
        assert!(e.contains("0/1/2/0") && e.contains("956305408"), "{e}");
        // Not a frame: a compressed size beyond the bytes, an unknown version.
        frame[12] = 0x30;
        assert_eq!(blosc_claim(&frame), None);
        assert_eq!(blosc_claim(&[0x28, 0xb5, 0x2f, 0xfd, 0, 0, 0, 0, 0, 0, 0, 0, 16, 0, 0, 0]), None);
    }

    /// A shard of two inner frames and an empty chunk, its index at the end with a
    /// checksum: read whole, each listed frame is checked; one claiming more than an
    /// inner chunk is refused, naming the shard and the frame's place.
    #[test]
    fn every_frame_a_shard_lists_is_checked() {
        let frame = |claim: u32| {
            let mut f = vec![0x02, 0x01, 0x91, 0x01];
            f.extend_from_slice(&claim.to_le_bytes());
            f.extend_from_slice(&[0x00, 0x10, 0x00, 0x00, 0x20, 0x00, 0x00, 0x00]);
            f.resize(0x20, 0);
            f
        };
        let index = ShardIndex { chunks: 3, at_end: true, checksum: true };
        let shard = |second: u32| {
            let mut s = frame(4096);
            s.extend(frame(second));
            for (offset, length) in [(0u64, 0x20u64), (0x20, 0x20), (u64::MAX, u64::MAX)] {
                s.extend_from_slice(&offset.to_le_bytes());
                s.extend_from_slice(&length.to_le_bytes());
            }
            s.extend_from_slice(&[0; 4]);
            s
        };
        assert_eq!(index.bytes(), 52);
        assert_eq!(index.frames(&shard(4096)), vec![0..0x20, 0x20..0x40]);
        let limit = Limit { chunk: 4096 * 8, shard: Some(index) };
        let key = StoreKey::new("0/c/0/0/0").unwrap();
        assert!(Guarded::check_whole(&key, limit, shard(4096).into()).is_ok());
        let e = Guarded::check_whole(&key, limit, shard(0x3900_1000).into()).unwrap_err().to_string();
        assert!(e.contains("0/c/0/0/0") && e.contains("byte 32") && e.contains("956305408"), "{e}");
        // (The first frame alone, as a whole-chunk check saw it, passes.)
        assert!(Guarded::check(&key, 4096 * 8, shard(0x3900_1000).into()).is_ok());
        // An index at the start; a shard too short for its index lists nothing.
        let at_start = ShardIndex { chunks: 1, at_end: false, checksum: false };
        let mut s = 16u64.to_le_bytes().to_vec();
        s.extend_from_slice(&0x20u64.to_le_bytes());
        s.extend(frame(4096));
        assert_eq!(at_start.frames(&s), vec![16..48]);
        assert!(index.frames(&[0u8; 20]).is_empty());
    }
}
