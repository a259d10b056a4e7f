//! The C library's `rand()` as glibc implements it (`TYPE_3`, additive feedback), so scenes
//! that call `rand()` pick the same shapes as Bullet did on Linux.

/// glibc's `random()`/`rand()` generator.
#[derive(Debug, Clone)]
pub struct GlibcRand {
    r: Vec<u32>,
}

impl GlibcRand {
    /// `srand(seed)`; `seed = 1` is the state of an unseeded process.
    pub fn new(seed: u32) -> Self {
        let seed = if seed == 0 { 1 } else { seed };
        let mut r = vec![0u32; 34];
        r[0] = seed;
        for i in 1..31 {
            // 16807 * r[i-1] % (2^31 - 1), by Schrage's method as glibc does.
            let word = r[i - 1] as i64;
            let hi = word / 127_773;
            let lo = word % 127_773;
            let mut w = 16_807 * lo - 2_836 * hi;
            if w < 0 {
                w += 2_147_483_647;
            }
            r[i] = w as u32;
        }
        for i in 31..34 {
            r[i] = r[i - 31];
        }
        let mut g = GlibcRand { r };
        for _ in 34..344 {
            g.step();
        }
        g
    }

    fn step(&mut self) -> u32 {
        let n = self.r.len();
        let v = self.r[n - 31].wrapping_add(self.r[n - 3]);
        self.r.push(v);
        if self.r.len() > 1024 {
            self.r.drain(..self.r.len() - 34);
        }
        v
    }

    /// The next `rand()` value in `[0, 2^31)`.
    #[allow(clippy::should_implement_trait)]
    pub fn next(&mut self) -> u32 {
        self.step() >> 1
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn matches_glibc_sequence() {
        // First values of rand() in a fresh glibc process.
        let mut g = GlibcRand::new(1);
        let got: Vec<u32> = (0..5).map(|_| g.next()).collect();
        assert_eq!(
            got,
            vec![1804289383, 846930886, 1681692777, 1714636915, 1957747793]
        );
    }
}
