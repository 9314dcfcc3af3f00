//! Every specialisation constant of the render pass, gathered in one place
//! from the scene, the render variant and the passes that run, so that
//! the scene model knows nothing of GPU constants and the render pass's
//! kernels (megakernel or wavefront) take one list.

use super::caustics::CausticMap;
use super::scene_gpu::GpuScene;
use super::RenderVariant;
use crate::gpu::shader_interface::{
    FILTER_COVARIANCE, FILTER_NONE, FILTER_RAY_CONES, SPEC_BEAMS_ENABLED, SPEC_CAUSTICS_ENABLED, SPEC_FILTER_MODE,
    SPEC_INTERSECT_MODE, SPEC_LOOKUP_MODE, SPEC_MEDIA_ENABLED, SPEC_RECORD_PATH, SPEC_SAMPLER, SPEC_SHADING_MODE,
    SPEC_VOLUME_ENABLED,
};
use crate::model::scene::{FilterMode, Scene};

/// The render shader's `FILTER_*` value for a filtering mode.
pub fn filter_constant(mode: FilterMode) -> u32 {
    match mode {
        FilterMode::None => FILTER_NONE,
        FilterMode::RayCones => FILTER_RAY_CONES,
        FilterMode::Covariance => FILTER_COVARIANCE,
    }
}

/// The render pass's specialisation: what the scene holds, what the
/// variant switches and which passes ran before it.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct RenderConfig {
    /// `SPEC_INTERSECT_MODE`: the variant's mode, or the base quadrics'
    /// roots where the scene has no perturbations.
    pub intersect: u32,
    /// `SPEC_LOOP_BUDGET` and `SPEC_FAR_RAYS`, from the uploaded scene.
    pub scene: [(u32, u32); 2],
    /// `SPEC_SHADING_MODE`.
    pub shading: u32,
    /// `SPEC_FILTER_MODE`: the scene's filtering mode.
    pub filter: u32,
    /// `SPEC_MEDIA_ENABLED`: the scene has fog or a dielectric's interior.
    pub media: bool,
    /// `SPEC_CAUSTICS_ENABLED`, `SPEC_BEAMS_ENABLED`: the caustic pass ran,
    /// and made beams in the fog.
    pub caustics: bool,
    pub beams: bool,
    /// `SPEC_VOLUME_ENABLED`: the volume pass ran.
    pub volume: bool,
    /// `SPEC_RECORD_PATH`, `SPEC_LOOKUP_MODE`, `SPEC_SAMPLER`: the variant's.
    pub record_path: bool,
    pub lookup: u32,
    pub sampler: u32,
}

impl RenderConfig {
    /// The specialisation for `scene` (uploaded as `gpu`) rendered with
    /// `variant`, after the caustic pass (`caustics`, when it ran) and the
    /// volume pass (when `volume`).
    pub fn new(
        gpu: &GpuScene,
        scene: &Scene,
        variant: RenderVariant,
        caustics: Option<&CausticMap>,
        volume: bool,
    ) -> Self {
        Self {
            intersect: gpu.intersect_mode(variant.intersect).constant(),
            scene: gpu.scene_constants(),
            shading: variant.shading.constant(),
            filter: filter_constant(scene.image.filter),
            media: scene.has_media(),
            caustics: caustics.is_some(),
            beams: caustics.is_some_and(|c| c.has_beams),
            volume,
            record_path: variant.record_path,
            lookup: variant.lookup.constant(),
            sampler: variant.sampler.constant(),
        }
    }

    /// The constants by id, as pipelines take them.
    pub fn constants(&self) -> Vec<(u32, u32)> {
        let [budget, far] = self.scene;
        vec![
            (SPEC_INTERSECT_MODE, self.intersect),
            budget,
            far,
            (SPEC_SHADING_MODE, self.shading),
            (SPEC_FILTER_MODE, self.filter),
            (SPEC_MEDIA_ENABLED, u32::from(self.media)),
            (SPEC_CAUSTICS_ENABLED, u32::from(self.caustics)),
            (SPEC_VOLUME_ENABLED, u32::from(self.volume)),
            (SPEC_BEAMS_ENABLED, u32::from(self.beams)),
            (SPEC_RECORD_PATH, u32::from(self.record_path)),
            (SPEC_LOOKUP_MODE, self.lookup),
            (SPEC_SAMPLER, self.sampler),
        ]
    }
}
