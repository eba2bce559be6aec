//! The messages of a distributed trace. A photon's identity ([`Key`]) is
//! its origin and direction, bit for bit. A batch to a peer is a count
//! and that many photons handed over (key, then `PathState`'s words), then
//! a count and that many finished results (key, then `TraceResult`'s
//! words; only to rank 0). Words are little-endian `u64` (`f64` bits).

use alloc::vec::Vec;

use glam::DVec3;
use rt_volume::{PathState, TraceResult};

/// Bytes of a photon handed over: its identity (6 words) and its
/// [`PathState`].
pub const PHOTON_BYTES: usize = 8 * (6 + PathState::WORDS);

/// Bytes of a finished photon's result sent to rank 0: its identity and
/// [`TraceResult::WORDS`] words.
pub const RESULT_BYTES: usize = 8 * (6 + TraceResult::WORDS);

/// A photon's identity: its origin and direction, bit for bit.
pub(crate) type Key = [u64; 6];

/// The key of the photon from `o` along `d`.
pub(crate) fn key(o: DVec3, d: DVec3) -> Key {
    [o.x, o.y, o.z, d.x, d.y, d.z].map(f64::to_bits)
}

/// The origin and direction of key `k`.
pub(crate) fn unkey(k: &Key) -> (DVec3, DVec3) {
    let v = k.map(f64::from_bits);
    (DVec3::new(v[0], v[1], v[2]), DVec3::new(v[3], v[4], v[5]))
}

/// Appends `n` as a word.
pub(crate) fn put_count(out: &mut Vec<u8>, n: usize) {
    out.extend((n as u64).to_le_bytes());
}

/// Appends `k` and `words`.
fn put(out: &mut Vec<u8>, k: &Key, words: &[f64]) {
    for w in k {
        out.extend(w.to_le_bytes());
    }
    for x in words {
        out.extend(x.to_bits().to_le_bytes());
    }
}

/// Appends a photon handed over.
pub(crate) fn put_photon(out: &mut Vec<u8>, k: &Key, s: &PathState) {
    put(out, k, &s.to_words());
}

/// Appends a finished photon's result.
pub(crate) fn put_result(out: &mut Vec<u8>, k: &Key, r: &TraceResult) {
    put(out, k, &r.to_words());
}

/// Little-endian words off a batch.
pub(crate) struct Words<'a>(pub(crate) &'a [u8]);

impl Words<'_> {
    /// The next word.
    pub(crate) fn u64(&mut self) -> Option<u64> {
        let (head, rest) = self.0.split_first_chunk::<8>()?;
        self.0 = rest;
        Some(u64::from_le_bytes(*head))
    }

    /// The next `N` words as `f64`s.
    fn f64s<const N: usize>(&mut self) -> Option<[f64; N]> {
        let mut v = [0f64; N];
        for x in &mut v {
            *x = f64::from_bits(self.u64()?);
        }
        Some(v)
    }

    /// The next key.
    fn key(&mut self) -> Option<Key> {
        let mut k = [0; 6];
        for w in &mut k {
            *w = self.u64()?;
        }
        Some(k)
    }

    /// The next photon handed over (`None`: short or not a state).
    pub(crate) fn photon(&mut self) -> Option<(Key, PathState)> {
        let k = self.key()?;
        Some((k, PathState::from_words(&self.f64s()?).ok()?))
    }

    /// The next finished result (`None`: short or not a result).
    pub(crate) fn result(&mut self) -> Option<(Key, TraceResult)> {
        let k = self.key()?;
        Some((k, TraceResult::from_words(&self.f64s()?).ok()?))
    }
}
