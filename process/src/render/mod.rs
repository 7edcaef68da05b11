//! The renderer: path tracing over triangle scenes with sun, sky, lamps and
//! interreflection. The simulator photographs its worlds with it and the
//! relighting stage renders novel times with it; solvers do not use it.
//!
//! - [`mesh`]: rays and triangles; [`accel`]: the bounding volume hierarchy.
//! - [`texture`], [`material`], [`surface_bsdf`]: what surfaces are made of.
//! - [`light`], [`sky`]: what lights them.
//! - [`camera`]: rays from the station's camera on its head.
//! - [`integrator`]: the light transport.

pub mod accel;
pub mod camera;
pub mod integrator;
pub mod light;
pub mod material;
pub mod mesh;
pub mod scene;
pub mod shapes;
pub mod sky;
pub mod surface_bsdf;
pub mod texture;

pub use camera::CameraRig;
pub use integrator::{DEFAULT_SPLIT_RAYS, Lighting, RenderSettings, irradiance, render, render_latlong, trace};
pub use light::{PointLight, SphereLight};
pub use material::Material;
pub use mesh::{Ray, Triangle};
pub use scene::{Scene, SceneError, SurfaceHit};
pub use sky::{Sky, SolarDisc, UniformSky};
pub use texture::{TexelImage, Texture};
