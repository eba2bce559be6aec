//! Every schedule on 1–6 in-process ranks with any pixels (up to 5×4):
//! rank 0's image equals the serial fold bit for bit; a rank given an
//! image of the wrong size makes every rank return `Err`.
#![no_main]

use std::time::Duration;

use libfuzzer_sys::fuzz_target;
use rt_composite::{Operator, Schedule, ThreadComm, composite, serial_fold};
use rt_core::Pixel;
use rt_fuzz::{bits, pixel};

fuzz_target!(|data: &[u8]| {
    let mut u = arbitrary::Unstructured::new(data);
    let (Ok(n), Ok(w), Ok(h), Ok(s), Ok(bad)) = (
        u.int_in_range(1usize..=6),
        u.int_in_range(1u32..=5),
        u.int_in_range(1u32..=4),
        u.int_in_range(0u8..=3),
        u.ratio(1u8, 8),
    ) else {
        return;
    };
    let schedule = match s {
        0 => Schedule::DirectSend,
        1 => Schedule::BinarySwap,
        2 => Schedule::RadixK(2),
        _ => Schedule::RadixK(3),
    };
    let len = (w * h) as usize;
    let mut images = Vec::new();
    for _ in 0..n {
        let mut img = Vec::with_capacity(len);
        for _ in 0..len {
            img.push(pixel(&mut u).unwrap_or(Pixel::BACKGROUND));
        }
        images.push(img);
    }
    let over = u.ratio(1u8, 3).unwrap_or(false);
    let mode =
        if over { Operator::Over { order: (0..n).rev().collect() } } else { Operator::Depth };
    let schedule = if over { Schedule::DirectSend } else { schedule };
    if bad {
        images[n - 1].pop();
    }
    let comms = ThreadComm::group(n, Duration::from_secs(10));
    let out: Vec<_> = std::thread::scope(|sc| {
        let hs: Vec<_> = comms
            .into_iter()
            .zip(&images)
            .map(|(c, img)| {
                let mode = &mode;
                sc.spawn(move || composite(&c, img, w, h, schedule, mode))
            })
            .collect();
        hs.into_iter().map(|h| h.join().expect("no panic")).collect()
    });
    if bad {
        assert!(out.iter().all(Result::is_err), "a short image was not an error everywhere");
        return;
    }
    let refs: Vec<&[Pixel]> = images.iter().map(Vec::as_slice).collect();
    let expected = serial_fold(&refs, &mode).expect("valid images");
    let (img, _) = out.into_iter().next().expect("rank 0").expect("no error");
    let img = img.expect("rank 0 gets the image");
    assert_eq!(
        img.iter().map(bits).collect::<Vec<_>>(),
        expected.iter().map(bits).collect::<Vec<_>>(),
        "{n} ranks {w}×{h} {schedule:?} {mode:?}"
    );
});
