//! The camera of a laboratory rig: a sensor of a fixed physical size
//! (2048 pixels of 5.5 µm, 11.3 mm across; a smaller image is that sensor
//! binned, so its pixels are larger and the field of view stays), a lens
//! from the usual range of focal lengths, about 1.5 m from the flow.

/// Pixels across the default sensor, and their pitch (metres).
pub(crate) const SENSOR_PIXELS: usize = 2048;
pub(crate) const SENSOR_PITCH: f64 = 5.5e-6;
/// The usual prime lenses (metres).
pub(crate) const FOCAL_LENGTHS: [f64; 9] = [0.024, 0.035, 0.05, 0.085, 0.105, 0.135, 0.2, 0.3, 0.4];
/// The camera distance a default lens is picked for (metres).
pub(crate) const LAB_DISTANCE: f64 = 1.5;
/// The field of view spans the flow's width and this margin.
pub(crate) const MARGIN: f64 = 1.05;

/// The camera for a flow `width` across on `pixels` pixels: `(pixel
/// pitch, focal length, distance to the flow)`, each as fixed or chosen:
/// the default sensor binned to `pixels`; the usual lens that fills the
/// view with the flow nearest [`LAB_DISTANCE`] (with the distance fixed,
/// the focal length that fills it there); the distance that fills the
/// view (thin lens, `Z = f·(1 + 1/M)`).
pub(crate) fn lab_camera(
    width: f64,
    pixels: usize,
    pitch: Option<f64>,
    focal_length: Option<f64>,
    distance: Option<f64>,
) -> (f64, f64, f64) {
    let pitch = pitch.unwrap_or(SENSOR_PITCH * SENSOR_PIXELS as f64 / pixels as f64);
    // The object-to-sensor ratio that fills the view: Z = f·(1 + ratio).
    let ratio = MARGIN * width / (pitch * pixels as f64);
    let f = match (focal_length, distance) {
        (Some(f), _) => f,
        (None, Some(z)) => z / (1.0 + ratio),
        (None, None) => {
            let miss = |f: f64| crate::math::ln(f * (1.0 + ratio) / LAB_DISTANCE).abs();
            FOCAL_LENGTHS.into_iter().min_by(|a, b| miss(*a).total_cmp(&miss(*b))).unwrap_or(0.1)
        }
    };
    (pitch, f, distance.unwrap_or(f * (1.0 + ratio)))
}
