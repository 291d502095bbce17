//! The paper's discrete test cases (Figs. 4 and 5): a complete binary sampling tree whose
//! leaves emit one unit, edges transport a fraction `albedo / 2` of it towards the root, and
//! the left child is sampled with probability 0.9. Inner nodes hold a cache value (exact for
//! Fig. 4, biased for Fig. 5). Everything is computable in closed form: the exact mean and
//! second moment of the radiance caching estimator under a termination rule, by enumerating
//! the tree. Optionally every inner node adds a direct-light term (next-event estimation, added
//! before Russian roulette as the tracer does), so that roulette keeps only part of a segment.

use super::decision::{Decision, LocalStats, PathState, decide, path_threshold};
use super::rule::TerminationRule;

#[derive(Clone, Debug)]
pub struct SamplingTree {
    /// Leaves at this depth (the root is depth 0).
    pub depth: u32,
    /// Probability of the left child.
    pub p_left: f64,
    /// Transport of each edge.
    pub edge_weight: f64,
    /// Direct light (NEE) each inner node adds before the continuation is rouletted.
    pub direct: f64,
    /// Cache value per node, heap order (children of i: 2i+1, 2i+2); leaves hold their emission.
    pub cache: Vec<f64>,
}

/// Mean and second moment of an estimator.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Moments {
    pub mean: f64,
    pub second: f64,
}

impl Moments {
    pub fn variance(&self) -> f64 {
        self.second - self.mean * self.mean
    }
}

impl SamplingTree {
    /// Fig. 4: exact caches (every inner node holds its true value).
    pub fn exact(depth: u32, albedo: f64) -> Self {
        Self::exact_with_direct(depth, albedo, 0.0)
    }

    /// Fig. 4's tree whose inner nodes also receive `direct` by next-event estimation.
    pub fn exact_with_direct(depth: u32, albedo: f64, direct: f64) -> Self {
        let mut tree = Self {
            depth,
            p_left: 0.9,
            edge_weight: albedo / 2.0,
            direct,
            cache: vec![0.0; (1usize << (depth + 1)) - 1],
        };
        for i in 0..tree.cache.len() {
            tree.cache[i] = tree.value(i);
        }
        tree
    }

    /// Fig. 5: inner node i holds its true value times (1 + relative_bias(node depth)).
    pub fn biased(depth: u32, albedo: f64, relative_bias: impl Fn(u32) -> f64) -> Self {
        let mut tree = Self::exact(depth, albedo);
        for i in 0..tree.cache.len() {
            if !tree.is_leaf(i) {
                tree.cache[i] *= 1.0 + relative_bias(node_depth(i));
            }
        }
        tree
    }

    pub fn is_leaf(&self, i: usize) -> bool {
        node_depth(i) == self.depth
    }

    fn children(&self, i: usize) -> [(usize, f64); 2] {
        [(2 * i + 1, self.p_left), (2 * i + 2, 1.0 - self.p_left)]
    }

    /// True value of node i: the leaves' unit (albedo)^(levels below) plus the direct light of
    /// every inner node on the way, v = direct + albedo · v(child).
    pub fn value(&self, i: usize) -> f64 {
        (node_depth(i)..self.depth).fold(1.0, |v, _| self.direct + 2.0 * self.edge_weight * v)
    }

    /// The cache statistics of inner node i: one segment Y = direct + (w/p_c) · cache(child),
    /// the continuation B = (w/p_c) · cache(child).
    pub fn local_stats(&self, i: usize) -> LocalStats {
        let w = self.edge_weight;
        let (mut mean, mut second, mut continuation2, mut deferred) = (0.0, 0.0, 0.0, 0.0);
        for (c, p) in self.children(i) {
            let b = w / p * self.cache[c];
            let y = self.direct + b;
            mean += p * y;
            second += p * y * y;
            continuation2 += p * b * b;
            let bias_c = self.cache[c] - self.value(c);
            deferred += p * (w / p) * (w / p) * bias_c * bias_c;
        }
        let bias = self.cache[i] - self.value(i);
        LocalStats {
            radiance: self.cache[i],
            variance: second - mean * mean,
            continuation2,
            bias2: bias * bias,
            deferred_bias2: deferred,
        }
    }

    /// Exact moments of the radiance caching estimator at the root under `rule`, with Russian
    /// roulette of survival `survival` on every continued segment.
    pub fn estimator(&self, rule: &TerminationRule, survival: f64) -> Moments {
        let stats = self.local_stats(0);
        let state = PathState {
            throughput2: 1.0,
            threshold: path_threshold(rule, Some(stats.radiance)),
            vertex: 1,
            ..Default::default()
        };
        self.moments_from(0, 1.0, state, rule, survival)
    }

    fn moments_from(
        &self,
        i: usize,
        throughput: f64,
        mut state: PathState,
        rule: &TerminationRule,
        q: f64,
    ) -> Moments {
        if self.is_leaf(i) {
            let y = throughput * self.cache[i];
            return Moments { mean: y, second: y * y };
        }
        state.throughput2 = throughput * throughput;
        let decision = decide(rule, q, &mut state, &self.local_stats(i));
        let alpha = decision.alpha();
        // The cache's share, then the continuation's moments (roulette: survive with q, 1/q).
        let mut base = throughput * (1.0 - alpha) * self.cache[i];
        let mut cont = Moments::default();
        if alpha > 0.0 {
            // NEE before the survival draw, scaled by α as the paper's line 17.
            base += throughput * alpha * self.direct;
            for (c, p) in self.children(i) {
                let t = throughput * alpha * self.edge_weight / (p * q);
                let m = match decision {
                    Decision::Continue => {
                        let mut next = state;
                        next.vertex += 1;
                        self.moments_from(c, t, next, rule, q)
                    }
                    // The blended segment terminates into the cache at its hit.
                    _ => Moments {
                        mean: t * self.cache[c],
                        second: t * t * self.cache[c] * self.cache[c],
                    },
                };
                cont.mean += p * q * m.mean;
                cont.second += p * q * m.second;
            }
        }
        Moments {
            mean: base + cont.mean,
            second: base * base + 2.0 * base * cont.mean + cont.second,
        }
    }

    /// Closed form of the variance under variance bounding with exact caches: every path's
    /// variance is its full path variance S, capped at t (Σ over outcomes of p · min(S, t)).
    /// Only valid for exact caches. Its local variances are enumerated here
    /// ([`SamplingTree::rouletted_segment_variance`]), not taken from the decision's formula.
    pub fn bounded_variance(&self, t: f64, survival: f64) -> f64 {
        self.bounded_from(0, 1.0, 0.0, t, survival)
    }

    fn bounded_from(&self, i: usize, throughput: f64, sum: f64, t: f64, q: f64) -> f64 {
        if self.is_leaf(i) {
            return sum;
        }
        let s = sum + throughput * throughput * self.rouletted_segment_variance(i, q);
        if s > t {
            return t;
        }
        // A path killed by roulette ends with its variance so far.
        let mut v = (1.0 - q) * s;
        for (c, p) in self.children(i) {
            v += p * q * self.bounded_from(c, throughput * self.edge_weight / (p * q), s, t, q);
        }
        v
    }

    /// Variance of one segment at inner node i under roulette of survival q, by enumeration:
    /// Y' = direct + χ (w / (p q)) cache(child), χ ~ Bernoulli(q). The direct light is
    /// constant, so it adds nothing.
    pub fn rouletted_segment_variance(&self, i: usize, q: f64) -> f64 {
        let w = self.edge_weight;
        let (mut mean, mut second) = (0.0, 0.0);
        for (c, p) in self.children(i) {
            let y = self.direct + w / (p * q) * self.cache[c];
            mean += p * (q * y + (1.0 - q) * self.direct);
            second += p * (q * y * y + (1.0 - q) * self.direct * self.direct);
        }
        second - mean * mean
    }

    /// The squared bias a continued path brings to its next vertex, per unit of squared
    /// throughput, by enumeration under roulette of survival q: Σ p q (w / (p q))² B²(child).
    pub fn next_vertex_bias2(&self, i: usize, q: f64) -> f64 {
        let w = self.edge_weight;
        self.children(i)
            .iter()
            .map(|&(c, p)| {
                let b = self.cache[c] - self.value(c);
                p * q * (w / (p * q)).powi(2) * b * b
            })
            .sum()
    }

    /// The smallest full path variance over root-to-leaf paths: below it, variance bounding
    /// meets t exactly; above it, some subtree is expanded completely and the bound detaches.
    pub fn detach_threshold(&self) -> f64 {
        self.min_path_sum(0, 1.0, 0.0)
    }

    fn min_path_sum(&self, i: usize, throughput: f64, sum: f64) -> f64 {
        if self.is_leaf(i) {
            return sum;
        }
        let s = sum + throughput * throughput * self.local_stats(i).variance;
        self.children(i)
            .iter()
            .map(|&(c, p)| self.min_path_sum(c, throughput * self.edge_weight / p, s))
            .fold(f64::INFINITY, f64::min)
    }

    /// Plain path tracing's moments without the cache: the leaves' emission and the direct
    /// light along the path, Σ_paths p · (Σ_vertices g · emission)².
    pub fn path_tracing(&self) -> Moments {
        self.path_tracing_from(0, 1.0)
    }

    fn path_tracing_from(&self, i: usize, g: f64) -> Moments {
        if self.is_leaf(i) {
            return Moments { mean: g, second: g * g };
        }
        let a = g * self.direct;
        let mut m = Moments { mean: a, second: a * a };
        for (c, p) in self.children(i) {
            let x = self.path_tracing_from(c, g * self.edge_weight / p);
            m.mean += p * x.mean;
            m.second += p * (2.0 * a * x.mean + x.second);
        }
        m
    }

    /// MSE of the N-sample average against the true root value.
    pub fn mse(&self, m: Moments, samples: f64) -> f64 {
        let bias = m.mean - self.value(0);
        m.variance() / samples + bias * bias
    }
}

fn node_depth(i: usize) -> u32 {
    (usize::BITS - 1) - (i + 1).leading_zeros()
}
