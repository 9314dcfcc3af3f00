//! Closed-form checks of the covariance-tracing operators (`src/model/covariance.rs`).

use glam::{DMat2, DMat4, DVec4};
use quadray::model::covariance::Covariance4;

/// Largest |a - b| over the entries, relative to the largest |b| entry (or 1).
fn rel_err4(a: DMat4, b: DMat4) -> f64 {
    let scale = b.to_cols_array().iter().fold(1.0f64, |m, v| m.max(v.abs()));
    let d = (a - b).to_cols_array().iter().fold(0.0f64, |m, v| m.max(v.abs()));
    d / scale
}

fn rel_err2(a: DMat2, b: DMat2) -> f64 {
    let scale = b.to_cols_array().iter().fold(0.0f64, |m, v| m.max(v.abs())).max(1e-300);
    let d = (a - b).to_cols_array().iter().fold(0.0f64, |m, v| m.max(v.abs()));
    d / scale
}

/// A generic, full-rank primal covariance with space-angle and x-y coupling.
fn generic() -> Covariance4 {
    let l = DMat4::from_cols_array_2d(&[
        [0.3, 0.05, 0.02, -0.01],
        [0.0, 0.2, 0.01, 0.03],
        [0.0, 0.0, 0.04, 0.005],
        [0.0, 0.0, 0.0, 0.03],
    ]);
    Covariance4::from_primal(l * l.transpose())
}

fn all_finite(c: &Covariance4) -> bool {
    c.sigma.to_cols_array().iter().chain(c.sigma_inv.to_cols_array().iter()).all(|v| v.is_finite())
}

fn std_xy(c: &Covariance4) -> (f64, f64) {
    let f = c.spatial_footprint();
    (f.x_axis.x.sqrt(), f.y_axis.y.sqrt())
}

#[test]
fn travel_there_and_back_is_identity() {
    let c = generic();
    for d in [0.1, 0.7, 3.0, 10.0, -5.0] {
        let r = c.travel(d).travel(-d);
        let (e, ei) = (rel_err4(r.sigma, c.sigma), rel_err4(r.sigma_inv, c.sigma_inv));
        println!("travel({d}) then travel({}) : rel err Σ {e:e}, Σ⁻¹ {ei:e}", -d);
        assert!(e < 1e-12 && ei < 1e-12);
    }
}

#[test]
fn mirror_twice_is_identity() {
    let c = generic();
    let r = c.mirror().mirror();
    let (e, ei) = (rel_err4(r.sigma, c.sigma), rel_err4(r.sigma_inv, c.sigma_inv));
    println!("mirror twice: rel err Σ {e:e}, Σ⁻¹ {ei:e}");
    assert!(e == 0.0 && ei == 0.0);
}

#[test]
fn rotation_there_and_back_and_quarter_turn() {
    let c = generic();
    let r = c.rotate(0.7).rotate(-0.7);
    let e = rel_err4(r.sigma, c.sigma).max(rel_err4(r.sigma_inv, c.sigma_inv));
    println!("rotate(0.7) then rotate(-0.7): rel err {e:e}");
    assert!(e < 1e-14);
    let q = c.rotate(std::f64::consts::FRAC_PI_2);
    let (f, g) = (c.spatial_footprint(), q.spatial_footprint());
    let e = ((g.x_axis.x - f.y_axis.y).abs() + (g.y_axis.y - f.x_axis.x).abs()) / f.x_axis.x;
    println!("quarter turn swaps the footprint axes: rel err {e:e}");
    assert!(e < 1e-14);
}

#[test]
fn flat_mirror_unfolds() {
    let c = generic();
    let flip = DMat2::from_diagonal(glam::DVec2::new(1.0, -1.0));
    for (d1, d2) in [(1.0, 2.0), (0.3, 7.0), (5.0, 0.5)] {
        let folded = c.travel(d2).mirror().travel(d1).spatial_footprint();
        let unfolded = c.travel(d1 + d2).spatial_footprint();
        let e = rel_err2(folded, flip * unfolded * flip);
        println!("travel({d2}) mirror travel({d1}) vs travel({}): rel err {e:e}", d1 + d2);
        assert!(e < 1e-12);
    }
}

#[test]
fn pinhole_footprint_grows_linearly() {
    let (ax, ay) = (1e-3, 2.5e-3);
    let c = Covariance4::from_pixel_footprint(ax, ay);
    for d in [0.01, 0.5, 1.0, 10.0, 1e3, 1e5] {
        let (sx, sy) = std_xy(&c.travel(d));
        let (ex, ey) = ((sx / (d * ax) - 1.0).abs(), (sy / (d * ay) - 1.0).abs());
        println!("d = {d}: std ({sx:e}, {sy:e}), expected ({:e}, {:e}), rel err ({ex:e}, {ey:e})", d * ax, d * ay);
        assert!(ex < 1e-9 && ey < 1e-9);
    }
}

#[test]
fn rough_lobe_widens_the_footprint() {
    let alpha = 2e-3;
    let d = 4.0;
    let c = Covariance4::from_pixel_footprint(alpha, alpha).travel(3.0);
    let mirror = std_xy(&c.travel(d)).0;
    let mut last = mirror;
    for rough in [1e-9, 1e-3, 1e-2, 5e-2, 0.1, 0.3] {
        let b = c.bsdf_bandlimit(rough * rough);
        let s = std_xy(&b.travel(d)).0;
        // Closed form: primal x = 3θ at the surface, θ' = θ + ε (ε the lobe),
        // after d: x = 7θ + 4ε.
        let expect = ((7.0 * alpha).powi(2) + (d * rough).powi(2)).sqrt();
        println!("roughness {rough}: std {s:e}, closed form {expect:e}, mirror case {mirror:e}");
        assert!((s / expect - 1.0).abs() < 1e-12);
        assert!(s >= last);
        last = s;
        if rough < 1e-6 {
            assert!((s / mirror - 1.0).abs() < 1e-12);
        }
    }
    // The spectral side (Woodbury update) stays the inverse of the primal side.
    let g = generic().bsdf_bandlimit(0.01);
    let e = rel_err4(g.sigma * g.sigma_inv, DMat4::IDENTITY);
    println!("bandlimited generic: |Σ Σ⁻¹ - I| = {e:e}");
    assert!(e < 1e-10);
}

#[test]
fn projection_round_trip_and_stretch() {
    let c = generic();
    for cos in [1.0, 0.8, 0.3, 0.05] {
        let r = c.project(cos).unproject(cos);
        let e = rel_err4(r.sigma, c.sigma).max(rel_err4(r.sigma_inv, c.sigma_inv));
        let (sx0, sy0) = std_xy(&c);
        let (sx, sy) = std_xy(&c.project(cos));
        let (ex, ey) = ((sx * cos / sx0 - 1.0).abs(), (sy / sy0 - 1.0).abs());
        println!(
            "cos {cos}: round trip rel err {e:e}; stretch x {:.6} (1/cos = {:.6}), y {:.6}",
            sx / sx0,
            1.0 / cos,
            sy / sy0
        );
        assert!(e < 1e-12 && ex < 1e-12 && ey < 1e-12);
    }
}

#[test]
fn spherical_mirror_is_a_thin_mirror_of_focal_length_half_radius() {
    // A point source seen through a concave mirror of radius R at distance s0:
    // after a further distance t the beam has std α |s0 + t (1 − 2 s0 / R)|,
    // zero at the image distance 1/t = 2/R − 1/s0.
    let alpha = 1e-2;
    for (radius, s0) in [(2.0, 3.0), (1.0, 5.0), (10.0, 2.0)] {
        let at_mirror =
            Covariance4::from_pixel_footprint(alpha, alpha).travel(s0).mirror().curvature(1.0 / radius, 1.0 / radius);
        for t in [0.5, 1.0, 4.0] {
            let s = std_xy(&at_mirror.travel(t));
            let expect = alpha * (s0 + t * (1.0 - 2.0 * s0 / radius)).abs();
            println!("R {radius}, s0 {s0}, t {t}: std ({:e}, {:e}), thin mirror {expect:e}", s.0, s.1);
            assert!((s.0 / expect - 1.0).abs() < 1e-9 && (s.1 / expect - 1.0).abs() < 1e-9);
        }
        let image = 1.0 / (2.0 / radius - 1.0 / s0);
        if image > 0.0 {
            // The variance cancels to rounding level (~1e-16 relative), so the
            // std only to its square root.
            let v = at_mirror.travel(image).spatial_footprint().x_axis.x;
            let v0 = (alpha * s0).powi(2);
            println!(
                "R {radius}, s0 {s0}: image at {image}, variance there {v:e} = {:e} × variance at the mirror",
                v / v0
            );
            assert!(v < 1e-14 * v0);
        }
    }
    // A collimated beam focuses at R/2 (concave) and spreads from a virtual
    // focus at R/2 behind a convex mirror.
    let sigma = 0.1;
    let beam = Covariance4::from_primal(DMat4::from_diagonal(DVec4::new(sigma * sigma, sigma * sigma, 0.0, 0.0)));
    for radius in [1.0, 3.0] {
        let focus = std_xy(&beam.mirror().curvature(1.0 / radius, 1.0 / radius).travel(radius / 2.0)).0;
        let t = 2.0;
        let convex = std_xy(&beam.mirror().curvature(-1.0 / radius, -1.0 / radius).travel(t)).0;
        let expect = sigma * (1.0 + 2.0 * t / radius);
        println!("collimated, R {radius}: std at R/2 {focus:e}; convex after {t}: {convex:e} (closed form {expect:e})");
        assert!(focus < 1e-12 * sigma);
        assert!((convex / expect - 1.0).abs() < 1e-12);
    }
}

#[test]
fn refraction_round_trip_and_scales() {
    let c = generic();
    let (eta, ci) = (1.0 / 1.5, 0.6f64);
    let st = eta * (1.0 - ci * ci).sqrt();
    let ct = (1.0 - st * st).sqrt();
    let r = c.refract(eta, ci, ct).refract(1.0 / eta, ct, ci);
    let e = rel_err4(r.sigma, c.sigma).max(rel_err4(r.sigma_inv, c.sigma_inv));
    println!("refract there and back: rel err {e:e}");
    assert!(e < 1e-12);
    let same = c.refract(1.0, 0.4, 0.4);
    let e = rel_err4(same.sigma, c.sigma).max(rel_err4(same.sigma_inv, c.sigma_inv));
    println!("refract with eta 1: rel err {e:e}");
    assert!(e < 1e-12);
    // A pinhole beam: the width across the plane of incidence is unchanged,
    // along it scaled by cos_t / cos_i; the angle across is scaled by eta.
    let p = Covariance4::from_pixel_footprint(1e-2, 1e-2).travel(2.0);
    let q = p.refract(eta, ci, ct);
    let (sx0, sy0) = std_xy(&p);
    let (sx, sy) = std_xy(&q);
    let a = q.angular_footprint().y_axis.y.sqrt();
    println!(
        "refracted widths x {:.9} (cos_t/cos_i {:.9}), y {:.9}; angle across {a:e} (eta·α {:e})",
        sx / sx0,
        ct / ci,
        sy / sy0,
        eta * 1e-2
    );
    assert!(
        (sx / sx0 - ct / ci).abs() < 1e-12 && (sy / sy0 - 1.0).abs() < 1e-12 && (a / (eta * 1e-2) - 1.0).abs() < 1e-12
    );
}

#[test]
fn singular_inputs_stay_finite() {
    let cases: Vec<(&str, Covariance4)> = vec![
        ("zero", Covariance4::ZERO),
        ("zero travel 1e300", Covariance4::ZERO.travel(1e300)),
        ("generic travel 1e300", generic().travel(1e300)),
        ("generic travel -inf", generic().travel(f64::NEG_INFINITY)),
        ("pinhole 0", Covariance4::from_pixel_footprint(0.0, 0.0)),
        ("pinhole 0 travel 1e300", Covariance4::from_pixel_footprint(0.0, 0.0).travel(1e300)),
        ("from_spectrum(0)", Covariance4::from_spectrum(DMat4::ZERO)),
        ("project cos 0", generic().project(0.0)),
        ("unproject cos 0", generic().unproject(0.0)),
        ("project 0 unproject 0 travel 1e300", generic().project(0.0).unproject(0.0).travel(1e300)),
        ("bandlimit 1e300", generic().bsdf_bandlimit(1e300)),
        ("bandlimit inf on pinhole", Covariance4::from_pixel_footprint(0.0, 0.0).bsdf_bandlimit(f64::INFINITY)),
        ("curvature 1e300", generic().curvature(1e300, -1e300).travel(1e300)),
        ("refract cos 0", generic().refract(0.0, 0.0, 0.0)),
        ("refract eta inf", generic().refract(f64::INFINITY, 1.0, 0.0)),
    ];
    for (name, mut c) in cases {
        assert!(all_finite(&c), "{name}: {c:?}");
        // Repeat to check that the entry clamps prevent overflow.
        for _ in 0..20 {
            c = c.travel(1e12).project(0.0).curvature(1e12, 1e12).bsdf_bandlimit(1e12).unproject(1e-300);
        }
        let f = c.spatial_footprint();
        println!("{name}: finite {}, footprint diag ({:e}, {:e})", all_finite(&c), f.x_axis.x, f.y_axis.y);
        assert!(all_finite(&c), "{name}: {c:?}");
    }
}

#[test]
fn spectral_and_primal_sides_stay_inverse() {
    let c = generic()
        .travel(2.0)
        .rotate(0.3)
        .project(0.7)
        .mirror()
        .curvature(0.5, -0.2)
        .bsdf_bandlimit(0.02)
        .unproject(0.4)
        .refract(1.0 / 1.3, 0.9, 0.95)
        .travel(-1.5);
    let e = rel_err4(c.sigma * c.sigma_inv, DMat4::IDENTITY);
    println!("after a chain of every operator: |Σ Σ⁻¹ − I| = {e:e}");
    assert!(e < 1e-9);
}
