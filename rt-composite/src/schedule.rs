//! Compositing schedules: direct send, binary swap (folding extra ranks
//! first when the rank count is not a power of two) and radix-k, then a
//! gather of the final image to rank 0.
//!
//! All three are one algorithm: rounds of groups. In a round of factor
//! `k`, ranks whose (virtual) indices differ only in one mixed-radix digit
//! form a group; each splits its current span of pixels into `k` parts,
//! sends part `j` to the group's `j`-th member and composites the `k`
//! copies of its own part in member order. Direct send is one round of
//! factor `n`; binary swap is rounds of factor 2; radix-k uses factors up
//! to `k`. Because the members of every group cover consecutive ranks
//! (consecutive positions of the visibility order for `over`), combining
//! in member order is the serial fold's order: ties in depth go to the
//! lower rank and the result equals [`serial_fold`] bit for bit.
//!
//! Errors are collective: a rank that finds a problem (a wrong image
//! size, a truncated or malformed message, a communication failure) keeps
//! following the schedule, sending "failed" messages in place of data,
//! and a last status round from rank 0 makes every rank return `Err`.
//! Nothing waits forever as long as the communicator's `recv` has a
//! timeout.

use alloc::{vec, vec::Vec};
use core::{fmt, ops::Range};

use crate::{CommError, Communicator, DecodeError, Fragment, SparseImage};

/// How ranks exchange pieces.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Schedule {
    /// Every rank owns `1/n` of the image and receives that part from all.
    DirectSend,
    /// log₂ rounds of pairwise exchange; with `n = 2^m + e` ranks, ranks
    /// `2i + 1 < 2e` first fold their image into rank `2i`.
    BinarySwap,
    /// Rounds of groups of at most `k` ranks (`k ≥ 2`); a rank count with
    /// a prime factor above `k` gets a round of that factor.
    RadixK(usize),
}

/// How fragments combine: the compositing operator.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum Operator {
    /// The nearer fragment; equal depths go to the lower rank.
    Depth,
    /// Ordered premultiplied `over`; `order[0]` is the rank in front.
    /// Floating-point `over` is not associative, so only
    /// [`Schedule::DirectSend`] (which folds each pixel in one place, in
    /// order) reproduces the serial fold; other schedules return
    /// [`CompositeError::OverNeedsDirectSend`].
    Over {
        /// Ranks front to back: a permutation of `0..size`.
        order: Vec<usize>,
    },
}

/// Why compositing failed (on every rank).
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum CompositeError {
    /// This rank's image does not hold `width × height` pixels.
    ImageSize {
        /// `width × height`.
        expected: usize,
        /// Pixels given.
        found: usize,
    },
    /// Another rank composites an image of a different size.
    SizeMismatch {
        /// The other rank.
        rank: usize,
        /// Its `(width, height)`.
        size: (u32, u32),
    },
    /// A message that is not what the schedule expects.
    Malformed {
        /// The sender.
        from: usize,
        /// What was wrong.
        problem: MessageProblem,
    },
    /// The transport failed.
    Comm(CommError),
    /// Another rank failed (it reported so); its own `Err` says why.
    FailedElsewhere,
    /// `RadixK(k)` with `k < 2`.
    BadRadix(usize),
    /// The visibility order is not a permutation of the ranks.
    BadOrder,
    /// `Operator::Over` with a schedule other than direct send.
    OverNeedsDirectSend,
}

impl fmt::Display for CompositeError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::ImageSize { expected, found } => {
                write!(f, "image has {found} pixels, width × height is {expected}")
            }
            Self::SizeMismatch { rank, size } => {
                write!(f, "rank {rank} composites a {}×{} image", size.0, size.1)
            }
            Self::Malformed { from, problem } => {
                write!(f, "bad message from rank {from}: {problem}")
            }
            Self::Comm(e) => write!(f, "{e}"),
            Self::FailedElsewhere => f.write_str("compositing failed on another rank"),
            Self::BadRadix(k) => write!(f, "radix-k needs k ≥ 2, got {k}"),
            Self::BadOrder => f.write_str("visibility order is not a permutation of the ranks"),
            Self::OverNeedsDirectSend => {
                f.write_str("ordered `over` is exact only with direct send")
            }
        }
    }
}

impl core::error::Error for CompositeError {
    fn source(&self) -> Option<&(dyn core::error::Error + 'static)> {
        match self {
            Self::Comm(e) => Some(e),
            Self::Malformed { problem: MessageProblem::Decode(e), .. } => Some(e),
            _ => None,
        }
    }
}

/// What was wrong with a message another rank sent.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum MessageProblem {
    /// Shorter than the message header, or without its magic number.
    NoHeader,
    /// A header flag this version does not know.
    UnknownFlag(u8),
    /// A sparse image of another pixel span than the schedule assigned.
    UnexpectedSpan,
    /// A gathered span that ends past the image.
    SpanPastImage,
    /// The sparse image does not decode.
    Decode(DecodeError),
}

impl fmt::Display for MessageProblem {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::NoHeader => f.write_str("no rt-composite header"),
            Self::UnknownFlag(v) => write!(f, "unknown flag {v}"),
            Self::UnexpectedSpan => f.write_str("not the expected pixel span"),
            Self::SpanPastImage => f.write_str("span past the image"),
            Self::Decode(e) => write!(f, "{e}"),
        }
    }
}

/// What a composite call moved and produced on this rank.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct Stats {
    /// Bytes this rank sent (message headers included).
    pub bytes_sent: usize,
    /// Messages this rank sent.
    pub messages: usize,
}

/// The serial fold of all ranks' images, the reference every schedule
/// reproduces: `images[0] ∘ images[1] ∘ …` with `z` (Depth) or, for
/// `Over`, the images in visibility order folded with `over`.
///
/// # Errors
/// [`CompositeError::ImageSize`] if the images differ in length,
/// [`CompositeError::BadOrder`].
pub fn serial_fold<F: Fragment>(
    images: &[&[F]],
    mode: &Operator,
) -> Result<Vec<F>, CompositeError> {
    let n = images.first().map_or(0, |i| i.len());
    if let Some(bad) = images.iter().find(|i| i.len() != n) {
        return Err(CompositeError::ImageSize { expected: n, found: bad.len() });
    }
    let order: Vec<usize> = match mode {
        Operator::Depth => (0..images.len()).collect(),
        Operator::Over { order } => {
            check_order(order, images.len())?;
            order.clone()
        }
    };
    let mut out = vec![F::BACKGROUND; n];
    for (k, &r) in order.iter().enumerate() {
        for (o, p) in out.iter_mut().zip(images[r]) {
            *o = if k == 0 { *p } else { combine(mode, *o, *p) };
        }
    }
    Ok(out)
}

fn combine<F: Fragment>(mode: &Operator, front: F, back: F) -> F {
    match mode {
        Operator::Depth => front.z(back),
        Operator::Over { .. } => front.over(back),
    }
}

fn check_order(order: &[usize], n: usize) -> Result<(), CompositeError> {
    let mut seen = vec![false; n];
    for &r in order {
        match seen.get_mut(r) {
            Some(s) if !*s => *s = true,
            _ => return Err(CompositeError::BadOrder),
        }
    }
    if order.len() == n { Ok(()) } else { Err(CompositeError::BadOrder) }
}

/// The rounds' factors for `n` (virtual) ranks.
fn factors(n: usize, schedule: Schedule) -> Vec<usize> {
    let k = match schedule {
        Schedule::DirectSend => return if n > 1 { vec![n] } else { vec![] },
        Schedule::BinarySwap => 2,
        Schedule::RadixK(k) => k,
    };
    let mut out = Vec::new();
    let mut m = n;
    while m > 1 {
        // The largest divisor of m not above k, else m's smallest prime.
        let f = (2..=k.min(m)).rev().find(|f| m.is_multiple_of(*f));
        let f = f.unwrap_or_else(|| (2..=m).find(|p| m.is_multiple_of(*p)).unwrap_or(m));
        out.push(f);
        m /= f;
    }
    out
}

/// Part `j` of `k` of `range`.
fn part(range: &Range<usize>, j: usize, k: usize) -> Range<usize> {
    let len = range.len();
    range.start + len * j / k..range.start + len * (j + 1) / k
}

const MAGIC: u32 = 0x5254_4331; // "RTC1"
const HEADER: usize = 13;
// Below 32768, the least tag upper bound MPI guarantees; round tags are
// `round + 1`, far below.
const GATHER_TAG: u32 = 0x7000;
const STATUS_TAG: u32 = GATHER_TAG + 1;

/// A message: magic, flag (0 data, 1 failed), width, height, then the
/// sparse image's part in `range` (data only), serialized straight from
/// the image.
fn message<F: Fragment>(
    size: (u32, u32),
    image: Option<(&SparseImage<F>, Range<usize>)>,
) -> Vec<u8> {
    let mut out = Vec::with_capacity(HEADER);
    out.extend(MAGIC.to_le_bytes());
    out.push(u8::from(image.is_none()));
    out.extend(size.0.to_le_bytes());
    out.extend(size.1.to_le_bytes());
    if let Some((i, range)) = image {
        i.append_slice_bytes(range, &mut out);
    }
    out
}

/// One rank's state through the schedule.
struct Run<'c, C, F> {
    comm: &'c C,
    size: (u32, u32),
    error: Option<CompositeError>,
    /// After a transport failure, stop waiting on further messages.
    comm_failed: bool,
    stats: Stats,
    _f: core::marker::PhantomData<F>,
}

impl<C: Communicator, F: Fragment> Run<'_, C, F> {
    fn fail(&mut self, e: CompositeError) {
        if let CompositeError::Comm(_) = e {
            self.comm_failed = true;
        }
        self.error.get_or_insert(e);
    }

    /// Sends `image` (its part in the range, when given), or "failed".
    fn send(
        &mut self,
        to: usize,
        tag: u32,
        image: Option<&SparseImage<F>>,
        range: Option<Range<usize>>,
    ) {
        let image = if self.error.is_some() { None } else { image };
        let image = image.map(|i| (i, range.unwrap_or_else(|| i.range())));
        let bytes = message(self.size, image);
        self.stats.bytes_sent += bytes.len();
        self.stats.messages += 1;
        if let Err(e) = self.comm.send(to, tag, bytes) {
            self.fail(CompositeError::Comm(e));
        }
    }

    /// Receives a span from `from`; `None` (with the error recorded) if it
    /// failed or is not the span `want`.
    fn recv(
        &mut self,
        from: usize,
        tag: u32,
        want: Option<&Range<usize>>,
    ) -> Option<SparseImage<F>> {
        if self.comm_failed {
            return None;
        }
        let bytes = match self.comm.recv(from, tag) {
            Ok(b) => b,
            Err(e) => {
                self.fail(CompositeError::Comm(e));
                return None;
            }
        };
        let malformed = |problem| CompositeError::Malformed { from, problem };
        if bytes.len() < HEADER || bytes[..4] != MAGIC.to_le_bytes() {
            self.fail(malformed(MessageProblem::NoHeader));
            return None;
        }
        let u = |i: usize| u32::from_le_bytes([bytes[i], bytes[i + 1], bytes[i + 2], bytes[i + 3]]);
        let size = (u(5), u(9));
        match bytes[4] {
            1 => {
                self.fail(CompositeError::FailedElsewhere);
                return None;
            }
            0 => {}
            flag => {
                self.fail(malformed(MessageProblem::UnknownFlag(flag)));
                return None;
            }
        }
        if size != self.size {
            self.fail(CompositeError::SizeMismatch { rank: from, size });
            return None;
        }
        match SparseImage::from_bytes(&bytes[HEADER..]) {
            Ok(img) if want.is_none_or(|w| img.range() == *w) => Some(img),
            Ok(_) => {
                self.fail(malformed(MessageProblem::UnexpectedSpan));
                None
            }
            Err(e) => {
                self.fail(malformed(MessageProblem::Decode(e)));
                None
            }
        }
    }
}

/// Composites this rank's `image` (`width × height` pixels, row-major)
/// with every other rank's; rank 0 gets `Some(final image)`, others
/// `None`. Call it on every rank of `comm` with the same arguments but
/// the image. Also returns what this rank sent.
///
/// # Errors
/// [`CompositeError`], on every rank when any rank fails (see the module
/// docs).
pub fn composite<C: Communicator, F: Fragment>(
    comm: &C,
    image: &[F],
    width: u32,
    height: u32,
    schedule: Schedule,
    mode: &Operator,
) -> Result<(Option<Vec<F>>, Stats), CompositeError> {
    let (n, rank) = (comm.size(), comm.rank());
    if rank >= n {
        return Err(CompositeError::Comm(CommError::NoSuchRank(rank)));
    }
    let total = (width as usize).saturating_mul(height as usize);
    let mut run = Run {
        comm,
        size: (width, height),
        error: None,
        comm_failed: false,
        stats: Stats::default(),
        _f: core::marker::PhantomData,
    };
    if image.len() != total {
        run.fail(CompositeError::ImageSize { expected: total, found: image.len() });
    }
    if let Schedule::RadixK(k) = schedule
        && k < 2
    {
        run.fail(CompositeError::BadRadix(k));
    }
    // Virtual ranks: visibility positions for `over`, ranks for depth;
    // `order[v]` is the rank at virtual index `v`.
    let order: Vec<usize> = match mode {
        Operator::Over { order } if check_order(order, n).is_ok() => order.clone(),
        Operator::Over { .. } => {
            run.fail(CompositeError::BadOrder);
            (0..n).collect()
        }
        Operator::Depth => (0..n).collect(),
    };
    if matches!(mode, Operator::Over { .. }) && schedule != Schedule::DirectSend && n > 1 {
        run.fail(CompositeError::OverNeedsDirectSend);
    }
    let at = |v: usize| order[v];
    let op = |a: F, b: F| combine(mode, a, b);
    let mut span = 0..total;
    let mut data = if run.error.is_none() {
        SparseImage::encode(0, image)
    } else {
        SparseImage::empty(span.clone())
    };

    // Binary swap on 2^m + e ranks: the first 2e fold pairwise.
    let me = order.iter().position(|&r| r == rank).unwrap_or(rank);
    let (mut v, count) = if schedule == Schedule::BinarySwap {
        let p = 1 << n.ilog2();
        let e = n - p;
        if me < 2 * e {
            if me % 2 == 1 {
                run.send(at(me - 1), 0, Some(&data), None);
                (None, p)
            } else {
                if let Some(theirs) = run.recv(at(me + 1), 0, Some(&span)) {
                    data = data.combine_owned(&theirs, op).unwrap_or(theirs); // spans checked on receipt
                }
                (Some(me / 2), p)
            }
        } else {
            (Some(me - e), p)
        }
    } else {
        (Some(me), n)
    };
    // Virtual index → real rank.
    let real = |virt: usize| -> usize {
        if schedule == Schedule::BinarySwap {
            let e = n - count;
            at(if virt < e { 2 * virt } else { virt + e })
        } else {
            at(virt)
        }
    };

    if let Some(vr) = v.as_mut() {
        let mut stride = 1;
        for (round, &k) in factors(count, schedule).iter().enumerate() {
            let tag = round as u32 + 1;
            let digit = (*vr / stride) % k;
            let base = *vr - digit * stride;
            for j in (0..k).filter(|&j| j != digit) {
                run.send(real(base + j * stride), tag, Some(&data), Some(part(&span, j, k)));
            }
            let mine = part(&span, digit, k);
            let mut own = Some(data.slice(mine.clone()));
            let mut acc: Option<SparseImage<F>> = None;
            for j in 0..k {
                let piece = if j == digit {
                    own.take()
                } else {
                    run.recv(real(base + j * stride), tag, Some(&mine))
                };
                let piece = piece.unwrap_or_else(|| SparseImage::empty(mine.clone()));
                acc = Some(match acc {
                    None => piece,
                    Some(a) => a.combine_owned(&piece, op).unwrap_or(piece), // received spans are checked
                });
            }
            span = mine.clone();
            data = acc.unwrap_or_else(|| SparseImage::empty(mine));
            stride *= k;
        }
    }

    // Gather to rank 0, with every rank's status; then rank 0 tells all.
    let mut result = None;
    if rank == 0 {
        let mut full = vec![F::BACKGROUND; if run.error.is_none() { total } else { 0 }];
        if v.is_some() {
            data.write_into(&mut full);
        }
        for r in 1..n {
            if let Some(img) = run.recv(r, GATHER_TAG, None) {
                if img.range().end > total {
                    run.fail(CompositeError::Malformed {
                        from: r,
                        problem: MessageProblem::SpanPastImage,
                    });
                } else if run.error.is_none() {
                    img.write_into(&mut full);
                }
            }
        }
        let ok = run.error.is_none();
        for r in 1..n {
            let status = if ok { Some(SparseImage::empty(0..0)) } else { None };
            run.send(r, STATUS_TAG, status.as_ref(), None);
        }
        result = Some(full);
    } else {
        let empty = SparseImage::empty(0..0);
        run.send(0, GATHER_TAG, Some(if v.is_some() { &data } else { &empty }), None);
        // Wait for the verdict even after a local failure.
        run.comm_failed = false;
        run.recv(0, STATUS_TAG, None);
    }
    match run.error {
        Some(e) => Err(e),
        None => Ok((result, run.stats)),
    }
}
