//! Covariance tracing of the local light field around a ray, used to
//! prefilter textures along light paths (the paper's section 2; Durand et al.
//! 2005, Belcour et al. 2013).
//!
//! References (the operators below are re-derived here from the first-order
//! ray model; no code was copied):
//!
//! - L. Belcour, C. Soler, K. Subr, N. Holzschuch, F. Durand, "5D Covariance
//!   Tracing for Efficient Defocus and Motion Blur", ACM TOG 32(3), 2013
//!   (section 4: travel, rotation, projection, curvature, reflection, BRDF,
//!   refraction in its appendix).
//! - L. Belcour, L.-Q. Yan, R. Ramamoorthi, D. Nowrouzezahrai, "Antialiasing
//!   Complex Global Illumination Effects in Path-space", ACM TOG 36(1), 2017
//!   (the 4D space+angle operators and the pixel-filter initialisation).
//!
//! # Conventions
//!
//! The *primal* coordinates of a ray near the central ray of direction `w`
//! are `v = (x, y, θ, φ)`:
//!
//! - `x, y`: offsets of the ray's position along the frame `(e1, e2)` in the
//!   plane orthogonal to `w` (units of length); after [`Covariance4::project`]
//!   they are coordinates in the surface's tangent plane instead;
//! - `θ, φ`: offsets of the direction, `w + θ e1 + φ e2` (tangent-plane
//!   parametrisation of directions, radians to first order).
//!
//! `(e1, e2, w)` is right-handed. The frame is owned by the caller: every
//! operator states how it moves the frame.
//!
//! Every operator is a linear map of the primal coordinates, `v' = A v`
//! (first order in the offsets). A Gaussian light-field footprint with primal
//! covariance `P` transforms as `P' = A P Aᵀ`. With the Fourier convention
//! `f̂(Ω) = ∫ f(v) e^{-2πi Ω·v} dv`, a Gaussian of covariance `P` has a
//! (Gaussian) spectrum of covariance `Σ = P⁻¹ / (4π²)` (a Gaussian of std `s`
//! has a spectrum of std `1/(2π s)`), so the spectrum covariance transforms as
//! `Σ' = A⁻ᵀ Σ A⁻¹`. Spectral units: spatial frequencies in cycles per unit
//! length, angular frequencies in cycles per radian.
//!
//! [`Covariance4`] keeps **both** `Σ` ([`Covariance4::sigma`], the spectrum
//! covariance of the papers) and `4π² P = Σ⁻¹` ([`Covariance4::sigma_inv`]).
//! Linear operators update both exactly; keeping the inverse avoids inverting
//! the near-singular matrices of pinhole cameras and collimated beams (whose
//! spectra are infinitely wide in space or angle), so footprints stay exact.
//!
//! # Clamps
//!
//! - Pseudo-inverses (only in the constructors): eigenvalues of the inverted
//!   matrix are clamped to `[1/MAX_VARIANCE, 1/MIN_VARIANCE]` before inverting,
//!   so a zero variance becomes [`MAX_VARIANCE`] (`1e12`) and an infinite one
//!   [`MIN_VARIANCE`] (`1e-12`) on the other side.
//! - Travel distances are clamped to `±`[`MAX_DISTANCE`] (`1e12`).
//! - Cosines are clamped to `[`[`MIN_COS`]` = 1e-6, 1]` in magnitude (sign
//!   ignored).
//! - Curvatures are clamped to `±`[`MAX_CURVATURE`] (`1e12`).
//! - Roughness variances are clamped to `[0, `[`MAX_VARIANCE`]`]`.
//! - After every operator the entries of both matrices are clamped to
//!   `±`[`MAX_ENTRY`] (`1e100`) so that repeated operators cannot overflow to
//!   infinity. NaN inputs are not sanitised (NaN in, NaN out).

use glam::{DMat2, DMat4, DVec2};
use std::f64::consts::PI;

/// Largest variance produced by a pseudo-inverse (a zero variance on the other
/// side of the Fourier transform becomes this).
pub const MAX_VARIANCE: f64 = 1e12;
/// Smallest variance produced by a pseudo-inverse.
pub const MIN_VARIANCE: f64 = 1e-12;
/// Largest travel distance (in magnitude).
pub const MAX_DISTANCE: f64 = 1e12;
/// Smallest cosine of projections and refractions.
pub const MIN_COS: f64 = 1e-6;
/// Largest magnitude of a matrix entry after an operator.
pub const MAX_ENTRY: f64 = 1e100;
/// Largest curvature (1/length) in magnitude.
pub const MAX_CURVATURE: f64 = 1e12;

const FOUR_PI2: f64 = 4.0 * PI * PI;

/// The 4D (x, y, θ, φ) covariance of the local light-field spectrum around a
/// ray, with its inverse (see the module documentation for the conventions).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Covariance4 {
    /// `Σ`: the covariance of the light-field spectrum, in (cycles/length,
    /// cycles/radian) coordinates `(Ωx, Ωy, Ωθ, Ωφ)`.
    pub sigma: DMat4,
    /// `Σ⁻¹ = 4π² P`, with `P` the primal (space, angle) covariance of the
    /// Gaussian footprint. Exact for linear operators; may differ from the
    /// inverse of [`Self::sigma`] where the constructors clamped.
    pub sigma_inv: DMat4,
}

/// Builds a matrix from its rows (glam is column-major).
fn rows(r: [[f64; 4]; 4]) -> DMat4 {
    DMat4::from_cols_array_2d(&r).transpose()
}

fn clamp_entries(m: DMat4) -> DMat4 {
    let mut a = m.to_cols_array();
    for v in &mut a {
        *v = v.clamp(-MAX_ENTRY, MAX_ENTRY);
    }
    DMat4::from_cols_array(&a)
}

fn symmetrize(m: DMat4) -> DMat4 {
    (m + m.transpose()) * 0.5
}

fn clamp_cos(c: f64) -> f64 {
    c.abs().clamp(MIN_COS, 1.0)
}

/// Eigen-decomposition of a symmetric 4x4 matrix by cyclic Jacobi rotations:
/// returns the eigenvalues and the matrix whose columns are the eigenvectors.
fn sym_eigen(m: DMat4) -> ([f64; 4], DMat4) {
    let mut a = m.transpose().to_cols_array_2d(); // a[i][j] = row i, col j
    let mut v = [[0.0; 4]; 4];
    for (i, row) in v.iter_mut().enumerate() {
        row[i] = 1.0;
    }
    for _sweep in 0..64 {
        let mut off = 0.0;
        let mut diag = 0.0;
        for (i, row) in a.iter().enumerate() {
            for (j, x) in row.iter().enumerate() {
                if i == j {
                    diag += x * x;
                } else {
                    off += x * x;
                }
            }
        }
        if off <= 1e-32 * diag || off == 0.0 {
            break;
        }
        for p in 0..3 {
            for q in p + 1..4 {
                if a[p][q] == 0.0 {
                    continue;
                }
                let theta = (a[q][q] - a[p][p]) / (2.0 * a[p][q]);
                let t = theta.signum() / (theta.abs() + (theta * theta + 1.0).sqrt());
                let t = if theta == 0.0 { 1.0 } else { t };
                let c = 1.0 / (t * t + 1.0).sqrt();
                let s = t * c;
                for row in a.iter_mut() {
                    let (akp, akq) = (row[p], row[q]);
                    row[p] = c * akp - s * akq;
                    row[q] = s * akp + c * akq;
                }
                let (mut rp, mut rq) = (a[p], a[q]);
                for (x, y) in rp.iter_mut().zip(rq.iter_mut()) {
                    let (apk, aqk) = (*x, *y);
                    *x = c * apk - s * aqk;
                    *y = s * apk + c * aqk;
                }
                (a[p], a[q]) = (rp, rq);
                for row in v.iter_mut() {
                    let (vkp, vkq) = (row[p], row[q]);
                    row[p] = c * vkp - s * vkq;
                    row[q] = s * vkp + c * vkq;
                }
            }
        }
    }
    ([a[0][0], a[1][1], a[2][2], a[3][3]], DMat4::from_cols_array_2d(&v).transpose())
}

/// Pseudo-inverse of a symmetric positive semi-definite matrix whose result
/// has its eigenvalues clamped to `[MIN_VARIANCE, MAX_VARIANCE]` (a zero or
/// negative eigenvalue becomes `MAX_VARIANCE`).
pub fn pinv_clamped(m: DMat4) -> DMat4 {
    let (l, v) = sym_eigen(symmetrize(m));
    let inv = |x: f64| if x > 1.0 / MAX_VARIANCE { (1.0 / x).clamp(MIN_VARIANCE, MAX_VARIANCE) } else { MAX_VARIANCE };
    let d = DMat4::from_diagonal(glam::DVec4::new(inv(l[0]), inv(l[1]), inv(l[2]), inv(l[3])));
    symmetrize(v * d * v.transpose())
}

/// Travel matrix `A` of the primal coordinates over a distance `d`:
/// `x' = x + d θ`, `y' = y + d φ` (angles unchanged).
pub fn travel_matrix(d: f64) -> DMat4 {
    let d = d.clamp(-MAX_DISTANCE, MAX_DISTANCE);
    rows([[1.0, 0.0, d, 0.0], [0.0, 1.0, 0.0, d], [0.0, 0.0, 1.0, 0.0], [0.0, 0.0, 0.0, 1.0]])
}

impl Covariance4 {
    /// The zero spectrum covariance (and zero inverse): no information.
    pub const ZERO: Self = Self { sigma: DMat4::ZERO, sigma_inv: DMat4::ZERO };

    /// From a spectrum covariance `Σ`; its inverse is the clamped
    /// pseudo-inverse ([`pinv_clamped`]).
    pub fn from_spectrum(sigma: DMat4) -> Self {
        let sigma = symmetrize(sigma);
        Self { sigma, sigma_inv: pinv_clamped(sigma) }
    }

    /// From the primal (space, angle) covariance `P` of a Gaussian footprint
    /// (units length², radian²): `Σ⁻¹ = 4π² P` exactly and `Σ` its clamped
    /// pseudo-inverse.
    pub fn from_primal(p: DMat4) -> Self {
        let sigma_inv = symmetrize(p) * FOUR_PI2;
        Self { sigma: pinv_clamped(sigma_inv), sigma_inv }
    }

    /// Initialisation at a pinhole camera (Belcour et al. 2017, sec. 4): the
    /// pixel filter is a Gaussian of std `(sigma_x, sigma_y)` in the image
    /// plane at unit distance from the pinhole, mapped to the ray's frame, so
    /// it is an angular std in radians; the position is exact (spatial primal
    /// variance 0, i.e. an infinitely wide spatial spectrum, clamped to
    /// [`MAX_VARIANCE`] in [`Self::sigma`]). Primal `P = diag(0, 0, σx², σy²)`;
    /// the spectrum's angular std is `1/(2π σ)`.
    pub fn from_pixel_footprint(sigma_x: f64, sigma_y: f64) -> Self {
        Self::from_primal(DMat4::from_diagonal(glam::DVec4::new(0.0, 0.0, sigma_x * sigma_x, sigma_y * sigma_y)))
    }

    /// Applies the primal linear map `A` (with `A⁻¹` given):
    /// `Σ' = A⁻ᵀ Σ A⁻¹`, `Σ'⁻¹ = A Σ⁻¹ Aᵀ`.
    pub fn apply(&self, a: DMat4, a_inv: DMat4) -> Self {
        Self {
            sigma: clamp_entries(symmetrize(a_inv.transpose() * self.sigma * a_inv)),
            sigma_inv: clamp_entries(symmetrize(a * self.sigma_inv * a.transpose())),
        }
    }

    /// Free-space transport over a distance `d` (Belcour 2013, sec. 4,
    /// "travel"). Primal: `x' = x + d θ`, `y' = y + d φ`. In the spectrum the
    /// angular frequencies are sheared by the spatial ones:
    /// `Σ' = T Σ Tᵀ` with `T = A⁻ᵀ = [[1,0,0,0],[0,1,0,0],[−d,0,1,0],[0,−d,0,1]]`
    /// (rows), i.e. `Ωθ' = Ωθ − d Ωx`. (Written `TᵀΣT` in the papers with their
    /// transposed `T`.) The frame is unchanged; `d` is clamped to
    /// `±MAX_DISTANCE`.
    pub fn travel(&self, d: f64) -> Self {
        self.apply(travel_matrix(d), travel_matrix(-d))
    }

    /// Rotation of the frame around the ray by `angle` (Belcour 2013, sec.
    /// 4.2.2): `e1' = cos a e1 + sin a e2`, `e2' = −sin a e1 + cos a e2`.
    /// Primal `A = diag(R, R)` with `R = [[c, s], [−s, c]]`, which is
    /// orthogonal, so `Σ' = A Σ Aᵀ` as well.
    pub fn rotate(&self, angle: f64) -> Self {
        let (s, c) = angle.sin_cos();
        let a = rows([[c, s, 0.0, 0.0], [-s, c, 0.0, 0.0], [0.0, 0.0, c, s], [0.0, 0.0, -s, c]]);
        self.apply(a, a.transpose())
    }

    /// Projection onto the tangent plane of a surface whose normal makes an
    /// angle θ with the ray (Belcour 2013, sec. 4). The frame must have
    /// `e1` in the plane of incidence (the tilt direction) and `e2` in the
    /// tangent plane; `x` becomes the coordinate along the tangent direction
    /// of `e1` and `y` along `e2`. Primal: `x' = x / cos θ` (the footprint is
    /// stretched by `1/cos θ` along the tilt), angles unchanged; spectrum: the
    /// spatial frequency `Ωx` is scaled by `cos θ`:
    /// `Σ' = D Σ D`, `D = diag(cos θ, 1, 1, 1)`. `|cos θ|` is clamped to
    /// `[MIN_COS, 1]`.
    pub fn project(&self, cos_theta: f64) -> Self {
        let c = clamp_cos(cos_theta);
        let a = DMat4::from_diagonal(glam::DVec4::new(1.0 / c, 1.0, 1.0, 1.0));
        let a_inv = DMat4::from_diagonal(glam::DVec4::new(c, 1.0, 1.0, 1.0));
        self.apply(a, a_inv)
    }

    /// The inverse of [`Self::project`]: from the tangent plane to the plane
    /// orthogonal to the (leaving) ray, whose direction makes an angle θ with
    /// the normal: `x' = x cos θ`, `Σ' = D⁻¹ Σ D⁻¹`.
    pub fn unproject(&self, cos_theta: f64) -> Self {
        let c = clamp_cos(cos_theta);
        let a = DMat4::from_diagonal(glam::DVec4::new(c, 1.0, 1.0, 1.0));
        let a_inv = DMat4::from_diagonal(glam::DVec4::new(1.0 / c, 1.0, 1.0, 1.0));
        self.apply(a, a_inv)
    }

    /// Curvature of a mirror-like reflection, in the tangent plane, with the
    /// principal directions along `(x, y)` and principal curvatures
    /// `(k1, k2)` (Belcour 2013, sec. 4, "curvature"). Same as
    /// [`Self::curvature_tensor`] with `K = diag(k1, k2)`.
    pub fn curvature(&self, k1: f64, k2: f64) -> Self {
        self.curvature_tensor(DMat2::from_diagonal(DVec2::new(k1, k2)))
    }

    /// Curvature of a reflection with the symmetric curvature tensor (the
    /// Hessian of the surface height over the tangent plane) `K`, to be
    /// applied after [`Self::mirror`], in the outgoing frame. The normal tilts
    /// by `K u` at tangent offset `u` and a reflected direction turns by twice
    /// the tilt of the normal, so the primal map is the angular shear
    /// `θ' = θ − 2 K u` (angle-space coupling `−2K`); in the spectrum the
    /// spatial frequencies are sheared by the angular ones:
    /// `Σ' = C Σ Cᵀ`, `C = [[I, 2K], [0, I]]`. Sign: `K` positive when the
    /// surface is concave as seen from the ray (a focusing mirror: a sphere
    /// of radius `R` seen from inside has `K = I/R` and focal length `R/2`).
    /// Entries of `K` are clamped to `±MAX_CURVATURE`.
    /// First order, exact at normal incidence; at oblique incidence the
    /// turn out of the plane of incidence is really `2 cos θ` times the tilt,
    /// which this operator (like the paper's) ignores
    /// ([`Self::reflection_curvature`] does not).
    pub fn curvature_tensor(&self, k: DMat2) -> Self {
        self.angular_shear(k * 2.0)
    }

    /// [`Self::curvature_tensor`] with the exact first-order turn of a
    /// mirror reflection at incidence angle θ (`cos_theta`, clamped as in
    /// the projections): the reflected direction turns by twice the tilt of
    /// the normal in the plane of incidence (`x`) and by `2 cos θ` times it
    /// across (`y`), so `θ' = θ − G K u` with `G = diag(2, 2 cos θ)`. The
    /// twin of the GPU's mirror bounce (glsl/lib/covariance.glsl, bounceJacobian);
    /// equal to [`Self::curvature_tensor`] at normal incidence.
    pub fn reflection_curvature(&self, k: DMat2, cos_theta: f64) -> Self {
        let g = DMat2::from_diagonal(DVec2::new(2.0, 2.0 * clamp_cos(cos_theta)));
        self.angular_shear(g * k)
    }

    /// The primal angular shear `θ' = θ − M u` (M: 2 x 2, entries clamped to
    /// `±2 MAX_CURVATURE`); in the spectrum `Σ' = C Σ Cᵀ`, `C = [[I, Mᵀ], [0, I]]`.
    fn angular_shear(&self, m: DMat2) -> Self {
        let bound = 2.0 * MAX_CURVATURE;
        let m = DMat2::from_cols_array(&m.to_cols_array().map(|v| v.clamp(-bound, bound)));
        let shear = |f: f64| {
            rows([
                [1.0, 0.0, 0.0, 0.0],
                [0.0, 1.0, 0.0, 0.0],
                [f * m.x_axis.x, f * m.y_axis.x, 1.0, 0.0],
                [f * m.x_axis.y, f * m.y_axis.y, 0.0, 1.0],
            ])
        };
        self.apply(shear(-1.0), shear(1.0))
    }

    /// Reflection symmetry (Belcour 2013, sec. 4). With the outgoing frame
    /// `e1' = reflect(e1)`, `e2' = −reflect(e2)` (the reflection of the
    /// incoming frame, with `e2` flipped to keep `(e1', e2', w')`
    /// right-handed), a flat mirror maps `(x, y, θ, φ)` to `(x, −y, θ, −φ)`:
    /// `A = diag(1, −1, 1, −1)`, its own inverse. (With the left-handed
    /// reflected frame a flat mirror is the identity; the paper writes the
    /// symmetry as a flip of the angles measured in the surface frame, which
    /// is the same thing once the frame flip is accounted for.)
    pub fn mirror(&self) -> Self {
        let a = DMat4::from_diagonal(glam::DVec4::new(1.0, -1.0, 1.0, -1.0));
        self.apply(a, a)
    }

    /// BSDF convolution in angle (Belcour 2013, sec. 4): convolving the
    /// light field in angle by an isotropic Gaussian lobe of angular variance
    /// `σ²` (radian²) multiplies the spectrum by the lobe's spectrum, a
    /// Gaussian of angular std `1/(2πσ)`, infinitely wide in space. For
    /// Gaussians the product gives, on the full 4x4 matrices,
    /// `Σ'⁻¹ = Σ⁻¹ + B⁻¹` with `B⁻¹ = diag(0, 0, 4π²σ², 4π²σ²)` (the primal
    /// angular variance grows by `σ²`; the papers' angular-block form is this
    /// with the coupling to space dropped). `Σ'` is computed without any
    /// inversion by the Woodbury identity
    /// `Σ' = Σ − Σ U (I + Uᵀ Σ U)⁻¹ Uᵀ Σ`, `U = 2πσ [e3 e4]`, whose middle
    /// factor is ≥ I, so always well-conditioned. `σ²` is clamped to
    /// `[0, MAX_VARIANCE]`. `σ² = 0` (a perfect mirror) leaves Σ unchanged.
    /// If the update overflows (entries near `MAX_ENTRY`), `Σ'` falls back to
    /// the clamped pseudo-inverse of `Σ'⁻¹` ([`pinv_clamped`]).
    pub fn bsdf_bandlimit(&self, angular_variance: f64) -> Self {
        let v = angular_variance.clamp(0.0, MAX_VARIANCE);
        let s2 = FOUR_PI2 * v; // (2πσ)²
        let mut sigma_inv = self.sigma_inv;
        sigma_inv.z_axis.z += s2;
        sigma_inv.w_axis.w += s2;
        // Columns 2, 3 of Σ (= rows, Σ symmetric) and its angular block.
        let m = self.sigma;
        let d = DMat2::from_cols(DVec2::new(m.z_axis.z, m.z_axis.w), DVec2::new(m.w_axis.z, m.w_axis.w));
        let mid = (DMat2::IDENTITY + d * s2).inverse();
        let mut out = m;
        let c2 = m.z_axis;
        let c3 = m.w_axis;
        for i in 0..4 {
            for j in 0..4 {
                let a = DVec2::new(c2[i], c3[i]);
                let b = DVec2::new(c2[j], c3[j]);
                out.col_mut(j)[i] -= s2 * a.dot(mid * b);
            }
        }
        let sigma_inv = clamp_entries(symmetrize(sigma_inv));
        if out.is_finite() {
            Self { sigma: clamp_entries(symmetrize(out)), sigma_inv }
        } else {
            // Only for entries near MAX_ENTRY, where `I + UᵀΣU` overflows.
            Self { sigma: pinv_clamped(sigma_inv), sigma_inv }
        }
    }

    /// Refraction through a smooth interface (Belcour 2013, appendix), in the
    /// standard first-order form; `eta = η_i / η_t`, `cos_i`, `cos_t` the
    /// cosines of the incident and transmitted directions with the normal.
    /// The frame must have `e1` in the plane of incidence; the transmitted
    /// frame keeps `e2` and has `e1'` in the plane of incidence, continuing
    /// the sense of `e1` across the interface. Steps: [`Self::project`] by
    /// `cos_i`; Snell's law `η_i sin θ_i = η_t sin θ_t` differentiated gives
    /// the angular scale `θ' = η cos_i / cos_t · θ` in the plane of incidence
    /// and `φ' = η φ` across it; [`Self::unproject`] by `cos_t`. Cosines are
    /// clamped as in the projections and `eta` to `[MIN_COS, 1/MIN_COS]`.
    /// Curvature of the interface is not included.
    pub fn refract(&self, eta: f64, cos_i: f64, cos_t: f64) -> Self {
        let eta = eta.abs().clamp(MIN_COS, 1.0 / MIN_COS);
        let (ci, ct) = (clamp_cos(cos_i), clamp_cos(cos_t));
        let st = eta * ci / ct;
        let a = DMat4::from_diagonal(glam::DVec4::new(1.0, 1.0, st, eta));
        let a_inv = DMat4::from_diagonal(glam::DVec4::new(1.0, 1.0, 1.0 / st, 1.0 / eta));
        self.project(ci).apply(a, a_inv).unproject(ct)
    }

    /// The spatial footprint: the covariance (length²) of the Gaussian filter
    /// in space over which the appearance should be averaged, i.e. the spatial
    /// block of the primal covariance `P = Σ⁻¹/(4π²)` — the marginal over all
    /// angles, equivalently the inverse of the slice `Ωθ = Ωφ = 0` of the
    /// spectrum. (The inverse of the spatial block of `Σ` alone would be the
    /// footprint at a *fixed* angle, which stays a point for a pinhole camera
    /// and is not what a surface sees.)
    /// The diagonal is clamped to `≥ 0` (rounding at a focus can make a zero
    /// variance slightly negative).
    pub fn spatial_footprint(&self) -> DMat2 {
        let p = self.sigma_inv * (1.0 / FOUR_PI2);
        DMat2::from_cols(DVec2::new(p.x_axis.x.max(0.0), p.x_axis.y), DVec2::new(p.y_axis.x, p.y_axis.y.max(0.0)))
    }

    /// The angular footprint (radian²): the angular block of `P = Σ⁻¹/(4π²)`,
    /// diagonal clamped to `≥ 0`.
    pub fn angular_footprint(&self) -> DMat2 {
        let p = self.sigma_inv * (1.0 / FOUR_PI2);
        DMat2::from_cols(DVec2::new(p.z_axis.z.max(0.0), p.z_axis.w), DVec2::new(p.w_axis.z, p.w_axis.w.max(0.0)))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn pinv_of_spd_is_inverse() {
        let a = rows([[4.0, 1.0, 0.5, 0.0], [1.0, 3.0, 0.2, 0.1], [0.5, 0.2, 2.0, 0.3], [0.0, 0.1, 0.3, 1.0]]);
        let err = (pinv_clamped(a) * a - DMat4::IDENTITY).to_cols_array().iter().fold(0.0f64, |m, v| m.max(v.abs()));
        println!("pinv error {err:e}");
        assert!(err < 1e-12);
    }

    #[test]
    fn pinv_clamps_singular() {
        let p = pinv_clamped(DMat4::ZERO);
        assert_eq!(p, DMat4::IDENTITY * MAX_VARIANCE);
    }
}
