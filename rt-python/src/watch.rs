//! Long renders watched from Python: progress and Ctrl-C.
//!
//! Python runs signal handlers only on the thread that called into the
//! extension, and only while it holds the interpreter. So a render runs
//! on a thread of its own (the GIL released), and the caller's thread
//! wakes every [`POLL`] to take the GIL, run `PyErr_CheckSignals` and
//! call the user's progress callback with the latest count. A pending
//! `KeyboardInterrupt` (or an exception from the callback) sets the stop
//! flag, which the render asks before every photon or ray
//! (`render_until`): it ends within a photon's time, its buffers are
//! dropped, and the exception is raised in the caller. Nothing of the
//! render is kept, since a partial image is not one of the images asked
//! for.

use core::{
    sync::atomic::{AtomicBool, AtomicU64, Ordering},
    time::Duration,
};

use pyo3::{exceptions::PyRuntimeError, prelude::*};

/// How often the caller's thread looks for signals and reports progress.
const POLL: Duration = Duration::from_millis(50);

/// Shared between a render and the thread watching it.
#[derive(Default)]
pub(crate) struct Watch {
    stop: AtomicBool,
    done: AtomicU64,
    total: AtomicU64,
}

impl Watch {
    /// Whether the render should stop (asked by the workers).
    pub(crate) fn stopped(&self) -> bool {
        self.stop.load(Ordering::Relaxed)
    }

    /// Records `done` of `total` units of work.
    pub(crate) fn progress(&self, done: u64, total: u64) {
        self.total.store(total, Ordering::Relaxed);
        self.done.store(done, Ordering::Relaxed);
    }

    /// Counts one unit of `total` (a ray, from the workers): batched per
    /// thread, so the shared counter is touched once per 256 rays. Call
    /// [`Watch::progress`] with the total at the end: up to 255 a thread
    /// are still in the batches.
    pub(crate) fn count_one(&self, total: u64) {
        thread_local! {
            static PENDING: core::cell::Cell<u64> = const { core::cell::Cell::new(0) };
        }
        PENDING.with(|pending| {
            let n = pending.get() + 1;
            if n < 256 {
                pending.set(n);
                return;
            }
            pending.set(0);
            self.total.store(total, Ordering::Relaxed);
            let done = self.done.fetch_add(n, Ordering::Relaxed) + n;
            // A batch left over from an earlier render cannot pass the end.
            if done > total {
                self.done.store(total, Ordering::Relaxed);
            }
        });
    }

    /// Runs `render` with a `stop` that counts each question as one of
    /// `total` units (`render_until` asks once a ray: width × height ×
    /// k² for BOS and focusing), then reports the total.
    pub(crate) fn counting<T>(
        &self,
        total: u64,
        render: impl FnOnce(&(dyn Fn() -> bool + Sync)) -> T,
    ) -> T {
        let out = render(&|| {
            self.count_one(total);
            self.stopped()
        });
        self.progress(total, total);
        out
    }

    fn seen(&self) -> (u64, u64) {
        (self.done.load(Ordering::Relaxed), self.total.load(Ordering::Relaxed))
    }
}

/// Runs `work` on its own thread with the GIL released while this thread
/// watches it (module doc): `progress(done, total)` is called on this
/// thread whenever the count moved, the final count included.
///
/// # Errors
/// The `KeyboardInterrupt` (or other signal handler's exception) or the
/// callback's exception that stopped the render; `RuntimeError` if the
/// render panicked.
pub(crate) fn watched<T: Send>(
    py: Python<'_>,
    progress: Option<Py<PyAny>>,
    work: impl FnOnce(&Watch) -> T + Send,
) -> PyResult<T> {
    let watch = Watch::default();
    let caller = std::thread::current();
    let (outcome, failed) = py.detach(|| {
        std::thread::scope(|s| {
            let worker = s.spawn(|| {
                let out = work(&watch);
                caller.unpark();
                out
            });
            let mut failed: Option<PyErr> = None;
            let mut shown = (0, 0);
            // Checks for signals and reports the count if it moved (so
            // the callback sees each count once, the last one included).
            let mut look = || {
                let now = watch.seen();
                let r = Python::attach(|py| -> PyResult<()> {
                    py.check_signals()?;
                    if let Some(cb) = &progress
                        && now.1 > 0
                        && now != shown
                    {
                        cb.bind(py).call1(now)?;
                    }
                    Ok(())
                });
                shown = now;
                r
            };
            while !worker.is_finished() {
                std::thread::park_timeout(POLL);
                if failed.is_none()
                    && let Err(e) = look()
                {
                    watch.stop.store(true, Ordering::Relaxed);
                    failed = Some(e);
                }
            }
            let outcome = worker.join();
            if failed.is_none()
                && outcome.is_ok()
                && let Err(e) = look()
            {
                failed = Some(e);
            }
            (outcome, failed)
        })
    });
    if let Some(e) = failed {
        return Err(e);
    }
    outcome.map_err(|panic| {
        let why = panic
            .downcast_ref::<&str>()
            .map(|s| (*s).to_owned())
            .or_else(|| panic.downcast_ref::<String>().cloned())
            .unwrap_or_default();
        PyRuntimeError::new_err(format!("rtvis: the render failed inside rt ({why})"))
    })
}
