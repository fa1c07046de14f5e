//! [`Complex`]: the tiny complex number type of the wrinkle module.
//!
//! pleat defines its own rather than re-exporting `faer::c64` or `num_complex`: it is
//! `#[repr(C)]` (two `f64`, real part first), so a C caller can pass `double[2]` per vertex, and
//! the public API does not change when a dependency bumps its complex type.

use std::ops::{Add, AddAssign, Mul, Neg, Sub};

/// A complex number `re + i·im` with C layout (`double re, im;`).
#[derive(Debug, Clone, Copy, Default, PartialEq)]
#[repr(C)]
pub struct Complex {
    /// Real part.
    pub re: f64,
    /// Imaginary part.
    pub im: f64,
}

impl Complex {
    /// Zero.
    pub const ZERO: Complex = Complex { re: 0.0, im: 0.0 };
    /// One.
    pub const ONE: Complex = Complex { re: 1.0, im: 0.0 };

    /// `re + i·im`.
    #[inline]
    pub const fn new(re: f64, im: f64) -> Complex {
        Complex { re, im }
    }

    /// `exp(i·theta) = cos(theta) + i·sin(theta)`: the unit complex number of phase `theta`.
    ///
    /// For `|theta| < 1e5` this is a branch-light sin/cos pair: Cody–Waite reduction by π/2 with
    /// a three-part π/2 (exact products for the quotient range used) and fdlibm's minimax
    /// kernels on `[−π/4, π/4]`; within 2 ulp of the correctly rounded values (tested against
    /// libm). Larger or non-finite arguments go to libm.
    #[inline]
    pub fn cis(theta: f64) -> Complex {
        if theta.abs() < 1.0e5 {
            let (s, c) = fast_sin_cos(theta);
            Complex { re: c, im: s }
        } else {
            let (s, c) = theta.sin_cos();
            Complex { re: c, im: s }
        }
    }

    /// `r·exp(i·theta)`.
    #[inline]
    pub fn from_polar(r: f64, theta: f64) -> Complex {
        Complex::cis(theta).scale(r)
    }

    /// Modulus `|z|` (overflow-safe).
    #[inline]
    pub fn abs(self) -> f64 {
        self.re.hypot(self.im)
    }

    /// Squared modulus `|z|²`.
    #[inline]
    pub fn norm_sqr(self) -> f64 {
        self.re * self.re + self.im * self.im
    }

    /// Argument in `(-π, π]` (0 for zero).
    #[inline]
    pub fn arg(self) -> f64 {
        self.im.atan2(self.re)
    }

    /// Complex conjugate.
    #[inline]
    pub fn conj(self) -> Complex {
        Complex::new(self.re, -self.im)
    }

    /// `s·z` for real `s`.
    #[inline]
    pub fn scale(self, s: f64) -> Complex {
        Complex::new(self.re * s, self.im * s)
    }

    /// True when both parts are finite.
    #[inline]
    pub fn is_finite(self) -> bool {
        self.re.is_finite() && self.im.is_finite()
    }

    /// The pair `[re, im]` (the layout of the C ABI and the `.cwf` file).
    #[inline]
    pub fn to_array(self) -> [f64; 2] {
        [self.re, self.im]
    }

    /// From the pair `[re, im]`.
    #[inline]
    pub fn from_array(a: [f64; 2]) -> Complex {
        Complex::new(a[0], a[1])
    }
}

/// `(sin x, cos x)` for `|x| < 1e5` (see [`Complex::cis`]).
#[inline]
#[allow(clippy::excessive_precision)] // fdlibm's published constants, verbatim
fn fast_sin_cos(x: f64) -> (f64, f64) {
    // π/2 = PIO2_1 + PIO2_2 + PIO2_2T; PIO2_1 and PIO2_2 have 33 significant bits, so k·PIO2_1
    // and k·PIO2_2 are exact for |k| < 2^20 (|x| < 1e5 gives |k| < 63662).
    const PIO2_1: f64 = 1.570_796_326_734_125_614_17e+00;
    const PIO2_2: f64 = 6.077_100_506_303_965_976_60e-11;
    const PIO2_2T: f64 = 2.022_266_248_795_950_631_54e-21;
    const INV_PIO2: f64 = std::f64::consts::FRAC_2_PI;
    // round to nearest (ties to even) without a libm call: valid for |x·2/π| < 2^51
    const SHIFTER: f64 = 6_755_399_441_055_744.0; // 1.5 · 2^52
    let k = (x * INV_PIO2 + SHIFTER) - SHIFTER;
    let r = ((x - k * PIO2_1) - k * PIO2_2) - k * PIO2_2T;
    let (s, c) = (kernel_sin(r), kernel_cos(r));
    match (k as i64) & 3 {
        0 => (s, c),
        1 => (c, -s),
        2 => (-s, -c),
        _ => (-c, s),
    }
}

/// fdlibm `__kernel_sin` (tail 0) on `[−π/4, π/4]`.
#[inline]
#[allow(clippy::excessive_precision)] // fdlibm's published constants, verbatim
fn kernel_sin(x: f64) -> f64 {
    const S1: f64 = -1.666_666_666_666_663_243_48e-01;
    const S2: f64 = 8.333_333_333_322_489_461_24e-03;
    const S3: f64 = -1.984_126_982_985_794_931_34e-04;
    const S4: f64 = 2.755_731_370_707_006_767_89e-06;
    const S5: f64 = -2.505_076_025_340_686_341_95e-08;
    const S6: f64 = 1.589_690_995_211_550_102_21e-10;
    let z = x * x;
    let v = z * x;
    let r = S2 + z * (S3 + z * (S4 + z * (S5 + z * S6)));
    x + v * (S1 + z * r)
}

/// fdlibm `__kernel_cos` (tail 0) on `[−π/4, π/4]`, with its `1 − z/2` split for accuracy.
#[inline]
#[allow(clippy::excessive_precision)] // fdlibm's published constants, verbatim
fn kernel_cos(x: f64) -> f64 {
    const C1: f64 = 4.166_666_666_666_660_190_37e-02;
    const C2: f64 = -1.388_888_888_887_410_957_49e-03;
    const C3: f64 = 2.480_158_728_947_672_941_78e-05;
    const C4: f64 = -2.755_731_435_139_066_330_35e-07;
    const C5: f64 = 2.087_572_321_298_174_827_90e-09;
    const C6: f64 = -1.135_964_755_778_819_482_65e-11;
    let z = x * x;
    let r = z * (C1 + z * (C2 + z * (C3 + z * (C4 + z * (C5 + z * C6)))));
    let hz = 0.5 * z;
    let w = 1.0 - hz;
    w + (((1.0 - w) - hz) + z * r)
}

impl Add for Complex {
    type Output = Complex;
    #[inline]
    fn add(self, o: Complex) -> Complex {
        Complex::new(self.re + o.re, self.im + o.im)
    }
}

impl AddAssign for Complex {
    #[inline]
    fn add_assign(&mut self, o: Complex) {
        self.re += o.re;
        self.im += o.im;
    }
}

impl Sub for Complex {
    type Output = Complex;
    #[inline]
    fn sub(self, o: Complex) -> Complex {
        Complex::new(self.re - o.re, self.im - o.im)
    }
}

impl Mul for Complex {
    type Output = Complex;
    #[inline]
    fn mul(self, o: Complex) -> Complex {
        Complex::new(
            self.re * o.re - self.im * o.im,
            self.re * o.im + self.im * o.re,
        )
    }
}

impl Mul<f64> for Complex {
    type Output = Complex;
    #[inline]
    fn mul(self, s: f64) -> Complex {
        self.scale(s)
    }
}

impl Neg for Complex {
    type Output = Complex;
    #[inline]
    fn neg(self) -> Complex {
        Complex::new(-self.re, -self.im)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn arithmetic() {
        let a = Complex::new(1.0, 2.0);
        let b = Complex::new(-3.0, 0.5);
        assert_eq!(a * b, Complex::new(-4.0, -5.5));
        assert_eq!(a + b - b, a);
        assert!((Complex::cis(0.3).abs() - 1.0).abs() < 1e-15);
        assert!((Complex::from_polar(2.0, 1.0).arg() - 1.0).abs() < 1e-15);
        assert_eq!(a.conj().im, -2.0);
        assert_eq!(Complex::from_array(a.to_array()), a);
    }

    #[test]
    fn fast_cis_matches_libm() {
        let mut x: u64 = 0x1234_5678_9abc_def1;
        let mut worst: f64 = 0.0;
        for i in 0..400_000 {
            x ^= x << 13;
            x ^= x >> 7;
            x ^= x << 17;
            let u = (x >> 11) as f64 / (1u64 << 53) as f64;
            let scale = [1e-8, 1.0, 4.0, 100.0, 3e4, 99_999.0][i % 6];
            let t = (2.0 * u - 1.0) * scale;
            let (s, c) = t.sin_cos();
            let z = Complex::cis(t);
            worst = worst.max((z.re - c).abs()).max((z.im - s).abs());
        }
        assert!(worst < 4.5e-16, "{worst:e}");
        for t in [0.0, -0.0, std::f64::consts::FRAC_PI_4, 1e5, -3e7, f64::NAN] {
            let (s, c) = t.sin_cos();
            let z = Complex::cis(t);
            assert!((z.re - c).abs() < 4.5e-16 || (c.is_nan() && z.re.is_nan()));
            assert!((z.im - s).abs() < 4.5e-16 || (s.is_nan() && z.im.is_nan()));
        }
    }
}
