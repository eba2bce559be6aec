//! Rows of an image traced one by one, or in parallel with feature
//! `parallel`, gathered in order.

use alloc::vec::Vec;

/// `row(j)` for rows `0..h`, in order: in parallel with feature
/// `parallel` (each row its own work, so the result does not depend on the
/// thread count).
pub(crate) fn rows<P: Send, E: Send>(
    h: usize,
    row: impl Fn(usize) -> Result<Vec<P>, E> + Sync + Send,
) -> Vec<Result<Vec<P>, E>> {
    #[cfg(feature = "parallel")]
    {
        use rayon::prelude::*;
        (0..h).into_par_iter().map(row).collect()
    }
    #[cfg(not(feature = "parallel"))]
    {
        (0..h).map(row).collect()
    }
}
