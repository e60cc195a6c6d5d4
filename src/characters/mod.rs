//! Characters for crowds: a procedural head-and-body figure ([`head`]), the hairstyle
//! generator ([`hairstyle`]) and scene presets ([`preset`]) that give every character its own
//! hair mesh, style and placement.

pub mod hairstyle;
pub mod head;
pub mod preset;
pub mod teapot;
