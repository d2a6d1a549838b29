//! Every sampler against a known correlated bivariate normal:
//! X ~ N(1, 0.5²), Y ~ N(2, 0.25²), ρ = 0.7.
//!
//! The parent population (10⁶ pairs, so the parents' own sampling noise is
//! small against the 0.02 budget) is binned 50 × 50 as in GSC 2.0; each
//! sampler then draws 10⁵ pairs and each marginal is compared with the exact
//! normal CDF. The draws' Pearson correlation must also match ρ.

use morph_dna::stats::normal_cdf;
use morph_dna::{
    AcceptanceRejection2d, Bandwidth, BicubicPdf, Descriptor, DnaTable, EnvelopeRejection2d,
    GaussianCopula, GaussianKde2d, Histogram2d, InverseCdfSampler2d, TabulatedPdf2d,
    ks_distance_to_cdf, stats::pearson,
};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use rand_distr::{Distribution, StandardNormal};

const SEED: u64 = 0x0065_7363_3230_3138;
const MX: f64 = 1.0;
const SX: f64 = 0.5;
const MY: f64 = 2.0;
const SY: f64 = 0.25;
const RHO: f64 = 0.7;
const N_PARENTS: usize = 1_000_000;
const N_DRAWS: usize = 100_000;
const KS_MAX: f64 = 0.02;

fn parents(rng: &mut impl Rng) -> (Vec<f64>, Vec<f64>) {
    (0..N_PARENTS)
        .map(|_| {
            let z1: f64 = StandardNormal.sample(rng);
            let z2: f64 = StandardNormal.sample(rng);
            (
                MX + SX * z1,
                MY + SY * (RHO * z1 + (1.0 - RHO * RHO).sqrt() * z2),
            )
        })
        .unzip()
}

/// KS of both marginals against the exact normals, and the draws' correlation.
fn check(name: &str, draws: &[(f64, f64)]) {
    let (x, y): (Vec<f64>, Vec<f64>) = draws.iter().copied().unzip();
    let kx = ks_distance_to_cdf(&x, |v| normal_cdf((v - MX) / SX)).expect("finite draws");
    let ky = ks_distance_to_cdf(&y, |v| normal_cdf((v - MY) / SY)).expect("finite draws");
    let r = pearson(&x, &y).expect("non-degenerate draws");
    #[expect(
        clippy::print_stdout,
        reason = "the acceptance numbers go into the report"
    )]
    {
        println!("{name}: KS_x = {kx:.4}, KS_y = {ky:.4}, rho = {r:.4} (seed {SEED:#x})");
    }
    assert!(kx <= KS_MAX, "{name}: KS_x = {kx}");
    assert!(ky <= KS_MAX, "{name}: KS_y = {ky}");
    assert!((r - RHO).abs() <= 0.02, "{name}: rho = {r}");
}

#[test]
fn every_sampler_reproduces_a_correlated_bivariate_normal() {
    #[expect(clippy::print_stdout, reason = "seeded tests print their seed")]
    {
        println!("seed {SEED:#x}");
    }
    let mut rng = ChaCha8Rng::seed_from_u64(SEED);
    let (xs, ys) = parents(&mut rng);
    let hist = Histogram2d::new(&xs, &ys, (50, 50), None, None).expect("valid histogram");
    let bicubic = BicubicPdf::from_histogram(&hist, 8).expect("valid pdf");

    // The seed's method: acceptance-rejection on the bicubic PDF.
    let ar = AcceptanceRejection2d::new(bicubic.clone()).expect("bounded");
    let draws: Vec<_> = (0..N_DRAWS).map(|_| ar.sample(&mut rng)).collect();
    check("acceptance-rejection (bicubic)", &draws);

    // Same target, per-bin envelope.
    let env = EnvelopeRejection2d::new(bicubic.clone()).expect("bounded");
    let draws: Vec<_> = (0..N_DRAWS).map(|_| env.sample(&mut rng)).collect();
    check("envelope rejection (bicubic)", &draws);
    #[expect(clippy::print_stdout, reason = "numbers for the report")]
    {
        println!(
            "expected proposals per draw: global bound {:.2}, per-bin envelope {:.2}",
            ar.expected_trials(),
            env.expected_trials()
        );
    }

    // Exact inverse CDF on the bicubic PDF tabulated 8× finer.
    let inverse =
        InverseCdfSampler2d::new(&bicubic.tabulate(8).expect("valid table")).expect("valid");
    let draws: Vec<_> = (0..N_DRAWS).map(|_| inverse.sample(&mut rng)).collect();
    check("inverse CDF (bicubic, 400 x 400)", &draws);

    // Exact inverse CDF on the raw histogram (piecewise constant).
    let raw = InverseCdfSampler2d::new(&TabulatedPdf2d::from_histogram(&hist).expect("valid"))
        .expect("valid");
    let draws: Vec<_> = (0..N_DRAWS).map(|_| raw.sample(&mut rng)).collect();
    check("inverse CDF (histogram, 50 x 50)", &draws);

    // Smoother alternative: Gaussian KDE, Scott's bandwidth, smoothed bootstrap.
    let kde = GaussianKde2d::fit(&xs, &ys, Bandwidth::Scott).expect("valid kde");
    let draws: Vec<_> = (0..N_DRAWS).map(|_| kde.sample(&mut rng)).collect();
    check("Gaussian KDE (Scott)", &draws);

    // Joint model: Gaussian copula over the empirical marginals.
    let table = DnaTable::from_columns(
        vec![
            Descriptor::MinPrincipalDimension,
            Descriptor::VolumeSurfaceRatio,
        ],
        vec![xs, ys],
    )
    .expect("valid table");
    let copula = GaussianCopula::fit(&table).expect("valid copula");
    let draws: Vec<_> = (0..N_DRAWS)
        .map(|_| {
            let v = copula.sample(&mut rng);
            (v[0], v[1])
        })
        .collect();
    check("Gaussian copula", &draws);

    // Conditional draws of Y given X = x0 against the exact conditional normal.
    let x0 = MX + 0.5 * SX;
    let m = MY + RHO * SY / SX * (x0 - MX);
    let s = SY * (1.0 - RHO * RHO).sqrt();
    let cond: Vec<f64> = (0..N_DRAWS)
        .map(|_| {
            inverse
                .sample_y_given_x(x0, &mut rng)
                .expect("column has mass")
        })
        .collect();
    let k = ks_distance_to_cdf(&cond, |v| normal_cdf((v - m) / s)).expect("finite");
    let cond: Vec<f64> = (0..N_DRAWS)
        .map(|_| {
            copula
                .sample_conditional(&[(Descriptor::MinPrincipalDimension, x0)], &mut rng)
                .expect("valid condition")[1]
        })
        .collect();
    let kc = ks_distance_to_cdf(&cond, |v| normal_cdf((v - m) / s)).expect("finite");
    let cond: Vec<f64> = (0..N_DRAWS)
        .map(|_| {
            ar.sample_y_given_x(x0, 10_000, &mut rng)
                .expect("slice has mass")
        })
        .collect();
    let ka = ks_distance_to_cdf(&cond, |v| normal_cdf((v - m) / s)).expect("finite");
    #[expect(
        clippy::print_stdout,
        reason = "the acceptance numbers go into the report"
    )]
    {
        println!(
            "conditional Y | X = {x0}: inverse CDF KS = {k:.4}, copula KS = {kc:.4}, \
             acceptance-rejection KS = {ka:.4}"
        );
    }
    assert!(ka <= KS_MAX, "acceptance-rejection conditional KS = {ka}");
    assert!(k <= KS_MAX, "inverse-CDF conditional KS = {k}");
    assert!(kc <= KS_MAX, "copula conditional KS = {kc}");
}

/// A bounded-support oracle where the density does not vanish at the edges
/// (it tests the bicubic PDF's edge handling): f(x, y) = x + y on [0, 1]²,
/// marginals F(t) = (t² + t)/2.
#[test]
fn samplers_reproduce_a_density_with_mass_at_the_edges() {
    let seed = SEED + 1;
    #[expect(clippy::print_stdout, reason = "seeded tests print their seed")]
    {
        println!("seed {seed:#x}");
    }
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let (xs, ys): (Vec<f64>, Vec<f64>) = (0..N_PARENTS)
        .map(|_| {
            let (u, v): (f64, f64) = (rng.random(), rng.random());
            let x = 0.5 * (-1.0 + (1.0 + 8.0 * u).sqrt());
            let y = -x + (x * x + 2.0 * v * (x + 0.5)).sqrt();
            (x, y)
        })
        .unzip();
    let hist = Histogram2d::new(&xs, &ys, (50, 50), Some((0.0, 1.0)), Some((0.0, 1.0)))
        .expect("valid histogram");
    let bicubic = BicubicPdf::from_histogram(&hist, 8).expect("valid pdf");
    let ar = AcceptanceRejection2d::new(bicubic.clone()).expect("bounded");
    let inverse =
        InverseCdfSampler2d::new(&bicubic.tabulate(8).expect("valid table")).expect("valid");
    let env = EnvelopeRejection2d::new(bicubic.clone()).expect("bounded");
    let cdf = |t: f64| 0.5 * (t * t + t);
    // Pearson correlation of f = x + y on the unit square: −1/11.
    let rho = -1.0 / 11.0;
    for (name, draws) in [
        (
            "acceptance-rejection (bicubic)",
            (0..N_DRAWS)
                .map(|_| ar.sample(&mut rng))
                .collect::<Vec<_>>(),
        ),
        (
            "inverse CDF (bicubic)",
            (0..N_DRAWS).map(|_| inverse.sample(&mut rng)).collect(),
        ),
        (
            "envelope rejection (bicubic)",
            (0..N_DRAWS).map(|_| env.sample(&mut rng)).collect(),
        ),
    ] {
        let (x, y): (Vec<f64>, Vec<f64>) = draws.iter().copied().unzip();
        let kx = ks_distance_to_cdf(&x, cdf).expect("finite");
        let ky = ks_distance_to_cdf(&y, cdf).expect("finite");
        let r = pearson(&x, &y).expect("non-degenerate");
        #[expect(
            clippy::print_stdout,
            reason = "the acceptance numbers go into the report"
        )]
        {
            println!(
                "x + y on [0,1]^2, {name}: KS_x = {kx:.4}, KS_y = {ky:.4}, rho = {r:.4} (exact {rho:.4})"
            );
        }
        assert!(kx <= KS_MAX && ky <= KS_MAX, "{name}: {kx} {ky}");
        assert!((r - rho).abs() <= 0.02, "{name}: rho = {r}");
    }
}
