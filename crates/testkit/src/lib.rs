//! fxbody-testkit: what the tests of every package share, so that each exists once.
//!
//! - [`Rng`]: the one seeded pseudo-random generator of the tests and benches (random
//!   bodies and scenes, damaged files, randomised round trips): the same numbers on every
//!   run and every machine, with no dependency.
//! - [`in_pool`]: run work in a rayon pool of a given size, for the tests that check a
//!   result is the same bits whatever the pool.
//!
//! A dev-dependency of the packages that test with it; never part of a product build.

/// A seeded pseudo-random sequence: Knuth's 64-bit linear congruential generator (MMIX
/// constants), whose state's high bits give the reals ([`Rng::uniform`]) and whose state
/// passed through a bit mixer (splitmix64's finaliser) gives the integers
/// ([`Rng::next_u64`]; an LCG's own low bits repeat with short periods).
///
/// ```
/// use fxbody_testkit::Rng;
///
/// let mut a = Rng::new(42);
/// let mut b = Rng::new(42);
/// let x: Vec<f64> = (0..1000).map(|_| a.uniform()).collect();
/// assert!(x.iter().all(|v| (0.0..1.0).contains(v)));
/// assert_eq!(x[999], (0..1000).map(|_| b.uniform()).last().unwrap());
/// // The mean of 1000 uniform numbers is 1/2 to a few times 1/sqrt(12 * 1000) = 0.009.
/// let mean = x.iter().sum::<f64>() / 1000.0;
/// assert!((mean - 0.5).abs() < 0.03, "{mean}");
/// ```
#[derive(Debug, Clone)]
pub struct Rng(u64);

impl Rng {
    /// The sequence of `seed` (any value, zero included).
    pub fn new(seed: u64) -> Rng {
        Rng(seed)
    }

    /// The next state of the generator.
    fn step(&mut self) -> u64 {
        self.0 = self
            .0
            .wrapping_mul(6_364_136_223_846_793_005)
            .wrapping_add(1_442_695_040_888_963_407);
        self.0
    }

    /// A uniform real in [0, 1): the state's top 53 bits.
    pub fn uniform(&mut self) -> f64 {
        (self.step() >> 11) as f64 / (1u64 << 53) as f64
    }

    /// A uniform real in [-1, 1).
    pub fn symmetric(&mut self) -> f64 {
        self.uniform() * 2.0 - 1.0
    }

    /// 64 uniform bits, every bit as random as the others.
    pub fn next_u64(&mut self) -> u64 {
        let mut z = self.step();
        z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        z ^ (z >> 31)
    }

    /// A uniform integer in `0..n` (0 when `n` is 0).
    pub fn below(&mut self, n: usize) -> usize {
        if n == 0 {
            0
        } else {
            (self.next_u64() % n as u64) as usize
        }
    }
}

/// `f` run in a rayon pool of `threads` threads: for the tests that check a result is
/// the same bits whatever the pool's size.
pub fn in_pool<T: Send>(threads: usize, f: impl FnOnce() -> T + Send) -> T {
    rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .expect("a thread pool")
        .install(f)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The reals are the state's high bits: the first value for seed 0 is the
    /// increment's top 53 bits over 2^53, computed by hand.
    #[test]
    fn first_values_are_the_lcg_by_hand() {
        let mut r = Rng::new(0);
        let want = (1_442_695_040_888_963_407u64 >> 11) as f64 / (1u64 << 53) as f64;
        assert_eq!(r.uniform(), want);
    }

    /// Each bit of `next_u64` is set about half the time (2000 draws: 1000 +- 5 sigma =
    /// 1000 +- 112), the low bits included, which an LCG's raw state fails (its lowest
    /// bit alternates).
    #[test]
    fn every_bit_is_balanced() {
        let mut r = Rng::new(7);
        let mut ones = [0usize; 64];
        for _ in 0..2000 {
            let x = r.next_u64();
            for (b, count) in ones.iter_mut().enumerate() {
                *count += ((x >> b) & 1) as usize;
            }
        }
        for (b, &count) in ones.iter().enumerate() {
            assert!((888..=1112).contains(&count), "bit {b}: {count} of 2000");
        }
        let mut below = [0usize; 3];
        for _ in 0..3000 {
            below[r.below(3)] += 1;
        }
        assert!(
            below.iter().all(|&c| (850..=1150).contains(&c)),
            "{below:?}"
        );
    }

    #[test]
    fn pools_of_each_size_run_the_work() {
        for threads in [1, 2, 3] {
            assert_eq!(in_pool(threads, rayon::current_num_threads), threads);
        }
    }
}
