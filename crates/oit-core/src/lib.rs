//! oit-core: order-independent transparency methods on wgpu, with an exact A-buffer and a
//! CPU float64 reference to measure them against. No Python, no windowing.

pub mod antialias;
pub mod bindings;
pub mod cache;
mod camera;
pub mod consts;
pub mod context;
pub mod error;
pub mod gpu_types;
pub mod load;
mod mesh;
pub mod method;
mod passes;
mod pipeline;
pub mod primitive;
pub mod reference;
pub mod renderer;
pub mod resources;
mod scan;
pub mod scene;
pub mod scenefile;
pub mod shader;
pub mod shading;
pub mod splat;
pub mod stats;
mod targets;
pub mod tiles;
mod timer;
mod upload;

pub use context::GpuContext;
pub use error::{OitError, Result};
pub use method::{
    memory_bytes, methods, AntialiasMode, ErrorBound, Memory, MethodInfo, Order, ParamInfo, ParamKind, ParamValue, Params, Tiling,
};
pub use primitive::Primitive;
pub use reference::{reference, reference_antialiased, ReferenceImage};
pub use renderer::{coverage_methods, shared_context, Antialias, Frame, Renderer, Target, COVERAGE_SAMPLES};
pub use scene::{Camera, Instance, Mesh, Scene};
pub use shading::{Falloff, Filter, Light, Material, Sampler, Shading, SplatDepth, Texture, TextureMap, Wrap, MAX_LIGHTS};
pub use stats::Stats;
