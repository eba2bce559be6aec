//! Rendering across ranks (threads, or MPI processes with feature `mpi`),
//! each checked against one process bit for bit: [`surface`], a terrain
//! whose shadow and ambient-occlusion rays every rank answers for its
//! part; [`volume`], a grid split into bricks with photons handed between
//! them (the protocol is `rt_photo::distributed`).

pub mod surface;
pub mod volume;
