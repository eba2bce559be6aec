//! Active-pixel run-length encoding: a span of pixels as alternating runs
//! of background and active pixels, with only the active ones stored.
//! Compositing walks the runs of both operands, so background is never
//! blended and never sent.

use alloc::vec::Vec;
use core::ops::Range;

use crate::Fragment;

/// A span `[start, start + len)` of an image's pixels (row-major index),
/// encoded as runs. Invariant: no stored pixel is the background.
#[derive(Clone, Debug, PartialEq)]
pub struct SparseImage<F> {
    start: usize,
    len: usize,
    /// `(background, active)` run lengths, in order; they sum to `len`.
    runs: Vec<(u32, u32)>,
    /// The active pixels, in order.
    active: Vec<F>,
}

/// Why bytes are not a sparse image.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum DecodeError {
    /// Fewer bytes than the header and runs announce.
    Truncated,
    /// Bytes left over after the announced content.
    TrailingBytes,
    /// The runs do not add up to the span, or the span overflows.
    Inconsistent,
    /// A stored pixel is the background (which is never stored).
    StoredBackground,
}

impl core::fmt::Display for DecodeError {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        f.write_str(match self {
            Self::Truncated => "sparse image truncated",
            Self::TrailingBytes => "bytes after the sparse image",
            Self::Inconsistent => "sparse image runs do not add up to its span",
            Self::StoredBackground => "sparse image stores a background pixel",
        })
    }
}

impl core::error::Error for DecodeError {}

impl<F: Fragment> SparseImage<F> {
    /// An all-background span.
    #[must_use]
    pub fn empty(range: Range<usize>) -> Self {
        let mut s = Self { start: range.start, len: 0, runs: Vec::new(), active: Vec::new() };
        s.push_background(range.len());
        s
    }

    /// Encodes `pixels`, the span starting at pixel `start`: active runs
    /// are copied whole.
    #[must_use]
    pub fn encode(start: usize, pixels: &[F]) -> Self {
        let count = pixels.iter().filter(|p| !p.is_background()).count();
        let mut s = Self { start, len: 0, runs: Vec::new(), active: Vec::with_capacity(count) };
        let mut rest = pixels;
        while !rest.is_empty() {
            let bg = rest.iter().position(|p| !p.is_background()).unwrap_or(rest.len());
            s.push_background(bg);
            rest = &rest[bg..];
            let active = rest.iter().position(Fragment::is_background).unwrap_or(rest.len());
            s.push_active_run(&rest[..active]);
            rest = &rest[active..];
        }
        s
    }

    /// The span's pixel range.
    #[must_use]
    pub fn range(&self) -> Range<usize> {
        self.start..self.start + self.len
    }

    /// Active (stored) pixels.
    #[must_use]
    pub fn active_count(&self) -> usize {
        self.active.len()
    }

    /// The runs, `(background, active)` pairs.
    #[must_use]
    pub fn runs(&self) -> &[(u32, u32)] {
        &self.runs
    }

    fn push_background(&mut self, mut n: usize) {
        self.len += n;
        while n > 0 {
            let take = n.min(u32::MAX as usize) as u32;
            match self.runs.last_mut() {
                Some((bg, 0)) if *bg as usize + take as usize <= u32::MAX as usize => *bg += take,
                _ => self.runs.push((take, 0)),
            }
            n -= take as usize;
        }
    }

    /// Counts `n` more active pixels (already stored) in the runs.
    fn count_active(&mut self, mut n: usize) {
        self.len += n;
        while n > 0 {
            match self.runs.last_mut() {
                Some((_, a)) if *a < u32::MAX => {
                    let take = n.min((u32::MAX - *a) as usize);
                    *a += take as u32;
                    n -= take;
                }
                _ => self.runs.push((0, 0)),
            }
        }
    }

    fn push_active(&mut self, p: F) {
        self.active.push(p);
        self.count_active(1);
    }

    /// Appends pixels known to be active.
    fn push_active_run(&mut self, pixels: &[F]) {
        self.active.extend_from_slice(pixels);
        self.count_active(pixels.len());
    }

    fn push(&mut self, p: F) {
        if p.is_background() { self.push_background(1) } else { self.push_active(p) }
    }

    /// Segments `(length, Some(first active index) | None)` in order.
    fn segments(&self) -> impl Iterator<Item = (usize, Option<usize>)> + '_ {
        let mut next = 0;
        self.runs.iter().flat_map(move |&(bg, a)| {
            let first = next;
            next += a as usize;
            [(bg as usize, None), (a as usize, Some(first))].into_iter().filter(|s| s.0 > 0)
        })
    }

    /// The part of the span in `range` (clipped to the span).
    #[must_use]
    pub fn slice(&self, range: Range<usize>) -> Self {
        let (mut out, pixels) = self.slice_runs(range);
        out.active.extend_from_slice(&self.active[pixels]);
        out
    }

    /// [`Self::slice`]'s runs with no pixels stored, and the range of
    /// `self`'s active pixels it holds (the active pixels of a contiguous
    /// span are contiguous).
    fn slice_runs(&self, range: Range<usize>) -> (Self, Range<usize>) {
        let lo = range.start.clamp(self.start, self.start + self.len);
        let hi = range.end.clamp(lo, self.start + self.len);
        let mut out = Self::empty(lo..lo);
        let mut pixels: Option<Range<usize>> = None;
        let mut at = self.start;
        for (n, active) in self.segments() {
            let (a, b) = (at.max(lo), (at + n).min(hi));
            if a < b {
                match active {
                    None => out.push_background(b - a),
                    Some(i) => {
                        let first = i + (a - at);
                        out.count_active(b - a);
                        let r = pixels.get_or_insert(first..first);
                        r.end = first + (b - a);
                    }
                }
            }
            at += n;
            if at >= hi {
                break;
            }
        }
        (out, pixels.unwrap_or(0..0))
    }

    /// Appends the wire form of `self.slice(range)` to `out`, without
    /// making the slice.
    pub fn append_slice_bytes(&self, range: Range<usize>, out: &mut Vec<u8>) {
        let (runs, pixels) = self.slice_runs(range);
        out.reserve(runs.byte_len() + F::SIZE * pixels.len());
        runs.append_header(out);
        F::write_all(&self.active[pixels], out);
    }

    /// `op(self, other)` per pixel over the same span (where only one side
    /// is active, that pixel is copied: the background is the identity);
    /// `None` if the spans differ.
    #[must_use]
    pub fn combine(&self, other: &Self, op: impl Fn(F, F) -> F) -> Option<Self> {
        if self.range() != other.range() {
            return None;
        }
        let mut out = Self::empty(self.start..self.start);
        out.active.reserve_exact((self.active.len() + other.active.len()).min(self.len));
        let (mut a, mut b) = (self.segments(), other.segments());
        let (mut sa, mut sb) = (a.next(), b.next());
        while let (Some((na, ia)), Some((nb, ib))) = (sa, sb) {
            let n = na.min(nb);
            match (ia, ib) {
                (None, None) => out.push_background(n),
                (Some(i), None) => out.push_active_run(&self.active[i..i + n]),
                (None, Some(j)) => out.push_active_run(&other.active[j..j + n]),
                (Some(i), Some(j)) => {
                    let from = out.active.len();
                    let (p, q) = (&self.active[i..i + n], &other.active[j..j + n]);
                    out.active.extend(p.iter().zip(q).map(|(p, q)| op(*p, *q)));
                    if out.active[from..].iter().any(Fragment::is_background) {
                        // An operator gave the background (not z, which
                        // returns an operand): re-encode this stretch.
                        for p in out.active.split_off(from) {
                            out.push(p);
                        }
                    } else {
                        out.count_active(n);
                    }
                }
            }
            sa = if na > n { Some((na - n, ia.map(|i| i + n))) } else { a.next() };
            sb = if nb > n { Some((nb - n, ib.map(|j| j + n))) } else { b.next() };
        }
        Some(out)
    }

    /// As [`Self::combine`], consuming `self`: where both operands have the
    /// same runs (dense images, or the same coverage) the result is
    /// written over `self`'s pixels, with no new storage.
    pub(crate) fn combine_owned(mut self, other: &Self, op: impl Fn(F, F) -> F) -> Option<Self> {
        if self.runs != other.runs || self.start != other.start {
            return self.combine(other, op);
        }
        for (p, q) in self.active.iter_mut().zip(&other.active) {
            *p = op(*p, *q);
        }
        if !self.active.iter().any(Fragment::is_background) {
            return Some(self);
        }
        // An operator gave the background somewhere: re-encode.
        let mut out = Self::empty(self.start..self.start);
        for (n, active) in self.segments() {
            match active {
                None => out.push_background(n),
                Some(i) => self.active[i..i + n].iter().for_each(|p| out.push(*p)),
            }
        }
        Some(out)
    }

    /// Writes the span into `image` (the whole image, indexed from 0):
    /// background runs as [`Fragment::BACKGROUND`]. Pixels outside the
    /// image are ignored.
    pub fn write_into(&self, image: &mut [F]) {
        let mut at = self.start;
        for (n, active) in self.segments() {
            let end = (at + n).min(image.len());
            if at < end {
                match active {
                    None => image[at..end].fill(F::BACKGROUND),
                    Some(i) => image[at..end].copy_from_slice(&self.active[i..i + (end - at)]),
                }
            }
            at += n;
        }
    }

    /// Bytes of [`Self::to_bytes`].
    #[must_use]
    pub fn byte_len(&self) -> usize {
        20 + 8 * self.runs.len() + F::SIZE * self.active.len()
    }

    /// The wire form: start and length (u64), run count (u32), runs, active
    /// pixels; little-endian.
    #[must_use]
    pub fn to_bytes(&self) -> Vec<u8> {
        let mut out = Vec::with_capacity(self.byte_len());
        self.append_bytes(&mut out);
        out
    }

    /// Appends [`Self::to_bytes`]'s form to `out`.
    pub fn append_bytes(&self, out: &mut Vec<u8>) {
        out.reserve(self.byte_len());
        self.append_header(out);
        F::write_all(&self.active, out);
    }

    /// Start, length, run count and runs: the wire form but the pixels.
    fn append_header(&self, out: &mut Vec<u8>) {
        out.extend((self.start as u64).to_le_bytes());
        out.extend((self.len as u64).to_le_bytes());
        out.extend((self.runs.len() as u32).to_le_bytes());
        for &(bg, a) in &self.runs {
            out.extend(bg.to_le_bytes());
            out.extend(a.to_le_bytes());
        }
    }

    /// Reads [`Self::to_bytes`]'s form, checking every length before
    /// allocating.
    ///
    /// # Errors
    /// [`DecodeError`] for truncated, inconsistent or trailing bytes.
    pub fn from_bytes(bytes: &[u8]) -> Result<Self, DecodeError> {
        let u64_at = |i: usize| -> Result<u64, DecodeError> {
            let b = bytes.get(i..i + 8).ok_or(DecodeError::Truncated)?;
            Ok(u64::from_le_bytes(b.try_into().map_err(|_| DecodeError::Truncated)?))
        };
        let u32_at = |i: usize| -> Result<u32, DecodeError> {
            let b = bytes.get(i..i + 4).ok_or(DecodeError::Truncated)?;
            Ok(u32::from_le_bytes(b.try_into().map_err(|_| DecodeError::Truncated)?))
        };
        let start = usize::try_from(u64_at(0)?).map_err(|_| DecodeError::Inconsistent)?;
        let len = usize::try_from(u64_at(8)?).map_err(|_| DecodeError::Inconsistent)?;
        start.checked_add(len).ok_or(DecodeError::Inconsistent)?;
        let nruns = u32_at(16)? as usize;
        let runs_end = nruns.checked_mul(8).and_then(|b| b.checked_add(20));
        let runs_end = runs_end.ok_or(DecodeError::Truncated)?;
        if bytes.len() < runs_end {
            return Err(DecodeError::Truncated);
        }
        let mut runs = Vec::with_capacity(nruns);
        let (mut total, mut actives) = (0usize, 0usize);
        for k in 0..nruns {
            let (bg, a) = (u32_at(20 + 8 * k)?, u32_at(24 + 8 * k)?);
            total = total
                .checked_add(bg as usize)
                .and_then(|t| t.checked_add(a as usize))
                .ok_or(DecodeError::Inconsistent)?;
            actives += a as usize;
            runs.push((bg, a));
        }
        if total != len {
            return Err(DecodeError::Inconsistent);
        }
        let need = actives.checked_mul(F::SIZE).and_then(|b| b.checked_add(runs_end));
        match need {
            Some(n) if bytes.len() < n => return Err(DecodeError::Truncated),
            Some(n) if bytes.len() > n => return Err(DecodeError::TrailingBytes),
            None => return Err(DecodeError::Truncated),
            Some(_) => {}
        }
        let active = F::read_all(&bytes[runs_end..]);
        if active.iter().any(Fragment::is_background) {
            return Err(DecodeError::StoredBackground);
        }
        Ok(Self { start, len, runs, active })
    }
}
