//! Communicators: what a compositing schedule needs from the transport
//! (the calls IceT makes of MPI: rank, size, tagged point-to-point byte
//! messages), and an in-process implementation on threads and channels.

use alloc::vec::Vec;
use core::fmt;

/// Why a message could not be sent or received.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum CommError {
    /// A rank outside `0..size`.
    NoSuchRank(usize),
    /// The peer is gone (its communicator was dropped or its thread died).
    Disconnected(usize),
    /// No message from `from` with `tag` within the communicator's timeout.
    Timeout {
        /// The awaited sender.
        from: usize,
        /// The awaited tag.
        tag: u32,
    },
    /// A tag the transport cannot carry (`MpiComm`: above `i32::MAX`,
    /// the largest MPI tag type).
    TagTooLarge(u32),
    /// A message longer than the transport can carry, in bytes
    /// (`MpiComm`: above `i32::MAX`, the largest MPI count).
    MessageTooLarge(usize),
    /// The transport itself failed, with its own error code (for
    /// communicators built on other libraries: an MPI error class, an
    /// `errno`, …).
    Transport {
        /// The transport's error code.
        code: i32,
    },
}

impl fmt::Display for CommError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::NoSuchRank(r) => write!(f, "no rank {r}"),
            Self::Disconnected(r) => write!(f, "rank {r} is gone"),
            Self::Timeout { from, tag } => {
                write!(f, "timed out waiting for rank {from} (tag {tag})")
            }
            Self::TagTooLarge(tag) => {
                write!(f, "tag {tag} is too large for the transport (an MPI tag is an i32)")
            }
            Self::MessageTooLarge(n) => write!(
                f,
                "a {n}-byte message is too large for the transport (an MPI count is an i32)"
            ),
            Self::Transport { code } => write!(f, "the transport failed with error code {code}"),
        }
    }
}

impl core::error::Error for CommError {}

/// Tagged point-to-point messages between the ranks of a group.
///
/// `send` must not wait for the matching `recv` (buffered or
/// non-blocking), so that two ranks may exchange by both sending first;
/// `recv` returns the oldest message from `from` with `tag`, and must not
/// wait forever (a timeout or a failure detector turns a lost peer into an
/// `Err`).
pub trait Communicator {
    /// This rank, in `0..size`.
    fn rank(&self) -> usize;
    /// Ranks in the group.
    fn size(&self) -> usize;
    /// Sends `data` to rank `to` with `tag`.
    ///
    /// # Errors
    /// [`CommError`].
    fn send(&self, to: usize, tag: u32, data: Vec<u8>) -> Result<(), CommError>;
    /// Receives the next message from rank `from` with `tag`.
    ///
    /// # Errors
    /// [`CommError`], including a timeout.
    fn recv(&self, from: usize, tag: u32) -> Result<Vec<u8>, CommError>;
}

#[cfg(feature = "mpi")]
pub use mpi_comm::MpiComm;
#[cfg(feature = "std")]
pub use threads::ThreadComm;

#[cfg(feature = "std")]
mod threads {
    use alloc::vec::Vec;
    use core::{cell::RefCell, time::Duration};
    use std::{
        sync::mpsc::{Receiver, RecvTimeoutError, Sender, channel},
        time::Instant,
    };

    use super::{CommError, Communicator};

    type Message = (usize, u32, Vec<u8>);

    /// One rank of an in-process group: each rank owns a channel receiver;
    /// sends never block. Move each to its own thread.
    #[derive(Debug)]
    pub struct ThreadComm {
        rank: usize,
        peers: Vec<Sender<Message>>,
        inbox: Receiver<Message>,
        /// Messages received while waiting for another.
        pending: RefCell<Vec<Message>>,
        timeout: Duration,
    }

    impl ThreadComm {
        /// A group of `size` connected ranks; `recv` gives up after
        /// `timeout`.
        #[must_use]
        pub fn group(size: usize, timeout: Duration) -> Vec<Self> {
            let (senders, inboxes): (Vec<_>, Vec<_>) = (0..size).map(|_| channel()).unzip();
            inboxes
                .into_iter()
                .enumerate()
                .map(|(rank, inbox)| Self {
                    rank,
                    peers: senders.clone(),
                    inbox,
                    pending: RefCell::new(Vec::new()),
                    timeout,
                })
                .collect()
        }
    }

    impl Communicator for ThreadComm {
        fn rank(&self) -> usize {
            self.rank
        }

        fn size(&self) -> usize {
            self.peers.len()
        }

        fn send(&self, to: usize, tag: u32, data: Vec<u8>) -> Result<(), CommError> {
            let peer = self.peers.get(to).ok_or(CommError::NoSuchRank(to))?;
            peer.send((self.rank, tag, data)).map_err(|_| CommError::Disconnected(to))
        }

        fn recv(&self, from: usize, tag: u32) -> Result<Vec<u8>, CommError> {
            if from >= self.peers.len() {
                return Err(CommError::NoSuchRank(from));
            }
            let mut pending = self.pending.borrow_mut();
            if let Some(i) = pending.iter().position(|m| m.0 == from && m.1 == tag) {
                return Ok(pending.remove(i).2);
            }
            let deadline = Instant::now() + self.timeout;
            loop {
                let left = deadline.saturating_duration_since(Instant::now());
                match self.inbox.recv_timeout(left) {
                    Ok(m) if m.0 == from && m.1 == tag => return Ok(m.2),
                    Ok(m) => pending.push(m),
                    Err(RecvTimeoutError::Timeout) => return Err(CommError::Timeout { from, tag }),
                    // Every sender is gone, ours included: cannot happen
                    // while `self` holds one, but answer it all the same.
                    Err(RecvTimeoutError::Disconnected) => {
                        return Err(CommError::Disconnected(from));
                    }
                }
            }
        }
    }
}

#[cfg(feature = "mpi")]
mod mpi_comm {
    use alloc::{boxed::Box, vec::Vec};
    use core::{cell::RefCell, time::Duration};
    use std::time::Instant;

    use mpi::{
        Tag,
        point_to_point::MatchedReceiveVec,
        request::{Request, StaticScope},
        topology::SimpleCommunicator,
        traits::{Communicator as _, Destination, Source},
    };

    use super::{CommError, Communicator};

    /// A send in flight: MPI reads `buffer` until the request completes,
    /// so the buffer is owned here, outside any borrow, and freed only
    /// after completion.
    struct InFlight {
        request: Request<'static, [u8], StaticScope>,
        buffer: *mut [u8],
    }

    /// The [`Communicator`] on MPI (feature `mpi`, through the `mpi` crate,
    /// re-exported as `rt_composite::mpi`).
    ///
    /// It works on a duplicate of the communicator it is given, so its
    /// messages never match the application's own. Sends are non-blocking
    /// (`MPI_Isend`; the buffer is kept until MPI is done with it); a
    /// receive polls `MPI_Improbe` until its message arrives or the
    /// timeout passes, so a dead or diverging peer is an `Err`, not a hang.
    /// Dropping the communicator waits up to the timeout for its sends to
    /// complete, then cancels the rest.
    ///
    /// Messages are limited to `i32::MAX` bytes (an MPI count) and tags to
    /// `i32::MAX`; [`composite`](crate::composite) uses tags below 32768,
    /// the least upper bound MPI guarantees.
    pub struct MpiComm {
        comm: SimpleCommunicator,
        rank: usize,
        size: usize,
        in_flight: RefCell<Vec<InFlight>>,
        timeout: Duration,
    }

    impl core::fmt::Debug for MpiComm {
        fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
            f.debug_struct("MpiComm")
                .field("rank", &self.rank)
                .field("size", &self.size)
                .field("sends_in_flight", &self.in_flight.borrow().len())
                .field("timeout", &self.timeout)
                .finish()
        }
    }

    impl MpiComm {
        /// Composites over (a duplicate of) `comm`; `recv` gives up after
        /// `timeout`. Every rank of `comm` must call this (duplication is
        /// collective).
        #[must_use]
        pub fn new(comm: &SimpleCommunicator, timeout: Duration) -> Self {
            let comm = comm.duplicate();
            // MPI ranks and sizes are non-negative `c_int`s.
            let rank = usize::try_from(comm.rank()).unwrap_or(0);
            let size = usize::try_from(comm.size()).unwrap_or(0);
            Self { comm, rank, size, in_flight: RefCell::new(Vec::new()), timeout }
        }

        fn peer(&self, r: usize) -> Result<i32, CommError> {
            if r < self.size {
                i32::try_from(r).map_err(|_| CommError::NoSuchRank(r))
            } else {
                Err(CommError::NoSuchRank(r))
            }
        }

        /// Frees the buffers of completed sends; `true` when none is left.
        fn reap(&self) -> bool {
            let mut in_flight = self.in_flight.borrow_mut();
            let pending = core::mem::take(&mut *in_flight);
            for InFlight { request, buffer } in pending {
                match request.test() {
                    // SAFETY: `buffer` came from `Box::into_raw` in `send`
                    // and its only borrow was the request, now complete.
                    Ok(_) => drop(unsafe { Box::from_raw(buffer) }),
                    Err(request) => in_flight.push(InFlight { request, buffer }),
                }
            }
            in_flight.is_empty()
        }
    }

    fn tag_of(tag: u32) -> Result<Tag, CommError> {
        Tag::try_from(tag).map_err(|_| CommError::TagTooLarge(tag))
    }

    impl Communicator for MpiComm {
        fn rank(&self) -> usize {
            self.rank
        }

        fn size(&self) -> usize {
            self.size
        }

        fn send(&self, to: usize, tag: u32, data: Vec<u8>) -> Result<(), CommError> {
            let peer = self.peer(to)?;
            let tag = tag_of(tag)?;
            if i32::try_from(data.len()).is_err() {
                return Err(CommError::MessageTooLarge(data.len()));
            }
            self.reap();
            let buffer = Box::into_raw(data.into_boxed_slice());
            // SAFETY: the box is freed only in `reap` after the request
            // completes, or leaked by `drop` if it never does; until then
            // nothing else touches it.
            let bytes: &'static [u8] = unsafe { &*buffer };
            let request =
                self.comm.process_at_rank(peer).immediate_send_with_tag(StaticScope, bytes, tag);
            self.in_flight.borrow_mut().push(InFlight { request, buffer });
            Ok(())
        }

        fn recv(&self, from: usize, tag: u32) -> Result<Vec<u8>, CommError> {
            let source = self.comm.process_at_rank(self.peer(from)?);
            let mpi_tag = tag_of(tag)?;
            let deadline = Instant::now() + self.timeout;
            let mut idle = Duration::from_micros(1);
            loop {
                if let Some(matched) = source.immediate_matched_probe_with_tag(mpi_tag) {
                    return Ok(matched.matched_receive_vec::<u8>().0);
                }
                // Sends progress while we wait (some MPIs need the calls).
                self.reap();
                let now = Instant::now();
                if now >= deadline {
                    return Err(CommError::Timeout { from, tag });
                }
                std::thread::sleep(idle.min(deadline - now));
                idle = (idle * 2).min(Duration::from_millis(1));
            }
        }
    }

    impl Drop for MpiComm {
        fn drop(&mut self) {
            let deadline = Instant::now() + self.timeout;
            while !self.reap() && Instant::now() < deadline {
                std::thread::sleep(Duration::from_micros(100));
            }
            for InFlight { request, buffer } in self.in_flight.get_mut().drain(..) {
                request.cancel();
                match request.test() {
                    // SAFETY: as in `reap`: the request is complete.
                    Ok(_) => drop(unsafe { Box::from_raw(buffer) }),
                    // A send that can neither finish nor be cancelled keeps
                    // its buffer forever (leaked) and its request is
                    // forgotten: MPI may still read the buffer.
                    Err(request) => core::mem::forget(request),
                }
            }
        }
    }
}
