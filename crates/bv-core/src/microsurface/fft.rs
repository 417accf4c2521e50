//! A radix-2 complex FFT (iterative Cooley–Tukey) and its 2D form, for the
//! spectral synthesis of [`super::surface`]. The workspace has no FFT crate
//! (`rustfft` is not in Cargo.lock) and this one transform is all the
//! generator needs: sizes are powers of two, and speed matters little next to
//! the ray tracing.

use rayon::prelude::*;
use std::f64::consts::PI;

/// A complex number as (re, im).
pub type Complex = [f64; 2];

/// In-place FFT of `a` (length a power of two). `inverse` uses e^{+i…} and
/// divides by the length, so `fft(fft(a), inverse)` is `a`.
pub fn fft(a: &mut [Complex], inverse: bool) {
    let n = a.len();
    debug_assert!(n.is_power_of_two());
    if n <= 1 {
        return;
    }
    // Bit-reversal permutation.
    let mut j = 0usize;
    for i in 1..n {
        let mut bit = n >> 1;
        while j & bit != 0 {
            j ^= bit;
            bit >>= 1;
        }
        j |= bit;
        if i < j {
            a.swap(i, j);
        }
    }
    let sign = if inverse { 1.0 } else { -1.0 };
    let mut len = 2;
    while len <= n {
        let ang = sign * 2.0 * PI / len as f64;
        let half = len / 2;
        // Twiddles computed directly (not by repeated multiplication) so the
        // error does not grow with the length.
        let tw: Vec<Complex> = (0..half)
            .map(|k| {
                let (s, c) = (ang * k as f64).sin_cos();
                [c, s]
            })
            .collect();
        for chunk in a.chunks_mut(len) {
            let (lo, hi) = chunk.split_at_mut(half);
            for ((u, v), w) in lo.iter_mut().zip(hi.iter_mut()).zip(&tw) {
                let t = [v[0] * w[0] - v[1] * w[1], v[0] * w[1] + v[1] * w[0]];
                *v = [u[0] - t[0], u[1] - t[1]];
                *u = [u[0] + t[0], u[1] + t[1]];
            }
        }
        len <<= 1;
    }
    if inverse {
        let s = 1.0 / n as f64;
        for v in a.iter_mut() {
            v[0] *= s;
            v[1] *= s;
        }
    }
}

/// In-place 2D FFT of an `n × n` row-major array: rows, then columns (each
/// row or column on its own, so the result does not depend on the threads).
pub fn fft2(a: &mut [Complex], n: usize, inverse: bool) {
    a.par_chunks_mut(n).for_each(|row| fft(row, inverse));
    transpose(a, n);
    a.par_chunks_mut(n).for_each(|row| fft(row, inverse));
    transpose(a, n);
}

fn transpose(a: &mut [Complex], n: usize) {
    for i in 0..n {
        for j in (i + 1)..n {
            a.swap(i * n + j, j * n + i);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Against the O(n²) definition of the DFT.
    #[test]
    fn matches_the_definition() {
        let n = 16;
        let x: Vec<Complex> = (0..n)
            .map(|i| [(i as f64 * 0.7).sin(), (i as f64 * 1.3).cos() * 0.5])
            .collect();
        let mut y = x.clone();
        fft(&mut y, false);
        for (k, yk) in y.iter().enumerate() {
            let mut s = [0.0, 0.0];
            for (j, xj) in x.iter().enumerate() {
                let (sn, c) = (-2.0 * PI * (j * k) as f64 / n as f64).sin_cos();
                s[0] += xj[0] * c - xj[1] * sn;
                s[1] += xj[0] * sn + xj[1] * c;
            }
            assert!((s[0] - yk[0]).abs() < 1e-12 && (s[1] - yk[1]).abs() < 1e-12);
        }
        fft(&mut y, true);
        for (a, b) in x.iter().zip(&y) {
            assert!((a[0] - b[0]).abs() < 1e-13 && (a[1] - b[1]).abs() < 1e-13);
        }
    }
}
