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
//! Not yet covered (issue 26): a sharded array whose inner chunks use blosc. Its inner
//! chunks read by byte range are checked one by one, but against the shard's size; a
//! shard read whole (one `get`, when a box covers it) is checked at its first bytes
//! only. Guarding those needs the shard index parsed here.

use std::sync::RwLock;

use zarrs::storage::byte_range::ByteRangeIterator;
use zarrs::storage::{MaybeBytes, MaybeBytesIterator, ReadableStorage, ReadableStorageTraits, StorageError, StoreKey};

/// The store the reader sees.
pub struct Guarded {
    inner: ReadableStorage,
    /// Key prefix (an array's path and `/`) and the largest decoded chunk, in bytes, of
    /// each array whose codecs include blosc.
    blosc: RwLock<Vec<(String, u64)>>,
}

impl Guarded {
    pub fn new(inner: ReadableStorage) -> Self {
        Self { inner, blosc: RwLock::new(Vec::new()) }
    }

    /// From now on, values under `prefix` are checked against `limit` bytes.
    pub fn guard(&self, prefix: String, limit: u64) {
        if let Ok(mut b) = self.blosc.write() {
            b.push((prefix, limit));
        }
    }

    fn limit(&self, key: &StoreKey) -> Option<u64> {
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
            (Some(b), Some(limit)) => Self::check(key, limit, b).map(Some),
            (value, _) => Ok(value),
        }
    }

    fn get_partial_many<'a>(&'a self, key: &StoreKey, byte_ranges: ByteRangeIterator<'a>) -> Result<MaybeBytesIterator<'a>, StorageError> {
        let values = self.inner.get_partial_many(key, byte_ranges)?;
        let Some(limit) = self.limit(key) else { return Ok(values) };
        let key = key.clone();
        Ok(values.map(|it| Box::new(it.map(move |b| b.and_then(|b| Self::check(&key, limit, b)))) as _))
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
}
