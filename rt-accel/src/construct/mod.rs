//! Making and updating a BVH: a binary tree by binned SAH ([`sah`], the
//! default) or obvhs's presets, collapsed to the 8-wide layout of least
//! SAH cost ([`build`]); refitting its boxes after vertices move
//! ([`refit`]).

#[cfg(feature = "obvhs")]
pub(crate) mod build;
#[cfg(feature = "alloc")]
pub(crate) mod refit;
#[cfg(feature = "obvhs")]
pub(crate) mod sah;
