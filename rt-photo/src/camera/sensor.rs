//! A camera sensor: an image of relative intensity recorded as a camera
//! would record it (docs/physics.md §11).
//!
//! A pixel of intensity `I` (1 = the background) collects `e = E·I`
//! electrons on average, `E` the exposure; the recorded count is
//! `Poisson(e)` (photon shot noise) plus `Normal(0, σ_r)` (read noise),
//! clipped to `[0, full well]` and quantised to `2^bits − 1` levels:
//! `DN = round(e_recorded / full_well · (2^bits − 1))`. With the noise off
//! (the default) the record is exact: `DN = round(min(E·I, FW)/FW · (2^bits − 1))`.
//!
//! With [`Sensor::airy`] set, the image is first blurred by the lens's
//! diffraction ([`Airy`]: an Airy pattern whose first dark ring has
//! diameter `2.44 λN`), as light is spread before the pixels count it;
//! off by default.
//!
//! Deterministic: pixel `p`'s noise comes from its own random stream
//! `(seed, p)`, so the same seed gives the same counts whatever the order
//! (or thread) pixels are recorded in; record a reference image and a flow
//! image with different seeds for independent noise, as two exposures of a
//! real camera have.
//!
//! Poisson variates: Knuth's multiplication method below a mean of 10,
//! Hörmann's transformed rejection with squeeze (PTRS, "The transformed
//! rejection method for generating Poisson random variables", Insurance:
//! Mathematics and Economics 12, 1993) above; normal variates by
//! Box–Muller.

use alloc::vec::Vec;

use rt_core::sampling::{Rng, rng_for, uniform_f64};

use super::Airy;
use super::sensor_error::{SensorError, check_image};
use crate::math::{cos, exp, floor, ln, sqrt};

/// Sensor settings.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Sensor {
    /// Electrons a pixel collects at the background intensity (`I = 1`).
    pub exposure: f64,
    /// Full-well capacity in electrons: the count saturates there.
    pub full_well: f64,
    /// Bits per sample, 1–16: `2^bits − 1` at the full well.
    pub bits: u32,
    /// Photon shot noise (Poisson in the electron count).
    pub shot_noise: bool,
    /// Read noise, electrons rms (0: none).
    pub read_noise: f64,
    /// Diffraction blur applied to the image before the pixels count it
    /// (`None`: none).
    pub airy: Option<Airy>,
}

impl Default for Sensor {
    /// A 16-bit sensor exposed to half its 20 000 e⁻ full well at the
    /// background, noise and diffraction blur off.
    fn default() -> Self {
        Self {
            exposure: 10_000.0,
            full_well: 20_000.0,
            bits: 16,
            shot_noise: false,
            read_noise: 0.0,
            airy: None,
        }
    }
}

impl Sensor {
    /// Checks every setting.
    ///
    /// # Errors
    /// The first bad setting, as a [`SensorError`].
    pub fn validate(&self) -> Result<(), SensorError> {
        if !(self.exposure.is_finite() && self.exposure >= 0.0) {
            return Err(SensorError::Exposure(self.exposure));
        }
        if !(self.full_well.is_finite() && self.full_well > 0.0) {
            return Err(SensorError::FullWell(self.full_well));
        }
        if !(1..=16).contains(&self.bits) {
            return Err(SensorError::Bits(self.bits));
        }
        if !(self.read_noise.is_finite() && self.read_noise >= 0.0) {
            return Err(SensorError::ReadNoise(self.read_noise));
        }
        if let Some(a) = &self.airy {
            a.validate()?;
        }
        Ok(())
    }

    /// The largest count, at the full well: `2^bits − 1`.
    #[must_use]
    pub fn max_count(&self) -> u16 {
        ((1u32 << self.bits.clamp(1, 16)) - 1) as u16
    }

    /// Records `image` (`width × height` intensities, row-major, 1 = the
    /// background) as counts, pixel `p`'s noise drawn from stream
    /// `(seed, p)`; blurred first by [`Sensor::airy`] if set.
    ///
    /// # Errors
    /// A bad setting, an image of the wrong size, or a sample that is not
    /// a finite intensity ≥ 0.
    pub fn record(
        &self,
        image: &[f64],
        width: usize,
        height: usize,
        seed: u64,
    ) -> Result<Vec<u16>, SensorError> {
        self.validate()?;
        check_image(image, width, height)?;
        let blurred;
        let image = match &self.airy {
            Some(a) => {
                blurred = a.kernel()?.convolve(image, width, height);
                &blurred
            }
            None => image,
        };
        let levels = f64::from(self.max_count());
        Ok(image
            .iter()
            .enumerate()
            .map(|(p, &i)| {
                let mean = self.exposure * i;
                let e = if self.shot_noise || self.read_noise > 0.0 {
                    let mut rng = rng_for(seed, p as u64);
                    let mut e = if self.shot_noise { poisson(mean, &mut rng) } else { mean };
                    if self.read_noise > 0.0 {
                        e += self.read_noise * normal(&mut rng);
                    }
                    e
                } else {
                    mean
                };
                let dn = floor(e.clamp(0.0, self.full_well) / self.full_well * levels + 0.5);
                dn.min(levels) as u16
            })
            .collect())
    }
}

/// A standard normal variate (Box–Muller).
fn normal(rng: &mut Rng) -> f64 {
    let u = 1.0 - uniform_f64(rng); // (0, 1]: ln is finite
    let v = uniform_f64(rng);
    sqrt(-2.0 * ln(u)) * cos(core::f64::consts::TAU * v)
}

/// `ln k!`: exact below 10, Stirling's series (error < 1e-10) above.
fn ln_factorial(k: f64) -> f64 {
    const SMALL: [f64; 10] = [
        0.0,
        0.0,
        core::f64::consts::LN_2,
        1.791_759_469_228_055,
        3.178_053_830_347_945_8,
        4.787_491_742_782_046,
        6.579_251_212_010_101,
        8.525_161_361_065_415,
        10.604_602_902_745_25,
        12.801_827_480_081_469,
    ];
    if k < 10.0 {
        return SMALL[k as usize];
    }
    let n = k + 1.0;
    let n2 = n * n;
    (n - 0.5) * ln(n) - n
        + 0.918_938_533_204_672_8 // ln √(2π)
        + (1.0 / 12.0 - (1.0 / 360.0 - 1.0 / (1260.0 * n2)) / n2) / n
}

/// A Poisson variate of mean `mean ≥ 0` (as `f64`).
fn poisson(mean: f64, rng: &mut Rng) -> f64 {
    if mean <= 0.0 {
        return 0.0;
    }
    if mean < 10.0 {
        // Knuth: multiply uniforms until the product falls below e^−mean.
        let limit = exp(-mean);
        let (mut k, mut prod) = (0.0, uniform_f64(rng));
        while prod > limit {
            k += 1.0;
            prod *= uniform_f64(rng);
        }
        return k;
    }
    // PTRS (Hörmann 1993).
    let slam = sqrt(mean);
    let loglam = ln(mean);
    let b = 0.931 + 2.53 * slam;
    let a = -0.059 + 0.024_83 * b;
    let inv_alpha = 1.123_9 + 1.132_8 / (b - 3.4);
    let vr = 0.927_7 - 3.622_4 / (b - 2.0);
    loop {
        let u = uniform_f64(rng) - 0.5;
        let v = uniform_f64(rng);
        let us = 0.5 - u.abs();
        let k = floor((2.0 * a / us + b) * u + mean + 0.43);
        if us >= 0.07 && v <= vr {
            return k;
        }
        if k < 0.0 || (us < 0.013 && v > us) {
            continue;
        }
        if v > 0.0
            && ln(v) + ln(inv_alpha) - ln(a / (us * us) + b) <= -mean + k * loglam - ln_factorial(k)
        {
            return k;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ln_factorial_is_continuous_at_the_table_edge_and_exact_in_it() {
        let mut exact = 0.0f64;
        for k in 1..=30u32 {
            exact += f64::from(k).ln();
            assert!((ln_factorial(f64::from(k)) - exact).abs() < 1e-9, "k = {k}");
        }
    }
}
