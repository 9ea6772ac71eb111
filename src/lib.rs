//! # lapidary
//!
//! A physically based renderer for procedurally textured, aventurescent gemstones, built on the
//! layered BRDF model of Weidlich & Wilkie (SIGGRAPH Asia 2009 course "Exploring the Potential of
//! Layered BRDF Models"). This crate holds the reflection models ([`bsdf`]), the colour type
//! ([`color`]), deterministic random numbers ([`sampler`]), procedural solid textures and the map
//! tree that picks a material per point ([`texture`]), rays, shapes and shading frames
//! ([`geometry`]), the recipe description format ([`recipe`]) and the runtime data it compiles into
//! ([`scene`]), light sources ([`light`]), the path tracer ([`render`]), EXR and PNG files
//! ([`image`]), and the command-line front end ([`cli`]).
//!
//! A coated Lambertian, evaluated by the default (Corrected) model:
//!
//! ```
//! use lapidary::bsdf::{Base, Bxdf, Coat, LayeredBsdf, StackDesc};
//! use lapidary::color::Rgb;
//! use glam::Vec3;
//!
//! let coat = Coat { ior: 1.5, roughness: 5.0, absorption: Rgb::ZERO, thickness: 0.0 };
//! let stack = LayeredBsdf::new(&StackDesc::new(vec![coat], Base::Lambert { albedo: Rgb::ONE }))?;
//! let wo = Vec3::new(0.3, 0.0, 0.954).normalize();
//! let f = stack.eval(wo, Vec3::Z);
//! assert!(f.is_valid() && f[0] > 0.0);
//! // Sampling returns the path weight f·cos/pdf directly.
//! let s = stack.sample(wo, 0.7, glam::Vec2::new(0.2, 0.4)).expect("a direction");
//! assert!((s.weight[0] - s.f[0] * s.wi.z / s.pdf).abs() < 1e-5);
//! # Ok::<(), lapidary::bsdf::StackError>(())
//! ```

#![forbid(unsafe_code)]
#![warn(missing_docs)]
// `!(x > 0.0)` is how this crate rejects NaN together with non-positive values, on purpose.
#![allow(clippy::neg_cmp_op_on_partial_ord)]

pub mod bsdf;
pub mod cli;
pub mod color;
pub mod cut;
pub mod geometry;
pub mod image;
pub mod light;
pub mod medium;
pub mod platelet;
pub mod polarisation;
pub mod recipe;
pub mod render;
pub mod sampler;
pub mod scene;
pub mod spectrum;
pub mod texture;
