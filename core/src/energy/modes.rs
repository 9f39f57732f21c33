//! The eigenmodes of an element's Hessian ([`Modes`]): its eigenvalues and eigenvectors, each
//! mode classified as a translation, a rotation, or a twist, flip or scale of the tet
//! ([`Class`], after Smith et al. 2019, "Analytic eigensystems for isotropic distortion
//! energies"), the eigenvalues projected to be positive semi-definite, and the frequencies of
//! the mass-weighted problem.
//!
//! # Formula
//! H v = λ v, v a unit 12-vector (the tet's four corners' displacements).
//!
//! - **Null modes**: |λ| ≤ [`ZERO`] × max |λ|. Every translation-invariant energy has three (the
//!   translations); at a configuration where ∇E = 0 the three rotations are null too.
//! - **Class**: v is split into its part along the three translations, along the three rotations
//!   about the centroid, and the rest, a deformation δF = δDs Dm⁻¹. In the frame of F's signed
//!   SVD, F = U Σ Vᵀ (U, V rotations, one σ negative when the tet is inverted), Uᵀ δF V splits
//!   into its antisymmetric off-diagonal part (twists), its symmetric off-diagonal part (flips)
//!   and its diagonal (scalings). The mode's class is the largest of the five shares.
//! - **Projected** (what projected Newton uses): the same eigenvectors with max(λ, 0): the
//!   12 × 12 eigenvalues clamped at zero, H⁺ = Q max(Λ, 0) Qᵀ. (Clamping in F-space, where the
//!   analytic system lives, gives another matrix: [`super::neohookean`].)
//! - **Frequencies**: H v = ω² M v with M the tet's lumped mass, the same m at each corner, so the
//!   modes are H's and ω² = λ / m. A mode with λ < 0 does not oscillate: it grows as e^(√(−λ/m) t).

use super::element::ElementEnergy;
use super::hessian::{Matrix12, coordinates, hessian};
use super::svd::{signed_svd, twist_flip_scale};
use glam::{DMat3, DVec3};
use nalgebra::SymmetricEigen;

/// Below this fraction of the largest |λ|, an eigenvalue counts as zero.
pub const ZERO: f64 = 1e-10;

/// Within this fraction of the largest |λ|, two eigenvalues count as one (a degenerate group).
const SAME: f64 = 1e-9;

/// What a mode moves.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Class {
    /// Every corner the same way.
    Translation,
    /// A rigid rotation about the centroid.
    Rotation,
    /// A twist: Uᵀ δF V antisymmetric, about one of F's principal axes.
    Twist,
    /// A flip: Uᵀ δF V symmetric, off the diagonal.
    Flip,
    /// A scaling along F's principal axes: Uᵀ δF V diagonal.
    Scale,
}

impl Class {
    /// Its name.
    pub fn name(self) -> &'static str {
        match self {
            Class::Translation => "translation",
            Class::Rotation => "rotation",
            Class::Twist => "twist",
            Class::Flip => "flip",
            Class::Scale => "scale",
        }
    }

    /// All five, in the order of [`Shares`].
    pub const ALL: [Class; 5] = [
        Class::Translation,
        Class::Rotation,
        Class::Twist,
        Class::Flip,
        Class::Scale,
    ];
}

/// How much of a unit mode is each class: five fractions that sum to 1.
pub type Shares = [f64; 5];

/// One eigenmode.
#[derive(Clone, Debug, PartialEq)]
pub struct Mode {
    /// Its eigenvalue λ.
    pub value: f64,
    /// Its unit eigenvector, one displacement per corner.
    pub vector: [DVec3; 4],
    /// Its class, the largest of its shares.
    pub class: Class,
    /// Its shares of the five classes.
    pub shares: Shares,
}

/// The eigenmodes of an element's Hessian at one configuration, lowest eigenvalue first.
#[derive(Clone, Debug, PartialEq)]
pub struct Modes {
    /// The Hessian.
    pub hessian: Matrix12,
    modes: Vec<Mode>,
    /// The corner mass m of the mass-weighted problem.
    pub mass: f64,
}

impl Modes {
    /// The modes of `energy`'s Hessian at the corners `x`.
    pub fn of(energy: &ElementEnergy, x: &[DVec3; 4]) -> Modes {
        let h = hessian(energy, &coordinates(x));
        Modes::of_matrix(h, x, &energy.rest_shape(), energy.corner_mass())
    }

    /// The modes of tet `tet` of `simulation` now: the energy of its active families
    /// ([`ElementEnergy::of_tet`]) at its corners. An error when no family is active, or where
    /// the Hessian is not finite (numbers too large for f64).
    pub fn of_tet(simulation: &crate::simulation::Simulation, tet: usize) -> Result<Modes, String> {
        let (energy, x) = ElementEnergy::of_tet(simulation, tet)?;
        let h = hessian(&energy, &coordinates(&x));
        if !h.iter().all(|v| v.is_finite()) {
            return Err(format!(
                "the Hessian of tet {tet} is not finite at its corners"
            ));
        }
        Ok(Modes::of_matrix(
            h,
            &x,
            &energy.rest_shape(),
            energy.corner_mass(),
        ))
    }

    /// The modes of the symmetric `h` (its lower triangle is read), for a tet at `x` with rest
    /// shape `rest` and corner mass `mass`.
    ///
    /// Within a group of equal eigenvalues (the null space, above all) any orthonormal basis is
    /// as good as another: the basis is turned to the classes, the translations first, then the
    /// rotations, twists, flips and scalings (`Frame::candidates`), so that a null space shows
    /// its three translations and, where ∇E = 0, its three rotations.
    pub fn of_matrix(h: Matrix12, x: &[DVec3; 4], rest: &[DVec3; 4], mass: f64) -> Modes {
        let eigen = SymmetricEigen::new(h);
        let frame = Frame::new(x, rest);
        let mut order: Vec<usize> = (0..12).collect();
        order.sort_by(|&a, &b| eigen.eigenvalues[a].total_cmp(&eigen.eigenvalues[b]));
        let values: Vec<f64> = order.iter().map(|&k| eigen.eigenvalues[k]).collect();
        let mut vectors: Vec<[DVec3; 4]> = order
            .iter()
            .map(|&k| {
                let column = eigen.eigenvectors.column(k);
                std::array::from_fn(|i| {
                    DVec3::new(column[3 * i], column[3 * i + 1], column[3 * i + 2])
                })
            })
            .collect();
        let largest = values.iter().fold(0.0f64, |m, v| m.max(v.abs()));
        let same = |a: f64, b: f64| {
            (a.abs() <= ZERO * largest && b.abs() <= ZERO * largest)
                || (a - b).abs() <= SAME * largest
        };
        let mut start = 0;
        while start < 12 {
            let mut end = start + 1;
            while end < 12 && same(values[start], values[end]) {
                end += 1;
            }
            if end - start > 1 {
                frame.align(&mut vectors[start..end]);
            }
            start = end;
        }
        let modes = values
            .into_iter()
            .zip(vectors)
            .map(|(value, vector)| {
                let shares = frame.shares(&vector);
                let class = Class::ALL[(0..5)
                    .max_by(|&a, &b| shares[a].total_cmp(&shares[b]))
                    .unwrap_or(0)];
                Mode {
                    value,
                    vector,
                    class,
                    shares,
                }
            })
            .collect();
        Modes {
            hessian: h,
            modes,
            mass,
        }
    }

    /// The modes, lowest eigenvalue first.
    pub fn modes(&self) -> &[Mode] {
        &self.modes
    }

    /// The eigenvalues, lowest first.
    pub fn values(&self) -> Vec<f64> {
        self.modes.iter().map(|m| m.value).collect()
    }

    /// The largest |λ|.
    pub fn largest(&self) -> f64 {
        self.modes
            .iter()
            .fold(0.0, |m, mode| m.max(mode.value.abs()))
    }

    /// Whether mode `k`'s eigenvalue counts as zero ([`ZERO`]).
    pub fn is_zero(&self, k: usize) -> bool {
        self.modes[k].value.abs() <= ZERO * self.largest()
    }

    /// How many eigenvalues count as zero.
    pub fn zero_count(&self) -> usize {
        (0..self.modes.len()).filter(|&k| self.is_zero(k)).count()
    }

    /// How many are negative (and not zero): the directions along which E is not convex.
    pub fn negative_count(&self) -> usize {
        (0..self.modes.len())
            .filter(|&k| !self.is_zero(k) && self.modes[k].value < 0.0)
            .count()
    }

    /// The lowest mode that is not a translation (the three translations are null for every
    /// energy and show nothing): the one a simulation's stiffness is weakest, or, negative, the
    /// one along which the energy is not convex.
    pub fn lowest_deformation(&self) -> &Mode {
        self.modes
            .iter()
            .find(|m| m.class != Class::Translation)
            .unwrap_or(&self.modes[0])
    }

    /// The eigenvalues of the projected H⁺: max(λ, 0).
    pub fn projected_values(&self) -> Vec<f64> {
        self.modes.iter().map(|m| m.value.max(0.0)).collect()
    }

    /// H⁺ = Q max(Λ, 0) Qᵀ.
    pub fn projected(&self) -> Matrix12 {
        let mut out = Matrix12::zeros();
        for mode in &self.modes {
            let v = nalgebra::SVector::<f64, 12>::from_fn(|k, _| mode.vector[k / 3][k % 3]);
            out += v * v.transpose() * mode.value.max(0.0);
        }
        out
    }

    /// ω² = λ / m of mode `k` (per second squared): positive, a frequency ω; negative, a growth
    /// rate √(−ω²).
    pub fn omega_squared(&self, k: usize) -> f64 {
        self.modes[k].value / self.mass
    }
}

/// What a displacement of the tet is split along: its translations and rotations, and the
/// signed SVD of its F for the rest.
struct Frame {
    translations: [[DVec3; 4]; 3],
    rotations: Vec<[DVec3; 4]>,
    /// Dm⁻¹, U and V of F = U Σ Vᵀ.
    inverse_rest: DMat3,
    u: DMat3,
    v: DMat3,
}

impl Frame {
    fn new(x: &[DVec3; 4], rest: &[DVec3; 4]) -> Frame {
        let translations = [DVec3::X, DVec3::Y, DVec3::Z].map(|e| [e * 0.5; 4]);
        let centre = (x[0] + x[1] + x[2] + x[3]) / 4.0;
        let mut rotations: Vec<[DVec3; 4]> = Vec::new();
        for axis in [DVec3::X, DVec3::Y, DVec3::Z] {
            let mut r: [DVec3; 4] = std::array::from_fn(|i| axis.cross(x[i] - centre));
            for earlier in &rotations {
                let along = dot(&r, earlier);
                for (a, b) in r.iter_mut().zip(earlier) {
                    *a -= *b * along;
                }
            }
            let norm = dot(&r, &r).sqrt();
            let size = x.iter().map(|p| (*p - centre).length()).fold(0.0, f64::max);
            // A flat or collinear tet has fewer than three independent rotations.
            if norm > 1e-9 * size.max(f64::MIN_POSITIVE) {
                rotations.push(r.map(|d| d / norm));
            }
        }
        let dm = DMat3::from_cols(rest[1] - rest[0], rest[2] - rest[0], rest[3] - rest[0]);
        let ds = DMat3::from_cols(x[1] - x[0], x[2] - x[0], x[3] - x[0]);
        let inverse_rest = if dm.determinant().abs() > f64::MIN_POSITIVE {
            dm.inverse()
        } else {
            DMat3::IDENTITY
        };
        let (u, _, v) = signed_svd(&(ds * inverse_rest));
        Frame {
            translations,
            rotations,
            inverse_rest,
            u,
            v,
        }
    }

    /// Directions of each class, in [`Class::ALL`]'s order: the three translations, the
    /// rotations, then the displacements (centred, so with no translation) whose δF is each of
    /// the nine twist, flip and scale directions U E Vᵀ.
    fn candidates(&self) -> Vec<[DVec3; 4]> {
        let mut out: Vec<[DVec3; 4]> = self.translations.to_vec();
        out.extend(self.rotations.iter().copied());
        let dm = self.inverse_rest.inverse();
        let e = std::f64::consts::FRAC_1_SQRT_2;
        let mut basis = Vec::new();
        for sign in [-1.0, 1.0] {
            for (a, b) in [(1, 2), (2, 0), (0, 1)] {
                let mut m = DMat3::ZERO;
                m.col_mut(b)[a] = e;
                m.col_mut(a)[b] = sign * e;
                basis.push(m);
            }
        }
        for k in 0..3 {
            let mut m = DMat3::ZERO;
            m.col_mut(k)[k] = 1.0;
            basis.push(m);
        }
        for m in basis {
            let df = self.u * m * self.v.transpose();
            // Corner k > 0 moves by δF (Dm's column k−1) relative to corner 0; then centred.
            let ds = df * dm;
            let mut d = [DVec3::ZERO, ds.col(0), ds.col(1), ds.col(2)];
            let centre = (d[0] + d[1] + d[2] + d[3]) / 4.0;
            for p in &mut d {
                *p -= centre;
            }
            let norm = dot(&d, &d).sqrt();
            if norm > 0.0 {
                out.push(d.map(|p| p / norm));
            }
        }
        out
    }

    /// Turns the orthonormal `vectors` (a basis of one eigenspace) to the classes: each
    /// candidate in turn is projected onto the part of the space not yet taken, and kept when
    /// most of it lies there.
    fn align(&self, vectors: &mut [[DVec3; 4]]) {
        let space = vectors.to_vec();
        let mut chosen: Vec<[DVec3; 4]> = Vec::new();
        for candidate in self.candidates() {
            if chosen.len() == space.len() {
                break;
            }
            // Its projection onto the space, less what the chosen ones already cover.
            let mut p = [DVec3::ZERO; 4];
            for b in &space {
                let along = dot(&candidate, b);
                for (a, v) in p.iter_mut().zip(b) {
                    *a += *v * along;
                }
            }
            for c in &chosen {
                let along = dot(&p, c);
                for (a, v) in p.iter_mut().zip(c) {
                    *a -= *v * along;
                }
            }
            let norm = dot(&p, &p).sqrt();
            if norm > 0.5 {
                chosen.push(p.map(|v| v / norm));
            }
        }
        // Whatever is left, completed from the space itself.
        for b in &space {
            if chosen.len() == space.len() {
                break;
            }
            let mut p = *b;
            for c in &chosen {
                let along = dot(&p, c);
                for (a, v) in p.iter_mut().zip(c) {
                    *a -= *v * along;
                }
            }
            let norm = dot(&p, &p).sqrt();
            if norm > 1e-6 {
                chosen.push(p.map(|v| v / norm));
            }
        }
        if chosen.len() == vectors.len() {
            vectors.copy_from_slice(&chosen);
        }
    }

    /// The shares of the unit displacement `d` ([`Class::ALL`]'s order).
    fn shares(&self, d: &[DVec3; 4]) -> Shares {
        let mut rest = *d;
        let mut take = |basis: &[DVec3; 4]| {
            let along = dot(&rest, basis);
            for (a, b) in rest.iter_mut().zip(basis) {
                *a -= *b * along;
            }
            along * along
        };
        let translation: f64 = self.translations.iter().map(&mut take).sum();
        let rotation: f64 = self.rotations.iter().map(&mut take).sum();
        let remainder = dot(&rest, &rest);
        let df = DMat3::from_cols(rest[1] - rest[0], rest[2] - rest[0], rest[3] - rest[0])
            * self.inverse_rest;
        let [twist, flip, scale] = twist_flip_scale(&self.u, &self.v, &df);
        let total = twist + flip + scale;
        let deformation = |part: f64| {
            if total > 0.0 {
                remainder * part / total
            } else {
                0.0
            }
        };
        let mut shares = [
            translation,
            rotation,
            deformation(twist),
            deformation(flip),
            deformation(scale),
        ];
        let sum: f64 = shares.iter().sum();
        if sum > 0.0 {
            for s in &mut shares {
                *s /= sum;
            }
        }
        shares
    }
}

/// The dot product of two displacements of the four corners.
fn dot(a: &[DVec3; 4], b: &[DVec3; 4]) -> f64 {
    a.iter().zip(b).map(|(x, y)| x.dot(*y)).sum()
}
