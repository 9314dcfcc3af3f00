//! Denoising with Intel Open Image Denoise (OIDN 2, Apache-2.0), loaded at
//! run time so that the renderer builds and runs without it.
//!
//! OIDN's `RT` filter is a neural network trained on path-traced images
//! (Áfra, "Intel Open Image Denoise", 2019-2024); it takes the noisy HDR
//! radiance and, where given, the albedo and normal images of the first
//! non-specular vertex (the render pass accumulates them over the samples:
//! `GpuAov::denoise_albedo`, `denoise_normal`). Its result is biased: it
//! does not converge to the reference as samples are added the way a raw
//! render does (`quadray bench` measures both; results/bench/README.md).
//!
//! The library is found, in this order, at `$QUADRAY_OIDN_LIB` (a path to
//! `libOpenImageDenoise.so.2`; when set, nothing else is tried), in
//! `third_party/oidn/lib/` of the source tree this binary was built from
//! (where `make setup` puts the official 2.5.1 build from the `pyoidn`
//! wheel), and then by the system's library search path. Only the CPU device
//! is used: its four files are all `make setup` installs.

use std::ffi::{c_char, c_int, c_void, CStr};
use std::path::PathBuf;

pub use crate::model::scene::DenoiseQuality;

/// The environment variable that names the library's path.
pub const LIBRARY_ENV: &str = "QUADRAY_OIDN_LIB";

/// Where `make setup` installs the library, in the source tree the binary
/// was built from.
pub const BUNDLED_LIBRARY: &str =
    concat!(env!("CARGO_MANIFEST_DIR"), "/third_party/oidn/lib/libOpenImageDenoise.so.2.5.1");

/// The library's name on the system search path.
const SYSTEM_LIBRARY: &str = "libOpenImageDenoise.so.2";

/// How to get the library, for the error that says it is missing.
pub const HOW_TO_INSTALL: &str = "`make setup` installs Intel Open Image Denoise 2.5.1 into third_party/oidn/lib \
     (from the pinned `pyoidn` wheel on PyPI), or set QUADRAY_OIDN_LIB to an installed libOpenImageDenoise.so.2; \
     or render without denoising (--no-denoise)";

/// Why denoising failed.
#[derive(Debug, thiserror::Error)]
pub enum DenoiseError {
    /// The library could not be loaded.
    #[error("cannot denoise: Intel Open Image Denoise is not installed ({tried}); {HOW_TO_INSTALL}")]
    Missing {
        /// What was tried and why each failed.
        tried: String,
    },
    /// The library reported an error.
    #[error("Intel Open Image Denoise failed ({what}): {message}")]
    Library {
        /// The call that failed.
        what: &'static str,
        /// The library's message.
        message: String,
    },
    /// The images do not fit the size.
    #[error("the {name} image has {got} pixels, not {width}x{height}")]
    Size {
        /// Which image.
        name: &'static str,
        /// Its pixel count.
        got: usize,
        /// The width.
        width: u32,
        /// The height.
        height: u32,
    },
}

/// OIDN's `OIDN_QUALITY_*` value of a quality.
fn oidn_quality(q: DenoiseQuality) -> c_int {
    match q {
        DenoiseQuality::Fast => 4,
        DenoiseQuality::Balanced => 5,
        DenoiseQuality::High => 6,
    }
}

/// One image to denoise: linear HDR radiance and, optionally, the
/// auxiliary albedo (in [0, 1]) and normal images, row by row.
pub struct DenoiseInput<'a> {
    /// Width in pixels.
    pub width: u32,
    /// Height in pixels.
    pub height: u32,
    /// Linear radiance.
    pub color: &'a [[f32; 3]],
    /// Albedo at the first non-specular vertex, averaged over the samples.
    pub albedo: Option<&'a [[f32; 3]]>,
    /// Normal there (any length; zero where there is none); used only with
    /// `albedo`, as OIDN requires.
    pub normal: Option<&'a [[f32; 3]]>,
}

type Handle = *mut c_void;

/// The C functions used, resolved from the library.
struct Api {
    new_device: unsafe extern "C" fn(c_int) -> Handle,
    commit_device: unsafe extern "C" fn(Handle),
    release_device: unsafe extern "C" fn(Handle),
    device_error: unsafe extern "C" fn(Handle, *mut *const c_char) -> c_int,
    device_int: unsafe extern "C" fn(Handle, *const c_char) -> c_int,
    new_filter: unsafe extern "C" fn(Handle, *const c_char) -> Handle,
    release_filter: unsafe extern "C" fn(Handle),
    #[allow(clippy::type_complexity)]
    set_image: unsafe extern "C" fn(Handle, *const c_char, *mut c_void, c_int, usize, usize, usize, usize, usize),
    set_bool: unsafe extern "C" fn(Handle, *const c_char, bool),
    set_int: unsafe extern "C" fn(Handle, *const c_char, c_int),
    commit_filter: unsafe extern "C" fn(Handle),
    execute_filter: unsafe extern "C" fn(Handle),
}

const OIDN_DEVICE_TYPE_CPU: c_int = 1;
const OIDN_FORMAT_FLOAT3: c_int = 3;

/// An OIDN CPU device, with the library that provides it.
pub struct Denoiser {
    api: Api,
    device: Handle,
    /// Where the library was loaded from.
    pub library: String,
    /// The library's version (major * 10000 + minor * 100 + patch).
    pub version: i32,
    // Last: unloaded after the device is released (Drop).
    _lib: libloading::Library,
}

// SAFETY: OIDN devices may be used from any thread, one call at a time;
// every use here takes &mut self.
unsafe impl Send for Denoiser {}

impl Denoiser {
    /// Loads the library (see the module documentation for where it is
    /// looked for) and creates a CPU device.
    pub fn load() -> Result<Self, DenoiseError> {
        let candidates: Vec<String> = match std::env::var_os(LIBRARY_ENV) {
            Some(p) => vec![PathBuf::from(p).display().to_string()],
            None => vec![BUNDLED_LIBRARY.to_string(), SYSTEM_LIBRARY.to_string()],
        };
        Self::load_first(&candidates)
    }

    /// The first of `candidates` (paths or names) that loads.
    fn load_first(candidates: &[String]) -> Result<Self, DenoiseError> {
        let mut tried = Vec::new();
        for name in candidates {
            // SAFETY: loading OIDN runs its (and TBB's) initialisers, which
            // have no preconditions.
            match unsafe { libloading::Library::new(name) } {
                Ok(lib) => return Self::with_library(lib, name.clone()),
                Err(e) => tried.push(format!("{name}: {e}")),
            }
        }
        Err(DenoiseError::Missing { tried: tried.join("; ") })
    }

    fn with_library(lib: libloading::Library, name: String) -> Result<Self, DenoiseError> {
        fn get<T: Copy>(lib: &libloading::Library, symbol: &str, name: &str) -> Result<T, DenoiseError> {
            // SAFETY: each symbol is read with the C signature oidn.h
            // (OIDN 2.x) declares for it.
            unsafe { lib.get::<T>(symbol.as_bytes()) }.map(|s| *s).map_err(|e| DenoiseError::Missing {
                tried: format!("{name} lacks {symbol} ({e}): not Open Image Denoise 2"),
            })
        }
        let api = Api {
            new_device: get(&lib, "oidnNewDevice", &name)?,
            commit_device: get(&lib, "oidnCommitDevice", &name)?,
            release_device: get(&lib, "oidnReleaseDevice", &name)?,
            device_error: get(&lib, "oidnGetDeviceError", &name)?,
            device_int: get(&lib, "oidnGetDeviceInt", &name)?,
            new_filter: get(&lib, "oidnNewFilter", &name)?,
            release_filter: get(&lib, "oidnReleaseFilter", &name)?,
            set_image: get(&lib, "oidnSetSharedFilterImage", &name)?,
            set_bool: get(&lib, "oidnSetFilterBool", &name)?,
            set_int: get(&lib, "oidnSetFilterInt", &name)?,
            commit_filter: get(&lib, "oidnCommitFilter", &name)?,
            execute_filter: get(&lib, "oidnExecuteFilter", &name)?,
        };
        // SAFETY: the functions were resolved above; a null device is
        // reported by oidnGetDeviceError(NULL).
        unsafe {
            let device = (api.new_device)(OIDN_DEVICE_TYPE_CPU);
            if device.is_null() {
                let message = Self::error_of(&api, device).unwrap_or_else(|| "no CPU device".into());
                return Err(DenoiseError::Library { what: "creating the CPU device", message });
            }
            let mut d = Self { api, device, library: name, version: 0, _lib: lib };
            (d.api.commit_device)(device);
            d.check("committing the CPU device")?;
            d.version = (d.api.device_int)(device, c"version".as_ptr());
            Ok(d)
        }
    }

    /// The device's first unread error, if any.
    unsafe fn error_of(api: &Api, device: Handle) -> Option<String> {
        let mut message: *const c_char = std::ptr::null();
        let code = (api.device_error)(device, &mut message);
        (code != 0).then(|| {
            let text = if message.is_null() { String::new() } else { CStr::from_ptr(message).to_string_lossy().into() };
            format!("{text} (error {code})")
        })
    }

    fn check(&self, what: &'static str) -> Result<(), DenoiseError> {
        // SAFETY: the device is valid while self lives.
        match unsafe { Self::error_of(&self.api, self.device) } {
            Some(message) => Err(DenoiseError::Library { what, message }),
            None => Ok(()),
        }
    }

    /// The denoised radiance of `input`: OIDN's `RT` filter over the HDR
    /// colour, guided by the albedo and normal images where given. Those
    /// are passed as they are (`cleanAux` off): denoising them first, OIDN's
    /// advice for noisy features, blurred their silhouettes and raised the
    /// error (default scene, 320x240, 4 spp against 1024 spp: relMSE 0.00193
    /// against 0.00171; results/bench/README.md).
    pub fn denoise(&mut self, input: &DenoiseInput, quality: DenoiseQuality) -> Result<Vec<[f32; 3]>, DenoiseError> {
        let (width, height) = (input.width, input.height);
        let n = width as usize * height as usize;
        let check = |name, got: usize| {
            if got == n {
                Ok(())
            } else {
                Err(DenoiseError::Size { name, got, width, height })
            }
        };
        check("colour", input.color.len())?;
        let aux = match (input.albedo, input.normal) {
            (Some(a), Some(nm)) => {
                check("albedo", a.len())?;
                check("normal", nm.len())?;
                Some((a, nm))
            }
            _ => None,
        };
        let mut out = vec![[0.0f32; 3]; n];
        if n == 0 {
            return Ok(out);
        }
        let api = &self.api;
        // SAFETY: every image is width x height FLOAT3 pixels, packed
        // (checked above), and outlives the filter; OIDN reads the inputs
        // and writes only `output` (a distinct buffer).
        unsafe {
            let filter = (api.new_filter)(self.device, c"RT".as_ptr());
            if filter.is_null() {
                return Err(self
                    .check("creating the RT filter")
                    .err()
                    .unwrap_or(DenoiseError::Library { what: "creating the RT filter", message: "no filter".into() }));
            }
            let set = |name: &CStr, data: *const [f32; 3]| {
                (api.set_image)(
                    filter,
                    name.as_ptr(),
                    data as *mut c_void,
                    OIDN_FORMAT_FLOAT3,
                    width as usize,
                    height as usize,
                    0,
                    0,
                    0,
                )
            };
            set(c"color", input.color.as_ptr());
            if let Some((albedo, normal)) = aux {
                set(c"albedo", albedo.as_ptr());
                set(c"normal", normal.as_ptr());
            }
            set(c"output", out.as_mut_ptr());
            (api.set_bool)(filter, c"hdr".as_ptr(), true);
            (api.set_int)(filter, c"quality".as_ptr(), oidn_quality(quality));
            (api.commit_filter)(filter);
            let committed = self.check("committing the filter");
            if committed.is_ok() {
                (api.execute_filter)(filter);
            }
            (api.release_filter)(filter);
            committed?;
            self.check("denoising")?;
        }
        Ok(out)
    }
}

impl Drop for Denoiser {
    fn drop(&mut self) {
        // SAFETY: the device was created by this library, which is still loaded.
        unsafe { (self.api.release_device)(self.device) }
    }
}

/// True when `out` has the denoiser's features: every render has them, an
/// EXR read from a file where it has the AOV channels (with zero features
/// where it lacks theirs).
pub fn has_features(out: &crate::passes::RenderOutput) -> bool {
    out.aov.len() == out.radiance.len()
}

/// [`Denoiser::denoise`] of a render: its radiance with the denoiser's
/// features from its AOVs (colour only when it has none, e.g. an EXR
/// without them).
pub fn denoise_output(
    denoiser: &mut Denoiser,
    out: &crate::passes::RenderOutput,
    quality: DenoiseQuality,
) -> Result<Vec<[f32; 3]>, DenoiseError> {
    let has_features = has_features(out);
    let albedo: Vec<[f32; 3]> = if has_features { out.aov.iter().map(|a| a.denoise_albedo).collect() } else { vec![] };
    let normal: Vec<[f32; 3]> = if has_features { out.aov.iter().map(|a| a.denoise_normal).collect() } else { vec![] };
    let input = DenoiseInput {
        width: out.width,
        height: out.height,
        color: &out.radiance,
        albedo: has_features.then_some(albedo.as_slice()),
        normal: has_features.then_some(normal.as_slice()),
    };
    denoiser.denoise(&input, quality)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_missing_library_says_what_was_tried_and_how_to_get_it() {
        let tried = ["/nonexistent/libOpenImageDenoise.so.2".to_string(), "/nonexistent/other.so".to_string()];
        let Err(e) = Denoiser::load_first(&tried) else { panic!("loaded a library that does not exist") };
        let text = e.to_string();
        assert!(text.contains("not installed") && text.contains("make setup") && text.contains(LIBRARY_ENV), "{text}");
        assert!(text.contains(&tried[0]) && text.contains(&tried[1]), "{text}");
    }

    #[test]
    fn a_library_that_is_not_oidn_is_named() {
        // libc loads but has none of OIDN's functions.
        let Err(e) = Denoiser::load_first(&["libc.so.6".to_string()]) else { panic!("libc is not OIDN") };
        assert!(e.to_string().contains("lacks oidnNewDevice"), "{e}");
    }
}
