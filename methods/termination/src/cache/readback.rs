//! The cache's buffers read back: counters, records and slots.

use super::TerminationCache;
use super::gpu_types::TcRecord;
use super::statistics::{TerminationStats, stats_of};
use render::error::RenderError;
use render::gpu::Gpu;
use render::readback::read_pod;

impl TerminationCache {
    /// The frame's counters so far (after [`Self::store`]: the insertions' and the store's too).
    pub fn read_counters(&self, gpu: &Gpu) -> Result<TerminationStats, RenderError> {
        Ok(stats_of(&read_pod::<u32>(gpu, &self.own.counters, "termination counters")?))
    }

    /// Each record's moments (slot order), for tests.
    pub fn read_records(&self, gpu: &Gpu) -> Result<Vec<TcRecord>, RenderError> {
        let all: Vec<TcRecord> = read_pod(gpu, &self.records, "termination records")?;
        Ok(all[..self.settings.capacity as usize].to_vec())
    }

    /// Slot words (checksum, claim, stored vertices, insertion claim), for tests.
    pub fn read_slots(&self, gpu: &Gpu) -> Result<Vec<[u32; 4]>, RenderError> {
        read_pod(gpu, &self.slots, "termination slots")
    }
}
