//! The sparse-image decoder on any bytes: a `DecodeError`, or an image
//! that serializes back to exactly those bytes, decodes to the pixels it
//! writes, and is unchanged by z-compositing with itself.
#![no_main]

use libfuzzer_sys::fuzz_target;
use rt_composite::{Fragment, Pixel8, SparseImage};
use rt_core::Pixel;
use rt_fuzz::bits;

fn check<F: Fragment>(data: &[u8], same: impl Fn(&[F], &[F]) -> bool) {
    let Ok(img) = SparseImage::<F>::from_bytes(data) else { return };
    assert_eq!(img.to_bytes(), data, "round trip");
    assert_eq!(img.byte_len(), data.len());
    let r = img.range();
    if r.end > 1 << 16 {
        return; // Bounded work: do not write out huge spans.
    }
    let mut full = vec![F::BACKGROUND; r.end];
    img.write_into(&mut full);
    let again = SparseImage::encode(r.start, &full[r.clone()]);
    assert_eq!(again.active_count(), img.active_count());
    let mut back = vec![F::BACKGROUND; r.end];
    again.write_into(&mut back);
    assert!(same(&full, &back));
    let z = img.combine(&img, F::z).expect("same span");
    let mut zz = vec![F::BACKGROUND; r.end];
    z.write_into(&mut zz);
    assert!(same(&full, &zz), "z with itself changed the image");
}

fuzz_target!(|data: &[u8]| {
    check::<Pixel>(data, |a, b| a.iter().map(bits).eq(b.iter().map(bits)));
    check::<Pixel8>(data, |a, b| a == b);
});
