//! Texel values as the GPU decodes them (UNORM16 and SNORM16), for the CPU twins that read
//! the baked textures.

/// A UNORM16 texel value as the GPU decodes it.
pub(crate) fn unorm(x: u16) -> f32 {
    x as f32 / 65535.0
}

/// A SNORM16 texel value as the GPU decodes it.
pub(crate) fn snorm(x: i16) -> f32 {
    (x as f32 / 32767.0).max(-1.0)
}
