//! BSDFs in the local shading frame (normal +z): evaluation, density and
//! sampling, the CPU twins of the renderer's materials.
//!
//! Conventions: `wo` points away from the surface toward the viewer (the
//! previous path vertex), `wi` toward the next vertex or the light; both are
//! unit vectors and cos θ = w.z. `eval` returns f (the BSDF, without the
//! cosine); `pdf` the solid-angle density with which `sample` produces `wi`
//! (0 for delta lobes, which `eval` also reports as 0); `sample` takes its
//! random numbers u1, u2, u3 ∈ [0, 1) explicitly and is deterministic.
//!
//! Opaque BSDFs (diffuse, conductor, mirror) reflect only when wo.z > 0: the
//! renderer turns the shading normal toward the viewer. Their `sample`
//! returns `None` for wo.z ≤ 0, and when the sampled `wi` is not above the
//! surface (wi.z ≤ 0).

use std::f64::consts::FRAC_1_PI;

use glam::DVec3;

use super::fresnel::{fresnel_conductor, fresnel_dielectric, fresnel_schlick};
use super::ggx::{self, alpha_from_roughness, DELTA_ALPHA};
use super::warp::sample_cosine_hemisphere;
use crate::model::scene::{ConductorFresnel, Material, MaterialKind};

/// A sampled direction and its Monte Carlo weight.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BsdfSample {
    /// The sampled incident direction (unit, local frame).
    pub wi: DVec3,
    /// f(wo, wi) |cos θi| / pdf per RGB channel; for a delta lobe, the
    /// lobe's reflectance (or transmittance) divided by the probability with
    /// which the lobe was chosen.
    pub weight: DVec3,
    /// The solid-angle density of `wi`; `None` for a delta lobe.
    pub pdf: Option<f64>,
}

impl BsdfSample {
    /// Whether the sample comes from a delta (perfectly specular) lobe.
    pub fn is_delta(&self) -> bool {
        self.pdf.is_none()
    }
}

/// The mirror direction of `wo` about the normal +z: (−wo.x, −wo.y, wo.z).
pub fn reflect(wo: DVec3) -> DVec3 {
    DVec3::new(-wo.x, -wo.y, wo.z)
}

/// The direction refracted from `wo` through the smooth interface with
/// normal +z, on the opposite side of the surface, or `None` under total
/// internal reflection.
///
/// `eta_rel` = n_t / n_i, the index of the side `wi` is on over that of the
/// side `wo` is on. With n' = (0, 0, sign wo.z), cos θi = |wo.z|,
/// cos θt = √(1 − (1 − cos²θi)/eta_rel²):
/// wi = −wo/eta_rel + (cos θi/eta_rel − cos θt) n'.
/// Then |wi| = 1, wi.z = −sign(wo.z) cos θt and sin θt = sin θi / eta_rel
/// (Snell), with wi's tangential part opposite to wo's.
pub fn refract(wo: DVec3, eta_rel: f64) -> Option<DVec3> {
    let cos_i = wo.z.abs();
    let sin2_t = (1.0 - cos_i * cos_i) / (eta_rel * eta_rel);
    if sin2_t >= 1.0 {
        return None;
    }
    let cos_t = (1.0 - sin2_t).sqrt();
    let n = DVec3::new(0.0, 0.0, wo.z.signum());
    Some(-wo / eta_rel + (cos_i / eta_rel - cos_t) * n)
}

/// Lambertian reflection: f = albedo / π for wo.z > 0 and wi.z > 0.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Diffuse {
    /// Reflectance (linear RGB).
    pub albedo: DVec3,
}

impl Diffuse {
    /// f(wo, wi) = albedo / π above the surface, else 0.
    pub fn eval(&self, wo: DVec3, wi: DVec3) -> DVec3 {
        if wo.z > 0.0 && wi.z > 0.0 {
            self.albedo * FRAC_1_PI
        } else {
            DVec3::ZERO
        }
    }

    /// wi.z / π above the surface, else 0.
    pub fn pdf(&self, wo: DVec3, wi: DVec3) -> f64 {
        if wo.z > 0.0 && wi.z > 0.0 {
            wi.z * FRAC_1_PI
        } else {
            0.0
        }
    }

    /// Cosine sampling ([`sample_cosine_hemisphere`] of u1, u2; u3 unused);
    /// weight = albedo, pdf = wi.z / π.
    pub fn sample(&self, wo: DVec3, u1: f64, u2: f64, _u3: f64) -> Option<BsdfSample> {
        if wo.z <= 0.0 {
            return None;
        }
        let wi = sample_cosine_hemisphere(u1, u2);
        if wi.z <= 0.0 {
            return None;
        }
        Some(BsdfSample { wi, weight: self.albedo, pdf: Some(wi.z * FRAC_1_PI) })
    }
}

/// The Fresnel reflectance of a conductor.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum FresnelModel {
    /// Exact, from the complex index η + iκ ([`fresnel_conductor`]).
    Complex {
        /// Real part η per channel.
        eta: DVec3,
        /// Extinction κ per channel.
        k: DVec3,
    },
    /// Schlick's approximation from the reflectance at normal incidence
    /// ([`fresnel_schlick`]).
    Schlick {
        /// Reflectance at normal incidence.
        f0: DVec3,
    },
}

impl FresnelModel {
    /// F(cos θ), cos θ clamped to [0, 1].
    pub fn eval(&self, cos_i: f64) -> DVec3 {
        match *self {
            Self::Complex { eta, k } => fresnel_conductor(cos_i, eta, k),
            Self::Schlick { f0 } => fresnel_schlick(cos_i, f0),
        }
    }
}

/// A GGX microfacet conductor (Walter et al. 2007, eq. 20, reflection only):
/// f = F(wo·m) D(m) G2(wo, wi) / (4 wo.z wi.z), m = normalize(wo + wi), with
/// the height-correlated Smith G2 and visible-normal sampling (see
/// [`ggx`]). With α < [`DELTA_ALPHA`] it is a perfect specular reflector
/// (delta lobe) of reflectance F(wo.z).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Conductor {
    /// GGX α (roughness²).
    pub alpha: f64,
    /// Fresnel reflectance.
    pub fresnel: FresnelModel,
}

impl Conductor {
    /// A conductor of perceptual `roughness` (α = roughness²).
    pub fn new(roughness: f64, fresnel: FresnelModel) -> Self {
        Self { alpha: alpha_from_roughness(roughness), fresnel }
    }

    /// Whether the lobe is a delta (α < [`DELTA_ALPHA`]).
    pub fn is_delta(&self) -> bool {
        self.alpha < DELTA_ALPHA
    }

    /// f(wo, wi) for wo.z > 0 and wi.z > 0, else 0 (and 0 for a delta lobe).
    pub fn eval(&self, wo: DVec3, wi: DVec3) -> DVec3 {
        if self.is_delta() || wo.z <= 0.0 || wi.z <= 0.0 {
            return DVec3::ZERO;
        }
        let m = (wo + wi).normalize();
        let a = self.alpha;
        self.fresnel.eval(wo.dot(m)) * (ggx::d(a, m) * ggx::g2(a, wo, wi) / (4.0 * wo.z * wi.z))
    }

    /// The density of [`Conductor::sample`]: D_wo(m) / (4 wo·m) with
    /// m = normalize(wo + wi) (Heitz 2018, eq. 17), for wo.z > 0 and
    /// wi.z > 0, else 0 (and 0 for a delta lobe).
    pub fn pdf(&self, wo: DVec3, wi: DVec3) -> f64 {
        if self.is_delta() || wo.z <= 0.0 || wi.z <= 0.0 {
            return 0.0;
        }
        let m = (wo + wi).normalize();
        let cos_om = wo.dot(m);
        if cos_om <= 0.0 {
            return 0.0;
        }
        ggx::pdf_vndf(self.alpha, wo, m) / (4.0 * cos_om)
    }

    /// Samples m by [`ggx::sample_vndf`] (u1, u2; u3 unused) and reflects:
    /// wi = 2 (wo·m) m − wo; `None` when wo·m ≤ 0 or wi.z ≤ 0.
    /// weight = F(wo·m) G2(wo, wi) / G1(wo); pdf = D_wo(m) / (4 wo·m), both
    /// from the sampled m.
    /// Delta lobe: wi = (−wo.x, −wo.y, wo.z), weight = F(wo.z), pdf `None`.
    pub fn sample(&self, wo: DVec3, u1: f64, u2: f64, _u3: f64) -> Option<BsdfSample> {
        if wo.z <= 0.0 {
            return None;
        }
        if self.is_delta() {
            return Some(BsdfSample { wi: reflect(wo), weight: self.fresnel.eval(wo.z), pdf: None });
        }
        let a = self.alpha;
        let m = ggx::sample_vndf(a, wo, u1, u2);
        let cos_om = wo.dot(m);
        if cos_om <= 0.0 {
            return None;
        }
        let wi = 2.0 * cos_om * m - wo;
        if wi.z <= 0.0 {
            return None;
        }
        let weight = self.fresnel.eval(cos_om) * (ggx::g2(a, wo, wi) / ggx::g1(a, wo));
        Some(BsdfSample { wi, weight, pdf: Some(ggx::pdf_vndf(a, wo, m) / (4.0 * cos_om)) })
    }
}

/// A perfect mirror of reflectance `albedo` (delta lobe).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Mirror {
    /// Reflectance (linear RGB).
    pub albedo: DVec3,
}

impl Mirror {
    /// Always 0 (delta lobe).
    pub fn eval(&self, _wo: DVec3, _wi: DVec3) -> DVec3 {
        DVec3::ZERO
    }

    /// Always 0 (delta lobe).
    pub fn pdf(&self, _wo: DVec3, _wi: DVec3) -> f64 {
        0.0
    }

    /// wi = (−wo.x, −wo.y, wo.z), weight = albedo, pdf `None`; `None` for
    /// wo.z ≤ 0. No random numbers are used.
    pub fn sample(&self, wo: DVec3, _u1: f64, _u2: f64, _u3: f64) -> Option<BsdfSample> {
        if wo.z <= 0.0 {
            return None;
        }
        Some(BsdfSample { wi: reflect(wo), weight: self.albedo, pdf: None })
    }
}

/// A smooth dielectric interface (glass, water): Fresnel reflection and
/// refraction, both delta lobes. The inside (wo.z < 0) has index `ior`
/// relative to the outside.
///
/// [`Bsdf::from_material`] uses it for dielectrics with α < [`DELTA_ALPHA`]
/// (and for ior = 1, see [`RoughDielectric`]); rougher ones are
/// [`RoughDielectric`].
///
/// What is conserved: the sample chooses reflection with probability F and
/// refraction with probability 1 − F, so E\[weight\] = F + (1 − F)/eta_rel²;
/// this is the radiance carried along a camera path, which is compressed by
/// eta_rel² entering a denser medium (radiance / n² is invariant). The power
/// (flux) is conserved: F + (1 − F) = 1, i.e. E\[weight × (eta_rel² on
/// refraction, 1 on reflection)\] = 1.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SmoothDielectric {
    /// Index of refraction of the inside relative to the outside.
    pub ior: f64,
}

impl SmoothDielectric {
    /// Always 0 (delta lobes).
    pub fn eval(&self, _wo: DVec3, _wi: DVec3) -> DVec3 {
        DVec3::ZERO
    }

    /// Always 0 (delta lobes).
    pub fn pdf(&self, _wo: DVec3, _wi: DVec3) -> f64 {
        0.0
    }

    /// `wo` may be on either side (wo.z < 0: inside); `None` for wo.z = 0.
    /// F = [`fresnel_dielectric`](wo.z, ior). If u3 < F, reflection:
    /// wi = (−wo.x, −wo.y, wo.z), weight 1. Otherwise refraction with
    /// eta_rel = (wo.z > 0 ? ior : 1/ior) (= n_t/n_i): wi = [`refract`](wo,
    /// eta_rel), weight 1/eta_rel² (pbrt's radiance scaling for camera
    /// paths). pdf `None` for both; u1 and u2 unused.
    pub fn sample(&self, wo: DVec3, _u1: f64, _u2: f64, u3: f64) -> Option<BsdfSample> {
        if wo.z == 0.0 {
            return None;
        }
        let f = fresnel_dielectric(wo.z, self.ior);
        let reflection = Some(BsdfSample { wi: reflect(wo), weight: DVec3::ONE, pdf: None });
        if u3 < f {
            return reflection;
        }
        let eta_rel = if wo.z > 0.0 { self.ior } else { 1.0 / self.ior };
        match refract(wo, eta_rel) {
            Some(wi) => Some(BsdfSample { wi, weight: DVec3::splat(1.0 / (eta_rel * eta_rel)), pdf: None }),
            // Unreachable in exact arithmetic: total internal reflection has F = 1.
            None => reflection,
        }
    }
}

/// A rough dielectric interface: GGX microfacet reflection and refraction
/// after B. Walter, S. R. Marschner, H. Li and K. E. Torrance, "Microfacet
/// Models for Refraction through Rough Surfaces", EGSR 2007, with the
/// visible-normal sampling of [`ggx::sample_vndf`] (Heitz 2018). The inside
/// (wo.z < 0) has index `ior` relative to the outside; `wo` may be on either
/// side. Requires ior ≠ 1 (an index-matched interface is invisible: a delta
/// transmission, which [`Bsdf::from_material`] gives to [`SmoothDielectric`]).
///
/// **The up frame.** With s = sign(wo.z) (wo.z = 0: `sample` returns `None`,
/// `eval` and `pdf` 0), everything is computed with directions mirrored
/// through the tangent plane when s < 0: o = (wo.x, wo.y, |wo.z|),
/// i = (wi.x, wi.y, s·wi.z), and with eta = (s > 0 ? ior : 1/ior) = n_t/n_i,
/// the index of the far side over that of wo's side. A sampled i is mirrored
/// back at the end: wi = (i.x, i.y, s·i.z). D = [`ggx::d`],
/// G1 = [`ggx::g1`], G2(o, i) = [`ggx::g2`] = 1/(1 + Λ(o) + Λ(i)) with Λ on
/// |z| (the height-correlated form, used for both lobes),
/// D_o(m) = [`ggx::pdf_vndf`](α, o, m) = G1(o) max(0, o·m) D(m)/o.z, and
/// F(c) = [`fresnel_dielectric`](c, eta) with c > 0.
///
/// **Sampling** (u1, u2, u3): m = [`ggx::sample_vndf`](α, o, u1, u2),
/// c = o·m; `None` if c ≤ 0. F = F(c).
/// - u3 < F, reflection: i = 2c m − o; `None` if i.z ≤ 0.
///   pdf = F D_o(m) / (4c); weight = G2(o, i)/G1(o).
/// - otherwise refraction: sin²θt = (1 − c²)/eta² (`None` if ≥ 1, which
///   cannot happen as F = 1 there), cos_t = √(1 − sin²θt),
///   i = −o/eta + (c/eta − cos_t) m (so i·m = −cos_t); `None` if i.z ≥ 0.
///   pdf = (1 − F) D_o(m) eta² cos_t / (c − eta cos_t)² (Walter eq. 17, the
///   Jacobian dω_m/dω_i = eta² |i·m| / (o·m + eta i·m)²);
///   weight = G2(o, i) / (G1(o) eta²).
/// - `None` too unless pdf > 0 and finite.
///
/// **eval and pdf** for any pair, in the up frame (both 0 when o.z = 0 or
/// i.z = 0):
/// - i.z > 0, reflection: h = normalize(o + i), c = o·h (0 unless h.z > 0 and
///   c > 0), F = F(c); f = F D(h) G2(o, i) / (4 o.z i.z) (Walter eq. 20),
///   pdf = F D_o(h) / (4c).
/// - i.z < 0, refraction: h = normalize(o + eta i) (Walter's generalised half
///   vector; 0 if o + eta i = 0), negated if h.z < 0; c = o·h, ci = i·h; 0
///   unless h.z > 0, c > 0 and ci < 0. F = F(c), den = c + eta ci;
///   f = c |ci| (1 − F) G2(o, i) D(h) / (o.z |i.z| den²),
///   pdf = (1 − F) D_o(h) eta² |ci| / den².
///
/// f is returned as the same value in all three channels. The transmission
/// f is Walter's eq. 21 with η_i = 1, η_o = eta, f_W = c |ci| eta² (1 − F)
/// G2 D / (o.z |i.z| den²), times 1/eta²: the radiance carried along camera
/// paths (the convention of [`SmoothDielectric`], to which the lobes tend as
/// α → 0: reflection weight G2/G1 → 1, refraction weight G2/(G1 eta²) →
/// 1/eta²). The flux (power) albedo, undoing that scaling, is
/// ∫ (f_r + eta² f_t) |cos θi| dωi = ∫ D_o(m) G2/G1 (F \[i_r.z > 0\] +
/// (1 − F) \[i_t.z < 0\]) dω_m ≤ 1, with i_r, i_t the reflected and
/// refracted directions of m. Reciprocity: f(wo, wi) = f(wi, wo) for
/// reflection; f(wo, wi)/n_wo² = f(wi, wo)/n_wi² for refraction.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RoughDielectric {
    /// GGX α (roughness²), ≥ [`DELTA_ALPHA`] in the renderer.
    pub alpha: f64,
    /// Index of refraction of the inside relative to the outside (≠ 1).
    pub ior: f64,
}

impl RoughDielectric {
    /// A rough dielectric of perceptual `roughness` (α = roughness²).
    pub fn new(roughness: f64, ior: f64) -> Self {
        Self { alpha: alpha_from_roughness(roughness), ior }
    }

    /// s = sign(wo.z), o = wo mirrored to +z, eta = n_t/n_i; `None` for wo.z = 0.
    fn up_frame(&self, wo: DVec3) -> Option<(f64, DVec3, f64)> {
        if wo.z == 0.0 || wo.z.is_nan() {
            return None;
        }
        let s = if wo.z > 0.0 { 1.0 } else { -1.0 };
        let eta = if s > 0.0 { self.ior } else { 1.0 / self.ior };
        Some((s, DVec3::new(wo.x, wo.y, wo.z.abs()), eta))
    }

    /// (f, pdf) of the pair (see the type's documentation).
    fn eval_pdf(&self, wo: DVec3, wi: DVec3) -> (f64, f64) {
        let Some((s, o, eta)) = self.up_frame(wo) else { return (0.0, 0.0) };
        let i = DVec3::new(wi.x, wi.y, s * wi.z);
        let a = self.alpha;
        if i.z > 0.0 {
            let h = (o + i).normalize();
            let c = o.dot(h);
            if h.z <= 0.0 || c <= 0.0 {
                return (0.0, 0.0);
            }
            let f = fresnel_dielectric(c, eta);
            let value = f * ggx::d(a, h) * ggx::g2(a, o, i) / (4.0 * o.z * i.z);
            (value, f * ggx::pdf_vndf(a, o, h) / (4.0 * c))
        } else if i.z < 0.0 {
            let v = o + eta * i;
            let len2 = v.length_squared();
            if len2 <= 0.0 {
                return (0.0, 0.0);
            }
            let mut h = v / len2.sqrt();
            if h.z < 0.0 {
                h = -h;
            }
            let (c, ci) = (o.dot(h), i.dot(h));
            if h.z <= 0.0 || c <= 0.0 || ci >= 0.0 {
                return (0.0, 0.0);
            }
            let t = 1.0 - fresnel_dielectric(c, eta);
            let den = c + eta * ci;
            let den2 = den * den;
            let value = c * -ci * t * ggx::g2(a, o, i) * ggx::d(a, h) / (o.z * -i.z * den2);
            (value, t * ggx::pdf_vndf(a, o, h) * eta * eta * -ci / den2)
        } else {
            (0.0, 0.0)
        }
    }

    /// f(wo, wi) (radiance convention; see the type's documentation).
    pub fn eval(&self, wo: DVec3, wi: DVec3) -> DVec3 {
        DVec3::splat(self.eval_pdf(wo, wi).0)
    }

    /// The solid-angle density with which [`RoughDielectric::sample`]
    /// produces `wi`.
    pub fn pdf(&self, wo: DVec3, wi: DVec3) -> f64 {
        self.eval_pdf(wo, wi).1
    }

    /// Samples a visible microfacet normal (u1, u2), then reflection with
    /// probability F (u3 < F) or refraction (see the type's documentation).
    pub fn sample(&self, wo: DVec3, u1: f64, u2: f64, u3: f64) -> Option<BsdfSample> {
        let (s, o, eta) = self.up_frame(wo)?;
        let a = self.alpha;
        let m = ggx::sample_vndf(a, o, u1, u2);
        let c = o.dot(m);
        if c <= 0.0 {
            return None;
        }
        let f = fresnel_dielectric(c, eta);
        let d_o = ggx::pdf_vndf(a, o, m);
        let (i, weight, pdf) = if u3 < f {
            let i = 2.0 * c * m - o;
            if i.z <= 0.0 {
                return None;
            }
            (i, ggx::g2(a, o, i) / ggx::g1(a, o), f * d_o / (4.0 * c))
        } else {
            let sin2_t = (1.0 - c * c) / (eta * eta);
            if sin2_t >= 1.0 {
                return None;
            }
            let cos_t = (1.0 - sin2_t).sqrt();
            let i = -o / eta + (c / eta - cos_t) * m;
            if i.z >= 0.0 {
                return None;
            }
            let den = c - eta * cos_t;
            let pdf = (1.0 - f) * d_o * eta * eta * cos_t / (den * den);
            (i, ggx::g2(a, o, i) / (ggx::g1(a, o) * eta * eta), pdf)
        };
        if !(pdf > 0.0 && pdf.is_finite()) {
            return None;
        }
        Some(BsdfSample { wi: DVec3::new(i.x, i.y, s * i.z), weight: DVec3::splat(weight), pdf: Some(pdf) })
    }
}

/// Any of the BSDFs, as the renderer selects it from a scene material.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Bsdf {
    /// [`Diffuse`].
    Diffuse(Diffuse),
    /// [`Conductor`].
    Conductor(Conductor),
    /// [`Mirror`].
    Mirror(Mirror),
    /// [`SmoothDielectric`]: dielectrics with α < [`DELTA_ALPHA`] (or ior = 1).
    Dielectric(SmoothDielectric),
    /// [`RoughDielectric`]: dielectrics with α ≥ [`DELTA_ALPHA`] (and ior ≠ 1).
    RoughDielectric(RoughDielectric),
}

impl Bsdf {
    /// The BSDF of a scene material (f32 parameters widened to f64). A
    /// dielectric of perceptual roughness r becomes a [`RoughDielectric`] when
    /// α = r² ≥ [`DELTA_ALPHA`] and ior ≠ 1, else a [`SmoothDielectric`].
    pub fn from_material(material: &Material) -> Self {
        let albedo = material.albedo.as_dvec3();
        match &material.kind {
            MaterialKind::Diffuse => Self::Diffuse(Diffuse { albedo }),
            MaterialKind::Conductor { roughness, fresnel } => {
                let fresnel = match *fresnel {
                    ConductorFresnel::Complex { eta, k } => {
                        FresnelModel::Complex { eta: eta.as_dvec3(), k: k.as_dvec3() }
                    }
                    ConductorFresnel::Schlick { f0 } => FresnelModel::Schlick { f0: f0.as_dvec3() },
                };
                Self::Conductor(Conductor::new(f64::from(*roughness), fresnel))
            }
            MaterialKind::Dielectric { roughness, ior } => {
                let (alpha, ior) = (alpha_from_roughness(f64::from(*roughness)), f64::from(*ior));
                // ior = 1: an index-matched interface, invisible whatever its
                // roughness (RoughDielectric is degenerate there).
                if alpha < DELTA_ALPHA || ior == 1.0 {
                    Self::Dielectric(SmoothDielectric { ior })
                } else {
                    Self::RoughDielectric(RoughDielectric { alpha, ior })
                }
            }
            MaterialKind::Mirror => Self::Mirror(Mirror { albedo }),
        }
    }

    /// f(wo, wi), without the cosine.
    pub fn eval(&self, wo: DVec3, wi: DVec3) -> DVec3 {
        match self {
            Self::Diffuse(b) => b.eval(wo, wi),
            Self::Conductor(b) => b.eval(wo, wi),
            Self::Mirror(b) => b.eval(wo, wi),
            Self::Dielectric(b) => b.eval(wo, wi),
            Self::RoughDielectric(b) => b.eval(wo, wi),
        }
    }

    /// Solid-angle density of `sample` producing `wi` (0 for delta lobes).
    pub fn pdf(&self, wo: DVec3, wi: DVec3) -> f64 {
        match self {
            Self::Diffuse(b) => b.pdf(wo, wi),
            Self::Conductor(b) => b.pdf(wo, wi),
            Self::Mirror(b) => b.pdf(wo, wi),
            Self::Dielectric(b) => b.pdf(wo, wi),
            Self::RoughDielectric(b) => b.pdf(wo, wi),
        }
    }

    /// A sampled direction with its weight, from u1, u2, u3 ∈ [0, 1).
    pub fn sample(&self, wo: DVec3, u1: f64, u2: f64, u3: f64) -> Option<BsdfSample> {
        match self {
            Self::Diffuse(b) => b.sample(wo, u1, u2, u3),
            Self::Conductor(b) => b.sample(wo, u1, u2, u3),
            Self::Mirror(b) => b.sample(wo, u1, u2, u3),
            Self::Dielectric(b) => b.sample(wo, u1, u2, u3),
            Self::RoughDielectric(b) => b.sample(wo, u1, u2, u3),
        }
    }

    /// Whether every lobe is a delta lobe (`eval` and `pdf` are then 0).
    pub fn is_delta(&self) -> bool {
        match self {
            Self::Diffuse(_) | Self::RoughDielectric(_) => false,
            Self::Conductor(b) => b.is_delta(),
            Self::Mirror(_) | Self::Dielectric(_) => true,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn refraction_obeys_snell_from_both_sides() {
        let ior = 1.5;
        for wo in [DVec3::new(0.3, -0.4, 0.866), DVec3::new(0.2, 0.1, -0.9)] {
            let wo = wo.normalize();
            let eta_rel = if wo.z > 0.0 { ior } else { 1.0 / ior };
            let wi = refract(wo, eta_rel).unwrap();
            assert!((wi.length() - 1.0).abs() < 1e-14);
            assert!(wi.z * wo.z < 0.0);
            let sin_i = (1.0 - wo.z * wo.z).sqrt();
            let sin_t = (1.0 - wi.z * wi.z).sqrt();
            assert!((sin_t * eta_rel - sin_i).abs() < 1e-14);
            assert!(wi.x * wo.x <= 0.0 && wi.y * wo.y <= 0.0);
        }
    }

    #[test]
    fn conductor_sample_weight_is_f_cos_over_pdf() {
        let c = Conductor { alpha: 0.3, fresnel: FresnelModel::Schlick { f0: DVec3::new(0.9, 0.6, 0.3) } };
        let wo = DVec3::new(0.5, 0.2, 0.7).normalize();
        let s = c.sample(wo, 0.3, 0.7, 0.0).unwrap();
        let pdf = s.pdf.unwrap();
        assert!((pdf - c.pdf(wo, s.wi)).abs() < 1e-12 * pdf);
        let want = c.eval(wo, s.wi) * s.wi.z / pdf;
        assert!((s.weight - want).abs().max_element() < 1e-12);
    }

    #[test]
    fn rough_dielectric_samples_agree_with_eval_and_pdf_from_both_sides() {
        let b = RoughDielectric::new(0.5, 1.5);
        let (mut reflected, mut refracted) = (0, 0);
        for wo in [DVec3::new(0.3, -0.4, 0.866), DVec3::new(0.2, 0.1, -0.9), DVec3::new(-0.6, 0.2, -0.5)] {
            let wo = wo.normalize();
            for (u1, u2) in [(0.1, 0.2), (0.5, 0.9), (0.8, 0.4)] {
                for u3 in [0.0, 0.999] {
                    let Some(s) = b.sample(wo, u1, u2, u3) else { continue };
                    let pdf = s.pdf.unwrap();
                    assert!((b.pdf(wo, s.wi) - pdf).abs() < 1e-10 * pdf);
                    let want = b.eval(wo, s.wi) * s.wi.z.abs() / pdf;
                    assert!((s.weight - want).abs().max_element() < 1e-10 * want.x);
                    if s.wi.z * wo.z > 0.0 {
                        reflected += 1;
                    } else {
                        refracted += 1;
                    }
                }
            }
        }
        assert!(reflected > 0 && refracted > 0);
        assert!(b.sample(DVec3::X, 0.5, 0.5, 0.5).is_none());
        assert_eq!(b.eval(DVec3::X, DVec3::Z), DVec3::ZERO);
    }
}
