//! Lights and renderer settings.

use alloc::vec::Vec;
use core::fmt;

use glam::Vec3;

/// A light.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Light {
    /// Light from every direction: `albedo · color`, darkened by ambient
    /// occlusion when it is on.
    Ambient {
        /// Linear RGB.
        color: [f32; 3],
    },
    /// A light at infinity.
    Directional {
        /// Direction *toward* the light (any length).
        direction: Vec3,
        /// Irradiance on a surface facing it, linear RGB.
        color: [f32; 3],
    },
    /// A point light; irradiance falls off as `1/d²`.
    Point {
        /// Where it is.
        position: Vec3,
        /// Irradiance at unit distance, linear RGB.
        color: [f32; 3],
    },
}

/// Renderer settings.
#[derive(Clone, Debug, PartialEq)]
pub struct Settings {
    /// The lights (none: only emission-free black, so add at least one).
    pub lights: Vec<Light>,
    /// Hard shadows from directional and point lights.
    pub shadows: bool,
    /// Ambient-occlusion rays per hit (0: off), cosine-weighted about the
    /// normal; occlusion counts only within `ao_distance`.
    pub ao_samples: u32,
    /// Longest AO ray.
    pub ao_distance: f32,
    /// Most mirror bounces; a mirror beyond them shows its local shading.
    pub max_bounces: u32,
    /// Most translucent layers a ray passes through.
    pub max_layers: u32,
    /// Linear RGB that reflected rays see where they miss everything.
    pub environment: [f32; 3],
    /// Seed of every random choice (pixel jitter, AO directions).
    pub seed: u64,
}

impl Default for Settings {
    fn default() -> Self {
        Self {
            lights: alloc::vec![
                Light::Ambient { color: [0.25; 3] },
                Light::Directional { direction: Vec3::new(-0.5, 1.0, 0.35), color: [0.8; 3] },
            ],
            shadows: true,
            ao_samples: 0,
            ao_distance: 1.0,
            max_bounces: 2,
            max_layers: 16,
            environment: [0.0; 3],
            seed: 0,
        }
    }
}

impl Settings {
    /// Most AO samples per hit.
    pub const MAX_AO_SAMPLES: u32 = 4096;
    /// Most mirror bounces.
    pub const MAX_BOUNCES: u32 = 64;
    /// Most translucent layers.
    pub const MAX_LAYERS: u32 = 1024;

    /// Checks every setting is in range.
    ///
    /// # Errors
    /// The first bad setting, as a [`SettingsError`].
    pub fn validate(&self) -> Result<(), SettingsError> {
        let rgb = |c: &[f32; 3]| c.iter().all(|v| v.is_finite() && *v >= 0.0);
        for (index, l) in self.lights.iter().enumerate() {
            let ok = match l {
                Light::Ambient { color } => rgb(color),
                Light::Directional { direction, color } => {
                    rgb(color) && direction.is_finite() && *direction != Vec3::ZERO
                }
                Light::Point { position, color } => rgb(color) && position.is_finite(),
            };
            if !ok {
                return Err(SettingsError::Light { index });
            }
        }
        if self.ao_samples > Self::MAX_AO_SAMPLES {
            return Err(SettingsError::AoSamples);
        }
        if self.ao_samples > 0 && !(self.ao_distance.is_finite() && self.ao_distance > 0.0) {
            return Err(SettingsError::AoDistance);
        }
        if self.max_bounces > Self::MAX_BOUNCES {
            return Err(SettingsError::MaxBounces);
        }
        if self.max_layers > Self::MAX_LAYERS {
            return Err(SettingsError::MaxLayers);
        }
        if !rgb(&self.environment) {
            return Err(SettingsError::Environment);
        }
        Ok(())
    }
}

/// Which renderer setting is out of range.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SettingsError {
    /// A light's colour is negative or not finite, or its position or
    /// direction is not finite (a directional light's direction is zero).
    Light {
        /// Its index in [`Settings::lights`].
        index: usize,
    },
    /// `ao_samples` above [`Settings::MAX_AO_SAMPLES`].
    AoSamples,
    /// `ao_distance` not finite and positive while AO is on.
    AoDistance,
    /// `max_bounces` above [`Settings::MAX_BOUNCES`].
    MaxBounces,
    /// `max_layers` above [`Settings::MAX_LAYERS`].
    MaxLayers,
    /// The environment colour is negative or not finite.
    Environment,
}

impl fmt::Display for SettingsError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::Light { index } => write!(
                f,
                "light {index}: colour must be finite and ≥ 0, position/direction finite (direction non-zero)"
            ),
            Self::AoSamples => {
                write!(
                    f,
                    "ao_samples above Settings::MAX_AO_SAMPLES ({})",
                    Settings::MAX_AO_SAMPLES
                )
            }
            Self::AoDistance => f.write_str("ao_distance must be finite and > 0"),
            Self::MaxBounces => {
                write!(f, "max_bounces above Settings::MAX_BOUNCES ({})", Settings::MAX_BOUNCES)
            }
            Self::MaxLayers => {
                write!(f, "max_layers above Settings::MAX_LAYERS ({})", Settings::MAX_LAYERS)
            }
            Self::Environment => f.write_str("environment colour must be finite and ≥ 0"),
        }
    }
}

impl core::error::Error for SettingsError {}
