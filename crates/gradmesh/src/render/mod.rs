//! Rendering the limit surface to pixels.
