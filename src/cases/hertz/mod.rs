//! Hertz validation: a cylinder (2D) and a ball (3D) pressed onto the rigid plane, and the
//! low-velocity impact of a ball, against Hertz's closed forms.

pub mod closed_form;
pub mod impact;
pub mod meshes;
pub mod profile;
pub mod statics;
