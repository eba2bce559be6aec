//! Rounds of batched all-to-all messages: the transport under work that
//! moves between ranks (occlusion queries, photons handed between bricks).
//!
//! Each round, every rank runs its step on what it received in the last
//! round, sends one message to **every** other rank (its batch for that
//! peer, possibly empty, after a two-byte header), and then receives one
//! message from each. So each rank has `size − 1` messages in flight
//! before it waits for any, a batch carries any number of items, and the
//! ranks never wait on one item's round trip, only on rounds.
//!
//! **Termination without a barrier.** A message's header says whether its
//! sender is *busy*: it has unfinished work or sent a non-empty batch this
//! round. Every rank receives every other rank's header, so all of them
//! see the same set of flags; when no rank is busy in a round, no batch is
//! in flight and no work is left anywhere, and every rank stops after that
//! same round. No extra collective and no per-item acknowledgement.
//!
//! **Failure.** A rank whose step fails, or whose transport fails, sends an
//! *abort* header to every peer and returns its error. A peer receives the
//! abort in place of that rank's next message and fails at once; a rank
//! that stops answering altogether makes its peers' receives time out
//! (the [`Communicator`] contract), so every rank returns an `Err` within
//! about one timeout and none hangs. Malformed headers are errors too.
//!
//! Messages between two ranks are matched by order (one per round per
//! pair, on one tag): the communicator delivers messages of one tag from
//! one sender in the order they were sent (channels do; MPI's
//! non-overtaking rule does).

use alloc::{vec, vec::Vec};
use core::fmt;

use crate::{CommError, Communicator};

/// The tag exchange rounds use (below 32768, the least upper bound MPI
/// guarantees; apart from the compositing schedules' tags).
pub const EXCHANGE_TAG: u32 = 0x7100;

const DATA: u8 = 0x5a;
const ABORT: u8 = 0xa5;

/// What rounds of exchange cost one rank.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct ExchangeStats {
    /// Rounds run (the last one carried only "not busy" headers).
    pub rounds: u32,
    /// Messages this rank sent (`size − 1` a round).
    pub messages: u64,
    /// Bytes this rank sent, headers included.
    pub bytes_sent: u64,
    /// The longest message this rank sent, in bytes (what its send
    /// buffers must hold at once for one peer).
    pub largest_message: u64,
}

impl ExchangeStats {
    /// Adds `o` to `self`.
    pub fn add(&mut self, o: &Self) {
        self.rounds += o.rounds;
        self.messages += o.messages;
        self.bytes_sent += o.bytes_sent;
        self.largest_message = self.largest_message.max(o.largest_message);
    }
}

/// Why rounds of exchange failed on this rank.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum ExchangeError<E> {
    /// This rank's step failed (its error).
    Step(E),
    /// Sending or receiving failed (a peer that stopped answering is a
    /// [`CommError::Timeout`]).
    Comm(CommError),
    /// Rank `from` failed and said so.
    PeerFailed {
        /// The rank that aborted.
        from: usize,
    },
    /// Rank `from` sent a message without a valid header.
    Malformed {
        /// The sender.
        from: usize,
    },
    /// Work was still moving after the most rounds allowed (a diverging
    /// rank, or work that cycles between ranks).
    TooManyRounds(u32),
}

impl<E: fmt::Display> fmt::Display for ExchangeError<E> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::Step(e) => write!(f, "{e}"),
            Self::Comm(e) => write!(f, "{e}"),
            Self::PeerFailed { from } => write!(f, "rank {from} failed"),
            Self::Malformed { from } => write!(f, "rank {from} sent a malformed message"),
            Self::TooManyRounds(n) => write!(f, "work still moving after {n} rounds"),
        }
    }
}

impl<E: fmt::Debug + fmt::Display> core::error::Error for ExchangeError<E> {}

/// A batch received: the sender and its bytes (empty when it had nothing
/// for this rank).
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Batch {
    /// The sender (this rank itself for what it addressed to itself).
    pub from: usize,
    /// The payload.
    pub bytes: Vec<u8>,
}

/// Runs rounds until no rank is busy.
///
/// Each round calls `step(round, inbox, outbox)`: `inbox` holds one
/// [`Batch`] per rank in rank order (all empty in round 0; a rank's batch
/// to itself is handed over in memory), `outbox[r]` starts empty and is
/// what this rank sends rank `r` (its own entry comes back next round).
/// `step` returns whether this rank still has unfinished work. Every rank
/// of the communicator must call `rounds` with the same `max_rounds`.
///
/// # Errors
/// [`ExchangeError`], on every rank when any fails (see the module docs).
pub fn rounds<C, E>(
    comm: &C,
    max_rounds: u32,
    mut step: impl FnMut(u32, &[Batch], &mut [Vec<u8>]) -> Result<bool, E>,
) -> Result<ExchangeStats, ExchangeError<E>>
where
    C: Communicator + ?Sized,
{
    let (me, size) = (comm.rank(), comm.size());
    let mut stats = ExchangeStats::default();
    let mut inbox: Vec<Batch> = (0..size).map(|from| Batch { from, bytes: Vec::new() }).collect();
    let abort = |stats: &mut ExchangeStats| {
        for peer in (0..size).filter(|&p| p != me) {
            // Best effort: a peer that is gone needs no notice.
            if comm.send(peer, EXCHANGE_TAG, vec![ABORT, 0]).is_ok() {
                stats.messages += 1;
                stats.bytes_sent += 2;
            }
        }
    };
    loop {
        if stats.rounds >= max_rounds {
            abort(&mut stats);
            return Err(ExchangeError::TooManyRounds(max_rounds));
        }
        let mut outbox = vec![Vec::new(); size];
        let working = match step(stats.rounds, &inbox, &mut outbox) {
            Ok(w) => w,
            Err(e) => {
                abort(&mut stats);
                return Err(ExchangeError::Step(e));
            }
        };
        stats.rounds += 1;
        let busy = working || outbox.iter().any(|b| !b.is_empty());
        let mine = core::mem::take(&mut outbox[me]);
        for (peer, batch) in outbox.into_iter().enumerate().filter(|&(p, _)| p != me) {
            let mut msg = Vec::with_capacity(batch.len() + 2);
            msg.extend([DATA, u8::from(busy)]);
            msg.extend(batch);
            stats.messages += 1;
            stats.bytes_sent += msg.len() as u64;
            stats.largest_message = stats.largest_message.max(msg.len() as u64);
            if let Err(e) = comm.send(peer, EXCHANGE_TAG, msg) {
                abort(&mut stats);
                return Err(ExchangeError::Comm(e));
            }
        }
        let mut any_busy = busy;
        for (from, slot) in inbox.iter_mut().enumerate() {
            if from == me {
                slot.bytes = mine.clone();
                continue;
            }
            let msg = match comm.recv(from, EXCHANGE_TAG) {
                Ok(m) => m,
                Err(e) => {
                    abort(&mut stats);
                    return Err(ExchangeError::Comm(e));
                }
            };
            match (msg.first(), msg.get(1)) {
                (Some(&DATA), Some(&flag)) if flag <= 1 => {
                    any_busy |= flag == 1;
                    slot.bytes.clear();
                    slot.bytes.extend_from_slice(&msg[2..]);
                }
                (Some(&ABORT), _) => {
                    abort(&mut stats);
                    return Err(ExchangeError::PeerFailed { from });
                }
                _ => {
                    abort(&mut stats);
                    return Err(ExchangeError::Malformed { from });
                }
            }
        }
        if !any_busy {
            return Ok(stats);
        }
    }
}

/// Every rank's `bytes`, in rank order, on every rank (one round).
///
/// # Errors
/// As [`rounds`].
pub fn all_gather<C: Communicator + ?Sized>(
    comm: &C,
    bytes: &[u8],
) -> Result<(Vec<Vec<u8>>, ExchangeStats), ExchangeError<core::convert::Infallible>> {
    let mut got = Vec::new();
    let mut sent = false;
    let stats = rounds(comm, 2, |_, inbox, outbox| {
        if sent {
            got = inbox.iter().map(|b| b.bytes.clone()).collect();
        } else {
            sent = true;
            for o in outbox.iter_mut() {
                o.extend_from_slice(bytes);
            }
        }
        Ok(false)
    })?;
    if !sent || got.is_empty() {
        // One rank, or every rank sent nothing: the payload is `bytes`.
        got = vec![bytes.to_vec(); comm.size()];
    }
    Ok((got, stats))
}

/// Little-endian readers over a payload: each returns `None` past its end.
#[derive(Debug)]
pub(crate) struct Reader<'a> {
    bytes: &'a [u8],
}

impl<'a> Reader<'a> {
    pub(crate) fn new(bytes: &'a [u8]) -> Self {
        Self { bytes }
    }

    pub(crate) fn take(&mut self, n: usize) -> Option<&'a [u8]> {
        if self.bytes.len() < n {
            return None;
        }
        let (head, rest) = self.bytes.split_at(n);
        self.bytes = rest;
        Some(head)
    }

    pub(crate) fn u32(&mut self) -> Option<u32> {
        self.take(4).map(|b| u32::from_le_bytes([b[0], b[1], b[2], b[3]]))
    }

    pub(crate) fn f32(&mut self) -> Option<f32> {
        self.u32().map(f32::from_bits)
    }

    pub(crate) fn is_empty(&self) -> bool {
        self.bytes.is_empty()
    }
}
