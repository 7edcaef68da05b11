//! Where a camera looks: the pinhole projection with radial distortion
//! (thesis §3.2, §4.7.2) and the pan-tilt head's kinematics, so that every
//! pixel of every frame maps to a direction in the world frame (x east,
//! y north, z up).
//!
//! Camera frame: x to the right of the image, y down, z along the optical
//! axis (forward).

mod head;
mod pinhole;

pub use head::{HeadPose, Mount, OrientedMount};
pub use pinhole::{Pinhole, Projection};
