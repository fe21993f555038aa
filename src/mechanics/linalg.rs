//! The engine's small fixed-size vectors and matrices: the integrators'
//! states (2 to 5 entries), the two-stage relay's 4 × 4 linear modes and
//! their 8 × 4 readouts.
//!
//! Stored by columns, indexed `[i]` (a vector's entry, or an entry in
//! column order) and `[(row, column)]`. Every sum has a fixed order, so a
//! run is reproducible to the last digit: a product's entry adds its
//! terms in column order, and a dot product of four terms adds them as
//! `(a₀b₀ + a₂b₂) + (a₁b₁ + a₃b₃)` (of two, three or more, in order). The
//! one solve, A·x = b for a 4 × 4 mode's equilibrium, is Gaussian
//! elimination with partial pivoting.

use std::ops::{Add, AddAssign, Div, Index, IndexMut, Mul, MulAssign, Neg, Sub, SubAssign};

/// An `R` × `C` matrix of `T` (here always `f64`), stored by columns.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SMatrix<T, const R: usize, const C: usize> {
    columns: [[T; R]; C],
}

/// A column vector of `N` entries.
pub type SVector<T, const N: usize> = SMatrix<T, N, 1>;
/// A vector of 2.
pub type Vector2<T> = SVector<T, 2>;
/// A vector of 3.
pub type Vector3<T> = SVector<T, 3>;
/// A vector of 4.
pub type Vector4<T> = SVector<T, 4>;
/// A 4 × 4 matrix.
pub type Matrix4<T> = SMatrix<T, 4, 4>;

impl<const R: usize, const C: usize> SMatrix<f64, R, C> {
    /// All zeros.
    #[inline]
    pub fn zeros() -> Self {
        Self::repeat(0.0)
    }

    /// Every entry `x`.
    #[inline]
    pub fn repeat(x: f64) -> Self {
        SMatrix {
            columns: [[x; R]; C],
        }
    }

    /// Entry (i, j) from `f(i, j)`.
    #[inline]
    pub fn from_fn(mut f: impl FnMut(usize, usize) -> f64) -> Self {
        let mut m = Self::zeros();
        for j in 0..C {
            for i in 0..R {
                m.columns[j][i] = f(i, j);
            }
        }
        m
    }

    /// The entries in column order.
    #[inline]
    pub fn iter(&self) -> std::slice::Iter<'_, f64> {
        self.columns.as_flattened().iter()
    }

    /// The entries in column order, to change.
    #[inline]
    pub fn iter_mut(&mut self) -> std::slice::IterMut<'_, f64> {
        self.columns.as_flattened_mut().iter_mut()
    }

    /// `f` of every entry.
    #[inline]
    pub fn map(&self, mut f: impl FnMut(f64) -> f64) -> Self {
        let mut m = *self;
        for column in &mut m.columns {
            for x in column {
                *x = f(*x);
            }
        }
        m
    }

    /// Every entry's absolute value.
    #[inline]
    pub fn abs(&self) -> Self {
        self.map(f64::abs)
    }

    /// The entries' sum, in column order.
    #[inline]
    pub fn sum(&self) -> f64 {
        self.iter().fold(0.0, |s, x| s + x)
    }

    /// The largest absolute entry.
    #[inline]
    pub fn amax(&self) -> f64 {
        self.iter().fold(0.0, |m, x| m.max(x.abs()))
    }

    /// The largest entry.
    #[inline]
    pub fn max(&self) -> f64 {
        self.iter().copied().fold(f64::NEG_INFINITY, f64::max)
    }

    /// The Euclidean (Frobenius) norm.
    #[inline]
    pub fn norm(&self) -> f64 {
        self.dot(self).sqrt()
    }

    /// Σ aᵢⱼ·bᵢⱼ, in the fixed order of the module's documentation.
    #[inline]
    pub fn dot(&self, other: &Self) -> f64 {
        let (a, b) = (self.as_slice(), other.as_slice());
        match a.len() {
            2 => a[0] * b[0] + a[1] * b[1],
            3 => a[0] * b[0] + a[1] * b[1] + a[2] * b[2],
            4 => (a[0] * b[0] + a[2] * b[2]) + (a[1] * b[1] + a[3] * b[3]),
            _ => a.iter().zip(b).map(|(x, y)| x * y).sum(),
        }
    }

    /// Aᵀ.
    #[inline]
    pub fn transpose(&self) -> SMatrix<f64, C, R> {
        SMatrix::from_fn(|i, j| self[(j, i)])
    }

    /// Aᵀ·v: entry j is the dot product of column j with v.
    #[inline]
    pub fn tr_mul(&self, v: &SVector<f64, R>) -> SVector<f64, C> {
        let mut out = SVector::zeros();
        for j in 0..C {
            out.columns[0][j] = SVector {
                columns: [self.columns[j]],
            }
            .dot(v);
        }
        out
    }

    /// `self·s + b` entry by entry, in place: each entry rounded as
    /// `self * s + b` rounds it, without the temporaries. Always inlined,
    /// so that it takes the instruction set of the code that calls it.
    #[inline(always)]
    pub fn scale_add(&mut self, s: f64, b: &Self) {
        for (column, add) in self.columns.iter_mut().zip(&b.columns) {
            for (x, a) in column.iter_mut().zip(add) {
                *x = *x * s + a;
            }
        }
    }

    /// Rows `start` to `start + N`, copied.
    #[inline]
    pub fn fixed_rows<const N: usize>(&self, start: usize) -> SMatrix<f64, N, C> {
        SMatrix::from_fn(|i, j| self.columns[j][start + i])
    }

    /// The matrix itself (the copies here are already owned).
    #[inline]
    pub fn into_owned(self) -> Self {
        self
    }

    /// Row `i` set to `row`.
    #[inline]
    pub fn set_row(&mut self, i: usize, row: &SMatrix<f64, 1, C>) {
        for j in 0..C {
            self.columns[j][i] = row.columns[j][0];
        }
    }

    #[inline]
    fn as_slice(&self) -> &[f64] {
        self.columns.as_flattened()
    }
}

impl<const N: usize> SMatrix<f64, N, N> {
    /// The identity.
    #[inline]
    pub fn identity() -> Self {
        Self::from_fn(|i, j| if i == j { 1.0 } else { 0.0 })
    }

    /// The factors of Gaussian elimination with partial pivoting, to
    /// solve with.
    #[inline]
    pub fn lu(&self) -> Lu<N> {
        Lu { a: *self }
    }
}

/// A square matrix to solve with ([`SMatrix::lu`]).
pub struct Lu<const N: usize> {
    a: SMatrix<f64, N, N>,
}

impl<const N: usize> Lu<N> {
    /// x with A·x = b, or `None` when a pivot is zero (A singular).
    #[inline]
    pub fn solve(&self, b: &SVector<f64, N>) -> Option<SVector<f64, N>> {
        let mut a = self.a;
        let mut x = *b;
        for k in 0..N {
            let p = (k..N).fold(k, |p, i| {
                if a[(i, k)].abs() > a[(p, k)].abs() {
                    i
                } else {
                    p
                }
            });
            if a[(p, k)] == 0.0 {
                return None;
            }
            for j in 0..N {
                a.columns[j].swap(k, p);
            }
            x.columns[0].swap(k, p);
            for i in k + 1..N {
                let f = a[(i, k)] / a[(k, k)];
                for j in k..N {
                    let akj = a[(k, j)];
                    a[(i, j)] -= f * akj;
                }
                let xk = x[k];
                x[i] -= f * xk;
            }
        }
        for k in (0..N).rev() {
            let mut s = x[k];
            for j in k + 1..N {
                s -= a[(k, j)] * x[j];
            }
            x[k] = s / a[(k, k)];
        }
        Some(x)
    }
}

impl SMatrix<f64, 1, 1> {
    #[inline]
    pub fn new(a: f64) -> Self {
        SMatrix { columns: [[a]] }
    }
}

impl SMatrix<f64, 2, 1> {
    #[inline]
    pub fn new(a: f64, b: f64) -> Self {
        SMatrix { columns: [[a, b]] }
    }
}

impl SMatrix<f64, 3, 1> {
    #[inline]
    pub fn new(a: f64, b: f64, c: f64) -> Self {
        SMatrix {
            columns: [[a, b, c]],
        }
    }
}

impl SMatrix<f64, 4, 1> {
    #[inline]
    pub fn new(a: f64, b: f64, c: f64, d: f64) -> Self {
        SMatrix {
            columns: [[a, b, c, d]],
        }
    }
}

impl SMatrix<f64, 5, 1> {
    #[inline]
    pub fn new(a: f64, b: f64, c: f64, d: f64, e: f64) -> Self {
        SMatrix {
            columns: [[a, b, c, d, e]],
        }
    }
}

impl SMatrix<f64, 4, 4> {
    /// From its sixteen entries row by row.
    #[allow(clippy::too_many_arguments)]
    #[inline]
    pub fn new(
        m11: f64,
        m12: f64,
        m13: f64,
        m14: f64,
        m21: f64,
        m22: f64,
        m23: f64,
        m24: f64,
        m31: f64,
        m32: f64,
        m33: f64,
        m34: f64,
        m41: f64,
        m42: f64,
        m43: f64,
        m44: f64,
    ) -> Self {
        SMatrix {
            columns: [
                [m11, m21, m31, m41],
                [m12, m22, m32, m42],
                [m13, m23, m33, m43],
                [m14, m24, m34, m44],
            ],
        }
    }
}

impl<const R: usize, const C: usize> Index<usize> for SMatrix<f64, R, C> {
    type Output = f64;
    #[inline]
    fn index(&self, i: usize) -> &f64 {
        if C == 1 {
            &self.columns[0][i]
        } else {
            &self.columns[i / R][i % R]
        }
    }
}

impl<const R: usize, const C: usize> IndexMut<usize> for SMatrix<f64, R, C> {
    #[inline]
    fn index_mut(&mut self, i: usize) -> &mut f64 {
        if C == 1 {
            &mut self.columns[0][i]
        } else {
            &mut self.columns[i / R][i % R]
        }
    }
}

impl<const R: usize, const C: usize> Index<(usize, usize)> for SMatrix<f64, R, C> {
    type Output = f64;
    #[inline]
    fn index(&self, (i, j): (usize, usize)) -> &f64 {
        &self.columns[j][i]
    }
}

impl<const R: usize, const C: usize> IndexMut<(usize, usize)> for SMatrix<f64, R, C> {
    #[inline]
    fn index_mut(&mut self, (i, j): (usize, usize)) -> &mut f64 {
        &mut self.columns[j][i]
    }
}

/// Entry by entry: `a op b` for owned and borrowed operands.
macro_rules! entrywise {
    ($trait:ident, $method:ident, $assign:ident, $assign_method:ident, $op:tt) => {
        impl<const R: usize, const C: usize> $assign for SMatrix<f64, R, C> {
            #[inline]
            fn $assign_method(&mut self, rhs: Self) {
                self.$assign_method(&rhs);
            }
        }
        impl<const R: usize, const C: usize> $assign<&SMatrix<f64, R, C>> for SMatrix<f64, R, C> {
            #[inline]
            fn $assign_method(&mut self, rhs: &Self) {
                for j in 0..C {
                    for i in 0..R {
                        self.columns[j][i] = self.columns[j][i] $op rhs.columns[j][i];
                    }
                }
            }
        }
        impl<const R: usize, const C: usize> $trait for SMatrix<f64, R, C> {
            type Output = Self;
            #[inline]
            fn $method(mut self, rhs: Self) -> Self {
                self.$assign_method(rhs);
                self
            }
        }
        impl<const R: usize, const C: usize> $trait<&SMatrix<f64, R, C>> for SMatrix<f64, R, C> {
            type Output = Self;
            #[inline]
            fn $method(mut self, rhs: &Self) -> Self {
                self.$assign_method(rhs);
                self
            }
        }
        impl<const R: usize, const C: usize> $trait<SMatrix<f64, R, C>> for &SMatrix<f64, R, C> {
            type Output = SMatrix<f64, R, C>;
            #[inline]
            fn $method(self, rhs: SMatrix<f64, R, C>) -> SMatrix<f64, R, C> {
                let mut out = *self;
                out.$assign_method(rhs);
                out
            }
        }
        impl<const R: usize, const C: usize> $trait<&SMatrix<f64, R, C>> for &SMatrix<f64, R, C> {
            type Output = SMatrix<f64, R, C>;
            #[inline]
            fn $method(self, rhs: &SMatrix<f64, R, C>) -> SMatrix<f64, R, C> {
                let mut out = *self;
                out.$assign_method(rhs);
                out
            }
        }
    };
}

entrywise!(Add, add, AddAssign, add_assign, +);
entrywise!(Sub, sub, SubAssign, sub_assign, -);

impl<const R: usize, const C: usize> Neg for SMatrix<f64, R, C> {
    type Output = Self;
    #[inline]
    fn neg(self) -> Self {
        self.map(|x| -x)
    }
}

impl<const R: usize, const C: usize> Neg for &SMatrix<f64, R, C> {
    type Output = SMatrix<f64, R, C>;
    #[inline]
    fn neg(self) -> SMatrix<f64, R, C> {
        self.map(|x| -x)
    }
}

impl<const R: usize, const C: usize> MulAssign<f64> for SMatrix<f64, R, C> {
    #[inline]
    fn mul_assign(&mut self, s: f64) {
        for column in &mut self.columns {
            for x in column {
                *x *= s;
            }
        }
    }
}

impl<const R: usize, const C: usize> Mul<f64> for SMatrix<f64, R, C> {
    type Output = Self;
    #[inline]
    fn mul(mut self, s: f64) -> Self {
        self *= s;
        self
    }
}

impl<const R: usize, const C: usize> Mul<f64> for &SMatrix<f64, R, C> {
    type Output = SMatrix<f64, R, C>;
    #[inline]
    fn mul(self, s: f64) -> SMatrix<f64, R, C> {
        *self * s
    }
}

impl<const R: usize, const C: usize> Mul<SMatrix<f64, R, C>> for f64 {
    type Output = SMatrix<f64, R, C>;
    #[inline]
    fn mul(self, m: SMatrix<f64, R, C>) -> SMatrix<f64, R, C> {
        m.map(|x| self * x)
    }
}

impl<const R: usize, const C: usize> Mul<&SMatrix<f64, R, C>> for f64 {
    type Output = SMatrix<f64, R, C>;
    #[inline]
    fn mul(self, m: &SMatrix<f64, R, C>) -> SMatrix<f64, R, C> {
        m.map(|x| self * x)
    }
}

impl<const R: usize, const C: usize> Div<f64> for SMatrix<f64, R, C> {
    type Output = Self;
    #[inline]
    fn div(self, s: f64) -> Self {
        self.map(|x| x / s)
    }
}

impl<const R: usize, const C: usize> Div<f64> for &SMatrix<f64, R, C> {
    type Output = SMatrix<f64, R, C>;
    #[inline]
    fn div(self, s: f64) -> SMatrix<f64, R, C> {
        self.map(|x| x / s)
    }
}

/// A·B: entry (i, j) adds aᵢₖ·bₖⱼ in the order of k. Always inlined,
/// so that it takes the instruction set of the code that calls it.
#[inline(always)]
fn product<const R: usize, const K: usize, const C: usize>(
    a: &SMatrix<f64, R, K>,
    b: &SMatrix<f64, K, C>,
) -> SMatrix<f64, R, C> {
    let mut out = SMatrix::zeros();
    for j in 0..C {
        for i in 0..R {
            let mut s = a.columns[0][i] * b.columns[j][0];
            for k in 1..K {
                s += a.columns[k][i] * b.columns[j][k];
            }
            out.columns[j][i] = s;
        }
    }
    out
}

macro_rules! products {
    ($($lhs:ty, $rhs:ty;)*) => {$(
        impl<const R: usize, const K: usize, const C: usize> Mul<$rhs> for $lhs {
            type Output = SMatrix<f64, R, C>;
            #[allow(clippy::needless_borrow)]
            #[inline]
            fn mul(self, rhs: $rhs) -> SMatrix<f64, R, C> {
                product(&self, &rhs)
            }
        }
    )*};
}

products! {
    SMatrix<f64, R, K>, SMatrix<f64, K, C>;
    SMatrix<f64, R, K>, &SMatrix<f64, K, C>;
    &SMatrix<f64, R, K>, SMatrix<f64, K, C>;
    &SMatrix<f64, R, K>, &SMatrix<f64, K, C>;
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn entries_are_stored_by_columns_and_read_by_row_and_column() {
        let m = Matrix4::new(
            1.0, 2.0, 3.0, 4.0, 5.0, 6.0, 7.0, 8.0, 9.0, 10.0, 11.0, 12.0, 13.0, 14.0, 15.0, 16.0,
        );
        assert_eq!(m[(1, 2)], 7.0);
        assert_eq!(m[1], 5.0, "the second entry in column order");
        assert_eq!(m.transpose()[(2, 1)], 7.0);
        let mut r = SMatrix::<f64, 2, 4>::zeros();
        // Aᵀ·e₁ is row 1 of A.
        r.set_row(1, &m.tr_mul(&Vector4::new(0.0, 1.0, 0.0, 0.0)).transpose());
        assert_eq!(r[(1, 0)], 5.0);
        assert_eq!(r[(1, 3)], 8.0);
        assert_eq!(r[(0, 3)], 0.0);
    }

    #[test]
    fn products_sums_and_dots_follow_their_definitions() {
        let a = Matrix4::from_fn(|i, j| (i * 4 + j) as f64 - 5.0);
        let b = Matrix4::from_fn(|i, j| if (i + j) % 3 == 0 { 2.0 } else { -0.5 });
        let ab = a * b;
        for i in 0..4 {
            for j in 0..4 {
                let want: f64 = (0..4).map(|k| a[(i, k)] * b[(k, j)]).sum();
                assert_eq!(ab[(i, j)], want);
            }
        }
        let v = Vector4::new(1.0, -2.0, 0.5, 3.0);
        let av = a * v;
        for i in 0..4 {
            assert_eq!(av[i], (0..4).map(|k| a[(i, k)] * v[k]).sum::<f64>());
        }
        let atv = a.tr_mul(&v);
        assert_eq!(atv, a.transpose() * v);
        assert_eq!(v.dot(&v), 1.0 + 4.0 + 0.25 + 9.0);
        assert_eq!(v.amax(), 3.0);
        assert_eq!((-v).max(), 2.0);
        assert_eq!((v * 2.0 - v) / 1.0 + Vector4::zeros(), v);
        assert_eq!(Matrix4::identity() * v, v);
        assert_eq!(Vector2::new(3.0, 4.0).norm(), 5.0);
        let mut m = a;
        m.scale_add(0.3, &b);
        assert_eq!(m, a * 0.3 + b);
        assert_ne!(m, a);
    }

    #[test]
    fn the_solve_pivots_and_refuses_a_singular_matrix() {
        // A zero first pivot: the rows must be exchanged.
        let a = Matrix4::new(
            0.0, 1.0, 0.0, 0.0, -4.0, -0.1, 1.0, 0.2, 0.0, 0.0, 0.0, 1.0, 3.0, 0.1, -5.0, -0.3,
        );
        let x = Vector4::new(0.25, -1.0, 2.0, 0.5);
        let b = a * x;
        let solved = a.lu().solve(&b).unwrap();
        assert!((solved - x).amax() < 1e-14, "{solved:?}");
        // Two equal rows: the elimination leaves an exact zero pivot.
        let singular = Matrix4::new(
            1.0, 2.0, 3.0, 4.0, 1.0, 2.0, 3.0, 4.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0,
        );
        assert_eq!(singular.lu().solve(&b), None);
    }
}
