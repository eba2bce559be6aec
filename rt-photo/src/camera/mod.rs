//! The camera of BOS and focusing schlieren: a thin lens and its sensor
//! (exposure, noise, bit depth), the lens's diffraction, and the camera of
//! a laboratory rig.

mod airy;
pub(crate) mod lab;
mod sensor;
mod sensor_error;
mod thin_lens;

pub use airy::{Airy, AiryKernel};
pub use sensor::Sensor;
pub use sensor_error::SensorError;
pub(crate) use thin_lens::Basis;
pub use thin_lens::{CameraError, ThinLens};
