//! The handle every part of the renderer names a character by.

/// A character handle (slot + generation, so a stale handle is refused).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct CharacterId {
    slot: u32,
    generation: u32,
}

impl CharacterId {
    /// The handle of `slot` at its `generation` (the crowd makes them).
    pub(crate) fn new(slot: u32, generation: u32) -> Self {
        CharacterId { slot, generation }
    }

    /// The character's slot (its index in the character table and texture arrays).
    pub fn slot(&self) -> u32 {
        self.slot
    }

    /// How many characters held the slot before this one.
    pub(crate) fn generation(&self) -> u32 {
        self.generation
    }

    /// The id of slot `slot`, generation 0 (unit tests of the tables keyed by it).
    #[cfg(test)]
    pub(crate) fn test_id(slot: u32) -> Self {
        CharacterId {
            slot,
            generation: 0,
        }
    }
}
