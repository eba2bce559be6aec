//! Where no adapter matches, `Gpu::new` says so (a caller then falls back
//! to the CPU). Its own test binary: it sets the process's environment.

use rt_gpu::{Gpu, GpuError};

#[test]
fn no_matching_adapter_is_a_clear_error() {
    // SAFETY: this binary's only test; nothing else reads the environment.
    unsafe { std::env::set_var("RT_GPU_ADAPTER", "no adapter has this name") };
    let e = Gpu::new().unwrap_err();
    assert_eq!(e, GpuError::NoAdapter);
    assert!(e.to_string().contains("no GPU adapter"), "{e}");
}
