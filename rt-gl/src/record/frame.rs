//! One frame's draws, as the recorder hands them to the renderer.

use std::sync::Arc;

use glam::Mat4;

use super::{Geometry, GeometryError, Lighting, Recorded};

/// One frame's draws: immediate geometry in eye space and instances of
/// cached display lists.
#[derive(Clone, Debug, Default)]
pub struct FrameDraws {
    /// Immediate-mode geometry, eye space.
    pub immediate: Geometry,
    /// Cached list geometry and the modelview of each call.
    pub instances: Vec<(Arc<Recorded>, Mat4)>,
    /// The lights in force at the frame's last lit draw (`None`: nothing
    /// lit was drawn): a program may turn its lights off after its 3-D
    /// pass, before the swap, as GL only applies them per draw.
    pub lighting: Option<Lighting>,
}

impl FrameDraws {
    /// Whether nothing was drawn.
    #[must_use]
    pub fn is_empty(&self) -> bool {
        self.immediate.is_empty() && self.instances.iter().all(|(r, _)| r.geometry().is_empty())
    }

    /// Everything in eye space, in one piece.
    ///
    /// # Errors
    /// What [`Geometry::check`] finds in the immediate geometry or in a
    /// recording's.
    pub fn flatten(&self) -> Result<Geometry, GeometryError> {
        self.immediate.check()?;
        let mut g = self.immediate.clone();
        for (inst, m) in &self.instances {
            inst.geometry().check()?;
            g.append_checked(inst.geometry(), m);
        }
        Ok(g)
    }
}
