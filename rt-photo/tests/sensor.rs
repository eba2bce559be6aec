//! The sensor model against its definition and the statistics of its
//! noise (docs/physics.md §11).

use rt_photo::{Airy, Sensor, SensorError};

fn stats(v: &[u16]) -> (f64, f64) {
    let n = v.len() as f64;
    let mean = v.iter().map(|&x| f64::from(x)).sum::<f64>() / n;
    let var = v.iter().map(|&x| (f64::from(x) - mean).powi(2)).sum::<f64>() / (n - 1.0);
    (mean, var)
}

/// Noise off: `DN = round(min(E·I, FW)/FW · (2^bits − 1))`, exactly;
/// saturation at the full well; every bit depth's top count.
#[test]
fn noise_free_record_is_the_definition() {
    let s = Sensor { exposure: 1000.0, full_well: 4000.0, bits: 12, ..Sensor::default() };
    let img = [0.0, 0.5, 1.0, 2.0, 3.999, 4.0, 7.5];
    let dn = s.record(&img, 7, 1, 1).unwrap();
    let want: Vec<u16> = img
        .iter()
        .map(|&i| (f64::min(1000.0 * i, 4000.0) / 4000.0 * 4095.0 + 0.5).floor() as u16)
        .collect();
    assert_eq!(dn, want);
    assert_eq!(dn[4], 4094);
    assert_eq!(dn[6], 4095);
    for bits in [1u32, 8, 16] {
        let s = Sensor { bits, ..s };
        assert_eq!(s.record(&[10.0], 1, 1, 0).unwrap()[0], s.max_count());
        assert_eq!(u32::from(s.max_count()), (1 << bits) - 1);
    }
}

/// Shot noise: a uniform image at 1000 e⁻ (1 e⁻ per count) has mean 1000
/// and variance 1000 (Poisson), to within the sampling error of 65 536
/// pixels (4σ); the PTRS branch. At a mean of 2 (Knuth's branch) the
/// counts follow the Poisson probabilities.
#[test]
fn shot_noise_is_poisson() {
    let n = 256 * 256;
    let s = Sensor {
        exposure: 1000.0,
        full_well: 65535.0,
        bits: 16,
        shot_noise: true,
        read_noise: 0.0,
        airy: None,
    };
    // Means on both sides of the switch to PTRS at 10, and large.
    for e in [9.5, 10.0, 37.0, 1000.0, 30000.0] {
        let dn = Sensor { exposure: e, ..s }.record(&vec![1.0; n], 256, 256, 7).unwrap();
        let (mean, var) = stats(&dn);
        assert!((mean - e).abs() < 4.0 * (e / n as f64).sqrt(), "E {e}: mean {mean}");
        // The sample variance's sd ≈ σ²·√(2/n) (+ a σ²/n kurtosis term).
        assert!((var - e).abs() < 4.0 * e * (2.0 / n as f64).sqrt() + 0.1, "E {e}: variance {var}");
    }

    let s = Sensor { exposure: 2.0, ..s };
    let dn = s.record(&vec![1.0; n], 256, 256, 8).unwrap();
    let mut p = 2f64.powi(0) * (-2.0f64).exp();
    for k in 0..6u16 {
        let seen = dn.iter().filter(|&&x| x == k).count() as f64 / n as f64;
        let sd = (p * (1.0 - p) / n as f64).sqrt();
        assert!((seen - p).abs() < 5.0 * sd, "P({k}) = {seen}, Poisson {p}");
        p *= 2.0 / f64::from(k + 1);
    }
}

/// Read noise alone: Gaussian with the given rms; it adds to shot noise
/// in variance.
#[test]
fn read_noise_adds_in_variance() {
    let n = 256 * 256;
    let base = Sensor {
        exposure: 500.0,
        full_well: 65535.0,
        bits: 16,
        shot_noise: false,
        read_noise: 12.0,
        airy: None,
    };
    let (mean, var) = stats(&base.record(&vec![1.0; n], 256, 256, 3).unwrap());
    assert!((mean - 500.0).abs() < 0.3, "mean {mean}");
    // Quantisation adds 1/12 count².
    assert!(
        (var - (144.0 + 1.0 / 12.0)).abs() < 4.0 * 144.0 * (2.0 / n as f64).sqrt(),
        "variance {var}"
    );
    let both = Sensor { shot_noise: true, ..base };
    let (_, var) = stats(&both.record(&vec![1.0; n], 256, 256, 3).unwrap());
    assert!((var - 644.0).abs() < 4.0 * 644.0 * (2.0 / n as f64).sqrt(), "variance {var}");
}

/// The same seed gives the same counts; another seed others; the noise of
/// a pixel does not depend on the others (its own stream).
#[test]
fn deterministic_by_seed_and_pixel() {
    let s = Sensor { shot_noise: true, read_noise: 3.0, ..Sensor::default() };
    let img: Vec<f64> = (0..64).map(|i| f64::from(i) / 32.0).collect();
    let a = s.record(&img, 8, 8, 11).unwrap();
    assert_eq!(a, s.record(&img, 8, 8, 11).unwrap());
    assert_ne!(a, s.record(&img, 8, 8, 12).unwrap());
    let mut other = img.clone();
    other[5] = 0.25;
    let b = s.record(&other, 8, 8, 11).unwrap();
    assert!(a.iter().zip(&b).enumerate().all(|(p, (x, y))| p == 5 || x == y));
}

#[test]
fn bad_settings_and_images_are_errors() {
    let s = Sensor::default();
    let bad = |t: Sensor| t.record(&[1.0], 1, 1, 0).unwrap_err();
    assert!(
        matches!(bad(Sensor { exposure: f64::NAN, ..s }), SensorError::Exposure(v) if v.is_nan())
    );
    assert!(matches!(bad(Sensor { exposure: -1.0, ..s }), SensorError::Exposure(_)));
    assert!(matches!(bad(Sensor { full_well: 0.0, ..s }), SensorError::FullWell(_)));
    assert!(matches!(bad(Sensor { bits: 0, ..s }), SensorError::Bits(0)));
    assert!(matches!(bad(Sensor { bits: 17, ..s }), SensorError::Bits(17)));
    assert!(matches!(bad(Sensor { read_noise: f64::INFINITY, ..s }), SensorError::ReadNoise(_)));
    assert_eq!(s.record(&[1.0; 3], 2, 2, 0), Err(SensorError::ImageSize { expected: 4, found: 3 }));
    assert_eq!(s.record(&[], 0, 5, 0), Err(SensorError::ImageSize { expected: 0, found: 0 }));
    assert_eq!(
        s.record(&[1.0; 2], usize::MAX, 2, 0),
        Err(SensorError::ImageSize { expected: 0, found: 2 })
    );
    assert!(matches!(
        s.record(&[1.0, -0.5], 2, 1, 0),
        Err(SensorError::Sample { index: 1, value }) if value == -0.5
    ));
    assert!(matches!(s.record(&[f64::NAN], 1, 1, 0), Err(SensorError::Sample { index: 0, .. })));
    assert!(!SensorError::Bits(0).to_string().is_empty());
}

/// The Airy kernel: symmetric, non-negative, summing to 1, keeping over
/// 99 % of the pattern's light; a uniform image stays uniform (inside and
/// at the clamped edges).
#[test]
fn airy_kernel_sums_to_one_and_keeps_uniform_images_uniform() {
    for s in [0.001, 0.3, 1.7, 3.0, 8.0] {
        let a = Airy::new(0.5e-6, s * 2.0, 1e-6);
        let k = a.kernel().unwrap();
        let n = 2 * k.radius + 1;
        assert_eq!(k.weights.len(), n * n);
        assert_eq!(k.radius, ((21.25 * a.scale()).ceil() as usize).max(1), "λN = {s} px");
        assert!((k.weights.iter().sum::<f64>() - 1.0).abs() < 1e-12, "λN = {s} px");
        assert!(k.weights.iter().all(|&w| w >= 0.0));
        assert!(k.captured > 0.99 && k.captured <= 1.0 + 1e-6, "λN = {s}: {}", k.captured);
        for y in 0..n {
            for x in 0..n {
                let w = k.weights[y * n + x];
                assert_eq!(w, k.weights[x * n + y]);
                assert_eq!(w, k.weights[y * n + (n - 1 - x)]);
            }
        }
    }
    let a = Airy::new(0.5e-6, 6.0, 1e-6); // λN = 3 px: a 64-pixel kernel
    let (w, h) = (30, 20);
    let out = a.blur(&vec![0.7; w * h], w, h).unwrap();
    assert!(out.iter().all(|v| (v - 0.7).abs() < 1e-12));
    // A tiny blur (λN = 0.001 px) nearly leaves the image as it was: the
    // rings beyond the centre pixel's inscribed circle hold
    // `J₀² + J₁² ≈ 2/(πx)` = 4e-4 of the light at x = π·0.5/0.001.
    let tiny = Airy::new(0.5e-6, 0.002, 1e-6);
    let k = tiny.kernel().unwrap();
    assert_eq!(k.radius, 1);
    assert!(k.weights[4] > 0.9995 && k.weights[4] < 0.9999, "{}", k.weights[4]);
    let img: Vec<f64> = (0..w * h).map(|i| (i % 7) as f64 / 7.0).collect();
    let out = tiny.blur(&img, w, h).unwrap();
    assert!(out.iter().zip(&img).all(|(a, b)| (a - b).abs() < 5e-4));
}

/// A point of light blurred by an Airy pattern of λN = 8 pixels (first
/// dark ring 9.76 pixels out): the pixels within the first dark ring hold
/// 83.8 % of the light (the Airy disc's encircled energy), within the
/// kernel's truncation (its light is rescaled by 1/`captured`); along a
/// row the profile is `[2 J₁(x)/x]²`; the light is conserved.
#[test]
fn airy_blur_of_a_point_is_the_airy_pattern() {
    let a = Airy::new(0.5e-6, 16.0, 1e-6);
    assert!((a.scale() - 8.0).abs() < 1e-12);
    let ring = a.first_dark_ring();
    assert!((ring - 1.22 * 8.0).abs() < 0.01, "{ring}");
    let (w, c) = (61usize, 30usize);
    let mut img = vec![0.0; w * w];
    img[c * w + c] = 1.0;
    let out = a.blur(&img, w, w).unwrap();
    let total: f64 = out.iter().sum();
    let mut inside = 0.0;
    for y in 0..w {
        for x in 0..w {
            let r = ((x as f64 - c as f64).powi(2) + (y as f64 - c as f64).powi(2)).sqrt();
            if r <= ring {
                inside += out[y * w + x];
            }
        }
    }
    let captured = a.kernel().unwrap().captured;
    println!(
        "λN = 8 px: energy inside the first dark ring {inside:.5} (×captured {:.5}; Airy 0.8378), in the image {total:.5}, kernel captured {captured:.5}",
        inside * captured
    );
    // 61² pixels hold the kernel's light out to 30 pixels (≈ 0.97 of it).
    assert!(total > 0.95 && total <= 1.0 + 1e-12, "{total}");
    assert!((inside - 0.838).abs() < 0.01, "encircled energy {inside}");
    assert!((inside * captured - 0.8378).abs() < 0.002, "{inside} × {captured}");
    // The profile along the centre row, relative to the centre.
    let peak = out[c * w + c];
    for dx in 1..=30 {
        let got = out[c * w + c + dx] / peak;
        let want = a.intensity(dx as f64);
        assert!((got - want).abs() < 2e-3 + 0.01 * want, "{dx} px: {got} vs {want}");
    }
}

/// The sensor blurs before counting: a bright pixel spreads; the counts
/// of a blurred uniform image are those of the image; noise stays
/// deterministic by seed; diffraction is off by default.
#[test]
fn sensor_applies_airy_before_counting() {
    assert_eq!(Sensor::default().airy, None);
    let s = Sensor { exposure: 1000.0, full_well: 4000.0, bits: 12, ..Sensor::default() };
    let blurred = Sensor { airy: Some(Airy::new(0.5e-6, 4.0, 1e-6)), ..s };
    let (w, h) = (21, 21);
    let mut img = vec![0.5; w * h];
    img[10 * w + 10] = 3.0;
    let sharp = s.record(&img, w, h, 0).unwrap();
    let soft = blurred.record(&img, w, h, 0).unwrap();
    assert!(soft[10 * w + 10] < sharp[10 * w + 10]);
    assert!(soft[10 * w + 11] > sharp[10 * w + 11]);
    let sum = |v: &[u16]| v.iter().map(|&x| f64::from(x)).sum::<f64>();
    assert!((sum(&soft) / sum(&sharp) - 1.0).abs() < 1e-3);
    let flat = vec![0.25; w * h];
    assert_eq!(blurred.record(&flat, w, h, 0).unwrap(), s.record(&flat, w, h, 0).unwrap());
    let noisy = Sensor { shot_noise: true, read_noise: 2.0, ..blurred };
    assert_eq!(noisy.record(&img, w, h, 4).unwrap(), noisy.record(&img, w, h, 4).unwrap());
    assert_ne!(noisy.record(&img, w, h, 4).unwrap(), noisy.record(&img, w, h, 5).unwrap());
}

#[test]
fn bad_airy_settings_are_errors() {
    let good = Airy::new(532e-9, 8.0, 5e-6);
    let s = Sensor { airy: Some(good), ..Sensor::default() };
    assert!(s.record(&[1.0], 1, 1, 0).is_ok());
    let bad = |a: Airy| Sensor { airy: Some(a), ..s }.record(&[1.0], 1, 1, 0).unwrap_err();
    assert!(matches!(bad(Airy { wavelength: 0.0, ..good }), SensorError::Wavelength(_)));
    assert!(
        matches!(bad(Airy { wavelength: f64::NAN, ..good }), SensorError::Wavelength(v) if v.is_nan())
    );
    assert!(matches!(bad(Airy { f_number: -8.0, ..good }), SensorError::FNumber(_)));
    assert!(matches!(bad(Airy { f_number: f64::INFINITY, ..good }), SensorError::FNumber(_)));
    assert!(matches!(bad(Airy { pixel_pitch: 0.0, ..good }), SensorError::PixelPitch(_)));
    assert!(matches!(bad(Airy { pixel_pitch: 1e-300, ..good }), SensorError::AiryTooWide(_)));
    assert!(matches!(bad(Airy { f_number: 1000.0, ..good }), SensorError::AiryTooWide(_)));
    assert_eq!(good.blur(&[1.0; 3], 2, 2), Err(SensorError::ImageSize { expected: 4, found: 3 }));
    assert!(matches!(good.blur(&[f64::NAN], 1, 1), Err(SensorError::Sample { index: 0, .. })));
    assert!(!SensorError::AiryTooWide(30.0).to_string().is_empty());
}
