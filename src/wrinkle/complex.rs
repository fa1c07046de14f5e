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
    #[inline]
    pub fn cis(theta: f64) -> Complex {
        let (s, c) = theta.sin_cos();
        Complex { re: c, im: s }
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
}
