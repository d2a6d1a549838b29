//! Population-level oracles: correlation coefficients of a known normal
//! population, the copula's joint model of three descriptors, determinism of
//! seeded sampling, and invariants under arbitrary input (proptest).

use morph_dna::stats::{normal_cdf, pearson, spearman};
use morph_dna::{
    CorrelationMatrix, CorrelationMethod, Descriptor, DnaTable, GaussianCopula, Histogram2d,
    InverseCdfSampler2d, TabulatedPdf2d, compare_populations, correlation_matrix, ks_distance,
    ks_distance_to_cdf, wasserstein1,
};
use proptest::prelude::*;
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use rand_distr::{Distribution, StandardNormal};

use Descriptor::{AspectRatio, MinPrincipalDimension, Roundness, VolumeSurfaceRatio};

/// Medina 2018, Table 1 (Pearson), in the order of
/// [`Descriptor::MEDINA_2018_TABLE_1`]: a valid correlation matrix to draw from.
const TABLE_1: [f64; 16] = [
    1.00, -0.13, 0.22, 0.51, //
    -0.13, 1.00, 0.88, -0.36, //
    0.22, 0.88, 1.00, -0.34, //
    0.51, -0.36, -0.34, 1.00,
];

/// Draws `n` vectors of N(0, R) by a plain Cholesky factor of `r` (4 × 4).
fn normal_population(r: &[f64; 16], n: usize, rng: &mut ChaCha8Rng) -> Vec<Vec<f64>> {
    let k = 4;
    let mut l = [0.0; 16];
    for j in 0..k {
        let d = r[j * k + j] - (0..j).map(|p| l[j * k + p] * l[j * k + p]).sum::<f64>();
        assert!(d > 0.0, "table 1 must be positive definite");
        l[j * k + j] = d.sqrt();
        for i in (j + 1)..k {
            let s = r[i * k + j] - (0..j).map(|p| l[i * k + p] * l[j * k + p]).sum::<f64>();
            l[i * k + j] = s / l[j * k + j];
        }
    }
    let mut cols: Vec<Vec<f64>> = (0..k).map(|_| Vec::with_capacity(n)).collect();
    for _ in 0..n {
        let e: Vec<f64> = (0..k).map(|_| StandardNormal.sample(rng)).collect();
        for (i, col) in cols.iter_mut().enumerate() {
            col.push((0..=i).map(|p| l[i * k + p] * e[p]).sum());
        }
    }
    cols
}

#[test]
fn spearman_of_a_bivariate_normal_matches_its_closed_form() {
    let seed = 51;
    #[expect(clippy::print_stdout, reason = "seeded tests print their seed")]
    {
        println!("seed {seed}");
    }
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let rho: f64 = 0.7;
    let (x, y): (Vec<f64>, Vec<f64>) = (0..200_000)
        .map(|_| {
            let z1: f64 = StandardNormal.sample(&mut rng);
            let z2: f64 = StandardNormal.sample(&mut rng);
            (z1, rho * z1 + (1.0 - rho * rho).sqrt() * z2)
        })
        .unzip();
    // Pearson 1907: ρ_S = (6/π) asin(ρ/2) for a bivariate normal.
    let rho_s = 6.0 / std::f64::consts::PI * (rho / 2.0).asin();
    // Standard errors at n = 2·10⁵ are ≈ 1.2·10⁻³; allow 4 of them.
    assert!((pearson(&x, &y).expect("ok") - rho).abs() < 5e-3);
    assert!((spearman(&x, &y).expect("ok") - rho_s).abs() < 5e-3);
    // Spearman is invariant under monotone transforms; Pearson is not.
    let ex: Vec<f64> = x.iter().map(|v| v.exp()).collect();
    assert!((spearman(&ex, &y).expect("ok") - rho_s).abs() < 5e-3);
    assert!((pearson(&ex, &y).expect("ok") - rho).abs() > 0.05);
}

#[test]
fn copula_reproduces_table_1_and_the_marginals() {
    let seed = 52;
    #[expect(clippy::print_stdout, reason = "seeded tests print their seed")]
    {
        println!("seed {seed}");
    }
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let cols = normal_population(&TABLE_1, 50_000, &mut rng);
    // Skewed marginals: exp() of the Gaussian scores (Pearson no longer
    // equals the Gaussian correlation, Spearman and the copula are unaffected).
    let cols: Vec<Vec<f64>> = cols
        .into_iter()
        .map(|c| c.into_iter().map(f64::exp).collect())
        .collect();
    let parents =
        DnaTable::from_columns(Descriptor::MEDINA_2018_TABLE_1.to_vec(), cols).expect("valid");
    let copula = GaussianCopula::fit(&parents).expect("fit");
    let truth = CorrelationMatrix {
        descriptors: Descriptor::MEDINA_2018_TABLE_1.to_vec(),
        method: CorrelationMethod::Pearson,
        values: TABLE_1.to_vec(),
    };
    let fitted = copula
        .correlation()
        .max_abs_difference(&truth)
        .expect("same");
    assert!(fitted < 0.02, "copula correlation off by {fitted}");
    let clones = copula.sample_table(50_000, &mut rng).expect("valid");
    let cmp = compare_populations(
        &parents,
        &clones,
        &Descriptor::MEDINA_2018_TABLE_1,
        CorrelationMethod::Spearman,
    )
    .expect("comparable");
    #[expect(clippy::print_stdout, reason = "numbers for the report")]
    {
        println!(
            "copula clones vs parents: mean err {:.3} %, std err {:.3} %, max |ΔR_S| {:.4}, KS {:?}",
            cmp.errors.average_mean_error_pct,
            cmp.errors.average_std_error_pct,
            cmp.correlation_max_abs_difference,
            cmp.distances.iter().map(|d| d.ks).collect::<Vec<_>>()
        );
    }
    assert!(cmp.correlation_max_abs_difference < 0.02);
    assert!(cmp.errors.average_mean_error_pct < 2.0);
    assert!(cmp.errors.average_std_error_pct < 5.0);
    for d in &cmp.distances {
        assert!(d.ks < 0.02, "{}: KS {}", d.descriptor, d.ks);
    }
    // Marginal of the clones against the exact log-normal.
    let ar = clones.column(AspectRatio).expect("present");
    let k = ks_distance_to_cdf(ar, |v| normal_cdf(v.ln())).expect("finite");
    assert!(k < 0.02, "aspect ratio marginal KS {k}");
    // Spearman matrix of the parents matches the closed form of Table 1.
    let s = correlation_matrix(&parents, CorrelationMethod::Spearman).expect("ok");
    let rs = s.get(Roundness, VolumeSurfaceRatio).expect("present");
    let expected = 6.0 / std::f64::consts::PI * (0.88f64 / 2.0).asin();
    assert!((rs - expected).abs() < 0.01, "{rs} vs {expected}");
    assert!(s.get(MinPrincipalDimension, AspectRatio).is_some());
}

#[test]
fn seeded_sampling_is_deterministic() {
    let x = [0.1, 0.5, 0.9, 0.3, 0.35, 0.8];
    let y = [1.0, 1.5, 1.9, 1.2, 1.1, 1.7];
    let h = Histogram2d::new(&x, &y, (3, 3), None, None).expect("valid");
    let s = InverseCdfSampler2d::new(&TabulatedPdf2d::from_histogram(&h).expect("valid"))
        .expect("valid");
    let draw = |seed: u64| {
        let mut rng = ChaCha8Rng::seed_from_u64(seed);
        (0..100)
            .map(|_| {
                let (x, y) = s.sample(&mut rng);
                (x.to_bits(), y.to_bits())
            })
            .collect::<Vec<_>>()
    };
    assert_eq!(draw(3), draw(3));
    assert_ne!(draw(3), draw(4));
}

proptest! {
    #[test]
    fn distances_are_symmetric_and_bounded(
        a in prop::collection::vec(-1e6f64..1e6, 1..60),
        b in prop::collection::vec(-1e6f64..1e6, 1..60),
    ) {
        let ks = ks_distance(&a, &b).expect("finite");
        prop_assert!((0.0..=1.0).contains(&ks));
        prop_assert!((ks - ks_distance(&b, &a).expect("finite")).abs() < 1e-12);
        let w = wasserstein1(&a, &b).expect("finite");
        prop_assert!(w >= 0.0 && w.is_finite());
        prop_assert!((w - wasserstein1(&b, &a).expect("finite")).abs() <= 1e-9 * (1.0 + w));
        // W1 ≥ |mean difference| (Jensen).
        let ma = a.iter().sum::<f64>() / a.len() as f64;
        let mb = b.iter().sum::<f64>() / b.len() as f64;
        prop_assert!(w + 1e-6 * (1.0 + w) >= (ma - mb).abs());
    }

    #[test]
    fn correlations_are_finite_and_bounded(
        rows in prop::collection::vec(prop::collection::vec(-1e3f64..1e3, 3), 2..40),
    ) {
        let t = DnaTable::from_rows(vec![AspectRatio, Roundness, VolumeSurfaceRatio], &rows)
            .expect("valid");
        for m in [CorrelationMethod::Pearson, CorrelationMethod::Spearman] {
            match correlation_matrix(&t, m) {
                Ok(c) => prop_assert!(c.values.iter().all(|v| v.is_finite() && v.abs() <= 1.0)),
                Err(morph_dna::Error::ConstantDescriptor { .. }) => {}
                Err(e) => prop_assert!(false, "unexpected {e:?}"),
            }
        }
    }

    #[test]
    fn samplers_stay_in_support(
        pts in prop::collection::vec((0.0f64..1.0, 0.0f64..1.0), 1..50),
        bins in 1usize..8,
        seed in any::<u64>(),
    ) {
        let (x, y): (Vec<f64>, Vec<f64>) = pts.into_iter().unzip();
        let h = Histogram2d::new(&x, &y, (bins, bins), Some((0.0, 1.0)), Some((0.0, 1.0)))
            .expect("inside range");
        let bicubic = morph_dna::BicubicPdf::from_histogram(&h, 4).expect("valid");
        let table = bicubic.tabulate(4).expect("valid");
        let inv = InverseCdfSampler2d::new(&table).expect("valid");
        let ar = morph_dna::AcceptanceRejection2d::new(bicubic).expect("bounded");
        let mut rng = ChaCha8Rng::seed_from_u64(seed);
        for _ in 0..20 {
            for (u, v) in [inv.sample(&mut rng), ar.sample(&mut rng)] {
                prop_assert!((0.0..=1.0).contains(&u) && (0.0..=1.0).contains(&v));
            }
            // Acceptance needs u·M < f, so accepted points have positive density.
            let (u, v) = ar.sample(&mut rng);
            prop_assert!(ar.pdf().density(u, v) > 0.0);
        }
    }
}

/// Conditioning on two of the four Table 1 descriptors: with standard normal
/// marginals the copula is the Gaussian itself, so the conditional mean and
/// covariance of the other two have the closed form
/// `μ = R_BA R_AA⁻¹ z_A`, `Σ = R_BB − R_BA R_AA⁻¹ R_AB`.
#[test]
fn copula_conditional_matches_gaussian_conditioning() {
    let seed = 53;
    #[expect(clippy::print_stdout, reason = "seeded tests print their seed")]
    {
        println!("seed {seed}");
    }
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let cols = normal_population(&TABLE_1, 100_000, &mut rng);
    let parents =
        DnaTable::from_columns(Descriptor::MEDINA_2018_TABLE_1.to_vec(), cols).expect("valid");
    let copula = GaussianCopula::fit(&parents).expect("fit");
    // A = {aspect ratio (0), roundness (1)}, B = {VSR (2), min p. dim. (3)}.
    let za = [0.5, -0.3];
    let r = |i: usize, j: usize| TABLE_1[i * 4 + j];
    let det = 1.0 - r(0, 1) * r(0, 1);
    let inv = [1.0 / det, -r(0, 1) / det, -r(0, 1) / det, 1.0 / det];
    let rba = |b: usize| [r(b, 0), r(b, 1)];
    let quad = |u: [f64; 2], v: [f64; 2]| {
        u[0] * (inv[0] * v[0] + inv[1] * v[1]) + u[1] * (inv[2] * v[0] + inv[3] * v[1])
    };
    let mean = [quad(rba(2), za), quad(rba(3), za)];
    let var = [1.0 - quad(rba(2), rba(2)), 1.0 - quad(rba(3), rba(3))];
    let cov23 = r(2, 3) - quad(rba(2), rba(3));
    let given = [(AspectRatio, za[0]), (Roundness, za[1])];
    let n = 20_000;
    let draws: Vec<Vec<f64>> = (0..n)
        .map(|_| copula.sample_conditional(&given, &mut rng).expect("valid"))
        .collect();
    let col = |k: usize| draws.iter().map(|d| d[k]).collect::<Vec<f64>>();
    let (v, m) = (col(2), col(3));
    for (k, x) in [(0, &v), (1, &m)] {
        let mu = x.iter().sum::<f64>() / n as f64;
        let sd = morph_dna::stats::sample_std(x).expect("ok");
        assert!((mu - mean[k]).abs() < 0.02, "mean {mu} vs {}", mean[k]);
        assert!(
            (sd - var[k].sqrt()).abs() < 0.02,
            "std {sd} vs {}",
            var[k].sqrt()
        );
    }
    let rho = cov23 / (var[0] * var[1]).sqrt();
    let got = pearson(&v, &m).expect("ok");
    assert!(
        (got - rho).abs() < 0.03,
        "conditional correlation {got} vs {rho}"
    );
    // Given values are returned bit for bit.
    assert!(
        draws
            .iter()
            .all(|d| d[0].to_bits() == za[0].to_bits() && d[1].to_bits() == za[1].to_bits())
    );
}
