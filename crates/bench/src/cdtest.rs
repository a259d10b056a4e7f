//! The CDTestFramework broadphase scene (Bullet `Extras/CDTestFramework`, P. Terdiman; see
//! `shared/bench/SCENES.md`): N boxes on a 3-D Lissajous curve, a fraction of them advancing
//! along it each frame. A SplitMix64 generator replaces the C library's `rand()`.

/// SplitMix64 (Steele et al. 2014): deterministic on every platform.
pub struct Rng(u64);

impl Rng {
    pub fn new(seed: u64) -> Self {
        Rng(seed)
    }
    pub fn next_u64(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }
    /// Uniform in [0, 1].
    pub fn unit(&mut self) -> f64 {
        (self.next_u64() >> 11) as f64 / ((1u64 << 53) - 1) as f64
    }
}

/// The scene state: box centres, half extents and curve phases.
pub struct Scene {
    pub centers: Vec<[f64; 3]>,
    pub half: Vec<[f64; 3]>,
    pub phase: Vec<f64>,
    /// Curve amplitude (100 in CDTestFramework).
    pub amplitude: f64,
    /// Phase advance per frame of a moving box (0.01).
    pub speed: f64,
    /// Number of boxes moved per frame (the first ones).
    pub moving: usize,
}

impl Scene {
    /// `n` boxes, `percent` of them moving per frame, curve amplitude `amplitude`.
    pub fn new(n: usize, percent: f64, speed: f64, amplitude: f64) -> Self {
        let mut rng = Rng::new(0);
        let mut centers = Vec::with_capacity(n);
        let mut half = Vec::with_capacity(n);
        let mut phase = Vec::with_capacity(n);
        for _ in 0..n {
            centers.push([
                (rng.unit() - 0.5) * 100.0,
                (rng.unit() - 0.5) * 10.0,
                (rng.unit() - 0.5) * 100.0,
            ]);
            half.push([
                2.0 + 2.0 * rng.unit(),
                2.0 + 2.0 * rng.unit(),
                2.0 + 2.0 * rng.unit(),
            ]);
            phase.push(2000.0 * rng.unit());
        }
        let moving = ((n as f64 * percent / 100.0).round() as usize).min(n);
        Scene {
            centers,
            half,
            phase,
            amplitude,
            speed,
            moving,
        }
    }

    /// Advances the boxes `0..count` along the curve; returns their displacements.
    pub fn advance(&mut self, count: usize) -> Vec<[f64; 3]> {
        let a = self.amplitude;
        let mut disp = Vec::with_capacity(count);
        for i in 0..count {
            self.phase[i] += self.speed;
            let t = self.phase[i];
            let c = [
                a * (2.17 * t).cos() + 0.5 * a * t.sin(),
                a * (1.38 * t).cos() + (a * t).sin(),
                a * (0.777 * t).sin(),
            ];
            let o = self.centers[i];
            disp.push([c[0] - o[0], c[1] - o[1], c[2] - o[2]]);
            self.centers[i] = c;
        }
        disp
    }

    /// Box `i` as (min, max).
    pub fn aabb(&self, i: usize) -> ([f64; 3], [f64; 3]) {
        let (c, h) = (self.centers[i], self.half[i]);
        (
            [c[0] - h[0], c[1] - h[1], c[2] - h[2]],
            [c[0] + h[0], c[1] + h[1], c[2] + h[2]],
        )
    }
}
