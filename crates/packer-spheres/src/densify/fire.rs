//! FIRE's time-step and velocity-mixing control (Bitzek et al. 2006, PRL 97,
//! 170201), shared by the sphere densification and the grain compaction
//! (`packer-grains`), which differ only in their start and largest steps.

/// The state of FIRE's adaptive control: time step, mixing factor α and the
/// count of consecutive steps with positive power.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FireControl {
    dt: f64,
    dt_max: f64,
    alpha: f64,
    n_positive: usize,
    n_delay: usize,
}

impl FireControl {
    /// Steps with positive power before the step may grow (FIRE's `N_min`).
    const N_MIN: usize = 5;
    /// FIRE 2.0's delay: positive steps before the step may grow (Guénolé et
    /// al. 2020, *Comput. Mater. Sci.* 175, 109584).
    pub const N_DELAY_2: usize = 20;
    /// Growth of the step after `N_MIN` positive steps.
    const F_INC: f64 = 1.1;
    /// Shrink of the step at a negative power.
    const F_DEC: f64 = 0.5;
    /// Mixing factor at the start and after a negative power.
    const ALPHA0: f64 = 0.1;
    /// Decay of the mixing factor while the step grows.
    const F_ALPHA: f64 = 0.99;

    /// A control starting at step `dt0` that never exceeds `dt_max`.
    #[must_use]
    pub fn new(dt0: f64, dt_max: f64) -> Self {
        Self::with_delay(dt0, dt_max, Self::N_MIN)
    }

    /// As [`FireControl::new`], the step growing only after `n_delay`
    /// consecutive steps of positive power (FIRE's `N_min` = 5; FIRE 2.0's
    /// [`FireControl::N_DELAY_2`] = 20).
    #[must_use]
    pub fn with_delay(dt0: f64, dt_max: f64, n_delay: usize) -> Self {
        Self {
            dt: dt0,
            dt_max,
            alpha: Self::ALPHA0,
            n_positive: 0,
            n_delay,
        }
    }

    /// The current time step: the one the last position update used.
    #[must_use]
    pub fn dt(&self) -> f64 {
        self.dt
    }

    /// The control after one force evaluation of power `P = F·v`, with the
    /// system's `v·v` and `F·F`: returns `(mix, α, dt)` for the velocity
    /// update `v ← (1 − α) v + mix · F + dt · F` (`mix = α |v| / |F|`) when
    /// the power is positive, and `mix = None` (velocities zeroed, then
    /// `v ← dt · F`) when it is not.
    pub fn update(&mut self, power: f64, vv: f64, ff: f64) -> (Option<f64>, f64, f64) {
        let mix = if power > 0.0 {
            self.n_positive += 1;
            if self.n_positive > self.n_delay {
                self.dt = (self.dt * Self::F_INC).min(self.dt_max);
                self.alpha *= Self::F_ALPHA;
            }
            Some(if ff > 0.0 {
                self.alpha * (vv / ff).sqrt()
            } else {
                0.0
            })
        } else {
            self.n_positive = 0;
            self.dt *= Self::F_DEC;
            self.alpha = Self::ALPHA0;
            None
        };
        (mix, self.alpha, self.dt)
    }
}

#[cfg(test)]
mod tests {
    use super::FireControl;

    #[test]
    fn the_step_grows_after_five_positive_steps_and_halves_at_a_negative_one() {
        let mut f = FireControl::new(0.1, 0.5);
        for _ in 0..5 {
            let (mix, a, dt) = f.update(1.0, 4.0, 1.0);
            assert_eq!((mix, a, dt), (Some(0.2), 0.1, 0.1));
        }
        let (mix, a, dt) = f.update(1.0, 4.0, 1.0);
        assert!((dt - 0.11).abs() < 1e-15 && (a - 0.099).abs() < 1e-15);
        assert!((mix.expect("mix") - 0.198).abs() < 1e-15);
        for _ in 0..100 {
            f.update(1.0, 1.0, 1.0);
        }
        assert_eq!(f.update(1.0, 1.0, 1.0).2, 0.5);
        assert_eq!(f.update(-1.0, 1.0, 1.0), (None, 0.1, 0.25));
        assert_eq!(f.update(1.0, 1.0, 0.0).0, Some(0.0));
    }

    #[test]
    fn fire2_waits_twenty_positive_steps() {
        let mut f = FireControl::with_delay(0.1, 0.5, FireControl::N_DELAY_2);
        for _ in 0..20 {
            assert_eq!(f.update(1.0, 1.0, 1.0).2, 0.1);
        }
        assert!((f.update(1.0, 1.0, 1.0).2 - 0.11).abs() < 1e-15);
        assert!((f.dt() - 0.11).abs() < 1e-15);
        assert!((f.update(-1.0, 1.0, 1.0).2 - 0.055).abs() < 1e-15);
    }
}
