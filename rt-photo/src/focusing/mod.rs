//! Focusing schlieren (lens and grid): an image sharp in one plane of the
//! flow, and the rig it is set up as, chosen for the flow.

mod render;
mod rig;

pub use render::{FocusingError, FocusingImages, FocusingSchlieren, SourceGrid};
pub use rig::{FocusingRig, FocusingRigOptions};
