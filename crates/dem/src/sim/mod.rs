//! The DEM simulation: particles, walls, contact law, neighbour lists and time integration.
//!
//! [`Simulation<L>`] is generic over its [`ContactLaw`]; the per-contact code is monomorphised for `L`.
//!
//! One step (velocity Verlet, the default):
//!
//! 1. half kick v += ½Δt F/m, ω += ½Δt τ/I, drift x += v Δt (parallel over particles);
//! 2. rebuild the neighbour and wall-candidate lists if particles may have moved more than half the skin
//!    (the bound is the running sum of the largest speed times Δt: no per-particle reference positions
//!    are stored); a rebuild re-sorts the particle arrays by cell and carries every contact state over by
//!    the particles' stable ids;
//! 3. forces: gravity + external, wall contacts (parallel over particle blocks), pair contacts over the
//!    half list in two colouring phases (see [`crate::par`]); energies and the largest overlap are
//!    reduced in a fixed tree, so results are identical for any thread count;
//! 4. second half kick.
//!
//! Symplectic Euler evaluates the forces first, then kicks by a full step and drifts.

mod clumps;
mod decomp;
mod forces;
mod impacts;
mod integrate;
mod neighbors;
mod rank_bodies;
mod repartition;
mod schemes;

pub use decomp::{RankState, DEFAULT_REBALANCE};
pub use impacts::WallImpact;
pub use integrate::Integrator;
pub use neighbors::{PairList, WallList};
pub use repartition::CheckpointPart;
pub use schemes::{SchemeHistory, Y as SchemeState};

use crate::contact::{ContactLaw, PairProps, PairTable};
use crate::error::DemError;
use crate::particles::{NewParticle, Particles, PermuteScratch};
use crate::walls::{Wall, WallKinematics, WallShape};
use serde::{Deserialize, Serialize};
use spatter_core::grid::CellGrid;
use spatter_core::material::Material;
use spatter_core::{Aabb, Vec3};

/// Engine options.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Settings {
    pub integrator: Integrator,
    /// Verlet skin \[m\]; `None` = 10 % of the largest particle diameter.
    pub skin: Option<f64>,
    /// Keep a Verlet list between rebuilds (true) or rebuild the cell search every step (false; for
    /// comparison).
    pub verlet_list: bool,
    /// Blow-up when an overlap exceeds this fraction of the smaller radius (default 0.25).
    pub max_overlap_fraction: f64,
    /// Particles whose centre leaves this box are removed and counted (none by default).
    pub domain: Option<Aabb>,
    /// The mass a clump member stands for in its contacts (m* of the contact law).
    #[serde(default)]
    pub clump_contact_mass: ClumpContactMass,
    /// Integrate the spins of single spheres (default true). Off, every sphere keeps ω = 0: contact
    /// torques are ignored, as in the 3D probe-indentation runs of Jasion (2013, Appendix C). Clump
    /// bodies always rotate.
    #[serde(default = "yes")]
    pub rotation: bool,
    /// Fixed-point iterations per step of the implicit integrators BD1, BD2, BD4 (required by them,
    /// ≥ 1; BD-p keeps its order with ≥ p).
    #[serde(default)]
    pub iterations: Option<u32>,
}

fn yes() -> bool {
    true
}

/// The mass a clump member stands for in its contacts: the contact laws compute m* = 1/(1/mᵢ + 1/mⱼ) from
/// it, so it sets the dashpot (restitution) of member contacts. No single value is exact for every
/// contact geometry of a rigid body (the exact one, the body's effective mass at the contact point along
/// the normal, depends on the contact); see docs/dem.md, "Clumps".
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum ClumpContactMass {
    /// The body mass M (LIGGGHTS multisphere; default). A body hitting a wall with one member at its
    /// centre of mass bounces with the pair's restitution; with k members sharing the load, each contact
    /// is damped as if it carried the whole body.
    #[default]
    Body,
    /// The member's share of the body mass by volume, M Vᵢ/ΣVⱼ: exact when all members touch at once
    /// with equal loads (a dumbbell dropped flat), too light for a single member contact.
    MemberShare,
}

impl Default for Settings {
    fn default() -> Self {
        Settings {
            integrator: Integrator::VelocityVerlet,
            skin: None,
            verlet_list: true,
            max_overlap_fraction: 0.25,
            domain: None,
            clump_contact_mass: ClumpContactMass::Body,
            rotation: true,
            iterations: None,
        }
    }
}

/// How the energy budget's elastic and dissipated terms are obtained (see docs/dem.md, "Energy budget").
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum EnergyMethod {
    /// Every contact books its stored and dissipated energy in every step (the contact law's `energy`
    /// flag must be on): the dissipation is the exact sum of dashpot, slip and rolling work.
    #[default]
    PerContact,
    /// Contacts book nothing in ordinary steps. The elastic energy is booked only in steps requested with
    /// [`Simulation::request_energy`]; the dissipated energy is the residual
    /// E_in + W_external + W_walls − E_mech(t), where E_in is the kinetic and potential energy the
    /// particles brought in (minus what removed particles took out). The residual also contains the
    /// integrator's own energy error (O(Δt²), either sign).
    Residual,
}

/// Energy accounts integrated over the run \[J\].
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct EnergyAccounts {
    /// Work dissipated by dashpots, Coulomb slip and rolling resistance (per-contact bookkeeping only).
    pub dissipated: f64,
    /// Kinetic energy of the particles at insertion, minus that of removed particles.
    pub injected_kinetic: f64,
    /// Rotational energy of the particles at insertion, minus that of removed particles (kept apart
    /// from the kinetic term so that the residual budget sums exactly like [`Simulation::energy`] and
    /// reads exactly zero before the first step).
    #[serde(default)]
    pub injected_rotational: f64,
    /// Σ m x of the free particles at insertion, minus that of removed particles \[kg m\]; their
    /// potential energy is −g·(Σ m x).
    pub injected_moment: Vec3,
    /// Work done on the particles by external forces (including the external-force hook).
    pub external_work: f64,
    /// Work done on the particles by moving walls.
    pub wall_work: f64,
}

/// Results of the last force evaluation.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct LastEvaluation {
    /// Elastic energy stored in contacts \[J\].
    pub elastic: f64,
    /// Particle–particle contacts.
    pub pair_contacts: u64,
    /// Particle–wall contacts.
    pub wall_contacts: u64,
    /// Largest overlap divided by the smaller radius.
    pub max_overlap_ratio: f64,
    /// The contacts booked their energies in this evaluation (`elastic` is meaningful).
    pub energy_booked: bool,
}

/// The energy budget at one instant.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct EnergyReport {
    pub time: f64,
    /// Σ ½ m v² \[J\].
    pub kinetic: f64,
    /// Σ ½ I ω² \[J\].
    pub rotational: f64,
    /// Elastic energy in contacts \[J\].
    pub elastic: f64,
    /// Gravitational potential Σ −m g·x \[J\].
    pub potential: f64,
    /// Accumulated dissipation \[J\].
    pub dissipated: f64,
    /// Accumulated work of external forces \[J\].
    pub external_work: f64,
    /// Accumulated work of moving walls \[J\].
    pub wall_work: f64,
    pub pair_contacts: u64,
    pub wall_contacts: u64,
}

impl EnergyReport {
    /// Mechanical energy KE + rotational + elastic + potential \[J\].
    pub fn mechanical(&self) -> f64 {
        self.kinetic + self.rotational + self.elastic + self.potential
    }

    /// The conserved total: mechanical + dissipated − work put in by external forces and walls \[J\].
    pub fn total(&self) -> f64 {
        self.mechanical() + self.dissipated - self.external_work - self.wall_work
    }
}

/// Everything that evolves during a run besides the particle arrays; checkpointed with them.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct DynState<S> {
    pub time: f64,
    pub step: u64,
    pub energy: EnergyAccounts,
    pub last: LastEvaluation,
    /// Forces in the particle arrays belong to the current positions (velocity Verlet needs them).
    pub forces_valid: bool,
    /// Bound on the largest particle displacement since the last rebuild \[m\].
    pub disp_particles: f64,
    /// Bound on the largest wall displacement since the last rebuild \[m\].
    pub disp_walls: f64,
    pub needs_rebuild: bool,
    pub rebuilds: u64,
    /// Particles removed for leaving the domain.
    pub removed: u64,
    pub list: PairList<S>,
    pub wall_list: WallList<S>,
    /// Largest particle radius seen \[m\].
    pub r_max: f64,
    /// Book energies in the evaluations of the next step (residual method).
    pub energy_requested: bool,
    /// Rigid bodies (clumps) whose members are in the particle store.
    #[serde(default)]
    pub bodies: crate::clump::Bodies,
    /// Past derivatives or states of the multi-step integrators (AB2, AB4, ABM4, BD2, BD4).
    #[serde(default)]
    pub history: SchemeHistory,
}

impl<S> Default for DynState<S> {
    fn default() -> Self {
        DynState {
            time: 0.0,
            step: 0,
            energy: EnergyAccounts::default(),
            last: LastEvaluation::default(),
            forces_valid: false,
            disp_particles: 0.0,
            disp_walls: 0.0,
            needs_rebuild: true,
            rebuilds: 0,
            removed: 0,
            list: PairList::default(),
            wall_list: WallList::default(),
            r_max: 0.0,
            energy_requested: false,
            bodies: crate::clump::Bodies::default(),
            history: SchemeHistory::default(),
        }
    }
}

/// Everything that evolves during a run; see [`Simulation::state`].
#[derive(Clone, Debug, Default, Serialize, Deserialize)]
pub struct SimState<S> {
    pub particles: Particles,
    pub dynamic: DynState<S>,
    /// Impact records of each wall (`None` for analytic walls).
    pub mesh_records: Vec<Option<crate::walls::MeshRecords>>,
}

/// Read-only view of the particle arrays for the external-force hook.
#[derive(Clone, Copy, Debug)]
pub struct ParticleView<'a> {
    pub id: &'a [u32],
    pub material: &'a [u16],
    pub pos: &'a [Vec3],
    pub vel: &'a [Vec3],
    pub omega: &'a [Vec3],
    pub radius: &'a [f64],
    /// 1/m (0 for frozen particles) \[1/kg\].
    pub inv_mass: &'a [f64],
}

/// Forces computed outside the engine (fluid drag, fields), called once per force evaluation. Add into
/// `force`/`torque` (indexed like the view; the arrays come zeroed). Must be deterministic for
/// reproducible runs.
pub trait ExternalForces: Send + Sync {
    fn add(&mut self, time: f64, particles: &ParticleView, force: &mut [Vec3], torque: &mut [Vec3]);

    /// True when the force and torque on each particle depend only on the time and that particle's own
    /// state (a drag from a prescribed or imported flow), so that on several ranks each rank may call the
    /// hook for the particles it owns and get what one rank would. A hook that looks at other particles
    /// (a void fraction, a bed's surface) keeps the default `false`, and runs that use it are refused on
    /// several ranks.
    fn per_particle(&self) -> bool {
        false
    }
}

#[derive(Default)]
struct Scratch {
    grid: CellGrid,
    perm: Vec<u32>,
    permute: PermuteScratch,
    kin: Vec<WallKinematics>,
    ext_force: Vec<Vec3>,
    ext_torque: Vec<Vec3>,
}

/// Pair properties for every pair of `materials` with one friction coefficient μ and restitution e.
pub fn uniform_pairs(materials: &[Material], friction: f64, restitution: f64) -> PairTable<PairProps> {
    PairTable::build(materials.len(), |a, b| {
        PairProps::new(&materials[a], &materials[b], friction, restitution)
    })
}

/// A DEM simulation with contact law `L`.
pub struct Simulation<L: ContactLaw> {
    pub law: L,
    materials: Vec<Material>,
    props: PairTable<PairProps>,
    params: PairTable<L::Params>,
    pub particles: Particles,
    pub walls: Vec<Wall>,
    /// Gravitational acceleration \[m/s²\].
    pub gravity: Vec3,
    /// Time step \[s\].
    pub dt: f64,
    pub settings: Settings,
    /// How the energy budget is obtained (default: per contact).
    pub energy_method: EnergyMethod,
    pub(crate) st: DynState<L::State>,
    /// Clump templates (shapes of the rigid bodies).
    templates: Vec<crate::clump::ClumpTemplate>,
    /// Erosion models per (particle material, wall material).
    wear: crate::wear::WearTable,
    scratch: Scratch,
    /// Collect [`WallImpact`]s in every evaluation.
    record_impacts: bool,
    /// The wall contacts that formed in the last evaluation (when recording).
    impacts: Vec<WallImpact>,
    external: Option<Box<dyn ExternalForces>>,
    /// Ids of the pair with the largest overlap in the last evaluation (second = `u32::MAX` for a wall).
    last_worst: (u32, u32),
    /// The force arrays already hold gravity and external forces for the next evaluation.
    base_forces_ready: bool,
    /// A kick met a non-finite velocity, angular velocity or position.
    state_maybe_nonfinite: bool,
    /// The velocities are half-step velocities v(t − Δt/2) (between the kicks of velocity Verlet).
    pub(crate) half_step_velocities: bool,
    /// Particles with ids below this had been through a force evaluation before the latest one (ids
    /// are assigned in increasing order); a blow-up at a newer particle's first evaluation means it was
    /// created overlapping.
    evaluated_ids: u32,
    /// In a trial stage of a multi-stage integrator: the time over which contact springs advance \[s\].
    trial_dt: Option<f64>,
    /// Buffers of the multi-stage integrators.
    stage: schemes::StageBuffers<L::State>,
    /// Force evaluations since the simulation was made (not part of the state; for benchmarks).
    evaluations: u64,
    /// This rank's share of a run split over several ranks (`None` on one rank).
    decomp: Option<decomp::Decomp<L::State>>,
    /// On several ranks: the load imbalance above which the split is rebuilt ([`Self::set_rebalance`]).
    rebalance: Option<f64>,
}

impl<L: ContactLaw> Simulation<L> {
    /// A simulation with `materials` (indexed by particle and wall material ids), pair properties for
    /// every material pair, and time step `dt` \[s\].
    pub fn new(
        law: L,
        materials: Vec<Material>,
        props: PairTable<PairProps>,
        dt: f64,
        settings: Settings,
    ) -> Self {
        assert_eq!(props.types(), materials.len(), "one pair-table row per material");
        let params = props.map(|k, p| law.params(k, p));
        Simulation {
            law,
            materials,
            props,
            params,
            particles: Particles::new(),
            walls: Vec::new(),
            gravity: Vec3::ZERO,
            dt,
            settings,
            energy_method: EnergyMethod::PerContact,
            st: DynState::default(),
            templates: Vec::new(),
            wear: crate::wear::WearTable::new(0),
            scratch: Scratch::default(),
            record_impacts: false,
            impacts: Vec::new(),
            external: None,
            last_worst: (0, 0),
            base_forces_ready: false,
            state_maybe_nonfinite: false,
            half_step_velocities: false,
            evaluated_ids: 0,
            trial_dt: None,
            stage: Default::default(),
            evaluations: 0,
            decomp: None,
            rebalance: Some(decomp::DEFAULT_REBALANCE),
        }
    }

    pub fn materials(&self) -> &[Material] {
        &self.materials
    }

    /// Pair properties of materials (a, b).
    pub fn pair_props(&self, a: usize, b: usize) -> &PairProps {
        self.props.get(a, b)
    }

    /// Precomputed contact-law parameters of materials (a, b).
    pub fn pair_params(&self, a: usize, b: usize) -> &L::Params {
        self.params.get(a, b)
    }

    /// Current time \[s\].
    pub fn time(&self) -> f64 {
        self.st.time
    }

    /// Steps taken.
    pub fn step_count(&self) -> u64 {
        self.st.step
    }

    /// Neighbour-list rebuilds so far.
    pub fn rebuild_count(&self) -> u64 {
        self.st.rebuilds
    }

    /// Particles removed for leaving the domain.
    pub fn removed_count(&self) -> u64 {
        self.st.removed
    }

    /// Results of the last force evaluation.
    pub fn last_evaluation(&self) -> &LastEvaluation {
        &self.st.last
    }

    pub fn energy_accounts(&self) -> &EnergyAccounts {
        &self.st.energy
    }

    /// Adds a particle (material `p.material` must exist); returns its id. The particle starts with the
    /// force of gravity (and no contact force: insert particles without overlaps), so adding particles
    /// during a run needs no extra force evaluation.
    pub fn add_particle(&mut self, p: NewParticle) -> u32 {
        let rho = self.materials[p.material as usize].density;
        self.st.r_max = self.st.r_max.max(p.radius);
        self.st.needs_rebuild = true;
        let id = self.particles.push(p, rho);
        let i = self.particles.len() - 1;
        if !p.frozen {
            let m = self.particles.mass(i);
            self.particles.force[i] = m * self.gravity;
            let pa = &self.particles;
            let e = &mut self.st.energy;
            e.injected_kinetic += 0.5 * m * pa.vel[i].length_squared();
            e.injected_rotational += 0.5 * pa.inertia(i) * pa.omega[i].length_squared();
            e.injected_moment += m * pa.pos[i];
        }
        id
    }

    /// A snapshot of everything that evolves (particles, contact states, lists, energy accounts, mesh
    /// records), for checkpoints. Restoring it into a simulation built from the same inputs continues the
    /// run bit for bit.
    pub fn state(&self) -> SimState<L::State> {
        SimState {
            particles: self.particles.clone(),
            dynamic: self.st.clone(),
            mesh_records: self
                .walls
                .iter()
                .map(|w| match &w.shape {
                    WallShape::Mesh(m) => Some(m.records.clone()),
                    _ => None,
                })
                .collect(),
        }
    }

    /// Restores a snapshot taken by [`Simulation::state`] of a simulation with the same materials and walls.
    pub fn restore(&mut self, s: SimState<L::State>) -> Result<(), String> {
        if s.mesh_records.len() != self.walls.len() {
            return Err(format!(
                "checkpoint has {} walls, the scene {}",
                s.mesh_records.len(),
                self.walls.len()
            ));
        }
        for (w, rec) in self.walls.iter_mut().zip(s.mesh_records) {
            match (&mut w.shape, rec) {
                (WallShape::Mesh(m), Some(r)) if r.impacts.len() == m.mesh.triangles.len() => {
                    m.records = r;
                    m.records.fill_missing();
                }
                (WallShape::Mesh(_), _) | (_, Some(_)) => {
                    return Err(format!("wall `{}` does not match the checkpoint", w.name));
                }
                _ => {}
            }
        }
        self.particles = s.particles;
        self.evaluated_ids = self.particles.next_id();
        self.st = s.dynamic;
        self.refresh_members();
        let n = self.st.wall_list.state.len();
        if self.st.wall_list.out.len() != n {
            self.st.wall_list.out.clear();
            self.st.wall_list.out.resize(n, forces::SlotOut::default());
        }
        Ok(())
    }

    /// Adds a wall; returns its index.
    pub fn add_wall(&mut self, w: Wall) -> usize {
        assert!((w.material as usize) < self.materials.len(), "wall material index out of range");
        self.walls.push(w);
        self.st.needs_rebuild = true;
        self.st.forces_valid = false;
        self.walls.len() - 1
    }

    /// Sets the erosion models of mesh walls (per particle material × wall material; see [`crate::wear`]).
    pub fn set_wear(&mut self, table: crate::wear::WearTable) {
        self.wear = table;
    }

    /// Turns the recording of wall impacts on or off (off by default; see [`WallImpact`]).
    pub fn set_impact_recording(&mut self, on: bool) {
        self.record_impacts = on;
        self.impacts.clear();
    }

    /// The particle–wall contacts that formed in the last force evaluation, in particle order (empty
    /// unless recording is on).
    pub fn last_impacts(&self) -> &[WallImpact] {
        &self.impacts
    }

    /// The erosion models in use.
    pub fn wear(&self) -> &crate::wear::WearTable {
        &self.wear
    }

    /// Total eroded mass of wall `w` \[kg\] (0 for an analytic wall).
    pub fn eroded_mass(&self, w: usize) -> f64 {
        match &self.walls[w].shape {
            WallShape::Mesh(m) => m.records.eroded_mass.iter().sum(),
            _ => 0.0,
        }
    }

    /// Installs the external-force hook.
    pub fn set_external_forces(&mut self, f: Box<dyn ExternalForces>) {
        self.external = Some(f);
        self.st.forces_valid = false;
    }

    /// Replaces the persistent external force of every particle by `forces` \[N\] (one per particle, in
    /// the current particle order; the external torques stay). Between velocity-Verlet steps the forces
    /// of the current state are already evaluated and the next step's first half-kick uses them: they are
    /// corrected by the change (members' forces too, then their bodies' sums), so that a force held for
    /// the next N steps acts over exactly those N steps rather than half a step late.
    pub fn replace_external_forces(&mut self, forces: &[Vec3]) {
        debug_assert_eq!(forces.len(), self.particles.len());
        let valid = self.st.forces_valid;
        let p = &mut self.particles;
        p.external_force_mut();
        for (i, &f) in forces.iter().enumerate() {
            if valid {
                p.force[i] += f - p.ext_force[i];
            }
            p.ext_force[i] = f;
        }
        if valid && !self.st.bodies.is_empty() {
            self.reduce_body_forces();
        }
    }

    /// Asks the next step to book the contacts' elastic energy (needed before [`Simulation::energy`] under
    /// [`EnergyMethod::Residual`]; a no-op cost-wise under per-contact bookkeeping).
    pub fn request_energy(&mut self) {
        self.st.energy_requested = true;
    }

    /// Whether contacts book their energies in the evaluations of the current step.
    pub(crate) fn booking_energy(&self) -> bool {
        self.energy_method == EnergyMethod::PerContact || self.st.energy_requested
    }

    /// Marks the neighbour lists as stale (after editing particles directly).
    pub fn invalidate(&mut self) {
        self.st.needs_rebuild = true;
        self.st.forces_valid = false;
        self.st.r_max = self.particles.radius.iter().copied().fold(0.0, f64::max);
    }

    /// The Verlet skin in use \[m\].
    pub fn skin(&self) -> f64 {
        if !self.settings.verlet_list {
            return 0.0;
        }
        self.settings.skin.unwrap_or(0.2 * self.st.r_max)
    }

    /// Largest interaction range beyond touching over all particle pairs and particle–wall pairs \[m\].
    fn range_max(&self, r: f64) -> (f64, f64) {
        let n = self.materials.len();
        let mut pp: f64 = 0.0;
        for a in 0..n {
            for b in 0..n {
                pp = pp.max(self.law.range(self.params.get(a, b), 0.5 * r));
            }
        }
        let mut pw: f64 = 0.0;
        for w in &self.walls {
            for a in 0..n {
                pw = pw.max(self.law.range(self.params.get(a, w.material as usize), r));
            }
        }
        (pp, pw)
    }

    /// Advances one time step.
    pub fn step(&mut self) -> Result<(), DemError> {
        if self.dt <= 0.0 || !self.dt.is_finite() {
            return Err(DemError::Config {
                key: "dt_s".into(),
                message: format!("dt_s = {} must be a positive number of seconds", self.dt),
            });
        }
        match self.settings.integrator {
            Integrator::VelocityVerlet => {
                if self.st.needs_rebuild {
                    self.rebuild();
                }
                if !self.st.forces_valid {
                    self.evaluate()?;
                }
                let vmax = self.kick_drift(0.5, true, true);
                let vmax = vmax.max(self.bodies_kick(0.5, true, true));
                if !self.settings.rotation {
                    self.clear_spins();
                }
                self.advance_time(vmax);
                self.half_step_velocities = true;
                self.maybe_rebuild();
                self.half_step_velocities = false;
                self.evaluate()?;
                self.kick_drift(0.5, false, false);
                self.bodies_kick(0.5, false, false);
            }
            Integrator::SymplecticEuler => {
                if self.st.needs_rebuild {
                    self.rebuild();
                }
                self.evaluate()?;
                let vmax = self.kick_drift(1.0, true, false);
                let vmax = vmax.max(self.bodies_kick(1.0, true, false));
                self.advance_time(vmax);
                self.maybe_rebuild();
                // Forces now belong to the previous positions.
                self.st.forces_valid = false;
            }
            other => {
                if let Some(scheme) = other.scheme() {
                    self.scheme_step(scheme)?;
                }
            }
        }
        self.st.step += 1;
        self.st.energy_requested = false;
        if !self.settings.rotation {
            self.clear_spins();
        }
        self.check_finite()
    }

    /// Force evaluations since the simulation was made (counted, not part of the checkpoint state): one
    /// per step for velocity Verlet and symplectic Euler once started, more for the multi-stage and
    /// implicit schemes.
    pub fn force_evaluations(&self) -> u64 {
        self.evaluations
    }

    /// Advances `n` steps.
    pub fn run_steps(&mut self, n: u64) -> Result<(), DemError> {
        for _ in 0..n {
            self.step()?;
        }
        Ok(())
    }

    fn advance_time(&mut self, vmax: f64) {
        self.st.time += self.dt;
        self.st.disp_particles += vmax * self.dt;
        let t = self.st.time;
        let mut wmax: f64 = 0.0;
        for w in &self.walls {
            if !matches!(w.motion, spatter_core::motion::Motion::Fixed) {
                let k = WallKinematics::of(&w.motion, t);
                wmax = wmax.max(k.max_speed(w.extent(0.0)));
            }
        }
        self.st.disp_walls += wmax * self.dt;
    }

    fn maybe_rebuild(&mut self) {
        let skin = self.skin();
        let dp = self.st.disp_particles;
        let dw = self.st.disp_walls;
        if self.st.needs_rebuild || !self.settings.verlet_list || (2.0 * dp).max(dp + dw) > skin {
            self.rebuild();
        }
    }

    /// Evaluates forces at the current state and checks for blow-up.
    fn evaluate(&mut self) -> Result<(), DemError> {
        self.compute_forces();
        self.evaluations += 1;
        if !self.st.bodies.is_empty() {
            self.reduce_body_forces();
        }
        self.st.forces_valid = true;
        if self.st.last.max_overlap_ratio > self.settings.max_overlap_fraction {
            return Err(self.blow_up_overlap());
        }
        self.evaluated_ids = self.particles.next_id();
        Ok(())
    }

    /// The energy budget now (kinetic energies use the current, full-step velocities). Under
    /// [`EnergyMethod::Residual`] call [`Simulation::request_energy`] before the last step, or the elastic
    /// energy of that step is unknown (reported as 0, and the dissipation absorbs it).
    pub fn energy(&self) -> EnergyReport {
        let p = &self.particles;
        let mut ke = 0.0;
        let mut rot = 0.0;
        let mut moment = Vec3::ZERO;
        for i in 0..p.len() {
            if p.inv_mass[i] == 0.0 || p.is_member(i) {
                continue;
            }
            let m = p.mass(i);
            ke += 0.5 * m * p.vel[i].length_squared();
            rot += 0.5 * p.inertia(i) * p.omega[i].length_squared();
            moment += m * p.pos[i];
        }
        let b = &self.st.bodies;
        for k in 0..b.len() {
            let m = b.mass(k);
            ke += 0.5 * m * b.vel[k].length_squared();
            rot += b.rotational_energy(k);
            moment += m * b.pos[k];
        }
        // Summed like the injected accounts, so the residual is exactly zero before the first step.
        let pot = -self.gravity.dot(moment);
        let a = &self.st.energy;
        let elastic = self.st.last.elastic;
        let dissipated = match self.energy_method {
            EnergyMethod::PerContact => a.dissipated,
            EnergyMethod::Residual => {
                let e_in = a.injected_kinetic + a.injected_rotational - self.gravity.dot(a.injected_moment);
                e_in + a.external_work + a.wall_work - (ke + rot + pot + elastic)
            }
        };
        EnergyReport {
            time: self.st.time,
            kinetic: ke,
            rotational: rot,
            elastic,
            potential: pot,
            dissipated,
            external_work: self.st.energy.external_work,
            wall_work: self.st.energy.wall_work,
            pair_contacts: self.st.last.pair_contacts,
            wall_contacts: self.st.last.wall_contacts,
        }
    }

    /// Smallest Rayleigh time step over the particle materials and radii present \[s\].
    pub fn rayleigh_time(&self) -> f64 {
        let p = &self.particles;
        let mut t = f64::INFINITY;
        for i in 0..p.len() {
            let m = &self.materials[p.material[i] as usize];
            if m.youngs_modulus.is_finite() {
                t = t.min(spatter_core::timestep::rayleigh_time(
                    p.radius[i],
                    m.density,
                    m.shear_modulus(),
                    m.poisson_ratio,
                ));
            }
        }
        t
    }

    /// Bytes of simulation state per particle between steps: particle arrays, pair list with contact
    /// states, wall candidates (the cell grid and sorting buffers exist only during a rebuild).
    pub fn bytes_per_particle(&self) -> f64 {
        let n = self.particles.len().max(1) as f64;
        let s = std::mem::size_of::<L::State>();
        let list = &self.st.list;
        let wl = &self.st.wall_list;
        let pairs = list.nbr.capacity() * 4 + list.state.capacity() * s + list.start.capacity() * 4;
        let walls = wl.start.capacity() * 4
            + wl.wall.capacity() * 2
            + wl.tri.capacity() * 4
            + wl.state.capacity() * s
            + wl.out.capacity() * std::mem::size_of::<forces::SlotOut>();
        self.particles.bytes_per_particle() as f64 + (pairs + walls) as f64 / n
    }

    /// Number of pairs in the neighbour list.
    pub fn pair_list_len(&self) -> usize {
        self.st.list.nbr.len()
    }

    /// Whether wall `w` is a mesh.
    pub fn is_mesh_wall(&self, w: usize) -> bool {
        matches!(self.walls[w].shape, WallShape::Mesh(_))
    }
}

#[cfg(test)]
mod clump_tests;
#[cfg(test)]
mod contact_option_tests;
#[cfg(test)]
mod scheme_tests;
#[cfg(test)]
mod tests;
#[cfg(test)]
mod wear_tests;
