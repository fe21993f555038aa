//! The fit's linear algebra: small dense matrices (a Jacobian of tens of
//! rows and at most six columns, its normal matrix), with the four
//! operations the solver needs: products, a linear solve and an inverse by
//! Gaussian elimination with partial pivoting, and the eigensystem of a
//! symmetric matrix by cyclic Jacobi rotations (Golub & Van Loan,
//! *Matrix Computations*, 4th ed., §8.5). At these sizes each is a few
//! microseconds against the milliseconds of one residual evaluation.

use std::ops::{Index, IndexMut};

/// A dense matrix of `f64`, row-major.
#[derive(Clone, Debug, PartialEq)]
pub(crate) struct Matrix {
    rows: usize,
    cols: usize,
    data: Vec<f64>,
}

impl Matrix {
    /// A `rows` × `cols` matrix of zeros.
    pub(crate) fn zeros(rows: usize, cols: usize) -> Self {
        Matrix {
            rows,
            cols,
            data: vec![0.0; rows * cols],
        }
    }

    /// The `n` × `n` identity.
    pub(crate) fn identity(n: usize) -> Self {
        let mut m = Matrix::zeros(n, n);
        for i in 0..n {
            m[(i, i)] = 1.0;
        }
        m
    }

    pub(crate) fn nrows(&self) -> usize {
        self.rows
    }

    pub(crate) fn ncols(&self) -> usize {
        self.cols
    }

    /// Row `r`.
    pub(crate) fn row(&self, r: usize) -> &[f64] {
        &self.data[r * self.cols..(r + 1) * self.cols]
    }

    /// Column `c`, copied.
    pub(crate) fn column(&self, c: usize) -> Vec<f64> {
        (0..self.rows).map(|r| self[(r, c)]).collect()
    }

    /// AᵀA.
    pub(crate) fn gram(&self) -> Matrix {
        let n = self.cols;
        let mut g = Matrix::zeros(n, n);
        for r in 0..self.rows {
            let row = self.row(r);
            for i in 0..n {
                for j in 0..n {
                    g[(i, j)] += row[i] * row[j];
                }
            }
        }
        g
    }

    /// Aᵀv.
    pub(crate) fn tr_mul(&self, v: &[f64]) -> Vec<f64> {
        assert_eq!(v.len(), self.rows, "Aᵀv: v has one entry per row of A");
        let mut out = vec![0.0; self.cols];
        for (r, &x) in v.iter().enumerate() {
            for (o, a) in out.iter_mut().zip(self.row(r)) {
                *o += a * x;
            }
        }
        out
    }

    /// Every entry times `s`.
    pub(crate) fn scaled(mut self, s: f64) -> Matrix {
        self.data.iter_mut().for_each(|x| *x *= s);
        self
    }

    /// The solution x of A·x = b for a square A, or `None` when a pivot
    /// of the elimination is zero or not finite (A singular to working
    /// precision, or not a number).
    pub(crate) fn solve(&self, b: &[f64]) -> Option<Vec<f64>> {
        let n = self.square();
        let mut rhs = Matrix {
            rows: n,
            cols: 1,
            data: b.to_vec(),
        };
        self.clone().eliminate(&mut rhs)?;
        Some(rhs.data)
    }

    /// A⁻¹ of a square A, or `None` as for [`Matrix::solve`].
    pub(crate) fn inverse(&self) -> Option<Matrix> {
        let mut inverse = Matrix::identity(self.square());
        self.clone().eliminate(&mut inverse)?;
        Some(inverse)
    }

    fn square(&self) -> usize {
        assert_eq!(self.rows, self.cols, "a square matrix");
        self.rows
    }

    /// Gauss–Jordan elimination with partial pivoting of `self` (consumed)
    /// applied to the columns of `rhs`, which become A⁻¹·rhs.
    fn eliminate(mut self, rhs: &mut Matrix) -> Option<()> {
        let n = self.rows;
        for k in 0..n {
            let pivot_row = (k..n).max_by(|&a, &b| {
                self[(a, k)]
                    .abs()
                    .partial_cmp(&self[(b, k)].abs())
                    .unwrap_or(std::cmp::Ordering::Equal)
            })?;
            let pivot = self[(pivot_row, k)];
            if pivot == 0.0 || !pivot.is_finite() {
                return None;
            }
            self.swap_rows(k, pivot_row);
            rhs.swap_rows(k, pivot_row);
            for r in 0..n {
                if r == k {
                    continue;
                }
                let factor = self[(r, k)] / pivot;
                if factor == 0.0 {
                    continue;
                }
                for c in k..n {
                    self[(r, c)] -= factor * self[(k, c)];
                }
                for c in 0..rhs.cols {
                    rhs[(r, c)] -= factor * rhs[(k, c)];
                }
            }
        }
        for k in 0..n {
            let pivot = self[(k, k)];
            for c in 0..rhs.cols {
                rhs[(k, c)] /= pivot;
            }
        }
        rhs.data.iter().all(|x| x.is_finite()).then_some(())
    }

    fn swap_rows(&mut self, a: usize, b: usize) {
        if a != b {
            for c in 0..self.cols {
                self.data.swap(a * self.cols + c, b * self.cols + c);
            }
        }
    }

    /// The eigenvalues of a symmetric A and its orthonormal eigenvectors
    /// (column i of the matrix belongs to eigenvalue i), by cyclic Jacobi
    /// rotations until the off-diagonal part is below 1e-15 of the whole.
    pub(crate) fn symmetric_eigen(&self) -> (Vec<f64>, Matrix) {
        let n = self.square();
        let mut a = self.clone();
        let mut v = Matrix::identity(n);
        let norm = a.data.iter().map(|x| x * x).sum::<f64>().sqrt();
        for _sweep in 0..100 {
            let off: f64 = (0..n)
                .flat_map(|i| (0..n).filter(move |&j| j != i).map(move |j| (i, j)))
                .map(|(i, j)| a[(i, j)] * a[(i, j)])
                .sum::<f64>()
                .sqrt();
            if off <= 1e-15 * norm || off == 0.0 {
                break;
            }
            for p in 0..n {
                for q in p + 1..n {
                    a.rotate(&mut v, p, q);
                }
            }
        }
        ((0..n).map(|i| a[(i, i)]).collect(), v)
    }

    /// One Jacobi rotation in the (p, q) plane that zeroes a[(p, q)],
    /// accumulated into `v`.
    fn rotate(&mut self, v: &mut Matrix, p: usize, q: usize) {
        let apq = self[(p, q)];
        if apq == 0.0 {
            return;
        }
        let n = self.rows;
        let theta = (self[(q, q)] - self[(p, p)]) / (2.0 * apq);
        let t = theta.signum() / (theta.abs() + (theta * theta + 1.0).sqrt());
        let t = if theta == 0.0 { 1.0 } else { t };
        let c = 1.0 / (t * t + 1.0).sqrt();
        let s = t * c;
        for k in 0..n {
            let (akp, akq) = (self[(k, p)], self[(k, q)]);
            self[(k, p)] = c * akp - s * akq;
            self[(k, q)] = s * akp + c * akq;
        }
        for k in 0..n {
            let (apk, aqk) = (self[(p, k)], self[(q, k)]);
            self[(p, k)] = c * apk - s * aqk;
            self[(q, k)] = s * apk + c * aqk;
        }
        for k in 0..n {
            let (vkp, vkq) = (v[(k, p)], v[(k, q)]);
            v[(k, p)] = c * vkp - s * vkq;
            v[(k, q)] = s * vkp + c * vkq;
        }
    }
}

impl Index<(usize, usize)> for Matrix {
    type Output = f64;
    fn index(&self, (r, c): (usize, usize)) -> &f64 {
        debug_assert!(r < self.rows && c < self.cols);
        &self.data[r * self.cols + c]
    }
}

impl IndexMut<(usize, usize)> for Matrix {
    fn index_mut(&mut self, (r, c): (usize, usize)) -> &mut f64 {
        debug_assert!(r < self.rows && c < self.cols);
        &mut self.data[r * self.cols + c]
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn from_rows(rows: &[&[f64]]) -> Matrix {
        let mut m = Matrix::zeros(rows.len(), rows[0].len());
        for (r, row) in rows.iter().enumerate() {
            for (c, x) in row.iter().enumerate() {
                m[(r, c)] = *x;
            }
        }
        m
    }

    fn product(a: &Matrix, b: &Matrix) -> Matrix {
        let mut p = Matrix::zeros(a.nrows(), b.ncols());
        for i in 0..a.nrows() {
            for j in 0..b.ncols() {
                p[(i, j)] = (0..a.ncols()).map(|k| a[(i, k)] * b[(k, j)]).sum();
            }
        }
        p
    }

    fn close(a: &Matrix, b: &Matrix, tol: f64) -> bool {
        a.data
            .iter()
            .zip(&b.data)
            .all(|(x, y)| (x - y).abs() <= tol)
    }

    #[test]
    fn the_gram_matrix_and_the_transposed_product_follow_their_definitions() {
        let j = from_rows(&[&[1.0, 2.0], &[3.0, -1.0], &[0.5, 4.0]]);
        // JᵀJ by hand: [1+9+0.25, 2-3+2; ., 4+1+16].
        assert_eq!(j.gram(), from_rows(&[&[10.25, 1.0], &[1.0, 21.0]]));
        assert_eq!(j.tr_mul(&[1.0, 1.0, 2.0]), vec![5.0, 9.0]);
        assert_eq!(j.row(1), &[3.0, -1.0]);
        assert_eq!(j.column(1), vec![2.0, -1.0, 4.0]);
    }

    #[test]
    fn a_solve_and_an_inverse_need_a_pivot_swap_and_undo_the_product() {
        // A zero in the first pivot position: without the row swap the
        // elimination divides by zero.
        let a = from_rows(&[&[0.0, 2.0, 1.0], &[1.0, 1.0, 0.0], &[3.0, 0.0, 1.0]]);
        let x = [1.0, -2.0, 0.5];
        let b: Vec<f64> = (0..3)
            .map(|r| (0..3).map(|c| a[(r, c)] * x[c]).sum())
            .collect();
        let solved = a.solve(&b).unwrap();
        for (s, want) in solved.iter().zip(x) {
            assert!((s - want).abs() < 1e-14, "{solved:?}");
        }
        let inverse = a.inverse().unwrap();
        assert!(close(&product(&a, &inverse), &Matrix::identity(3), 1e-14));
        // Singular: two equal rows.
        let singular = from_rows(&[&[1.0, 2.0], &[1.0, 2.0]]);
        assert_eq!(singular.inverse(), None);
        assert_eq!(singular.solve(&[1.0, 1.0]), None);
    }

    #[test]
    fn the_symmetric_eigensystem_rebuilds_its_matrix() {
        let a = from_rows(&[
            &[4.0, 1.0, -2.0, 0.5],
            &[1.0, 3.0, 0.0, 1.0],
            &[-2.0, 0.0, 5.0, -1.0],
            &[0.5, 1.0, -1.0, 1e-9],
        ]);
        let (values, vectors) = a.symmetric_eigen();
        // A·v = λ·v for every pair, and the vectors are orthonormal.
        for (i, &lambda) in values.iter().enumerate() {
            let v = vectors.column(i);
            for r in 0..4 {
                let av: f64 = (0..4).map(|c| a[(r, c)] * v[c]).sum();
                assert!((av - lambda * v[r]).abs() < 1e-12, "{values:?}");
            }
        }
        let mut vt = Matrix::zeros(4, 4);
        for r in 0..4 {
            for c in 0..4 {
                vt[(r, c)] = vectors[(c, r)];
            }
        }
        assert!(close(&product(&vt, &vectors), &Matrix::identity(4), 1e-13));
        // The trace is the eigenvalues' sum.
        let trace = 4.0 + 3.0 + 5.0 + 1e-9;
        assert!((values.iter().sum::<f64>() - trace).abs() < 1e-12);
        // A diagonal matrix is its own eigensystem.
        let (d, _) = from_rows(&[&[2.0, 0.0], &[0.0, -3.0]]).symmetric_eigen();
        assert_eq!(d, vec![2.0, -3.0]);
    }
}
