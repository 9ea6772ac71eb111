//! The path tracer.
