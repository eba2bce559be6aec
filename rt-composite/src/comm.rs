//! Communicators: what a compositing schedule needs from the transport
//! (the calls IceT makes of MPI: rank, size, tagged point-to-point byte
//! messages), and an in-process implementation on threads and channels.

use alloc::{string::String, vec::Vec};
use core::fmt;

/// Why a message could not be sent or received.
#[derive(Clone, Debug, PartialEq, Eq)]
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
    /// The transport reported an error (e.g. MPI).
    Transport(String),
}

impl fmt::Display for CommError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::NoSuchRank(r) => write!(f, "no rank {r}"),
            Self::Disconnected(r) => write!(f, "rank {r} is gone"),
            Self::Timeout { from, tag } => {
                write!(f, "timed out waiting for rank {from} (tag {tag})")
            }
            Self::Transport(m) => write!(f, "transport: {m}"),
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
