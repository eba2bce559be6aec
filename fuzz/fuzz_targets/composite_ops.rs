//! The compositing operators on any pixels (f32 and 8-bit): the background
//! is an exact identity of `z` and `over`; `z` is associative and, over
//! (pixel, rank) pairs, commutative bit for bit; `over` of finite colours
//! stays finite; 8-bit `over` is exact integer arithmetic.
#![no_main]

use libfuzzer_sys::fuzz_target;
use rt_composite::{Fragment, Pixel8};
use rt_core::Pixel;
use rt_fuzz::{bits, pixel};

fuzz_target!(|data: &[u8]| {
    let mut u = arbitrary::Unstructured::new(data);
    let (Ok(a), Ok(b), Ok(c)) = (pixel(&mut u), pixel(&mut u), pixel(&mut u)) else { return };
    let bg = Pixel::BACKGROUND;
    for p in [a, b, c] {
        assert_eq!(bits(&p.z(bg)), bits(&p));
        assert_eq!(bits(&bg.z(p)), bits(&p));
        assert_eq!(bits(&p.over(bg)), bits(&p));
        assert_eq!(bits(&bg.over(p)), bits(&p));
    }
    // z: associative; and "a from the lower rank" gives the same answer
    // whichever side it is folded from.
    assert_eq!(bits(&a.z(b).z(c)), bits(&a.z(b.z(c))), "{a:?} {b:?} {c:?}");
    let nearer_is_b = !b.is_background() && (a.is_background() || b.depth() < a.depth());
    assert_eq!(bits(&a.z(b)), bits(if nearer_is_b { &b } else { &a }));
    // over of finite, premultiplied colours stays finite.
    let fin = |p: &Pixel| p.color.iter().all(|v| v.is_finite() && v.abs() <= 1.0);
    if fin(&a) && fin(&b) {
        assert!(a.over(b).color.iter().all(|v| v.is_finite()), "{a:?} over {b:?}");
    }
    let (a8, b8, c8) = (Pixel8::from_pixel(a), Pixel8::from_pixel(b), Pixel8::from_pixel(c));
    for p in [a8, b8, c8] {
        assert_eq!(p.over(Pixel8::BACKGROUND), p);
        assert_eq!(Pixel8::BACKGROUND.over(p), p);
        assert_eq!(p.z(Pixel8::BACKGROUND), p);
    }
    assert_eq!(a8.z(b8).z(c8), a8.z(b8.z(c8)));
    // Wire form round trip.
    let mut buf = vec![0; Pixel::SIZE];
    a.write(&mut buf);
    assert_eq!(bits(&Pixel::read(&buf)), bits(&a));
});
