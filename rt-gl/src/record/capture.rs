//! Recording a draw once in the entry space of the modelview at its call,
//! and instancing the recording: what the list and buffer-draw caches share.

use std::sync::Arc;

use glam::{Mat3, Mat4, Vec3, Vec4};

use super::{Geometry, Instance, Paint, Recorded, Recorder, Shading};

/// The inherited state a cached list's geometry depends on.
#[derive(Clone, Debug, PartialEq)]
pub(super) struct Inherited {
    pub(super) color: Vec4,
    pub(super) normal: Vec3,
    pub(super) shading: Shading,
    /// Clockwise front faces (`glFrontFace(GL_CW)`).
    pub(super) front_cw: bool,
    /// Colour written (`glColorMask`).
    pub(super) color_write: bool,
    /// Definitions seen (lists that call others).
    generation: u64,
}

pub(super) struct Capture {
    pub(super) geometry: Geometry,
    /// Eye space to the list's entry space.
    pub(super) to_local: Mat4,
    /// Eye-space normals to entry space.
    pub(super) normal_to_local: Mat3,
    /// Vertices recorded before the first `glColor` of the capture.
    pub(super) color_from: Option<usize>,
}

impl Recorder {
    /// The state a cached draw inherits; `generation`: the list
    /// definitions it depends on (0: none).
    pub(super) fn inherited(&self, generation: u64) -> Inherited {
        Inherited {
            color: self.color,
            normal: self.normal,
            shading: self.shading(),
            front_cw: self.front_cw,
            color_write: self.color_write,
            generation,
        }
    }

    /// Runs `f` with its geometry recorded in the entry space of the
    /// modelview `mv` (`to_local` its inverse).
    pub(super) fn captured(
        &mut self,
        mv: Mat4,
        to_local: Mat4,
        f: impl FnOnce(&mut Self),
    ) -> (Arc<Recorded>, u32) {
        let (g, inherit) = self.capture_painted(mv, to_local, f);
        (Arc::new(Recorded::new(g)), inherit)
    }

    /// The geometry `f` draws, in the entry space of the modelview `mv`
    /// (`to_local` its inverse).
    pub(super) fn capture_geometry(
        &mut self,
        mv: Mat4,
        to_local: Mat4,
        f: impl FnOnce(&mut Self),
    ) -> Geometry {
        self.capture_painted(mv, to_local, f).0
    }

    /// [`Recorder::capture_geometry`] and how many of its first vertices
    /// took the caller's colour.
    fn capture_painted(
        &mut self,
        mv: Mat4,
        to_local: Mat4,
        f: impl FnOnce(&mut Self),
    ) -> (Geometry, u32) {
        self.capture = Some(Capture {
            geometry: Geometry::default(),
            to_local,
            normal_to_local: Mat3::from_mat4(mv).transpose(),
            color_from: None,
        });
        f(self);
        let (g, from) = self.capture.take().map(|c| (c.geometry, c.color_from)).unwrap_or_default();
        let inherit = from.unwrap_or(g.positions.len());
        (g, u32::try_from(inherit).unwrap_or(u32::MAX))
    }

    /// The paint of a call made now whose recording's first `vertices`
    /// take the caller's colour.
    pub(super) fn paint(&self, vertices: u32) -> Paint {
        Paint { shading: self.shading(), color: self.color, vertices }
    }

    /// Adds an instance of cached geometry to the frame.
    pub(super) fn instance(&mut self, recorded: Arc<Recorded>, mv: Mat4, paint: Option<Paint>) {
        if !recorded.geometry().is_empty() && self.state_only == 0 && self.color_write {
            let shadings = recorded.geometry().shadings.iter();
            let (lit, fogged) = match &paint {
                Some(p) => (p.shading.lit, p.shading.fog),
                None => shadings.fold((false, false), |(l, f), s| (l || s.lit, f || s.fog)),
            };
            let inst = Instance { recorded, transform: mv, paint };
            self.draws(lit, fogged).instances.push(inst);
        }
    }

    /// The modelview's inverse, if it has a finite one.
    pub(super) fn to_local(mv: &Mat4) -> Option<Mat4> {
        (mv.determinant() != 0.0).then(|| mv.inverse()).filter(|m| m.is_finite())
    }
}
