//! The sensor model against its definition and the statistics of its
//! noise (DESIGN §4 "Sensor").

use rt_photo::{Sensor, SensorError};

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
