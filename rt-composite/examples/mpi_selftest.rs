//! The schedules on real MPI processes, checked against the serial fold
//! bit for bit, and the failures that must be an `Err` on every rank.
//!
//! ```text
//! cargo build -p rt-composite --features mpi --example mpi_selftest
//! mpirun -np 4 target/debug/examples/mpi_selftest
//! ```
//!
//! Every rank makes every rank's image from the same seeds, so each can
//! compute the serial fold itself; rank 0 compares the gathered image with
//! it. Each rank prints its failures and the process exits non-zero if
//! there is one anywhere (the verdict is reduced over all ranks).
#![allow(clippy::std_instead_of_core, clippy::std_instead_of_alloc, clippy::alloc_instead_of_core)]

// The seeded image generator the tests use.
#[path = "../tests/support/mod.rs"]
mod support;

use std::{process::ExitCode, time::Duration};

use rt_composite::{
    CommError, Communicator, Fragment, MpiComm, Operator, Pixel8, Schedule, composite,
    mpi::{collective::SystemOperation, traits::CommunicatorCollectives},
    serial_fold,
};
use rt_core::Pixel;
use support::image;

fn bits<F: Fragment>(p: &[F]) -> Vec<u8> {
    let mut out = vec![0; p.len() * F::SIZE];
    for (px, chunk) in p.iter().zip(out.chunks_exact_mut(F::SIZE)) {
        px.write(chunk);
    }
    out
}

/// Sends everything cut short by one byte.
struct Truncating<'a>(&'a MpiComm, bool);

impl Communicator for Truncating<'_> {
    fn rank(&self) -> usize {
        self.0.rank()
    }
    fn size(&self) -> usize {
        self.0.size()
    }
    fn send(&self, to: usize, tag: u32, mut data: Vec<u8>) -> Result<(), CommError> {
        if self.1 {
            data.pop();
        }
        self.0.send(to, tag, data)
    }
    fn recv(&self, from: usize, tag: u32) -> Result<Vec<u8>, CommError> {
        self.0.recv(from, tag)
    }
}

fn check_equal<F: Fragment>(
    comm: &MpiComm,
    mine: &[F],
    all: &[Vec<F>],
    size: (u32, u32),
    s: Schedule,
    m: &Operator,
    failures: &mut Vec<String>,
) {
    let what = format!("{s:?} {m:?} {}×{}", size.0, size.1);
    match composite(comm, mine, size.0, size.1, s, m) {
        Ok((Some(img), _)) => {
            let refs: Vec<&[F]> = all.iter().map(Vec::as_slice).collect();
            match serial_fold(&refs, m) {
                Ok(expected) if bits(&img) == bits(&expected) => {}
                _ => failures.push(format!("{what}: differs from the serial fold")),
            }
        }
        Ok((None, _)) if comm.rank() != 0 => {}
        Ok((None, _)) => failures.push(format!("{what}: rank 0 got no image")),
        Err(e) => failures.push(format!("{what}: {e}")),
    }
}

fn main() -> ExitCode {
    let Some(universe) = rt_composite::mpi::initialize() else {
        eprintln!("mpi_selftest: MPI was already initialised");
        return ExitCode::FAILURE;
    };
    let world = universe.world();
    let comm = MpiComm::new(&world, Duration::from_secs(30));
    let (rank, n) = (comm.rank(), comm.size());
    let mut failures = Vec::new();
    let schedules = [
        Schedule::DirectSend,
        Schedule::BinarySwap,
        Schedule::RadixK(2),
        Schedule::RadixK(3),
        Schedule::RadixK(16),
    ];
    let mut cases = 0;
    for (w, h) in [(1, 1), (7, 3), (13, 11), (256, 192)] {
        for active in [0.0, 0.1, 1.0] {
            let all: Vec<Vec<Pixel>> =
                (0..n).map(|r| image(r as u64 * 31 + w as u64, (w * h) as usize, active)).collect();
            for s in schedules {
                check_equal(&comm, &all[rank], &all, (w, h), s, &Operator::Depth, &mut failures);
                cases += 1;
            }
            let order: Vec<usize> = (0..n).rev().collect();
            let over = Operator::Over { order };
            check_equal(
                &comm,
                &all[rank],
                &all,
                (w, h),
                Schedule::DirectSend,
                &over,
                &mut failures,
            );
            let all8: Vec<Vec<Pixel8>> = all
                .iter()
                .map(|img| img.iter().map(|p| Pixel8::from_pixel(*p)).collect())
                .collect();
            check_equal(
                &comm,
                &all8[rank],
                &all8,
                (w, h),
                Schedule::BinarySwap,
                &Operator::Depth,
                &mut failures,
            );
            cases += 2;
        }
    }
    // Failures must be an Err on every rank, without a hang.
    let img = image(rank as u64, 35, 0.8);
    for s in schedules {
        // One rank claims 5×7 where the others say 7×5.
        let size = if rank == n - 1 && n > 1 { (5, 7) } else { (7, 5) };
        if n > 1 && composite(&comm, &img, size.0, size.1, s, &Operator::Depth).is_ok() {
            failures.push(format!("{s:?}: mismatched sizes were not an error"));
        }
        // One rank truncates every message it sends.
        let cut = Truncating(&comm, rank == n / 2);
        if n > 1 && composite(&cut, &img, 7, 5, s, &Operator::Depth).is_ok() {
            failures.push(format!("{s:?}: truncated messages were not an error"));
        }
        cases += 2;
    }
    let over = Operator::Over { order: (0..n).collect() };
    if n > 1 && composite(&comm, &img, 7, 5, Schedule::BinarySwap, &over).is_ok() {
        failures.push("over with binary swap was not an error".into());
    }
    for f in &failures {
        eprintln!("rank {rank}: {f}");
    }
    let mine = u32::try_from(failures.len()).unwrap_or(u32::MAX);
    let mut total = 0u32;
    world.all_reduce_into(&mine, &mut total, SystemOperation::sum());
    if rank == 0 {
        println!("mpi_selftest: {n} ranks, {cases} cases per rank, {total} failures");
    }
    if total == 0 { ExitCode::SUCCESS } else { ExitCode::FAILURE }
}
