//! Chi-square tests of the Henyey–Greenstein sampler (`sampling::phase`, the
//! CPU twin of `glsl/lib/media.glsl`) against its density, for isotropic,
//! forward, strongly forward and backward scattering, with travel
//! directions off the binning axis (`sampling::chi2` bins the whole sphere);
//! likewise the halo sampler and the mixture of a path's first scattering
//! event (`sample_halo`, `sample_scatter`).
//! A test fails below the Šidák-corrected level for a family-wise level of
//! 0.01 over the [`CHI2_TESTS`] tests, or when the density's integral
//! differs from the fraction of valid samples by more than 1e-2.

use glam::DVec3;
use quadray::model::sampling::chi2::{self, chi2_test, Chi2Config};
use quadray::model::sampling::phase::{
    halo_pdf, hg_pdf, sample_halo, sample_hg, sample_scatter, scatter_pdf, HALO_SHARE,
};

/// Tests in this file: 5 values of g, the halo, and 3 mixtures.
const CHI2_TESTS: usize = 9;
const FAMILY_LEVEL: f64 = 0.01;

#[test]
fn henyey_greenstein_sampling_matches_its_density() {
    let level = chi2::sidak_level(FAMILY_LEVEL, CHI2_TESTS);
    let d = DVec3::new(0.3, -0.5, 0.81).normalize();
    for g in [0.0, 0.3, -0.6, 0.8, 0.95] {
        // Bin around the travel direction so that forward lobes are resolved.
        let config = Chi2Config { axis: d, ..Chi2Config::default() };
        let report = chi2_test(&config, |u| Some(sample_hg(g, d, u[0], u[1])), |w| hg_pdf(g, d.dot(w)));
        report.assert_passes(&format!("Henyey-Greenstein g = {g}"), level);
    }
}

#[test]
fn the_harness_rejects_a_wrong_g() {
    let d = DVec3::Z;
    let config = Chi2Config { samples: 200_000, ..Chi2Config::default() };
    let report = chi2_test(&config, |u| Some(sample_hg(0.5, d, u[0], u[1])), |w| hg_pdf(0.45, d.dot(w)));
    assert!(!report.passed(1e-6), "sampling g = 0.5 against the density of g = 0.45 must fail");
}

#[test]
fn halo_sampling_matches_its_density() {
    let level = chi2::sidak_level(FAMILY_LEVEL, CHI2_TESTS);
    let a = DVec3::new(-0.4, 0.2, 0.89).normalize();
    // The density's 1/sin θ pole is at the axis: cells integrated over θ.
    let config = Chi2Config { axis: a, polar: true, ..Chi2Config::default() };
    let report = chi2_test(&config, |u| Some(sample_halo(a, u[0], u[1])), |w| halo_pdf(a, w));
    report.assert_passes("halo", level);
}

#[test]
fn first_scattering_mixture_matches_its_density() {
    let level = chi2::sidak_level(FAMILY_LEVEL, CHI2_TESTS);
    let d = DVec3::new(0.3, -0.5, 0.81).normalize();
    // The halo densities' poles at the binning axis and its opposite, where
    // the cells integrated over θ cancel them (two lights on one line
    // through the scattering point, one on either side).
    let one = [DVec3::new(-0.4, 0.2, 0.89).normalize()];
    let two = [one[0], -one[0]];
    for (g, axes, share) in [(0.5, &one[..], HALO_SHARE), (-0.3, &two[..], HALO_SHARE), (0.9, &two[..], 0.15)] {
        let config = Chi2Config { axis: one[0], polar: true, ..Chi2Config::default() };
        let report =
            chi2_test(&config, |u| Some(sample_scatter(g, d, axes, share, u)), |w| scatter_pdf(g, d, axes, share, w));
        report.assert_passes(&format!("mixture g = {g}, {} lights, share {share}", axes.len()), level);
    }
}
