//! A small deterministic generator for the simulation's randomized tests.

/// A linear congruential generator (Knuth's MMIX constants).
pub(super) struct Lcg(pub u64);

impl Lcg {
    /// The next value, uniform on `[0, 1)` (24 bits).
    pub(super) fn next(&mut self) -> f32 {
        self.0 = self
            .0
            .wrapping_mul(6_364_136_223_846_793_005)
            .wrapping_add(1_442_695_040_888_963_407);
        (self.0 >> 40) as f32 / (1u64 << 24) as f32
    }
}
