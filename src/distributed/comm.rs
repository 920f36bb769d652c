//! The few collective operations the driver needs, over an MPI communicator:
//! an all-to-all of byte messages, reductions, and the agreement that turns
//! one rank's failure into every rank's clean exit.

use mpi::collective::SystemOperation;
use mpi::datatype::{Partition, PartitionMut};
use mpi::topology::SimpleCommunicator;
use mpi::traits::*;
use mpi::Count;
use std::sync::atomic::{AtomicBool, Ordering};

/// A communicator with its rank and size.
pub struct Comm {
    world: SimpleCommunicator,
    /// This rank.
    pub rank: u32,
    /// Number of ranks.
    pub size: u32,
}

/// What a rank that did not fail reports when another one did: its own
/// message is printed by the failing rank.
pub const OTHER_RANK_FAILED: &str = "another rank failed (its message is above)";

/// Set once [`Comm::agree`] has printed this rank's own failure.
static FAILURE_PRINTED: AtomicBool = AtomicBool::new(false);

/// Whether [`Comm::agree`] already printed this rank's failure to stderr
/// (the caller's top level then need not print it again).
pub fn failure_printed() -> bool {
    FAILURE_PRINTED.load(Ordering::Relaxed)
}

impl Comm {
    /// Wraps `world`.
    pub fn new(world: SimpleCommunicator) -> Comm {
        let (rank, size) = (world.rank() as u32, world.size() as u32);
        Comm { world, rank, size }
    }

    /// Sends `out[r]` to rank `r` and returns what every rank sent here, in
    /// rank order. A message over 2 GiB (MPI's `int` counts) is an error on
    /// every rank, not a truncation.
    pub fn exchange(&self, out: Vec<Vec<u8>>) -> Result<Vec<Vec<u8>>, String> {
        assert_eq!(out.len(), self.size as usize, "one message per rank");
        let too_big = out.iter().map(Vec::len).sum::<usize>() > Count::MAX as usize;
        self.agree(if too_big {
            Err(format!(
                "rank {}: more than 2 GiB to send in one exchange; run on more ranks",
                self.rank
            ))
        } else {
            Ok(())
        })?;
        let counts: Vec<Count> = out.iter().map(|m| m.len() as Count).collect();
        let mut recv_counts = vec![0 as Count; self.size as usize];
        self.world
            .all_to_all_into(&counts[..], &mut recv_counts[..]);
        let total_in: usize = recv_counts.iter().map(|&c| c as usize).sum();
        self.agree(if total_in > Count::MAX as usize {
            Err(format!(
                "rank {}: more than 2 GiB to receive in one exchange; run on more ranks",
                self.rank
            ))
        } else {
            Ok(())
        })?;
        let displs = offsets(&counts);
        let recv_displs = offsets(&recv_counts);
        // One spare byte each: two empty vectors share one dangling address,
        // and Open MPI refuses a send buffer equal to the receive buffer.
        let total_out: usize = out.iter().map(Vec::len).sum();
        let mut send: Vec<u8> = Vec::with_capacity(total_out + 1);
        out.iter().for_each(|m| send.extend_from_slice(m));
        send.push(0);
        let mut recv = vec![0u8; total_in + 1];
        {
            let s = Partition::new(&send[..total_out], &counts[..], &displs[..]);
            let mut r =
                PartitionMut::new(&mut recv[..total_in], &recv_counts[..], &recv_displs[..]);
            self.world.all_to_all_varcount_into(&s, &mut r);
        }
        Ok(recv_counts
            .iter()
            .zip(&recv_displs)
            .map(|(&c, &d)| recv[d as usize..(d + c) as usize].to_vec())
            .collect())
    }

    /// Sums of `x` over the ranks, element by element.
    pub fn sum(&self, x: &[u64]) -> Vec<u64> {
        let mut out = vec![0u64; x.len()];
        self.world
            .all_reduce_into(x, &mut out[..], SystemOperation::sum());
        out
    }

    /// Minimum of `x` over the ranks.
    pub fn min(&self, x: f64) -> f64 {
        let mut out = 0.0;
        self.world
            .all_reduce_into(&x, &mut out, SystemOperation::min());
        out
    }

    /// Maximum of `x` over the ranks.
    pub fn max(&self, x: f64) -> f64 {
        let mut out = 0.0;
        self.world
            .all_reduce_into(&x, &mut out, SystemOperation::max());
        out
    }

    /// Every rank's `x`, in rank order.
    pub fn all_gather(&self, x: u64) -> Vec<u64> {
        let mut out = vec![0u64; self.size as usize];
        self.world.all_gather_into(&x, &mut out[..]);
        out
    }

    /// Rank 0's `bytes` on every rank.
    pub fn broadcast(&self, bytes: Vec<u8>) -> Vec<u8> {
        let root = self.world.process_at_rank(0);
        let mut n = bytes.len() as u64;
        root.broadcast_into(&mut n);
        let mut buf = if self.rank == 0 {
            bytes
        } else {
            vec![0u8; n as usize]
        };
        // In pieces below MPI's int count.
        for chunk in buf.chunks_mut(1 << 30) {
            root.broadcast_into(chunk);
        }
        buf
    }

    /// Whether every rank succeeded: each rank's own result comes back where
    /// all succeeded; where any failed, every rank gets an error (the
    /// failing ones their own message, the others [`OTHER_RANK_FAILED`]).
    /// A collective, so no rank goes on into a later collective alone (which
    /// would hang).
    ///
    /// A failing rank prints `error: <its message>` to stderr *before* the
    /// reduction: no rank can leave the reduction before every rank entered
    /// it, so the message is written before any rank exits and mpirun, which
    /// ends the job at the first non-zero exit, cannot cut it off.
    /// [`failure_printed`] tells the caller it was printed.
    pub fn agree<T>(&self, local: Result<T, String>) -> Result<T, String> {
        if let Err(e) = &local {
            eprintln!("error: {e}");
            FAILURE_PRINTED.store(true, Ordering::Relaxed);
        }
        let failed = u64::from(local.is_err());
        let any = self.sum(&[failed])[0];
        match local {
            Err(e) => Err(e),
            Ok(_) if any > 0 => Err(OTHER_RANK_FAILED.to_string()),
            Ok(x) => Ok(x),
        }
    }

    /// [`Comm::agree`] for a check every rank makes alike (of the command's
    /// arguments, say): its message is printed once, by rank 0, not once
    /// per rank. A rank whose failure rank 0 did not share prints its own
    /// (and every rank waits for that print before going on).
    pub fn agree_alike<T>(&self, local: Result<T, String>) -> Result<T, String> {
        let failed = local.is_err();
        if let Err(e) = &local {
            if self.rank == 0 {
                eprintln!("error: {e}");
            }
            FAILURE_PRINTED.store(true, Ordering::Relaxed);
        }
        let root_failed = failed && self.rank == 0;
        let s = self.sum(&[u64::from(failed), u64::from(root_failed)]);
        if s[0] > 0 && s[1] == 0 {
            if let Err(e) = &local {
                eprintln!("error: {e}");
            }
            // No rank leaves (and ends the job) before those prints.
            self.barrier();
        }
        match local {
            Err(e) => Err(e),
            Ok(_) if s[0] > 0 => Err(OTHER_RANK_FAILED.to_string()),
            Ok(x) => Ok(x),
        }
    }

    /// Waits for every rank.
    pub fn barrier(&self) {
        self.world.barrier();
    }
}

/// Exclusive prefix sums of `counts`.
fn offsets(counts: &[Count]) -> Vec<Count> {
    let mut d = Vec::with_capacity(counts.len());
    let mut at: Count = 0;
    for &c in counts {
        d.push(at);
        at += c;
    }
    d
}
