//! The settings of the PUMA 560 study ([`run`](super::run), [`crate::puma_study`]): its seeds.

/// Settings of [`run`](super::run).
#[derive(Clone, Debug)]
pub struct PumaSettings {
    /// Seed of the measurement noise (identification data; the held-out data use seed + 1).
    pub seed: u64,
    /// Seed of the pose grid's orientations and of the held-out poses.
    pub pose_seed: u64,
}

impl Default for PumaSettings {
    fn default() -> Self {
        PumaSettings {
            seed: 1,
            pose_seed: 6,
        }
    }
}
