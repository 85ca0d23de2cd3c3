//! Fluid particle storage: structure of arrays, re-sorted by cell every step.

use rayon::prelude::*;
use serde::{Deserialize, Serialize};
use spatter_core::Vec3;

/// The fluid particles. Every array has one entry per particle, in the current (cell) order; `id` is the
/// particle's stable number. All particles share the mass `SphParams::mass()`.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct Fluid {
    pub pos: Vec<Vec3>,
    /// Velocity \[m/s\]. Between the predictor and the corrector it holds the predicted velocity.
    pub vel: Vec<Vec3>,
    /// Density \[kg/m³\].
    pub rho: Vec<f64>,
    /// Acceleration of the last force evaluation \[m/s²\].
    pub acc: Vec<Vec3>,
    /// Density rate of the last force evaluation \[kg/(m³ s)\].
    pub drho: Vec<f64>,
    pub id: Vec<u32>,
    /// Bit k set when a boundary particle of part k (bit 31: any part ≥ 31) was within the support at
    /// the last force evaluation; only such particles can reach a wall within one step.
    pub near: Vec<u32>,
    /// Shifting displacement for the next drift \[m\] (empty when shifting is off).
    pub shift: Vec<Vec3>,
}

/// Buffers for permuting the arrays without allocating: one of each element type, lent by the caller
/// (the simulation lends its force buffers, which are free while particles are re-sorted).
pub struct PermuteScratch<'a> {
    pub v3: &'a mut Vec<Vec3>,
    pub f: &'a mut Vec<f64>,
    pub u: &'a mut Vec<u32>,
}

fn permute<T: Copy + Send + Sync + Default>(v: &mut Vec<T>, perm: &[u32], scratch: &mut Vec<T>) {
    if v.is_empty() {
        return;
    }
    scratch.resize(perm.len(), T::default());
    if perm.len() > 20_000 {
        scratch.par_iter_mut().zip(perm.par_iter()).for_each(|(s, &i)| *s = v[i as usize]);
    } else {
        scratch.iter_mut().zip(perm).for_each(|(s, &i)| *s = v[i as usize]);
    }
    std::mem::swap(v, scratch);
}

impl Fluid {
    pub fn len(&self) -> usize {
        self.pos.len()
    }

    pub fn is_empty(&self) -> bool {
        self.pos.is_empty()
    }

    /// Appends a particle at rest acceleration.
    pub fn push(&mut self, pos: Vec3, vel: Vec3, rho: f64, id: u32, shifting: bool) {
        self.pos.push(pos);
        self.vel.push(vel);
        self.rho.push(rho);
        self.acc.push(Vec3::ZERO);
        self.drho.push(0.0);
        self.id.push(id);
        self.near.push(0);
        if shifting {
            self.shift.push(Vec3::ZERO);
        }
    }

    /// Reorders every array so that new entry `k` is old entry `perm[k]`.
    pub fn permute(&mut self, perm: &[u32], s: PermuteScratch) {
        debug_assert_eq!(perm.len(), self.len());
        permute(&mut self.pos, perm, s.v3);
        permute(&mut self.vel, perm, s.v3);
        permute(&mut self.acc, perm, s.v3);
        permute(&mut self.shift, perm, s.v3);
        permute(&mut self.rho, perm, s.f);
        permute(&mut self.drho, perm, s.f);
        permute(&mut self.id, perm, s.u);
        permute(&mut self.near, perm, s.u);
    }

    /// Keeps the particles with `keep[i]`, in order.
    pub fn retain(&mut self, keep: &[bool]) {
        fn r<T>(v: &mut Vec<T>, keep: &[bool]) {
            if v.is_empty() {
                return;
            }
            let mut k = keep.iter();
            v.retain(|_| *k.next().unwrap_or(&true));
        }
        r(&mut self.pos, keep);
        r(&mut self.vel, keep);
        r(&mut self.rho, keep);
        r(&mut self.acc, keep);
        r(&mut self.drho, keep);
        r(&mut self.id, keep);
        r(&mut self.near, keep);
        r(&mut self.shift, keep);
    }

    /// Bytes held per particle by the state arrays (capacity, not length).
    pub fn bytes(&self) -> usize {
        use std::mem::size_of;
        self.pos.capacity() * size_of::<Vec3>()
            + self.vel.capacity() * size_of::<Vec3>()
            + self.acc.capacity() * size_of::<Vec3>()
            + self.shift.capacity() * size_of::<Vec3>()
            + self.rho.capacity() * 8
            + self.drho.capacity() * 8
            + self.id.capacity() * 4
            + self.near.capacity() * 4
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn permute_and_retain_keep_arrays_consistent() {
        let mut f = Fluid::default();
        for i in 0..5 {
            f.push(Vec3::splat(i as f64), Vec3::X * i as f64, 1000.0 + i as f64, i, true);
        }
        let (mut a, mut b, mut c) = (Vec::new(), Vec::new(), Vec::new());
        f.permute(&[4, 2, 0, 1, 3], PermuteScratch { v3: &mut a, f: &mut b, u: &mut c });
        assert_eq!(f.id, vec![4, 2, 0, 1, 3]);
        for k in 0..5 {
            let i = f.id[k] as f64;
            assert_eq!(f.pos[k], Vec3::splat(i));
            assert_eq!(f.vel[k].x, i);
            assert_eq!(f.rho[k], 1000.0 + i);
        }
        f.retain(&[true, false, true, false, true]);
        assert_eq!(f.id, vec![4, 0, 3]);
        assert_eq!(f.rho, vec![1004.0, 1000.0, 1003.0]);
        assert_eq!(f.shift.len(), 3);
    }
}
