//! Small deterministic random numbers and hashes, identical on the CPU and in GLSL.

/// PCG32 generator (O'Neill 2014) for reproducible bakes and tests.
#[derive(Clone, Debug)]
pub struct Pcg32 {
    state: u64,
}

impl Pcg32 {
    /// A generator seeded with `seed`.
    pub fn new(seed: u64) -> Self {
        let mut r = Pcg32 { state: 0 };
        r.next_u32();
        r.state = r.state.wrapping_add(seed);
        r.next_u32();
        r
    }

    /// A generator seeded with `key` scrambled by SplitMix64's finaliser, so that keys that
    /// differ in a few low bits (consecutive seeds) give independent first draws.
    pub fn hashed(key: u64) -> Self {
        let mut z = key.wrapping_add(0x9E37_79B9_7F4A_7C15);
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        Pcg32::new(z ^ (z >> 31))
    }

    /// Next 32 random bits.
    pub fn next_u32(&mut self) -> u32 {
        let old = self.state;
        self.state = old
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        let xorshifted = (((old >> 18) ^ old) >> 27) as u32;
        let rot = (old >> 59) as u32;
        xorshifted.rotate_right(rot)
    }

    /// Uniform in `[0, 1)` with 24 bits.
    pub fn next_f32(&mut self) -> f32 {
        (self.next_u32() >> 8) as f32 * (1.0 / 16_777_216.0)
    }
}

/// Integer hash (PCG output permutation); `hash_u32` in `glsl/common.glsl` is the same function.
pub fn hash_u32(x: u32) -> u32 {
    let state = x.wrapping_mul(747796405).wrapping_add(2891336453);
    let word = ((state >> ((state >> 28).wrapping_add(4))) ^ state).wrapping_mul(277803737);
    (word >> 22) ^ word
}

/// Hash to `[0, 1)` with 24 bits; exact in both f32 on the CPU and `float` in GLSL.
pub fn hash_f32(x: u32) -> f32 {
    (hash_u32(x) >> 8) as f32 * (1.0 / 16_777_216.0)
}
