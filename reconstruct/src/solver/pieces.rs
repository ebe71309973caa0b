//! The pieces of a normal matrix and their relative heights, for the
//! iterative solver (`conjugate_gradient`).
//!
//! A piece is a set of unknowns the rows couple (non-zero entries of `CᵀC`,
//! without the membrane of `lsq`); a pixel without rows is a piece of its
//! own. The rows fix a piece's heights up to a constant. Pieces of one
//! component touch only through the membrane (pixels that meet at a corner,
//! pixels without rows), whose weight `ε` is tiny: the relative height of
//! two such pieces is a mode of `CᵀC + ε L` with an eigenvalue of order
//! `ε`, which conjugate gradients cannot resolve (rounding, amplified by
//! the preconditioner, grows along it without bound). Instead each piece is
//! solved with zero mean, and the constants are then chosen as the
//! factorisation of the whole system chooses them as `ε → 0`: minimising the
//! membrane energy `Σ (z_i + c_p − z_j − c_q)²` over the 8-neighbour pairs
//! that join different pieces (a graph Laplacian on the pieces, solved by
//! Jacobi-preconditioned conjugate gradients). Pixels without rows thus get
//! the harmonic interpolation of their neighbours, as in `lsq`.

use super::slots::{NEIGHBOUR_SLOTS, slot_pixel};
use crate::solver::domain::Domain;

/// Tolerance of the conjugate gradients on the pieces' graph.
const TOLERANCE: f64 = 1e-12;

/// The piece of every unknown and the number of pieces, numbered in order
/// of first appearance.
pub(crate) fn pieces(domain: &Domain, upper: &[[f64; 13]]) -> (Vec<u32>, usize) {
    let n = domain.len();
    let mut parent: Vec<u32> = (0..n as u32).collect();
    fn root(parent: &mut [u32], mut k: u32) -> u32 {
        while parent[k as usize] != k {
            let up = parent[parent[k as usize] as usize];
            parent[k as usize] = up;
            k = up;
        }
        k
    }
    for (k, row) in upper.iter().enumerate() {
        for (s, &v) in row.iter().enumerate().skip(1) {
            if v == 0.0 {
                continue;
            }
            if let Some(j) = slot_pixel(domain, k, s) {
                let (a, b) = (root(&mut parent, k as u32), root(&mut parent, j as u32));
                parent[a.max(b) as usize] = a.min(b);
            }
        }
    }
    let mut number = vec![u32::MAX; n];
    let mut count = 0u32;
    let label = (0..n as u32)
        .map(|k| {
            let r = root(&mut parent, k) as usize;
            if number[r] == u32::MAX {
                number[r] = count;
                count += 1;
            }
            number[r]
        })
        .collect();
    (label, count as usize)
}

/// The constant of every piece (module doc) for heights `z` that have zero
/// mean on each piece.
pub(crate) fn offsets(domain: &Domain, piece: &[u32], count: usize, z: &[f64]) -> Vec<f64> {
    // Links between pieces: (p, q, z_i − z_j) for each 8-neighbour pair.
    let mut links = Vec::new();
    for k in 0..domain.len() {
        for s in NEIGHBOUR_SLOTS {
            if let Some(j) = slot_pixel(domain, k, s)
                && piece[k] != piece[j]
            {
                links.push((piece[k], piece[j], z[k] - z[j]));
            }
        }
    }
    let mut degree = vec![0.0; count];
    let mut b = vec![0.0; count];
    for &(p, q, d) in &links {
        degree[p as usize] += 1.0;
        degree[q as usize] += 1.0;
        // Minimise (d + c_p − c_q)²: L c = b with b_p −= d, b_q += d.
        b[p as usize] -= d;
        b[q as usize] += d;
    }
    let apply = |c: &[f64], out: &mut [f64]| {
        out.iter_mut()
            .zip(c)
            .zip(&degree)
            .for_each(|((o, &c), &d)| *o = d * c);
        for &(p, q, _) in &links {
            let (p, q) = (p as usize, q as usize);
            out[p] -= c[q];
            out[q] -= c[p];
        }
    };
    // Conjugate gradients, Jacobi-preconditioned; isolated pieces keep 0.
    let inverse: Vec<f64> = degree
        .iter()
        .map(|&d| if d > 0.0 { 1.0 / d } else { 0.0 })
        .collect();
    let dot = |a: &[f64], b: &[f64]| a.iter().zip(b).map(|(a, b)| a * b).sum::<f64>();
    let mut c = vec![0.0; count];
    let mut r = b;
    let norm = dot(&r, &r).sqrt();
    if norm == 0.0 {
        return c;
    }
    let mut y: Vec<f64> = r.iter().zip(&inverse).map(|(r, i)| r * i).collect();
    let mut p = y.clone();
    let mut q = vec![0.0; count];
    let mut ry = dot(&r, &y);
    for _ in 0..count.max(1) * 4 {
        apply(&p, &mut q);
        let pq = dot(&p, &q);
        if pq <= 0.0 {
            break;
        }
        let alpha = ry / pq;
        c.iter_mut().zip(&p).for_each(|(c, p)| *c += alpha * p);
        r.iter_mut().zip(&q).for_each(|(r, q)| *r -= alpha * q);
        if dot(&r, &r).sqrt() <= TOLERANCE * norm {
            break;
        }
        y.iter_mut()
            .zip(&r)
            .zip(&inverse)
            .for_each(|((y, r), i)| *y = r * i);
        let next = dot(&r, &y);
        let beta = next / ry;
        ry = next;
        p.iter_mut().zip(&y).for_each(|(p, y)| *p = y + beta * *p);
    }
    c
}
