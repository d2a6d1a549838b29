//! The run loop: seeding the front (or a slab's imported neighbours), the
//! window of upcoming sizes, the decision for each popped site and its
//! application, and the optional site-generation worker with the lag-one
//! rule.

use std::sync::mpsc;

use packer_quadtree::FrontOrder;

use super::sites::{Key, Site, Sites};
use super::{FREE, Front3, MAX_SKIPS, Pack3Stats, RunOpts, Start, WALL};

/// Bisection steps of a site's capacity.
const BISECTIONS: usize = 4;

/// What happens to a popped site.
#[derive(Clone, Copy, Debug)]
enum Outcome {
    /// Killed by a later sphere: retired without a test.
    Dead,
    /// No room even for the smallest size: retired.
    Drop,
    /// Too small for the window: back in the queue with this capacity.
    Defer(f64),
    /// Window entry `i` (radius `r`) goes to `p`.
    Place { p: [f64; 3], r: f64, i: usize },
}

/// A message to the site-generation worker.
enum Job {
    /// Insert a placed sphere `[x, y, z, r]` into the replica.
    Place([f64; 4]),
    /// Generate the open sites of sphere `id` (secondary key `g`).
    Generate(u32, f64),
}

/// The channels to the worker.
struct Pipe {
    jobs: mpsc::Sender<Job>,
    results: mpsc::Receiver<Vec<Site>>,
}

impl Pipe {
    fn send(&self, job: Job) {
        // A failed send means the worker is gone; the receive below then
        // reports an empty batch and the packing ends early but valid.
        let _ = self.jobs.send(job);
    }
    fn receive(&self) -> Vec<Site> {
        spin_receive(&self.results).unwrap_or_default()
    }
}

/// Receives with a short spin before blocking (the two threads hand work
/// to each other every few microseconds; parking costs more than that).
fn spin_receive<T>(rx: &mpsc::Receiver<T>) -> Option<T> {
    for i in 0..20_000u32 {
        match rx.try_recv() {
            Ok(x) => return Some(x),
            Err(mpsc::TryRecvError::Disconnected) => return None,
            Err(mpsc::TryRecvError::Empty) => {
                if i % 64 == 63 {
                    std::thread::yield_now();
                } else {
                    std::hint::spin_loop();
                }
            }
        }
    }
    rx.recv().ok()
}

/// The open sites with the lag-one rule's pending sphere.
struct Lag {
    sites: Sites,
    /// The last placed sphere, whose sites are not merged yet.
    pending: Option<(u32, f64)>,
    pipe: Option<Pipe>,
}

/// The window of upcoming radii, oldest first, and the size stream that
/// refills it.
struct Window<'s> {
    radii: Vec<f64>,
    /// Its length when full (the look-ahead).
    w: usize,
    /// Sizes drawn so far.
    k: usize,
    sizes: &'s mut dyn FnMut(usize) -> Option<f64>,
}

impl Window<'_> {
    /// Draws sizes until the window is full or the sizes end.
    fn refill(&mut self, st: &mut Pack3Stats) {
        while self.radii.len() < self.w {
            let Some(d) = (self.sizes)(self.k) else { break };
            self.k += 1;
            st.sizes_drawn += 1;
            self.radii.push(0.5 * d);
        }
    }
}

/// The scratch of the speculative pass kept between passes.
struct Speculation<'a> {
    /// Decisions made while the worker ran, in pop order.
    spec: &'a mut Vec<(Site, Outcome)>,
    /// Decisions still valid (nothing placed since), by slot.
    cache: &'a mut Vec<(u32, Outcome)>,
    /// Sizes skipped in a row.
    skips: &'a mut usize,
}

impl Front3<'_> {
    /// Runs the front loop; `sizes(k)` gives the `k`-th diameter. A site
    /// takes the oldest of the next `lookahead` sizes that fits it (1: the
    /// strict size order of the seed).
    pub(crate) fn run(
        &mut self,
        sizes: &mut dyn FnMut(usize) -> Option<f64>,
        opts: RunOpts,
        start: Start,
    ) {
        let order = opts.order;
        self.seed_x = start.seed_x;
        // Secondary key per order: lowest candidate (none), lowest
        // generating sphere, newest generating sphere (stack).
        let gkey = |s: &Self, id: u32| match order {
            FrontOrder::LowestFirst => s.xs[id as usize][2],
            FrontOrder::Stack => -f64::from(id),
            _ => 0.0,
        };
        let mut k = 0usize;
        let Some(sites) = self.first_sites(sizes, &mut k, start, &gkey) else {
            return;
        };
        let window = Window {
            radii: Vec::with_capacity(opts.lookahead.max(1)),
            w: opts.lookahead.max(1),
            k,
            sizes,
        };
        let threaded = opts.pipeline && rayon::current_num_threads() >= 2;
        if threaded {
            self.run_threaded(sites, window, opts, &gkey);
        } else {
            let mut lag = Lag {
                sites,
                pending: None,
                pipe: None,
            };
            self.main_loop(&mut lag, window, opts, &gkey);
        }
    }

    /// The open sites the front starts from: those of the imported spheres
    /// near the slab, or of the seed sphere (drawing sizes, counted in `k`,
    /// until one fits). `None` when the run ends before it starts.
    fn first_sites(
        &mut self,
        sizes: &mut dyn FnMut(usize) -> Option<f64>,
        k: &mut usize,
        start: Start,
        gkey: &impl Fn(&Self, u32) -> f64,
    ) -> Option<Sites> {
        let (blo, bhi) = self.container.bbox();
        let mut sites = Sites::new(
            self.r_min,
            self.r_max,
            [blo.x, blo.y, blo.z],
            [bhi.x, bhi.y, bhi.z],
            self.periodic,
        );
        let mut batch = Vec::new();
        if let Some(region) = start.region {
            sites.region = region;
        }
        if !start.imported.is_empty() {
            // A slab between packed neighbours: their spheres are obstacles,
            // and those within reach of the slab start the front.
            let reach = 2.0 * self.r_max;
            let (x0, x1) = (sites.region[0] - reach, sites.region[1] + reach);
            let first = self.xs.len() as u32;
            for q in &start.imported {
                self.place([q[0], q[1], q[2]], q[3]);
            }
            for id in first..self.xs.len() as u32 {
                let x = self.xs[id as usize][0];
                if x >= x0 && x < x1 {
                    let g = gkey(self, id);
                    self.generate(id, g, &mut batch);
                    for st in batch.drain(..) {
                        sites.add(st);
                    }
                }
            }
            if sites.is_empty() {
                return None;
            }
        } else {
            let first = loop {
                let d = sizes(*k)?;
                *k += 1;
                self.stats.sizes_drawn += 1;
                if let Some(id) = self.seed(0.5 * d) {
                    break id;
                }
                self.stats.sizes_skipped += 1;
                if *k > MAX_SKIPS {
                    return None;
                }
            };
            let g = gkey(self, first);
            self.generate(first, g, &mut batch);
            for st in batch.drain(..) {
                sites.add(st);
            }
            if sites.is_empty()
                && let Some(floor) = self.all_planes.iter().position(|w| w.n[2] > 0.999_999)
            {
                // Periodic in x and y (or a slab periodic in y): nothing
                // but the floor around the first sphere; the second one
                // sits beside it.
                let q = self.xs[first as usize];
                sites.add(Site {
                    k: [q[0] + q[3] + self.r_min, q[1], q[2]],
                    ids: [first, WALL + floor as u32, FREE],
                    g,
                    cap: f64::INFINITY,
                    slot: 0,
                });
            }
        }
        Some(sites)
    }

    /// The main loop on a second thread generating the sites: a replica of
    /// the front receives the placements and generates each new sphere's
    /// sites; its counters are added to this front's.
    fn run_threaded(
        &mut self,
        sites: Sites,
        window: Window<'_>,
        opts: RunOpts,
        gkey: &impl Fn(&Self, u32) -> f64,
    ) {
        let mut replica = self.clone();
        replica.stats = Pack3Stats::default();
        let (job_tx, job_rx) = mpsc::channel::<Job>();
        let (res_tx, res_rx) = mpsc::channel::<Vec<Site>>();
        let worker_stats = std::thread::scope(|scope| {
            let worker = scope.spawn(move || {
                loop {
                    match spin_receive(&job_rx) {
                        Some(Job::Place(q)) => {
                            replica.place([q[0], q[1], q[2]], q[3]);
                        }
                        Some(Job::Generate(id, g)) => {
                            let mut b = Vec::new();
                            replica.generate(id, g, &mut b);
                            if res_tx.send(b).is_err() {
                                break;
                            }
                        }
                        None => break,
                    }
                }
                replica.stats
            });
            let mut lag = Lag {
                sites,
                pending: None,
                pipe: Some(Pipe {
                    jobs: job_tx,
                    results: res_rx,
                }),
            };
            self.main_loop(&mut lag, window, opts, gkey);
            // Closing the job channel stops the worker.
            drop(lag.pipe.take());
            worker.join().unwrap_or_default()
        });
        self.stats.evaluations += worker_stats.evaluations;
        self.stats.neighbours += worker_stats.neighbours;
        self.stats.candidates += worker_stats.candidates;
        self.stats.sites += worker_stats.sites;
    }

    /// Pops, decides and applies sites until the sphere limit, the end of
    /// the sizes or of the open sites (or of the skips allowed).
    fn main_loop(
        &mut self,
        lag: &mut Lag,
        mut window: Window<'_>,
        opts: RunOpts,
        gkey: &impl Fn(&Self, u32) -> f64,
    ) {
        let RunOpts { max, max_skips, .. } = opts;
        window.refill(&mut self.stats);
        let mut skips = 0usize;
        let mut peak = 0usize;
        let mut spec: Vec<(Site, Outcome)> = Vec::new();
        let mut cache: Vec<(u32, Outcome)> = Vec::new();
        while self.xs.len() < max && !window.radii.is_empty() {
            let r_small = window.radii.iter().copied().fold(f64::INFINITY, f64::min);
            if lag.pending.is_some() {
                let mut pass = Speculation {
                    spec: &mut spec,
                    cache: &mut cache,
                    skips: &mut skips,
                };
                self.speculate_and_replay(lag, &mut window, r_small, &mut pass, gkey);
                peak = peak.max(lag.sites.len());
                continue;
            }
            let Some(site) = lag.sites.pop_for(r_small) else {
                if lag.sites.is_empty() || skips >= max_skips {
                    break;
                }
                // No site takes any size of the window: skip the oldest.
                self.stats.sizes_skipped += 1;
                skips += 1;
                window.radii.remove(0);
                window.refill(&mut self.stats);
                continue;
            };
            // A decision made while speculating still holds: nothing
            // was placed since.
            let cached = cache
                .iter()
                .position(|c| c.0 == site.slot)
                .map(|i| cache.swap_remove(i).1);
            let o = match cached {
                Some(o) => o,
                None if lag.sites.is_alive(site.slot) => self.decide(&site, &window.radii),
                None => Outcome::Dead,
            };
            if self.apply(site, o, lag, &mut window.radii, gkey) {
                skips = 0;
                cache.clear();
                window.refill(&mut self.stats);
            }
            peak = peak.max(lag.sites.len());
        }
        self.merge_pending(lag, None);
        self.note_memory(peak * std::mem::size_of::<Site>());
    }

    /// While the worker generates the last sphere's sites: decides the
    /// next pops meanwhile (read-only), then replays them in the exact
    /// sequential order once the sites are in (a decision overtaken by a
    /// lower new site goes back to the queue and to the cache).
    fn speculate_and_replay(
        &mut self,
        lag: &mut Lag,
        window: &mut Window<'_>,
        r_small: f64,
        pass: &mut Speculation<'_>,
        gkey: &impl Fn(&Self, u32) -> f64,
    ) {
        let Speculation { spec, cache, skips } = pass;
        spec.clear();
        let mut ready: Option<Vec<Site>> = None;
        loop {
            // Speculate only while the worker is busy: the
            // replay gives the same packing however far we got.
            if let Some(pipe) = &lag.pipe
                && let Ok(b) = pipe.results.try_recv()
            {
                ready = Some(b);
                break;
            }
            let Some(site) = lag.sites.pop_for(r_small) else {
                break;
            };
            let o = if lag.sites.is_alive(site.slot) {
                self.decide(&site, &window.radii)
            } else {
                Outcome::Dead
            };
            let stop = matches!(o, Outcome::Place { .. });
            spec.push((site, o));
            if stop {
                break;
            }
        }
        self.merge_pending(lag, ready);
        let mut iter = std::mem::take(*spec).into_iter();
        while let Some((site, o)) = iter.next() {
            if lag
                .sites
                .peek_for(r_small)
                .is_some_and(|t| Key::of(&t) > Key::of(&site))
            {
                // A new site is lower: the sequential loop would
                // have taken it first.
                lag.sites.push(site);
                cache.push((site.slot, o));
                for (rest, ro) in iter.by_ref() {
                    lag.sites.push(rest);
                    cache.push((rest.slot, ro));
                }
                break;
            }
            if self.apply(site, o, lag, &mut window.radii, gkey) {
                **skips = 0;
                cache.clear();
                window.refill(&mut self.stats);
            }
        }
    }

    /// What the front does with a popped site for the current window
    /// (reads the spheres, changes nothing but scratch and counters).
    fn decide(&mut self, site: &Site, window: &[f64]) -> Outcome {
        self.stats.pops += 1;
        let r0 = window[0];
        let mut r0_failed = false;
        if site.cap >= r0 {
            if let Some(p) = self.try_site(site, r0) {
                return Outcome::Place { p, r: r0, i: 0 };
            }
            r0_failed = true;
        }
        self.stats.site_tests += 1;
        let Some(c) = self.site_position(site, self.r_min) else {
            return Outcome::Drop;
        };
        if !self.feasible(&c, self.r_min) {
            return Outcome::Drop;
        }
        // Capacity by bisection on [r_min, min(r0, cap)] to 1/16, against
        // the spheres gathered once (the top is known to fail when it is
        // r0 and r0 failed against the full index).
        let top = r0.min(site.cap);
        self.gather_local(site, &c, top);
        let (mut lo, mut hi) = (self.r_min, top);
        if !(r0_failed && top == r0) && self.try_local(site, hi) {
            lo = hi;
        } else {
            for _ in 0..BISECTIONS {
                let mid = 0.5 * (lo + hi);
                if self.try_local(site, mid) {
                    lo = mid;
                } else {
                    hi = mid;
                }
            }
        }
        // The oldest size of the window that fits. A size the local test
        // admits but the full index refuses (a sphere beyond the gathered
        // reach) lowers the capacity below it, so the site cannot come back
        // for the same sizes.
        for (i, &r) in window.iter().enumerate() {
            if r > lo {
                continue;
            }
            if let Some(p) = self.try_site(site, r) {
                return Outcome::Place { p, r, i };
            }
            lo = r * (1.0 - 1e-9);
        }
        if lo < self.r_min {
            Outcome::Drop
        } else {
            Outcome::Defer(lo)
        }
    }

    /// Carries out a decision; returns whether a sphere was placed (the
    /// window entry is then removed and must be refilled).
    fn apply(
        &mut self,
        site: Site,
        o: Outcome,
        lag: &mut Lag,
        window: &mut Vec<f64>,
        g_of: &dyn Fn(&Self, u32) -> f64,
    ) -> bool {
        match o {
            Outcome::Dead => {
                lag.sites.retire(site.slot);
                false
            }
            Outcome::Drop => {
                self.stats.fronts_removed += 1;
                lag.sites.retire(site.slot);
                false
            }
            Outcome::Defer(lo) => {
                lag.sites.push(Site { cap: lo, ..site });
                false
            }
            Outcome::Place { p, r, i } => {
                lag.sites.retire(site.slot);
                let id = self.place(p, r);
                let q = self.xs[id as usize];
                self.stats.fronts_removed +=
                    lag.sites
                        .kill_near(&[q[0], q[1], q[2]], r, self.r_min, self.tol);
                let g = g_of(self, id);
                match &lag.pipe {
                    Some(pipe) => {
                        pipe.send(Job::Place(q));
                        pipe.send(Job::Generate(id, g));
                        lag.pending = Some((id, g));
                    }
                    None => {
                        let mut b = std::mem::take(&mut self.batch);
                        self.generate(id, g, &mut b);
                        for st in b.drain(..) {
                            lag.sites.add(st);
                        }
                        self.batch = b;
                    }
                }
                window.remove(i);
                true
            }
        }
    }

    /// Adds the pending sphere's sites (from the worker) to the open sites.
    fn merge_pending(&mut self, lag: &mut Lag, ready: Option<Vec<Site>>) {
        if lag.pending.take().is_none() {
            return;
        }
        if let Some(pipe) = &lag.pipe {
            let batch = ready.unwrap_or_else(|| pipe.receive());
            for st in batch {
                lag.sites.add(st);
            }
        }
    }
}
