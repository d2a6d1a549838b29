//! Sampler throughput: the tabulated inverse-CDF sampler (acceptance: at
//! least 10⁷ draws per second), the seed's acceptance–rejection, the KDE's
//! smoothed bootstrap and the Gaussian copula, all on a correlated bivariate
//! normal population of 10⁴ parents binned 50 × 50 (GSC 2.0's bin count).

use std::hint::black_box;

use criterion::{Criterion, Throughput, criterion_group, criterion_main};
use morph_dna::{
    AcceptanceRejection2d, Bandwidth, BicubicPdf, Descriptor, DnaTable, EnvelopeRejection2d,
    GaussianCopula, GaussianKde2d, Histogram2d, InverseCdfSampler2d,
};
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use rand_distr::{Distribution, StandardNormal};

const BATCH: u64 = 10_000;

fn parents(n: usize) -> (Vec<f64>, Vec<f64>) {
    let mut rng = ChaCha8Rng::seed_from_u64(2018);
    let rho: f64 = 0.7;
    (0..n)
        .map(|_| {
            let z1: f64 = StandardNormal.sample(&mut rng);
            let z2: f64 = StandardNormal.sample(&mut rng);
            (z1, rho * z1 + (1.0 - rho * rho).sqrt() * z2)
        })
        .unzip()
}

fn samplers(c: &mut Criterion) {
    let (xs, ys) = parents(10_000);
    let hist = Histogram2d::new(&xs, &ys, (50, 50), None, None).expect("valid histogram");
    let pdf = BicubicPdf::from_histogram(&hist, 8).expect("valid pdf");
    let table = pdf.tabulate(8).expect("valid table");
    let inverse = InverseCdfSampler2d::new(&table).expect("valid table");
    let env = EnvelopeRejection2d::new(pdf.clone()).expect("bounded pdf");
    let ar = AcceptanceRejection2d::new(pdf).expect("bounded pdf");
    let kde = GaussianKde2d::fit(&xs, &ys, Bandwidth::Scott).expect("valid kde");
    let dna = DnaTable::from_columns(
        vec![Descriptor::AspectRatio, Descriptor::Roundness],
        vec![xs.clone(), ys.clone()],
    )
    .expect("valid table");
    let copula = GaussianCopula::fit(&dna).expect("valid copula");

    let mut g = c.benchmark_group("samplers");
    g.throughput(Throughput::Elements(BATCH));
    let mut rng = ChaCha8Rng::seed_from_u64(1);
    g.bench_function("inverse_cdf_2d_400x400", |b| {
        b.iter(|| {
            let mut acc = 0.0;
            for _ in 0..BATCH {
                let (x, y) = inverse.sample(&mut rng);
                acc += x + y;
            }
            black_box(acc)
        });
    });
    g.bench_function("inverse_cdf_conditional", |b| {
        b.iter(|| {
            let mut acc = 0.0;
            for k in 0..BATCH {
                let x = -1.0 + (k % 100) as f64 * 0.02;
                acc += inverse.sample_y_given_x(x, &mut rng).unwrap_or(0.0);
            }
            black_box(acc)
        });
    });
    g.bench_function("acceptance_rejection_bicubic", |b| {
        b.iter(|| {
            let mut acc = 0.0;
            for _ in 0..BATCH {
                let (x, y) = ar.sample(&mut rng);
                acc += x + y;
            }
            black_box(acc)
        });
    });
    g.bench_function("envelope_rejection_bicubic", |b| {
        b.iter(|| {
            let mut acc = 0.0;
            for _ in 0..BATCH {
                let (x, y) = env.sample(&mut rng);
                acc += x + y;
            }
            black_box(acc)
        });
    });
    g.bench_function("kde_smoothed_bootstrap", |b| {
        b.iter(|| {
            let mut acc = 0.0;
            for _ in 0..BATCH {
                let (x, y) = kde.sample(&mut rng);
                acc += x + y;
            }
            black_box(acc)
        });
    });
    g.bench_function("gaussian_copula_2d", |b| {
        b.iter(|| {
            let mut acc = 0.0;
            for _ in 0..BATCH {
                acc += copula.sample(&mut rng)[0];
            }
            black_box(acc)
        });
    });
    g.finish();
}

criterion_group!(benches, samplers);
criterion_main!(benches);
