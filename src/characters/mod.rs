//! Characters for crowds: people ([`person`]: the human head of [`human`] on a mannequin
//! body, with [`eyes`] that read as eyes), furry balls ([`head`]) and teapots ([`teapot`]), the hairstyle generator
//! ([`hairstyle`]) and scene presets ([`preset`]) that give every character its own hair
//! mesh, style and placement; [`any_head`] grows the same hairstyles on a user's head;
//! [`scalp`] draws a hairstyle's scalp and measures how much of it shows through the hair.

pub mod any_head;
pub mod eyes;
pub mod far_mesh;
pub mod hairstyle;
pub mod head;
pub mod human;
pub mod own;
pub mod people;
pub mod person;
pub mod preset;
pub mod scalp;
pub mod teapot;
