//! Porosity control by a genetic algorithm (Pinto 2009, §4.1–4.2) and
//! functionally graded property layers (§4.3).
//!
//! Representation (§4.2.1): a chromosome has `n_est` genes (Eq. 3-1), one
//! per particle in placement order; a gene is a cumulative passing fraction
//! `u ∈ [0, 1]` converted to a diameter by the inverse grading curve, so
//! every individual obeys the prescribed grading. Fitness (to minimise):
//! `(φ − φ_target)²` with `φ` of Eq. 4-2 of the packing built from the
//! genes. Operators (§4.1.3): roulette selection (slice ∝ `1/(fitness + ε)`
//! because the problem is a minimisation), one-point crossover with
//! probability `crossover_rate`, per-gene mutation (a fresh uniform value)
//! with probability `mutation_rate`, and elitism (the best individual is
//! copied unchanged). Stop (§4.1.4): a maximum number of generations or a
//! fitness below `fitness_tolerance`.
//!
//! Choices the seed leaves to JGAP defaults, made here: population 24,
//! 30 generations, crossover rate 0.35 and mutation rate 1/12 (JGAP's
//! documented defaults for the two rates), ε = 1e-12.
//!
//! Determinism: individual `i` of the initial population draws from the
//! ChaCha8 stream `(seed, i)`; child `i` of generation `g` from stream
//! `(seed, (g + 1) << 32 | i)`; fitness evaluations run in parallel with
//! rayon but are pure, so results are identical for any thread count.

use crate::domain::Domain;
use crate::error::{Error, Result};
use crate::grading::{Grading, estimate_count};
use crate::metrics::porosity;
use crate::packer::{Disk, PackParams, Packing, pack_sizes};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use rayon::prelude::*;

/// Genetic-algorithm parameters.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GaParams {
    /// Individuals per generation (≥ 2).
    pub population: usize,
    /// Maximum number of generations.
    pub generations: usize,
    /// Probability that a selected pair is recombined.
    pub crossover_rate: f64,
    /// Probability that a gene is replaced by a fresh uniform value.
    pub mutation_rate: f64,
    /// Stop when the best fitness falls below this value.
    pub fitness_tolerance: f64,
    /// Porosity to reach.
    pub target_porosity: f64,
}

impl Default for GaParams {
    fn default() -> Self {
        Self {
            population: 24,
            generations: 30,
            crossover_rate: 0.35,
            mutation_rate: 1.0 / 12.0,
            fitness_tolerance: 1e-6,
            target_porosity: 0.5,
        }
    }
}

impl GaParams {
    /// Checks the parameters.
    ///
    /// # Errors
    /// [`Error::Parameter`] for a value outside its range.
    pub fn validate(&self) -> Result<()> {
        let unit = |what, v: f64| {
            if (0.0..=1.0).contains(&v) {
                Ok(())
            } else {
                Err(Error::Parameter {
                    what,
                    value: v,
                    range: "[0, 1]",
                })
            }
        };
        if self.population < 2 {
            return Err(Error::Parameter {
                what: "population",
                value: self.population as f64,
                range: "[2, inf)",
            });
        }
        unit("crossover_rate", self.crossover_rate)?;
        unit("mutation_rate", self.mutation_rate)?;
        unit("target_porosity", self.target_porosity)?;
        if self.fitness_tolerance.is_nan() || self.fitness_tolerance < 0.0 {
            return Err(Error::Parameter {
                what: "fitness_tolerance",
                value: self.fitness_tolerance,
                range: "[0, inf)",
            });
        }
        Ok(())
    }
}

/// Outcome of [`optimise_porosity`].
#[derive(Debug, Clone)]
pub struct GaResult {
    /// Genes (passing fractions) of the best individual.
    pub genes: Vec<f64>,
    /// Its packing.
    pub packing: Packing,
    /// Its porosity (Eq. 4-2).
    pub porosity: f64,
    /// Porosity of the first individual of the initial population (a plain
    /// random draw from the grading: the "before" value).
    pub initial_porosity: f64,
    /// Best fitness after each generation (index 0: initial population).
    pub history: Vec<f64>,
    /// Number of packings built.
    pub evaluations: usize,
}

fn stream(seed: u64, s: u64) -> ChaCha8Rng {
    let mut r = ChaCha8Rng::seed_from_u64(seed);
    r.set_stream(s);
    r
}

/// Optimises the particle sizes (through their passing fractions) so that
/// the packing's porosity approaches `ga.target_porosity` (Pinto 2009,
/// §4.2).
///
/// # Errors
/// Validation errors of the inputs; packing errors.
pub fn optimise_porosity(
    domain: &Domain,
    grading: &Grading,
    pack_params: &PackParams,
    ga: &GaParams,
    seed: u64,
) -> Result<GaResult> {
    ga.validate()?;
    grading.validate()?;
    pack_params.validate()?;
    let n = estimate_count(domain.area()?, grading.d_min()) as usize;
    let d_max = grading.d_max();
    let evaluate = |genes: &[f64]| -> Result<(f64, Packing)> {
        let sizes: Vec<f64> = genes.iter().map(|&u| grading.diameter_at(u)).collect();
        let p = pack_sizes(domain, &sizes, d_max, pack_params)?;
        let phi = porosity(domain, &p.disks)?;
        Ok((phi, p))
    };
    let mut pop: Vec<Vec<f64>> = (0..ga.population)
        .map(|i| {
            let mut r = stream(seed, i as u64);
            (0..n).map(|_| r.random::<f64>()).collect()
        })
        .collect();
    let score = |pop: &[Vec<f64>]| -> Result<Vec<(f64, f64)>> {
        pop.par_iter()
            .map(|g| evaluate(g).map(|(phi, _)| (phi, (phi - ga.target_porosity).powi(2))))
            .collect()
    };
    let mut scores = score(&pop)?;
    let initial_porosity = scores[0].0;
    let mut evaluations = pop.len();
    let best_of = |s: &[(f64, f64)]| -> usize {
        let mut b = 0;
        for (i, x) in s.iter().enumerate() {
            if x.1 < s[b].1 {
                b = i;
            }
        }
        b
    };
    let mut history = vec![scores[best_of(&scores)].1];
    for gen_idx in 0..ga.generations {
        let b = best_of(&scores);
        if scores[b].1 <= ga.fitness_tolerance {
            break;
        }
        let weights: Vec<f64> = scores.iter().map(|s| 1.0 / (s.1 + 1e-12)).collect();
        let total: f64 = weights.iter().sum();
        let roulette = |r: &mut ChaCha8Rng| -> usize {
            let mut x = r.random::<f64>() * total;
            for (i, w) in weights.iter().enumerate() {
                if x < *w {
                    return i;
                }
                x -= w;
            }
            weights.len() - 1
        };
        let mut next: Vec<Vec<f64>> = Vec::with_capacity(pop.len());
        next.push(pop[b].clone());
        for i in 1..pop.len() {
            let mut r = stream(seed, ((gen_idx as u64 + 1) << 32) | i as u64);
            let (pa, pb) = (roulette(&mut r), roulette(&mut r));
            let mut child = pop[pa].clone();
            if r.random::<f64>() < ga.crossover_rate && n > 1 {
                let cut = r.random_range(1..n);
                child[cut..].copy_from_slice(&pop[pb][cut..]);
            }
            for g in &mut child {
                if r.random::<f64>() < ga.mutation_rate {
                    *g = r.random::<f64>();
                }
            }
            next.push(child);
        }
        pop = next;
        // The elite keeps its score; only the children are evaluated.
        let elite = scores[b];
        let mut s = vec![elite];
        s.extend(score(&pop[1..])?);
        evaluations += pop.len() - 1;
        scores = s;
        history.push(scores[best_of(&scores)].1);
    }
    let b = best_of(&scores);
    let (phi, packing) = evaluate(&pop[b])?;
    evaluations += 1;
    Ok(GaResult {
        genes: pop[b].clone(),
        packing,
        porosity: phi,
        initial_porosity,
        history,
        evaluations,
    })
}

/// Functionally graded property layers (Pinto 2009, §4.3, tests MGF-1..3):
/// the packing is kept, and each disk gets the index (0-based, from the
/// bottom) of the horizontal band of equal height, between `y_min` and
/// `y_max`, that contains its centre.
///
/// # Errors
/// [`Error::Parameter`] for zero layers or `y_max <= y_min`;
/// [`Error::NonFinite`] for non-finite bounds.
pub fn graded_layers(disks: &[Disk], layers: usize, y_min: f64, y_max: f64) -> Result<Vec<usize>> {
    crate::error::finite("y_min", y_min)?;
    crate::error::finite("y_max", y_max)?;
    if layers == 0 {
        return Err(Error::Parameter {
            what: "layers",
            value: 0.0,
            range: "[1, inf)",
        });
    }
    if y_max <= y_min {
        return Err(Error::Parameter {
            what: "y_max - y_min",
            value: y_max - y_min,
            range: "(0, inf)",
        });
    }
    let h = (y_max - y_min) / layers as f64;
    Ok(disks
        .iter()
        .map(|d| (((d.center.y - y_min) / h).floor().max(0.0) as usize).min(layers - 1))
        .collect())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ga_raises_porosity_towards_target_and_is_deterministic() {
        let seed = 3;
        println!("seed {seed}");
        let domain = Domain::Rectangle {
            width: 12.0,
            height: 12.0,
        };
        let grading = Grading::Uniform { min: 1.2, max: 2.4 };
        let ga = GaParams {
            population: 8,
            generations: 6,
            ..GaParams::default()
        };
        let a =
            optimise_porosity(&domain, &grading, &PackParams::default(), &ga, seed).expect("ga");
        assert!(
            a.porosity >= a.initial_porosity,
            "{} < {}",
            a.porosity,
            a.initial_porosity
        );
        // Elitism: the best fitness never gets worse.
        assert!(a.history.windows(2).all(|w| w[1] <= w[0]));
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(1)
            .build()
            .expect("pool");
        let b = pool
            .install(|| optimise_porosity(&domain, &grading, &PackParams::default(), &ga, seed))
            .expect("ga");
        assert_eq!(a.genes, b.genes);
        assert_eq!(a.packing.disks.len(), b.packing.disks.len());
    }

    #[test]
    fn layers_split_by_height() {
        use nalgebra::Point2;
        let d = |y| Disk {
            center: Point2::new(0.0, y),
            radius: 0.1,
        };
        let l = graded_layers(&[d(0.5), d(1.5), d(2.9), d(3.0)], 3, 0.0, 3.0).expect("valid");
        assert_eq!(l, vec![0, 1, 2, 2]);
        assert!(graded_layers(&[], 0, 0.0, 1.0).is_err());
        assert!(graded_layers(&[], 2, 1.0, 1.0).is_err());
    }
}
