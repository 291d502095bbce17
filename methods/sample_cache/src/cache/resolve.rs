//! TAA's resolve over the cache's image.

use super::SampleCache;
use render::error::RenderError;
use render::gpu::Gpu;

impl SampleCache {
    /// TAA's resolve (`taa`, its own submission) over the last frame's image, with each pixel's
    /// closest visible sample's primary attributes (reconstruct.wgsl) for its reprojection and
    /// history rejection: the paper applies TAA to every method for its error figures. The
    /// resolve reads no jitter: the cache's samples lie anywhere in their pixels.
    pub fn resolve_taa(
        &self,
        gpu: &Gpu,
        taa: &mut taa::Taa,
    ) -> Result<taa::TaaOutput, RenderError> {
        let (colour, primary) = (&self.colour, &self.primary);
        taa.resolve_external(gpu, [0.5; 2], |encoder, current, taa_primary| {
            encoder.copy_buffer_to_buffer(colour, 0, current, 0, colour.size());
            encoder.copy_buffer_to_buffer(primary, 0, taa_primary, 0, primary.size());
        })
    }
}
