//! What a BVH holds: the primitive seam and spheres and capsules
//! ([`prim`]), triangles packed eight to a leaf item ([`tri_packet`]),
//! plain triangle meshes ([`mesh`]), instances of objects ([`instance`])
//! and a scene of every kind behind one query ([`scene`]).

#[cfg(feature = "alloc")]
pub(crate) mod instance;
#[cfg(feature = "alloc")]
pub(crate) mod mesh;
pub(crate) mod prim;
#[cfg(feature = "alloc")]
pub(crate) mod scene;
pub(crate) mod tri_packet;
