//! The BVH as memory: 8-wide nodes of quantized child boxes ([`node`]),
//! the owned tree ([`bvh`]), its byte format with the checks that make a
//! loaded tree safe to traverse ([`bytes`], [`check`], [`aligned`]), and
//! large pages for big trees ([`pages`]).

#[cfg(feature = "alloc")]
pub(crate) mod aligned;
#[cfg(feature = "alloc")]
pub(crate) mod bvh;
pub(crate) mod bytes;
#[cfg(feature = "alloc")]
pub(crate) mod check;
pub(crate) mod node;
#[cfg(feature = "alloc")]
pub(crate) mod pages;
