//! Background-oriented schlieren: a camera looks through the flow at a
//! background (random dots, a dot grid or an image); the rig it is set up
//! as, chosen for the flow.

mod background;
#[cfg(feature = "png")]
mod png_image;
mod render;
mod rig;

pub use background::{Background, BackgroundChoice, DotBackground, DotGrid, ImageBackground};
#[cfg(feature = "png")]
pub use png_image::PngError;
pub use render::{Bos, BosError, BosImages};
pub use rig::{BosRig, BosRigOptions};
