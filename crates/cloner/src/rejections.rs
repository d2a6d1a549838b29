//! The rejection counters of a clone run (in their own module: the error type
//! reports them and the pipeline counts them).

use serde::{Deserialize, Serialize};

/// Why candidates were rejected (counts).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
pub struct Rejections {
    /// The target draw failed (a conditional slice without mass).
    pub target_unavailable: u64,
    /// The raw candidate was already rounder than its target.
    pub too_round: u64,
    /// Polishing did not reach the target within `max_iterations`.
    pub roundness_unreached: u64,
    /// A degenerate surface or level set.
    pub degenerate: u64,
    /// The V/S quality control.
    pub quality_control: u64,
    /// The roundness measured on the level set missed its target by more
    /// than `roundness_tolerance`.
    pub measured_roundness: u64,
    /// The roundness predicted from the surface missed its target by more
    /// than `roundness_tolerance` (`RoundnessCheck::Predicted`).
    #[serde(default)]
    pub predicted_roundness: u64,
}

impl Rejections {
    /// All rejections.
    pub fn total(&self) -> u64 {
        self.target_unavailable
            + self.too_round
            + self.roundness_unreached
            + self.degenerate
            + self.quality_control
            + self.measured_roundness
            + self.predicted_roundness
    }
}
