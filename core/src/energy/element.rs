//! The energy of some families on one tet ([`ElementEnergy`]): their constraints on the tet, each
//! with its rest value, what it stores and its compliance, and E = Σ ½ C² / α of them, in any
//! number type that compares to a `bool` (f64, and the dual numbers of [`super::hessian`]).
//!
//! Which constraints lie on a tet is what each family's binding lays on a mesh of that one tet
//! ([`crate::constraints::Binding::particles`]): one volume, four heights, six edges; for a family
//! of the surface, the tet's own four faces and six hinges, as if it stood alone.

use crate::constraints::differentiable::value_and_gradient;
use crate::constraints::{Binding, Families, Family, PerFamily, Stored};
use crate::numbers::vector::Real;
use crate::scene::SceneBody;
use crate::scene::mesh::TetMesh;
use crate::simulation::{DENSITY, Settings, Simulation};
use glam::DVec3;

/// Where a family's compliance α in E = ½ C² / α comes from.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Compliance {
    /// The family's own (`--compliance`), or the material's (the neo-Hookean pair, a file's
    /// `stiffness`).
    Given(f64),
    /// The family is rigid (α = 0): its energy is taken with α = 1.
    Rigid,
}

impl Compliance {
    /// The α used.
    pub fn alpha(self) -> f64 {
        match self {
            Compliance::Given(alpha) => alpha,
            Compliance::Rigid => 1.0,
        }
    }
}

/// One constraint on the tet.
#[derive(Clone, Debug)]
pub struct Term {
    /// Its family.
    pub family: Family,
    /// Its particles, as corners of the tet (0…3), the first `arity` of them.
    pub corners: [usize; 4],
    /// How many particles it has.
    pub arity: usize,
    /// Its rest value.
    pub rest: f64,
    /// What it stores, worked out from the rest shape and the material.
    pub stored: Stored,
    /// 1/α.
    pub stiffness: f64,
}

/// The energy E = Σ ½ C² / α of some families' constraints on one tet, at rest at `rest_shape`.
#[derive(Clone, Debug)]
pub struct ElementEnergy {
    families: Families,
    rest_shape: [DVec3; 4],
    terms: Vec<Term>,
    /// Per family whose constraints are on the tet, in table order: its compliance.
    pub compliances: Vec<(Family, Compliance)>,
    /// The density its corner masses are lumped with, kg/m³ ([`DENSITY`] unless the tet's body
    /// has its own, [`ElementEnergy::of_tet`]).
    density: f64,
}

impl ElementEnergy {
    /// The energy of the `active` families of `families` on a tet at rest at `rest_shape`, with
    /// the compliances and material of `settings`. A family that reads where its particles were
    /// at the start of the substep (a damper: `start0`…, `h`) is left out: its ½ C² / α is a
    /// potential of the motion, not an energy of the positions alone. A family on single
    /// particles (a pin: C = |p0 − q0|) is left out too: it ties the body to the world, not a
    /// tet's corners to each other, and a tet alone has none of the mesh's chosen particles.
    /// An error when no family
    /// with an energy has a constraint on a tet.
    pub fn new(
        families: &Families,
        active: &PerFamily<bool>,
        settings: &Settings,
        rest_shape: [DVec3; 4],
    ) -> Result<ElementEnergy, String> {
        let mesh = TetMesh {
            positions: rest_shape.to_vec(),
            tets: vec![[0, 1, 2, 3]],
        };
        let material = &settings.material;
        let mut terms = Vec::new();
        let mut compliances = Vec::new();
        let of_positions = |f: Family| !families.file(f).is_some_and(|file| file.reads_motion());
        // A pin holds a particle to the world, a contact two surfaces apart: neither is an
        // energy of one tet.
        let of_the_body =
            |f: Family| !matches!(families.binding(f), Binding::Particles | Binding::Contacts);
        for family in (families.all()).filter(|&f| active[f] && of_positions(f) && of_the_body(f)) {
            let compliance = match families.row(family).compliance_from_material {
                Some(from) => Compliance::Given(from(material)),
                None if settings.compliance[family] > 0.0 => {
                    Compliance::Given(settings.compliance[family])
                }
                None => Compliance::Rigid,
            };
            let arity = families.arity(family);
            let particles = families.binding(family).particles(&mesh);
            for chunk in particles.chunks(arity) {
                let mut corners = [0; 4];
                for (k, &p) in chunk.iter().enumerate() {
                    corners[k] = p as usize;
                }
                let shape: Vec<DVec3> = chunk.iter().map(|&p| rest_shape[p as usize]).collect();
                terms.push(Term {
                    family,
                    corners,
                    arity,
                    rest: families.constraint(family).rest_value(&shape, material),
                    stored: families.constraint(family).store(&shape, material),
                    stiffness: 1.0 / compliance.alpha(),
                });
            }
            compliances.push((family, compliance));
        }
        if terms.is_empty() {
            return Err(
                "no family is active that has an energy of the positions (a damper, a pin or a contact \
                 has none on a tet): name one (--constraints or --constraint-file)"
                    .into(),
            );
        }
        Ok(ElementEnergy {
            families: families.clone(),
            rest_shape,
            terms,
            compliances,
            density: DENSITY,
        })
    }

    /// The energy of `simulation`'s active families on its tet `tet`, at rest at the tet's rest
    /// corners, with the simulation's compliances and material; and the tet's corners now. In a
    /// scene of several bodies, the families laid on the tet's body, with its own material and
    /// density where it has them ([`crate::scene::SceneBody`]), as the simulation projects
    /// them. An error when no family is active or there is no such tet.
    ///
    /// ```
    /// use tetlab_core::energy::element::ElementEnergy;
    /// use tetlab_core::scene::Scene;
    /// use tetlab_core::simulation::{Settings, Simulation};
    /// let text = "[[body]]\nmesh = \"tet\"\n[[body]]\nmesh = \"tet\"\ntranslate = [2, 0, 0]\n\
    ///             density = 250\nconstraints = \"volume\"\n";
    /// let scene = Scene::parse_file("two.toml".as_ref(), text).unwrap();
    /// let simulation = Simulation::new(&scene, Settings::default()); // edges and volume
    /// let (first, _) = ElementEnergy::of_tet(&simulation, 0).unwrap();
    /// let (second, _) = ElementEnergy::of_tet(&simulation, 1).unwrap();
    /// assert_eq!(first.compliances.len(), 2, "edges and volume");
    /// assert_eq!(second.compliances.len(), 1, "its volume alone");
    /// let (m1, m2) = (first.corner_mass(), second.corner_mass());
    /// assert!((4.0 * m2 - m1).abs() < 1e-12 * m1, "a quarter of the density: {m1} {m2}");
    /// ```
    pub fn of_tet(
        simulation: &Simulation,
        tet: usize,
    ) -> Result<(ElementEnergy, [DVec3; 4]), String> {
        let corners = simulation
            .tets()
            .get(tet)
            .ok_or_else(|| format!("there is no tet {tet} ({} tets)", simulation.tets().len()))?;
        let at = |positions: &[DVec3]| corners.map(|i| positions[i as usize]);
        let families = simulation.families();
        let bodies = simulation.bodies();
        let body = SceneBody::owner(bodies, corners[0]).map(|b| &bodies[b]);
        let mut settings = *simulation.settings();
        if let Some(material) = body.and_then(|b| b.material) {
            settings.material = material;
        }
        let active = families
            .per_family(|f| settings.active[f] && body.is_none_or(|b| b.takes(families, f)));
        let rest = at(simulation.rest_positions());
        let mut energy = ElementEnergy::new(families, &active, &settings, rest)?;
        energy.density = body.map_or(DENSITY, |b| b.density);
        Ok((energy, at(simulation.positions())))
    }

    /// Its constraints.
    pub(crate) fn terms(&self) -> &[Term] {
        &self.terms
    }

    /// The families it is the energy of.
    pub fn families(&self) -> &Families {
        &self.families
    }

    /// The rest shape.
    pub fn rest_shape(&self) -> [DVec3; 4] {
        self.rest_shape
    }

    /// The mass of each corner: ρ × |V₀| / 4, the tet's own share of the lumped masses the
    /// simulation uses ([`crate::simulation::DENSITY`], or its body's density).
    pub fn corner_mass(&self) -> f64 {
        self.density * crate::constraints::volume::signed_volume(&self.rest_shape).abs() / 4.0
    }

    /// C and ∇C of term `t` at the corners `x`, in any number type `T` that compares to a bool:
    /// ∇C as the family gives it (its formula, or a file's compiled AD: never a file's own
    /// gradient, which is what is checked against it), scattered to the tet's corners (a corner
    /// the constraint does not touch gets 0).
    pub fn evaluate<T: Real<Mask = bool>>(&self, t: usize, x: &[[T; 3]; 4]) -> (T, [[T; 3]; 4]) {
        let term = &self.terms[t];
        fn on<T: Real<Mask = bool>, const N: usize>(
            e: &ElementEnergy,
            term: &Term,
            x: &[[T; 3]; 4],
        ) -> (T, [[T; 3]; 4]) {
            let p: [[T; 3]; N] = std::array::from_fn(|k| x[term.corners[k]]);
            let shape: [DVec3; N] = std::array::from_fn(|k| e.rest_shape[term.corners[k]]);
            let (value, gradients) = value_and_gradient(
                &e.families,
                term.family,
                &p,
                (term.rest, &term.stored),
                &shape,
            );
            let mut out = [[T::ZERO; 3]; 4];
            for (k, g) in gradients.iter().enumerate() {
                for (a, b) in out[term.corners[k]].iter_mut().zip(g) {
                    *a += *b;
                }
            }
            (value, out)
        }
        crate::constraints::for_arity!(term.arity, |N| on::<T, N>(self, term, x))
    }

    /// E at the corners `x`.
    pub fn energy<T: Real<Mask = bool>>(&self, x: &[[T; 3]; 4]) -> T {
        let mut sum = T::ZERO;
        for (t, term) in self.terms.iter().enumerate() {
            let (c, _) = self.evaluate(t, x);
            sum += T::from_f64(0.5 * term.stiffness) * c * c;
        }
        sum
    }
}
