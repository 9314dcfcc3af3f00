//! Quality presets: named sets of the settings that trade speed for accuracy.
//!
//! A scene's quality is the seven settings of [`Quality`]: samples per
//! pixel, path depth, texture filtering, caustic rays, caustic light samples,
//! volume samples and denoising. A preset sets all seven at once; a scene
//! file picks one with `[image] preset = "final"`, and its own explicit keys
//! (`spp`, `max_depth`, `filter`, `denoise`, `[caustics]`, `[volume]`) then
//! override single settings. On the command line, `--preset` replaces all
//! seven (the scene file's keys included), and the individual flags
//! (`--spp`, `--filter`, `--denoise`, …) override it.
//!
//! `quadray bench` measures what each preset costs and how far its image is
//! from `reference` (results/bench/README.md).

use std::fmt;
use std::str::FromStr;

use super::Scene;

/// Texture filtering: how colour, normal and displacement maps are looked up
/// at each path vertex.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash, serde::Serialize)]
pub enum FilterMode {
    /// Bilinear lookups of mip level 0: unbiased with many samples per pixel,
    /// the reference.
    #[default]
    None,
    /// Lookups over ray-cone footprints (Akenine-Möller et al. 2021): a few
    /// trilinear probes along the footprint's major axis (EWA is the
    /// reference lookup, `filter-bench --lookup ewa`).
    RayCones,
    /// The same probes over footprints from covariance tracing, carried along
    /// the whole path (the paper's method).
    Covariance,
}

impl FilterMode {
    /// Every mode, in the order the viewer cycles through them.
    pub const ALL: [FilterMode; 3] = [FilterMode::None, FilterMode::RayCones, FilterMode::Covariance];

    /// The scene-file and command-line spelling.
    pub fn name(self) -> &'static str {
        match self {
            Self::None => "none",
            Self::RayCones => "ray-cones",
            Self::Covariance => "covariance",
        }
    }

    /// The next mode in [`FilterMode::ALL`], wrapping around.
    pub fn next(self) -> Self {
        let i = Self::ALL.iter().position(|&m| m == self).unwrap_or(0);
        Self::ALL[(i + 1) % Self::ALL.len()]
    }
}

impl fmt::Display for FilterMode {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

impl FromStr for FilterMode {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        from_name(&Self::ALL, Self::name, "filter", s)
    }
}

/// The denoiser's quality (Intel Open Image Denoise's network,
/// `crate::jobs::denoise`): speed against fidelity.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash, serde::Serialize)]
pub enum DenoiseQuality {
    /// The fastest network, for previews and the viewer.
    Fast,
    /// Between the two.
    Balanced,
    /// The best network; about 2-6x the time of `fast`.
    #[default]
    High,
}

impl DenoiseQuality {
    /// Every quality, fastest first.
    pub const ALL: [DenoiseQuality; 3] = [Self::Fast, Self::Balanced, Self::High];

    /// The scene-file and command-line spelling.
    pub fn name(self) -> &'static str {
        match self {
            Self::Fast => "fast",
            Self::Balanced => "balanced",
            Self::High => "high",
        }
    }
}

impl fmt::Display for DenoiseQuality {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

impl FromStr for DenoiseQuality {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        from_name(&Self::ALL, Self::name, "denoise quality", s)
    }
}

/// The value of `all` whose `name` is `s`, or an error that names `what`
/// and lists every name (the `FromStr` of the named settings).
pub(crate) fn from_name<T: Copy>(all: &[T], name: fn(T) -> &'static str, what: &str, s: &str) -> Result<T, String> {
    all.iter().copied().find(|&v| name(v) == s).ok_or_else(|| {
        let names: Vec<&str> = all.iter().map(|&v| name(v)).collect();
        format!("unknown {what} `{s}`; expected one of: {}", names.join(", "))
    })
}

/// The settings a preset fixes.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize)]
pub struct Quality {
    /// Samples per pixel (`[image] spp`).
    pub spp: u32,
    /// Longest path in bounces (`[image] max_depth`).
    pub max_depth: u32,
    /// Texture filtering (`[image] filter`).
    pub filter: FilterMode,
    /// Caustic rays per light and light sample; 0 leaves caustics to the
    /// path tracer (`[caustics] rays`).
    pub caustic_rays: u32,
    /// Points on each sphere light that emit caustic rays (`[caustics] light_samples`).
    pub caustic_light_samples: u32,
    /// Volume-pass camera rays per pixel and sample; 0 leaves the fog's
    /// single scattering to the path tracer (`[volume] samples`).
    pub volume_samples: u32,
    /// Denoise the finished image with Intel Open Image Denoise (`[image]
    /// denoise`; `crate::jobs::denoise`).
    pub denoise: bool,
}

/// Without a preset, a scene file's missing keys take these: 16 spp, depth
/// [`DEFAULT_MAX_DEPTH`](super::DEFAULT_MAX_DEPTH), no filtering, and the
/// `[caustics]` and `[volume]` defaults.
impl Default for Quality {
    fn default() -> Self {
        Self {
            spp: 16,
            max_depth: super::DEFAULT_MAX_DEPTH,
            filter: FilterMode::None,
            caustic_rays: super::DEFAULT_CAUSTIC_RAYS,
            caustic_light_samples: super::DEFAULT_CAUSTIC_LIGHT_SAMPLES,
            volume_samples: super::DEFAULT_VOLUME_SAMPLES,
            denoise: false,
        }
    }
}

/// A named [`Quality`].
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, serde::Serialize)]
pub enum Preset {
    /// A first look in about a second: 1 spp, 3 bounces (the fewest that
    /// still show caustics), prefiltered textures, few caustic rays,
    /// denoised.
    Preview,
    /// The viewer's default: 4 spp per refresh, 4 bounces, denoised.
    Interactive,
    /// An image to keep: 64 spp, 8 bounces, 256k caustic rays from 8 points
    /// of each sphere light; not denoised unless asked (`--denoise`).
    Final,
    /// The ground truth the others are measured against: 1024 spp, 16
    /// bounces, no prefiltering, and no caustic or volume pass (the path
    /// tracer alone, by brute force).
    Reference,
}

impl Preset {
    /// Every preset, fastest first.
    pub const ALL: [Preset; 4] = [Preset::Preview, Preset::Interactive, Preset::Final, Preset::Reference];

    /// The settings of this preset.
    pub fn quality(self) -> Quality {
        match self {
            Self::Preview => Quality {
                spp: 1,
                max_depth: 3,
                filter: FilterMode::Covariance,
                caustic_rays: 16_384,
                caustic_light_samples: 1,
                volume_samples: 1,
                denoise: true,
            },
            Self::Interactive => Quality {
                spp: 4,
                max_depth: 4,
                filter: FilterMode::Covariance,
                caustic_rays: 65_536,
                caustic_light_samples: 4,
                volume_samples: 1,
                denoise: true,
            },
            Self::Final => Quality {
                spp: 64,
                max_depth: 8,
                filter: FilterMode::Covariance,
                caustic_rays: 262_144,
                caustic_light_samples: 8,
                volume_samples: 2,
                denoise: false,
            },
            Self::Reference => Quality {
                spp: 1024,
                max_depth: 16,
                filter: FilterMode::None,
                caustic_rays: 0,
                caustic_light_samples: 1,
                volume_samples: 0,
                denoise: false,
            },
        }
    }

    /// The scene-file and command-line spelling.
    pub fn name(self) -> &'static str {
        match self {
            Self::Preview => "preview",
            Self::Interactive => "interactive",
            Self::Final => "final",
            Self::Reference => "reference",
        }
    }

    /// The next preset in [`Preset::ALL`], wrapping around.
    pub fn next(self) -> Self {
        let i = Self::ALL.iter().position(|&p| p == self).unwrap_or(0);
        Self::ALL[(i + 1) % Self::ALL.len()]
    }
}

impl fmt::Display for Preset {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

impl FromStr for Preset {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        from_name(&Self::ALL, Self::name, "preset", s)
    }
}

impl Scene {
    /// The scene's current quality settings.
    pub fn quality(&self) -> Quality {
        Quality {
            spp: self.image.spp,
            max_depth: self.image.max_depth,
            filter: self.image.filter,
            caustic_rays: self.caustics.rays,
            caustic_light_samples: self.caustics.light_samples,
            volume_samples: self.volume.samples,
            denoise: self.image.denoise,
        }
    }

    /// Replaces all quality settings with `q`.
    pub fn set_quality(&mut self, q: Quality) {
        self.image.spp = q.spp;
        self.image.max_depth = q.max_depth;
        self.image.filter = q.filter;
        self.caustics.rays = q.caustic_rays;
        self.caustics.light_samples = q.caustic_light_samples;
        self.volume.samples = q.volume_samples;
        self.image.denoise = q.denoise;
    }

    /// Replaces all quality settings with those of `preset`, and records it.
    pub fn apply_preset(&mut self, preset: Preset) {
        self.set_quality(preset.quality());
        self.image.preset = Some(preset);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_round_trip() {
        for p in Preset::ALL {
            assert_eq!(p.name().parse::<Preset>().unwrap(), p);
        }
        for m in FilterMode::ALL {
            assert_eq!(m.name().parse::<FilterMode>().unwrap(), m);
        }
        assert!("fast".parse::<Preset>().unwrap_err().contains("preview, interactive"));
        for q in DenoiseQuality::ALL {
            assert_eq!(q.name().parse::<DenoiseQuality>(), Ok(q));
        }
        assert!("best".parse::<DenoiseQuality>().unwrap_err().contains("fast, balanced, high"));
    }

    #[test]
    fn presets_get_dearer_in_every_setting() {
        for w in Preset::ALL.windows(2) {
            let (a, b) = (w[0].quality(), w[1].quality());
            assert!(a.spp < b.spp && a.max_depth < b.max_depth, "{:?} vs {:?}", w[0], w[1]);
        }
        // Only the reference is brute force.
        for p in Preset::ALL {
            let q = p.quality();
            assert_eq!(p == Preset::Reference, q.caustic_rays == 0 && q.volume_samples == 0);
            assert_eq!(p == Preset::Reference, q.filter == FilterMode::None);
            // The quick presets denoise; an image to keep or compare does not.
            assert_eq!(q.denoise, matches!(p, Preset::Preview | Preset::Interactive));
        }
    }

    #[test]
    fn cycling_visits_every_value() {
        let mut p = Preset::Preview;
        let mut seen = vec![p];
        for _ in 1..Preset::ALL.len() {
            p = p.next();
            seen.push(p);
        }
        assert_eq!(seen, Preset::ALL);
        assert_eq!(p.next(), Preset::Preview);
        assert_eq!(FilterMode::Covariance.next(), FilterMode::None);
    }
}
