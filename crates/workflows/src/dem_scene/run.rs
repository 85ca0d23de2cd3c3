//! Running a scene: law selection, time loop, injection, outputs, checkpoint and resume.

use super::config::{NormalKind, SceneConfig, TangentialKind};
use super::event_ranks::trajectory_rows_with;
use super::events::{EventLog, TRAJECTORY_COLUMNS};
use super::setup;
use serde::{Deserialize, Serialize};
use spatter_core::check::Checker;
use spatter_core::comm::{Comm, SERIAL};
use spatter_core::control::Finished;
use spatter_core::{Aabb, Vec3};
use spatter_dem::adhesion::{DmtLaw, JkrLaw, SjkrLaw};
use spatter_dem::clump::NewBody;
use spatter_dem::contact::{
    Composed, ContactLaw, Hertz, Hooke, HookeParams, HookeStiffness, LinearCohesion, LinearHistory, Mindlin,
    MindlinVariant, RestitutionDamping,
};
use spatter_dem::error::DemError;
use spatter_dem::insertion::{InjectionRate, Injector, InjectorState, Region, WallClearance};
use spatter_dem::output::{
    body_rows_with, energy_row, particles_vtu, write_mesh, write_particles, BODY_COLUMNS, ENERGY_COLUMNS,
};
use spatter_dem::restitution_models::{RestitutionModel, SpeedDependentDamping};
use spatter_dem::sim::{Integrator, RankState, SimState, Simulation};
use spatter_dem::timestep;
use spatter_io::csv::CsvSeries;
use spatter_io::pvd::PvdSeries;
use spatter_io::rank_checkpoint::Resumed;
use spatter_io::run::{MeshMapRecord, RunContext, RunSummary};

/// Everything a resumed run needs (the checkpoint header names the input it belongs to: a resume with
/// another scene is refused when it is loaded).
#[derive(Serialize, Deserialize)]
struct Checkpoint<S, P> {
    sim: SimState<S>,
    /// The state of the [`StepPartner`] (nothing without one).
    partner: P,
    /// State of each injector (particles and mass placed, pending draw, random generator).
    injectors: Vec<InjectorState>,
    output_index: u64,
    csv_bytes: u64,
    /// Bytes written to `bodies.csv` and `wear.csv` (0 when not written).
    bodies_csv_bytes: u64,
    wear_csv_bytes: u64,
    /// Bytes written to `trajectories.csv` (0 when not written).
    trajectories_csv_bytes: u64,
    /// The event log (empty when not kept).
    events: EventLog,
    warnings: Vec<String>,
    /// Progress of the `[pour]` (None without one).
    pour: Option<super::pour::PourState>,
    /// The probe's state and samples (None without `[probe]`).
    probe: Option<super::probe::ProbeState>,
}

/// One rank's part of a checkpoint written on several ranks: the scene's checkpoint with this rank's
/// particles and partial sums (energy accounts, mesh records; rank 0 also the file offsets), and the
/// split of space with the contact states across it.
#[derive(Serialize, Deserialize)]
struct RankPart<S, P> {
    scene: Checkpoint<S, P>,
    rank: Option<RankState<S>>,
}

/// What runs on one rank only: a run on several ranks (`mpirun`) with any of these is refused with one
/// sentence naming the key. `external`: the run has forces from outside the engine that look beyond each
/// particle's own state ([`spatter_dem::sim::ExternalForces::per_particle`]).
fn refuse_on_ranks(cfg: &SceneConfig, external: bool, comm: &dyn Comm) -> Result<(), DemError> {
    if comm.size() == 1 {
        return Ok(());
    }
    let one_rank = [
        (
            "engine.integrator",
            !matches!(cfg.engine.integrator, Integrator::VelocityVerlet | Integrator::SymplecticEuler),
        ),
        ("(forces from a flow)", external),
    ];
    match one_rank.iter().find(|(_, on)| *on) {
        None => Ok(()),
        Some((key, _)) => Err(DemError::Config {
            key: (*key).into(),
            message: format!(
                "runs on one rank only in this version, and this run has {} ranks: remove `{key}` (or use \
                 velocity_verlet or symplectic_euler for engine.integrator), or start the run without mpirun",
                comm.size()
            ),
        }),
    }
}

/// `b` grown by the injection regions and the mesh walls: the box particles can reach.
fn reach_bounds<L: ContactLaw>(mut b: Aabb, cfg: &SceneConfig, sim: &Simulation<L>) -> Aabb {
    let regions = cfg.inject.iter().map(|j| &j.region).chain(cfg.pour.iter().map(|p| &p.region));
    for region in regions {
        if let Ok(r) = setup::region(region) {
            b = b.union(r.bounds());
        }
    }
    for w in &sim.walls {
        if let spatter_dem::walls::WallShape::Mesh(m) = &w.shape {
            b = b.union(m.mesh.bounds());
        }
    }
    b
}

/// The points the split over ranks balances: the particles at the start, and for a scene with
/// injection or a pour also a 16 × 16 × 16 lattice over where particles will be (the engine's domain
/// when given, else the box around the injection and pour regions, the mesh walls and the particles).
fn split_points<L: ContactLaw>(cfg: &SceneConfig, sim: &Simulation<L>) -> Vec<Vec3> {
    let mut points = sim.particles.pos.clone();
    if cfg.inject.is_empty() && cfg.pour.is_none() {
        return points;
    }
    let b = match (cfg.engine.domain_min_m, cfg.engine.domain_max_m) {
        (Some(a), Some(b)) => Aabb::new(a, b),
        _ => reach_bounds(Aabb::from_points(&points), cfg, sim),
    };
    const N: usize = 16;
    let e = b.extent();
    for k in 0..N * N * N {
        let (i, j, l) = (k % N, (k / N) % N, k / (N * N));
        let f = |n: usize| (n as f64 + 0.5) / N as f64;
        points.push(b.min + Vec3::new(f(i) * e.x, f(j) * e.y, f(l) * e.z));
    }
    points
}

/// Runs a DEM scene into `ctx.dir`: `energy.csv`, `particles.pvd` + `particles/*.vtu`, and for every mesh
/// wall `<name>_wall.pvd` + `walls/<name>_*.vtu` with per-triangle impact records. Stops cleanly (with
/// `checkpoint.bin`) when `ctx.control` asks; with `ctx.resume` continues from the checkpoint so that the
/// outputs equal those of an uninterrupted run bit for bit.
pub fn run(cfg: &SceneConfig, ctx: &RunContext) -> Result<RunSummary, DemError> {
    run_collect(cfg, ctx).map(|(summary, _)| summary)
}

/// What a finished scene leaves for a workflow built on it (see [`run_collect`]).
#[derive(Clone, Debug)]
pub struct SceneResults {
    /// Per mesh wall (in `[[walls]]` order, analytic walls left out): its name and per triangle the
    /// eroded mass \[kg\] and the impacts.
    pub mesh_walls: Vec<MeshWallResult>,
    /// The event log (empty without `[output.events]`).
    pub events: EventLog,
    /// The rigid bodies present at the end: id, template index (alphabetical order of `[templates]`)
    /// and centre of mass \[m\].
    pub bodies: Vec<(u32, u32, Vec3)>,
    /// Member spheres in each template, in template order.
    pub template_members: Vec<usize>,
    /// Particles (spheres, members included) removed for leaving the domain.
    pub removed_spheres: u64,
}

/// Per-triangle records of one mesh wall at the end of a run.
#[derive(Clone, Debug)]
pub struct MeshWallResult {
    pub name: String,
    pub eroded_mass: Vec<f64>,
    pub impacts: Vec<u64>,
}

/// The records of a completed run; `bodies` are the rows of [`body_rows_with`] (every rank's bodies).
fn results<L: ContactLaw>(sim: &Simulation<L>, events: EventLog, bodies: &[Vec<f64>]) -> SceneResults {
    let mut mesh_walls = Vec::new();
    for w in &sim.walls {
        if let spatter_dem::walls::WallShape::Mesh(m) = &w.shape {
            mesh_walls.push(MeshWallResult {
                name: w.name.clone(),
                eroded_mass: m.records.eroded_mass.clone(),
                impacts: m.records.impacts.clone(),
            });
        }
    }
    SceneResults {
        mesh_walls,
        events,
        bodies: bodies.iter().map(|r| (r[1] as u32, r[2] as u32, Vec3::new(r[3], r[4], r[5]))).collect(),
        template_members: sim.templates().iter().map(|t| t.spheres.len()).collect(),
        removed_spheres: sim.removed_count(),
    }
}

/// Like [`run`], and for a completed run also the [`SceneResults`] (`None` when the run was
/// interrupted), so that a workflow composing a scene reads its records without re-reading files.
pub fn run_collect(
    cfg: &SceneConfig,
    ctx: &RunContext,
) -> Result<(RunSummary, Option<SceneResults>), DemError> {
    run_collect_with(cfg, ctx, None)
}

/// Like [`run_collect`], with forces from outside the engine (e.g. the drag of a prescribed air flow
/// through [`crate::fluid_forces::FluidForces`]) added at every force evaluation. The hook must be a
/// function of time and the particles' state only (it is not part of the checkpoint), so that resumed
/// runs stay bit-identical.
pub fn run_collect_with(
    cfg: &SceneConfig,
    ctx: &RunContext,
    external: Option<Box<dyn spatter_dem::sim::ExternalForces>>,
) -> Result<(RunSummary, Option<SceneResults>), DemError> {
    run_collect_partnered(cfg, ctx, external, NoPartner)
}

/// Something stepped in the scene's loop beside the DEM, with a state of its own that the scene's
/// checkpoint carries: the coupled fluid of a CFD–DEM run ([`crate::cfd_dem::partner::CoupledFluid`]).
/// The scene calls it before every DEM step (after the injection), at every output, on resume and at the
/// end; everything else (injection, events, wear, outputs, checkpoints) stays the scene's.
pub trait StepPartner {
    /// What a checkpoint keeps of the partner.
    type State: Serialize + serde::de::DeserializeOwned;
    /// The partner's failures; a DEM failure converts into it.
    type Error: From<DemError>;
    /// Before DEM step `sim.step_count()`: may set the particles' persistent external forces.
    fn before_step<L: ContactLaw>(&mut self, sim: &mut Simulation<L>) -> Result<(), Self::Error>;
    /// At each output of the scene (after the scene's own files, at the same time).
    fn output<L: ContactLaw>(&mut self, sim: &Simulation<L>, ctx: &RunContext) -> Result<(), Self::Error>;
    fn state(&self) -> Self::State;
    /// Continues from a checkpoint written at time `t` \[s\].
    fn restore(&mut self, state: Self::State, ctx: &RunContext, t: f64) -> Result<(), Self::Error>;
    /// After the last step: the partner's results into the summary.
    fn finish<L: ContactLaw>(
        &mut self,
        sim: &Simulation<L>,
        ctx: &RunContext,
        summary: &mut RunSummary,
    ) -> Result<(), Self::Error>;
}

/// No partner: the scene alone.
pub struct NoPartner;

impl StepPartner for NoPartner {
    type State = ();
    type Error = DemError;
    fn before_step<L: ContactLaw>(&mut self, _: &mut Simulation<L>) -> Result<(), DemError> {
        Ok(())
    }
    fn output<L: ContactLaw>(&mut self, _: &Simulation<L>, _: &RunContext) -> Result<(), DemError> {
        Ok(())
    }
    fn state(&self) {}
    fn restore(&mut self, _: (), _: &RunContext, _: f64) -> Result<(), DemError> {
        Ok(())
    }
    fn finish<L: ContactLaw>(
        &mut self,
        _: &Simulation<L>,
        _: &RunContext,
        _: &mut RunSummary,
    ) -> Result<(), DemError> {
        Ok(())
    }
}

/// Like [`run_collect_with`], with `partner` stepped beside the DEM (see [`StepPartner`]).
pub fn run_collect_partnered<P: StepPartner>(
    cfg: &SceneConfig,
    ctx: &RunContext,
    external: Option<Box<dyn spatter_dem::sim::ExternalForces>>,
    partner: P,
) -> Result<(RunSummary, Option<SceneResults>), P::Error> {
    Checker::run(cfg, None).map_err(DemError::Invalid)?;
    with_law(cfg, SceneRun { cfg, ctx, external, partner })?
}

/// The scene's own run, as a [`WithLaw`] visitor.
struct SceneRun<'a, P> {
    cfg: &'a SceneConfig,
    ctx: &'a RunContext<'a>,
    external: Option<Box<dyn spatter_dem::sim::ExternalForces>>,
    partner: P,
}

impl<P: StepPartner> WithLaw for SceneRun<'_, P> {
    type Output = Result<(RunSummary, Option<SceneResults>), P::Error>;
    fn with<L: ContactLaw>(self, law: L, mut built: setup::Built) -> Result<Self::Output, DemError> {
        built.external = self.external;
        Ok(run_with(law, built, self.cfg, self.ctx, self.partner))
    }
}

/// Something run with the contact law a scene chooses (`[contact]` and the pairs decide the law's type,
/// so the engine is monomorphised for it): the scene's own run, or a workflow that drives the DEM itself
/// (the `cfd_dem` kind).
pub trait WithLaw {
    type Output;
    /// Called once with the scene's law and its built materials, pairs, walls and templates.
    fn with<L: ContactLaw>(self, law: L, built: setup::Built) -> Result<Self::Output, DemError>;
}

/// The global Hooke stiffness `[contact]` chooses: a constant k_n, or k_n from a characteristic speed
/// (1 m/s when neither key is given). A pair's own `stiffness_n_m` overrides it.
fn hooke_stiffness(c: &super::config::ContactConfig) -> HookeStiffness {
    match (c.hooke_stiffness_n_m, c.hooke_characteristic_speed_m_s) {
        (Some(k), _) => HookeStiffness::Constant(k),
        (None, Some(v)) => HookeStiffness::CharacteristicVelocity(v),
        (None, None) => HookeStiffness::CharacteristicVelocity(1.0),
    }
}

/// Builds the scene's engine objects and calls `v` with the contact law `[contact]` chooses (one
/// monomorphised engine per combination). The scene must have been validated.
pub fn with_law<V: WithLaw>(cfg: &SceneConfig, v: V) -> Result<V::Output, DemError> {
    let c = &cfg.contact;
    let damping = RestitutionDamping {
        tensile_clamp: c.tensile_clamp,
        calibration: c.damping_calibration,
        tangential: c.tangential_damping,
    };
    let linear = LinearHistory { stiffness_ratio: c.linear_stiffness_ratio };
    let hooke = Hooke { stiffness: hooke_stiffness(c) };
    let jkr = JkrLaw { break_criterion: c.jkr_break, damping: c.jkr_damping, coulomb: c.adhesive_coulomb };
    let r = c.rolling;
    let built = setup::build(cfg)?;
    if built.speed_dependent_restitution() {
        // Some pair has a speed-dependent e: the damping law keeps each contact's coefficient in its
        // state (16 bytes more per contact), so it gets engines of its own; scenes with constant e only
        // keep the default law. Every pair carries its model, the law's own is never used.
        let d = SpeedDependentDamping {
            model: RestitutionModel::Constant { restitution: cfg.pair_defaults.restitution },
            base: damping,
        };
        let variant = MindlinVariant { history: c.tangential.mindlin_history().unwrap_or_default() };
        let ac = c.adhesive_coulomb;
        return match (c.normal, c.tangential) {
            (NormalKind::Hertz, TangentialKind::Linear) => {
                v.with(configured(Composed::new(Hertz, d, linear, r), cfg), built)
            }
            (NormalKind::Hertz, _) => v.with(configured(Composed::new(Hertz, d, variant, r), cfg), built),
            (NormalKind::Hooke, TangentialKind::Linear) => {
                v.with(configured(Composed::new(hooke, d, linear, r), cfg), built)
            }
            (NormalKind::Hooke, _) => v.with(configured(Composed::new(hooke, d, variant, r), cfg), built),
            (NormalKind::Jkr, _) => v.with(configured(Composed::new(jkr, d, Mindlin, r), cfg), built),
            (NormalKind::Dmt, _) => {
                v.with(configured(Composed::new(DmtLaw { coulomb: ac }, d, Mindlin, r), cfg), built)
            }
            (NormalKind::Sjkr, _) => {
                v.with(configured(Composed::new(SjkrLaw { coulomb: ac }, d, Mindlin, r), cfg), built)
            }
        };
    }
    // One monomorphised engine per combination.
    let cohesive = LinearCohesion { hooke, radius_ratio: c.cohesion_radius_ratio };
    match (c.normal, c.tangential) {
        // Linear cohesion (Hooke with an attractive cohesion spring) only where some pair has it.
        (NormalKind::Hooke, TangentialKind::Linear) if cfg.has_cohesion() => {
            v.with(configured(Composed::new(cohesive, damping, linear, r), cfg), built)
        }
        (NormalKind::Hooke, k) if cfg.has_cohesion() => {
            let t = MindlinVariant { history: k.mindlin_history().unwrap_or_default() };
            v.with(configured(Composed::new(cohesive, damping, t, r), cfg), built)
        }
        (NormalKind::Hertz, TangentialKind::Mindlin) => {
            v.with(configured(Composed::new(Hertz, damping, Mindlin, r), cfg), built)
        }
        (NormalKind::Hertz, TangentialKind::Linear) => {
            v.with(configured(Composed::new(Hertz, damping, linear, r), cfg), built)
        }
        (NormalKind::Hooke, TangentialKind::Mindlin) => {
            v.with(configured(Composed::new(hooke, damping, Mindlin, r), cfg), built)
        }
        (NormalKind::Hooke, TangentialKind::Linear) => {
            v.with(configured(Composed::new(hooke, damping, linear, r), cfg), built)
        }
        // The other Mindlin history rules share one engine per normal law (the rule is a runtime field).
        (NormalKind::Hertz, k) => {
            let t = MindlinVariant { history: k.mindlin_history().unwrap_or_default() };
            v.with(configured(Composed::new(Hertz, damping, t, r), cfg), built)
        }
        (NormalKind::Hooke, k) => {
            let t = MindlinVariant { history: k.mindlin_history().unwrap_or_default() };
            v.with(configured(Composed::new(hooke, damping, t, r), cfg), built)
        }
        (NormalKind::Jkr, _) => v.with(configured(Composed::new(jkr, damping, Mindlin, r), cfg), built),
        (NormalKind::Dmt, _) => v.with(
            configured(Composed::new(DmtLaw { coulomb: c.adhesive_coulomb }, damping, Mindlin, r), cfg),
            built,
        ),
        (NormalKind::Sjkr, _) => v.with(
            configured(Composed::new(SjkrLaw { coulomb: c.adhesive_coulomb }, damping, Mindlin, r), cfg),
            built,
        ),
    }
}

/// The outputs of a run; on several ranks only rank 0 holds the files.
struct Outputs {
    /// The files rank 0 writes (`None` on the other ranks).
    files: Option<OutputFiles>,
    /// Outputs written so far.
    index: u64,
}

struct OutputFiles {
    csv: CsvSeries,
    particles: PvdSeries,
    meshes: Vec<Option<PvdSeries>>,
    /// `bodies.csv` (scenes with clump templates).
    bodies: Option<CsvSeries>,
    /// `wear.csv` (scenes with a wear model).
    wear: Option<CsvSeries>,
    /// `trajectories.csv` (with `[output.trajectories]`).
    trajectories: Option<CsvSeries>,
}

/// Columns of `wear.csv`: time, then per mesh wall its eroded mass and impacts so far.
fn wear_columns<L: ContactLaw>(sim: &Simulation<L>) -> Vec<String> {
    let mut cols = vec!["t_s".to_string()];
    for w in (0..sim.walls.len()).filter(|&w| sim.is_mesh_wall(w)) {
        let name = &sim.walls[w].name;
        cols.push(format!("{name}_eroded_mass_kg"));
        cols.push(format!("{name}_impacts"));
    }
    cols
}

fn wear_row<L: ContactLaw>(sim: &Simulation<L>) -> Vec<f64> {
    let mut row = vec![sim.time()];
    for w in 0..sim.walls.len() {
        if let spatter_dem::walls::WallShape::Mesh(m) = &sim.walls[w].shape {
            row.push(sim.eroded_mass(w));
            row.push(m.records.impacts.iter().sum::<u64>() as f64);
        }
    }
    row
}

/// Opens (or on resume, truncates and reopens) an optional CSV series.
fn series(path: &std::path::Path, columns: &[String], resume: Option<u64>) -> Result<CsvSeries, DemError> {
    let cols: Vec<&str> = columns.iter().map(String::as_str).collect();
    let r = match resume {
        Some(bytes) => CsvSeries::resume(path, &cols, bytes),
        None => CsvSeries::create(path, &cols),
    };
    r.map_err(|source| DemError::Io { path: path.to_owned(), source })
}

impl Outputs {
    /// Flushes the CSV series.
    fn flush(&mut self) -> Result<(), DemError> {
        let Some(f) = self.files.as_mut() else { return Ok(()) };
        f.flush()
    }

    /// Writes output number `index` (collective on several ranks: the totals are summed over the ranks,
    /// every rank writes its piece of the particles, rank 0 the rest).
    fn write<L: ContactLaw>(
        &mut self,
        cfg: &SceneConfig,
        sim: &mut Simulation<L>,
        ctx: &RunContext,
    ) -> Result<(), DemError> {
        let comm = ctx.comm;
        let e = sim.energy_with(comm);
        let count = sim.particle_count_with(comm);
        sim.gather_mesh_records(comm);
        let bodies = match sim.templates().is_empty() {
            true => Vec::new(),
            false => body_rows_with(sim, comm),
        };
        let rel = match cfg.output.particles_vtu {
            true => Some(write_particle_output(sim, ctx, self.index)?),
            false => None,
        };
        if let Some(f) = self.files.as_mut() {
            f.write(cfg, sim, ctx, (&e, count, &bodies), rel.as_deref(), self.index)?;
        }
        self.index += 1;
        Ok(())
    }

    /// Bytes written to each CSV series (for the checkpoint; zeros on the ranks that write none).
    fn bytes(&self) -> [u64; 4] {
        let Some(f) = &self.files else { return [0; 4] };
        [
            f.csv.bytes_written(),
            f.bodies.as_ref().map_or(0, CsvSeries::bytes_written),
            f.wear.as_ref().map_or(0, CsvSeries::bytes_written),
            f.trajectories.as_ref().map_or(0, CsvSeries::bytes_written),
        ]
    }
}

/// Writes the particle output number `index`; returns its path relative to the run folder (for the
/// `.pvd`). One rank: `particles/particles_00012.vtu`. Several: every rank writes its piece
/// `particles/particles_00012_r0003.vtu` and rank 0 the `particles/particles_00012.pvtu` joining them.
fn write_particle_output<L: ContactLaw>(
    sim: &Simulation<L>,
    ctx: &RunContext,
    index: u64,
) -> Result<String, DemError> {
    let comm = ctx.comm;
    let io = |p: &std::path::Path| {
        let p = p.to_owned();
        move |source| DemError::Io { path: p, source }
    };
    if comm.size() == 1 {
        let rel = format!("particles/particles_{index:05}.vtu");
        let path = ctx.dir.path(&rel);
        write_particles(sim, &path).map_err(io(&path))?;
        return Ok(rel);
    }
    let piece = |r: usize| format!("particles_{index:05}_r{r:04}.vtu");
    let vtu = particles_vtu(sim);
    let path = ctx.dir.path(&format!("particles/{}", piece(comm.rank())));
    if let Err(e) = vtu.write(&path) {
        // The other ranks cannot be told in a collective they are not in: the run ends here.
        eprintln!(
            "error on rank {} of {}: {}: {e}; ending the run",
            comm.rank(),
            comm.size(),
            path.display()
        );
        comm.abort(1);
    }
    let rel = format!("particles/particles_{index:05}.pvtu");
    if comm.is_root() {
        let path = ctx.dir.path(&rel);
        let pieces: Vec<String> = (0..comm.size()).map(piece).collect();
        vtu.write_pvtu(&path, &pieces).map_err(io(&path))?;
    }
    Ok(rel)
}

impl OutputFiles {
    /// Flushes the CSV series.
    fn flush(&mut self) -> Result<(), DemError> {
        let all = [Some(&mut self.csv), self.bodies.as_mut(), self.wear.as_mut(), self.trajectories.as_mut()];
        for s in all.into_iter().flatten() {
            s.flush().map_err(|source| DemError::Io { path: s.path().to_owned(), source })?;
        }
        Ok(())
    }

    /// Rank 0's part of an output: the energy row (`e` and the particle `count` over all ranks), the
    /// `bodies` rows (of all ranks), wear, the `.pvd` entry of the particle output `rel` and the mesh
    /// walls.
    fn write<L: ContactLaw>(
        &mut self,
        cfg: &SceneConfig,
        sim: &Simulation<L>,
        ctx: &RunContext,
        (e, count, bodies): (&spatter_dem::EnergyReport, u64, &[Vec<f64>]),
        rel: Option<&str>,
        index: u64,
    ) -> Result<(), DemError> {
        let io = |p: &std::path::Path| {
            let p = p.to_owned();
            move |source| DemError::Io { path: p, source }
        };
        let mut row = energy_row(sim, e);
        row[2] = count as f64;
        self.csv.row(&row).map_err(io(self.csv.path()))?;
        if let Some(b) = &mut self.bodies {
            for row in bodies {
                b.row(row).map_err(io(b.path()))?;
            }
        }
        if let Some(w) = &mut self.wear {
            w.row(&wear_row(sim)).map_err(io(w.path()))?;
        }
        let t = sim.time();
        if let Some(rel) = rel {
            self.particles.push(t, rel).map_err(io(&ctx.dir.path("particles.pvd")))?;
        }
        if cfg.output.mesh_vtu {
            write_mesh_snapshots(sim, ctx, &mut self.meshes, index, t)?;
        }
        Ok(())
    }
}

/// The `<name>_wall.pvd` series of every mesh wall (`None` for the analytic walls); on resume at time `t`
/// \[s\] loaded and cut after `t`.
pub(crate) fn mesh_series<L: ContactLaw>(
    sim: &Simulation<L>,
    dir: &spatter_io::run::RunDir,
    resume: Option<f64>,
    enabled: bool,
) -> Result<Vec<Option<PvdSeries>>, DemError> {
    let mut meshes = Vec::new();
    for w in 0..sim.walls.len() {
        if !enabled || !sim.is_mesh_wall(w) {
            meshes.push(None);
            continue;
        }
        let p = dir.path(&format!("{}_wall.pvd", sim.walls[w].name));
        meshes.push(Some(match resume {
            Some(t) => {
                let mut s =
                    PvdSeries::load_or_new(&p).map_err(|source| DemError::Io { path: p.clone(), source })?;
                s.truncate_after(t).map_err(|source| DemError::Io { path: p.clone(), source })?;
                s
            }
            None => PvdSeries::new(&p),
        }));
    }
    Ok(meshes)
}

/// Snapshot number `index` of every mesh wall: `walls/<name>_NNNNN.vtu` in its pose at the current time
/// with its per-triangle impact records, added to the wall's series at the current time.
pub(crate) fn write_mesh_snapshots<L: ContactLaw>(
    sim: &Simulation<L>,
    ctx: &RunContext,
    meshes: &mut [Option<PvdSeries>],
    index: u64,
    t: f64,
) -> Result<(), DemError> {
    for (w, series) in meshes.iter_mut().enumerate() {
        if let Some(series) = series {
            let rel = format!("walls/{}_{index:05}.vtu", sim.walls[w].name);
            let path = ctx.dir.path(&rel);
            let io = |source| DemError::Io { path: path.clone(), source };
            write_mesh(sim, w, &path).map_err(io)?;
            series.push(t, &rel).map_err(io)?;
        }
    }
    Ok(())
}

/// After a step: the wall impacts and plane crossings into the event log (with `[output.events]`), and
/// the followed objects' rows into `trajectories` every `every_steps` steps (with
/// `[output.trajectories]`; `None` on the ranks that write no files). Collective on several ranks.
pub(crate) fn record_step<L: ContactLaw>(
    cfg: &SceneConfig,
    sim: &Simulation<L>,
    events: &mut EventLog,
    trajectories: Option<&mut CsvSeries>,
    comm: &dyn Comm,
) -> Result<(), DemError> {
    if let Some(e) = &cfg.output.events {
        events.hand_over(sim, comm);
        events.after_step(sim, e);
    }
    if let Some(tc) = &cfg.output.trajectories {
        if sim.step_count() % tc.every_steps == 0 {
            let rows = trajectory_rows_with(sim, tc, comm);
            if let Some(tr) = trajectories {
                for row in rows {
                    tr.row(&row).map_err(|source| DemError::Io { path: tr.path().to_owned(), source })?;
                }
            }
        }
    }
    Ok(())
}

/// Opens `trajectories.csv` with `[output.trajectories]` (on resume cut to the `bytes` a checkpoint
/// recorded); `None` without it.
pub(crate) fn trajectory_series(
    cfg: &SceneConfig,
    dir: &spatter_io::run::RunDir,
    resume: Option<u64>,
) -> Result<Option<CsvSeries>, DemError> {
    if cfg.output.trajectories.is_none() {
        return Ok(None);
    }
    let columns: Vec<String> = TRAJECTORY_COLUMNS.iter().map(|c| c.to_string()).collect();
    series(&dir.path("trajectories.csv"), &columns, resume).map(Some)
}

/// The summary's part of the event log and the trajectories: the counts of objects that hit a wall and
/// crossed the plane, and the two files as artifacts.
pub(crate) fn summarize_records(cfg: &SceneConfig, events: &EventLog, ctx: &RunContext, s: &mut RunSummary) {
    if let Some(e) = &cfg.output.events {
        let (hit, crossed) = events.counts();
        s.scalar("objects_hit_wall", hit as f64);
        s.headline.push(format!("events: {hit} bodies/spheres hit a wall, {crossed} crossed the plane"));
        if e.crossing_plane.is_some() {
            s.scalar("objects_crossed_plane", crossed as f64);
        }
        s.artifacts.push(("impact and crossing events".into(), ctx.dir.path("events.csv")));
    }
    if cfg.output.trajectories.is_some() {
        s.artifacts.push(("trajectories".into(), ctx.dir.path("trajectories.csv")));
    }
}

/// The `<name>_wall.pvd` series of the mesh walls as artifacts (with `output.mesh_vtu`).
pub(crate) fn mesh_artifacts<L: ContactLaw>(
    cfg: &SceneConfig,
    sim: &Simulation<L>,
    ctx: &RunContext,
    s: &mut RunSummary,
) {
    if !cfg.output.mesh_vtu {
        return;
    }
    for w in (0..sim.walls.len()).filter(|&w| sim.is_mesh_wall(w)) {
        let name = &sim.walls[w].name;
        s.artifacts
            .push((format!("wall {name} impacts (ParaView)"), ctx.dir.path(&format!("{name}_wall.pvd"))));
    }
}

/// Applies the scene's energy-tracking choice to a composed law.
/// The law with the scene's options that every combination shares (energy booking, Coulomb load).
fn configured<N, D, T, R>(mut law: Composed<N, D, T, R>, cfg: &SceneConfig) -> Composed<N, D, T, R> {
    law.energy = cfg.engine.track_energy;
    law.coulomb_load = cfg.contact.coulomb_load;
    law
}

/// The scene's simulation with its law, engine settings, gravity, walls, templates and wear models, and
/// no particles yet (the fills are [`setup::initial_particles`]).
pub fn simulation<L: ContactLaw>(law: L, built: setup::Built, cfg: &SceneConfig) -> Simulation<L> {
    let e = &cfg.engine;
    let settings = spatter_dem::sim::Settings {
        integrator: e.integrator,
        skin: e.skin_m,
        verlet_list: e.verlet_list,
        max_overlap_fraction: e.max_overlap_fraction,
        domain: match (e.domain_min_m, e.domain_max_m) {
            (Some(a), Some(b)) => Some(Aabb::new(a, b)),
            _ => None,
        },
        clump_contact_mass: e.clump_contact_mass,
        rotation: e.rotation,
        iterations: e.iterations,
    };
    let mut sim = Simulation::new(law, built.materials, built.pairs, cfg.dt_s, settings);
    sim.energy_method =
        if e.track_energy { e.energy_method } else { spatter_dem::sim::EnergyMethod::PerContact };
    sim.gravity = cfg.gravity_m_s2;
    sim.set_rebalance(e.rebalance());
    for w in built.walls {
        sim.add_wall(w);
    }
    for t in built.templates {
        sim.add_template(t);
    }
    sim.set_wear(built.wear);
    if let Some(f) = built.external {
        sim.set_external_forces(f);
    }
    sim
}

/// Reads the checkpoint for a run on the ranks of `ctx.comm` (collective), restores the simulation from
/// it and returns the rest of the scene's state (its `sim` field left empty). On as many ranks as wrote
/// it, every rank takes its own part and the run continues bit for bit. With `--repartition` (or a
/// one-rank checkpoint on several ranks, which needs it) the parts are joined in id order with their
/// contact history ([`Simulation::join_parts`]; the scene's other state is that of rank 0, which holds
/// the file offsets) and split afresh over this run's ranks by the same bisection as at the start.
fn resume_sim<L: ContactLaw, P: StepPartner>(
    cfg: &SceneConfig,
    sim: &mut Simulation<L>,
    ctx: &RunContext,
) -> Result<Checkpoint<L::State, P::State>, DemError> {
    let comm = ctx.comm;
    let (mut ck, parts) = match ctx
        .load_checkpoint_parts::<Checkpoint<L::State, P::State>, RankPart<_, _>>()?
    {
        Resumed::Mine(RankPart { mut scene, rank }) => {
            sim.restore(std::mem::take(&mut scene.sim)).map_err(DemError::Resume)?;
            match rank {
                Some(rs) => sim.restore_rank_state(rs, comm)?,
                None if comm.size() > 1 => {
                    return Err(DemError::Resume("the checkpoint part holds no split over the ranks".into()))
                }
                None => {}
            }
            return Ok(scene);
        }
        Resumed::Whole(mut ck) => {
            let state = std::mem::take(&mut ck.sim);
            (ck, vec![(state, None)])
        }
        Resumed::All(parts) => {
            let mut parts = parts.into_iter();
            let Some(RankPart { scene: mut ck, rank }) = parts.next() else {
                return Err(DemError::Resume("the checkpoint has no parts".into()));
            };
            let mut states = vec![(std::mem::take(&mut ck.sim), rank)];
            for p in parts {
                ck.events.merge(p.scene.events);
                states.push((p.scene.sim, p.rank));
            }
            (ck, states)
        }
    };
    sim.join_parts(parts)?;
    if comm.size() > 1 {
        sim.decompose_over(comm, &split_points(cfg, sim))?;
        // Rank 0 keeps the joined event log (the first step hands each object's plane side on to its
        // new owner); the others start empty, so that the merged log counts every record once.
        if !comm.is_root() {
            ck.events = EventLog::default();
        }
    }
    Ok(ck)
}

fn run_with<L: ContactLaw, P: StepPartner>(
    law: L,
    built: setup::Built,
    cfg: &SceneConfig,
    ctx: &RunContext,
    mut partner: P,
) -> Result<(RunSummary, Option<SceneResults>), P::Error> {
    let comm = ctx.comm;
    let (root, ranks) = (comm.is_root(), comm.size() > 1);
    refuse_on_ranks(cfg, built.external.as_ref().is_some_and(|e| !e.per_particle()), comm)?;
    let mut sim = simulation(law, built, cfg);
    let mut injectors = setup::injectors(cfg, sim.templates())?;
    let total_steps = (cfg.duration_s / cfg.dt_s).round().max(1.0) as u64;
    let out_every = ((cfg.output_interval_s / cfg.dt_s).round() as u64).max(1);
    let inject_every: Vec<u64> =
        cfg.inject.iter().map(|j| ((j.interval_s / cfg.dt_s).round() as u64).max(1)).collect();
    let dir = ctx.dir;
    let csv_path = dir.path("energy.csv");
    let pvd_path = dir.path("particles.pvd");
    let io = |p: &std::path::Path| {
        let p = p.to_owned();
        move |source| DemError::Io { path: p, source }
    };
    let has_bodies = !sim.templates().is_empty();
    let has_wear = !sim.wear().is_empty();
    let bodies_path = dir.path("bodies.csv");
    let wear_path = dir.path("wear.csv");
    let body_columns: Vec<String> = BODY_COLUMNS.iter().map(|c| c.to_string()).collect();
    sim.set_impact_recording(cfg.output.events.is_some());
    let mut events = EventLog::default();
    let warnings: Vec<String>;
    let mut out;
    let mut pour = cfg.pour.as_ref().map(|_| super::pour::PourState::new(cfg.seed));
    let pour_material = match &cfg.pour {
        Some(p) => cfg.materials.keys().position(|k| *k == p.material).unwrap_or(0) as u16,
        None => 0,
    };
    let pour_every = cfg.pour.as_ref().map_or(1, |p| ((p.interval_s / cfg.dt_s).round() as u64).max(1));
    let mut probe = None;
    let probe_every = cfg.probe.as_ref().map_or(1, |p| super::probe::sample_every(p, cfg.dt_s));
    if ctx.resume {
        let ck = resume_sim::<L, P>(cfg, &mut sim, ctx)?;
        partner.restore(ck.partner, ctx, sim.time())?;
        if ck.injectors.len() != injectors.len() {
            return Err(DemError::Resume("the number of injectors changed".into()).into());
        }
        for (slot, state) in injectors.iter_mut().zip(ck.injectors) {
            slot.0.state = state;
        }
        let t = sim.time();
        let files = if root {
            let mut particles = PvdSeries::load_or_new(&pvd_path).map_err(io(&pvd_path))?;
            particles.truncate_after(t).map_err(io(&pvd_path))?;
            let meshes = mesh_series(&sim, dir, Some(t), cfg.output.mesh_vtu)?;
            Some(OutputFiles {
                csv: CsvSeries::resume(&csv_path, ENERGY_COLUMNS, ck.csv_bytes).map_err(io(&csv_path))?,
                particles,
                meshes,
                bodies: match has_bodies {
                    true => Some(series(&bodies_path, &body_columns, Some(ck.bodies_csv_bytes))?),
                    false => None,
                },
                wear: match has_wear {
                    true => Some(series(&wear_path, &wear_columns(&sim), Some(ck.wear_csv_bytes))?),
                    false => None,
                },
                trajectories: trajectory_series(cfg, dir, Some(ck.trajectories_csv_bytes))?,
            })
        } else {
            None
        };
        out = Outputs { files, index: ck.output_index };
        events = ck.events;
        warnings = ck.warnings;
        if pour.is_some() != ck.pour.is_some() {
            return Err(DemError::Resume("the [pour] table was added or removed".into()).into());
        }
        pour = ck.pour;
        if cfg.probe.is_some() != ck.probe.is_some() {
            return Err(DemError::Resume("the [probe] table was added or removed".into()).into());
        }
        probe = ck.probe;
        tracing::info!("resumed at step {} (t = {} s)", sim.step_count(), t);
    } else {
        // The fills do not avoid the probe (the last wall): a probe placed in the bed is an error, not a
        // hole in it.
        let container = sim.walls.len() - usize::from(cfg.probe.is_some());
        let initial = setup::initial_particles(cfg, &sim.walls[..container], sim.templates())?;
        for p in initial.spheres {
            sim.add_particle(p);
        }
        for (template, material, body) in initial.bodies {
            sim.add_clump(template, material, body)?;
        }
        for t in sim.templates() {
            let path = dir.path(&format!("templates/{}.vtu", t.name));
            spatter_dem::clump::fill::write_template_vtu(t, &path).map_err(io(&path))?;
        }
        if let Some(p) = &cfg.probe {
            probe = Some(super::probe::start(p, &sim)?);
        }
        warnings = time_step_warnings(cfg, &sim);
        for w in &warnings {
            tracing::warn!("{w}");
        }
        // Every rank built the whole set-up: each keeps the particles in its box.
        if ranks {
            sim.decompose_over(comm, &split_points(cfg, &sim))?;
        }
        let files = if root {
            let meshes = mesh_series(&sim, dir, None, cfg.output.mesh_vtu)?;
            Some(OutputFiles {
                csv: CsvSeries::create(&csv_path, ENERGY_COLUMNS).map_err(io(&csv_path))?,
                particles: PvdSeries::new(&pvd_path),
                meshes,
                bodies: match has_bodies {
                    true => Some(series(&bodies_path, &body_columns, None)?),
                    false => None,
                },
                wear: match has_wear {
                    true => Some(series(&wear_path, &wear_columns(&sim), None)?),
                    false => None,
                },
                trajectories: trajectory_series(cfg, dir, None)?,
            })
        } else {
            None
        };
        out = Outputs { files, index: 0 };
        out.write(cfg, &mut sim, ctx)?;
        partner.output(&sim, ctx)?;
    }

    while sim.step_count() < total_steps {
        let poll = ctx.poll();
        let stop = poll.stop;
        if stop || poll.checkpoint {
            out.flush()?;
            let [csv_bytes, bodies_csv_bytes, wear_csv_bytes, trajectories_csv_bytes] = out.bytes();
            let ck = Checkpoint {
                sim: sim.state(),
                partner: partner.state(),
                injectors: injectors.iter().map(|(i, _)| i.state.clone()).collect(),
                output_index: out.index,
                csv_bytes,
                bodies_csv_bytes,
                wear_csv_bytes,
                trajectories_csv_bytes,
                events: events.clone(),
                warnings: warnings.clone(),
                pour: pour.clone(),
                probe: probe.clone(),
            };
            if ranks {
                let part = RankPart { scene: ck, rank: sim.rank_state() };
                ctx.save_checkpoint_part(&part).map_err(DemError::from)?;
            } else {
                ctx.save_checkpoint(&ck).map_err(DemError::from)?;
            }
            write_events(cfg, &sim, &events.gathered(comm), ctx)?;
        }
        if stop {
            let mut s = RunSummary::new(Finished::Interrupted);
            s.headline.push(format!(
                "stopped at step {} of {total_steps} (t = {:.6} s); checkpoint written, resume to continue",
                sim.step_count(),
                sim.time()
            ));
            return Ok((s, None));
        }
        let step = sim.step_count();
        for (k, (inj, region)) in injectors.iter_mut().enumerate() {
            if step % inject_every[k] == 0 {
                inject_with(&mut sim, inj, region, k, comm);
            }
        }
        if let (Some(p), Some(state)) = (&cfg.pour, pour.as_mut()) {
            if step % pour_every == 0 && state.poured < p.count {
                super::pour::add_next(&mut sim, p, pour_material, state, comm)?;
            }
        }
        // The step that takes the probe to its largest depth ends the run with an output.
        let probe_ends = match (&cfg.probe, &probe) {
            (Some(p), Some(st)) => st.depth(p.speed_m_s, sim.time() + cfg.dt_s) >= p.max_depth_m,
            _ => false,
        };
        if (step + 1) % out_every == 0 || step + 1 == total_steps || probe_ends {
            sim.request_energy();
        }
        partner.before_step(&mut sim)?;
        sim.step_with(comm)?;
        if let (Some(p), Some(st)) = (&cfg.probe, probe.as_mut()) {
            super::probe::after_step(p, &sim, st, probe_every, comm);
        }
        let trajectories = out.files.as_mut().and_then(|f| f.trajectories.as_mut());
        record_step(cfg, &sim, &mut events, trajectories, comm)?;
        if sim.step_count() % out_every == 0 || sim.step_count() == total_steps || probe_ends {
            out.write(cfg, &mut sim, ctx)?;
            partner.output(&sim, ctx)?;
            // A pour is checked for rest at the outputs, so that a run ending early ends on one.
            if let (Some(p), Some(state)) = (&cfg.pour, pour.as_mut()) {
                if state.settled_s.is_none() && super::pour::settled(&sim, p, state, comm) {
                    state.settled_s = Some(sim.time());
                    if root {
                        tracing::info!("pour settled at t = {:.6} s", sim.time());
                    }
                    if p.stop_when_settled {
                        break;
                    }
                }
            }
        }
        if probe_ends {
            tracing::info!("probe at its largest depth at t = {:.6} s", sim.time());
            break;
        }
        if sim.step_count() % 200 == 0 {
            ctx.control.progress(sim.step_count(), total_steps);
        }
    }
    out.flush()?;
    // The log of the whole run (every rank's records merged) for the file, the summary and the results.
    let events = events.gathered(comm);
    write_events(cfg, &sim, &events, ctx)?;
    // The checkpoint is of no more use: `checkpoint.bin` and, when ranks wrote it (also a checkpoint of
    // several ranks continued on one), its parts.
    if root {
        spatter_io::rank_checkpoint::remove(dir.root()).map_err(io(&dir.checkpoint_path()))?;
    }
    // Totals over the ranks (collective), then rank 0 holds the whole mesh records.
    let totals = Totals {
        energy: sim.energy_with(comm),
        particles: sim.particle_count_with(comm),
        removed: sim.removed_count_with(comm),
        bodies: body_rows_with(&sim, comm),
    };
    sim.gather_mesh_records(comm);
    let mut s = summary(cfg, &sim, &totals, &injectors, &warnings, ctx);
    super::bed_outputs::finish(cfg, &sim, pour.as_ref(), ctx, &mut s)?;
    // Every rank holds the same samples; rank 0 writes them.
    if let (Some(p), Some(st), true) = (&cfg.probe, &probe, root) {
        super::probe::finish(p, st, ctx, &mut s)?;
    }
    summarize_records(cfg, &events, ctx, &mut s);
    let maps = if root { write_wear_maps(&sim, ctx)? } else { Vec::new() };
    for (name, png, record) in maps {
        s.artifacts.push((format!("eroded mass map {name}"), png));
        s.artifacts.push((format!("eroded mass per triangle {name} (VTU)"), record.vtu.clone()));
        s.maps.push(record);
    }
    partner.finish(&sim, ctx, &mut s)?;
    let mut r = results(&sim, events, &totals.bodies);
    r.removed_spheres = totals.removed;
    Ok((s, Some(r)))
}

/// Writes `events.csv` (the whole log so far, on several ranks gathered by [`EventLog::gathered`];
/// rewritten at every checkpoint and at the end) when the scene keeps an event log; rank 0 only.
pub(crate) fn write_events<L: ContactLaw>(
    cfg: &SceneConfig,
    sim: &Simulation<L>,
    log: &EventLog,
    ctx: &RunContext,
) -> Result<(), DemError> {
    if cfg.output.events.is_none() || !ctx.comm.is_root() {
        return Ok(());
    }
    let path = ctx.dir.path("events.csv");
    let names: Vec<String> = sim.walls.iter().map(|w| w.name.clone()).collect();
    let mut csv = series(&path, &EventLog::columns(&names), None)?;
    for row in log.rows() {
        csv.row_with_gaps(&row).map_err(|source| DemError::Io { path: path.clone(), source })?;
    }
    csv.flush().map_err(|source| DemError::Io { path: path.clone(), source })
}

/// For every mesh wall that a wear model applies to, `wear/<name>_eroded_mass.png`: the eroded mass per
/// triangle at the end of the run, seen against the wall's area-weighted mean normal (the side the
/// particles hit), with the global z axis (or y for a horizontal wall) towards the top; and
/// `wear/<name>_eroded_mass.vtu`, the wall in its final pose with the cell array `eroded_mass_kg` the picture
/// shows. Returns (wall name, picture, map record); the record lets a study redraw the map of every case on
/// one colour scale.
fn write_wear_maps<L: ContactLaw>(
    sim: &Simulation<L>,
    ctx: &RunContext,
) -> Result<Vec<(String, std::path::PathBuf, MeshMapRecord)>, DemError> {
    let mut out = Vec::new();
    let mats = sim.materials().len();
    for wall in &sim.walls {
        let spatter_dem::walls::WallShape::Mesh(m) = &wall.shape else { continue };
        if !(0..mats).any(|p| sim.wear().get(p, wall.material as usize).is_some()) {
            continue;
        }
        let k = spatter_dem::walls::WallKinematics::of(&wall.motion, sim.time());
        let mut mesh = m.mesh.clone();
        mesh.map_vertices(|v| k.pose.apply(v));
        let n: Vec3 = (0..mesh.triangles.len()).map(|t| mesh.normal(t) * mesh.area(t)).sum();
        let view = -n.normalize_or_zero();
        let up = if view.cross(Vec3::Z).length() > 1e-3 { Vec3::Z } else { Vec3::Y };
        let name = &wall.name;
        let vtu = ctx.dir.path(&format!("wear/{name}_eroded_mass.vtu"));
        spatter_io::vtu::Vtu::triangles(&mesh.vertices, &mesh.triangles)
            .cell_scalar("eroded_mass_kg", &m.records.eroded_mass)
            .write(&vtu)
            .map_err(|source| DemError::Io { path: vtu.clone(), source })?;
        let png = ctx.dir.path(&format!("wear/{name}_eroded_mass.png"));
        let title = format!("{name}: eroded mass per triangle ({})", sim.wear().names().join(", "));
        let colorbar = "eroded mass [kg]";
        spatter_io::plot::mesh_map_png(&png, &mesh, &m.records.eroded_mass, view, up, &title, colorbar)
            .map_err(|source| DemError::Io { path: png.clone(), source })?;
        let record = MeshMapRecord {
            label: format!("{name} eroded mass"),
            vtu,
            array: "eroded_mass_kg".into(),
            view_dir: view.to_array(),
            up: up.to_array(),
            title,
            colorbar_label: colorbar.into(),
            scale: None,
        };
        out.push((name.clone(), png, record));
    }
    Ok(out)
}

/// Places the particles injector `k` owes at the current time, clear of the particles present and of the
/// walls where they are now.
pub(crate) fn inject<L: ContactLaw>(sim: &mut Simulation<L>, inj: &mut Injector, region: &Region, k: usize) {
    inject_with(sim, inj, region, k, &SERIAL);
}

/// [`inject`] on the ranks of `comm` (collective): the particles near the region are gathered from
/// every rank (sorted by id; the placement only asks whether a place is free, so their order does not
/// matter), every rank places the same particles, and each keeps those in its box.
fn inject_with<L: ContactLaw>(
    sim: &mut Simulation<L>,
    inj: &mut Injector,
    region: &Region,
    k: usize,
    comm: &dyn Comm,
) {
    let t = sim.time();
    if t < inj.start || (inj.due(t) == 0 && inj.state.pending.is_some()) {
        return;
    }
    let mut r_max = [sim.particles.radius.iter().copied().fold(0.0, f64::max)];
    if sim.ranks() > 1 {
        comm.all_max_f64(&mut r_max);
    }
    let reach = region.bounds().inflated(r_max[0]);
    let p = &sim.particles;
    let mut existing: Vec<_> =
        (0..p.len()).filter(|&i| reach.contains(p.pos[i])).map(|i| (p.pos[i], p.radius[i])).collect();
    if sim.ranks() > 1 {
        existing = gather_near(sim, reach, comm);
    }
    let postponed = inj.state.postponed;
    let walls = WallClearance::new(&sim.walls, t);
    if let Some(mix) = inj.clumps.clone() {
        let placed = inj.place_clumps(region, t, &existing, &walls);
        if postponed == 0 && inj.state.postponed > 0 {
            let slot = inj.state.pending.unwrap_or(0.0) as usize;
            tracing::warn!(
                "inject[{k}]: at t = {t:.6} s the region had no room for the next body (template `{}`) in {} \
                 random positions and orientations; it waits for the next placement (the run summary gives \
                 the total)",
                sim.templates()[mix.shapes[slot].template].name,
                inj.attempts
            );
        }
        for p in placed {
            let body = NewBody { pos: p.pos, quat: p.quat, vel: inj.velocity, omega: Vec3::ZERO };
            // The template and material were checked when the scene was built.
            if let Err(e) = sim.add_clump_split(mix.shapes[p.slot].template, inj.material, body) {
                tracing::error!("inject[{k}]: {e}");
            }
        }
        return;
    }
    let placed = inj.place(region, t, &existing, &walls);
    if postponed == 0 && inj.state.postponed > 0 {
        tracing::warn!(
            "inject[{k}]: at t = {t:.6} s the region had no room for the next particle (diameter {:e} m) \
             in {} random positions; it waits for the next placement (the run summary gives the total)",
            inj.state.pending.unwrap_or(0.0),
            inj.attempts
        );
    }
    for (x, r) in placed {
        let mut np = spatter_dem::particles::NewParticle::at(x, r, inj.material);
        np.vel = inj.velocity;
        sim.add_particle_split(np);
    }
}

/// Position and radius of every particle inside `reach` on any rank, in id order (collective).
fn gather_near<L: ContactLaw>(sim: &Simulation<L>, reach: Aabb, comm: &dyn Comm) -> Vec<(Vec3, f64)> {
    let p = &sim.particles;
    let mut w = spatter_core::comm::WireWriter::with_capacity(0);
    for i in (0..p.len()).filter(|&i| reach.contains(p.pos[i])) {
        w.u32(p.id[i]).vec3(p.pos[i]).f64(p.radius[i]);
    }
    let mut all: Vec<(u32, Vec3, f64)> = Vec::new();
    for buf in comm.all_gather_bytes(&w.finish()) {
        let mut r = spatter_core::comm::WireReader::new(&buf);
        let bad = "particle message from another rank of this run";
        while !r.is_done() {
            all.push((r.u32().expect(bad), r.vec3().expect(bad), r.f64().expect(bad)));
        }
    }
    all.sort_unstable_by_key(|a| a.0);
    all.into_iter().map(|(_, x, r)| (x, r)).collect()
}

/// Time-step warnings for the particles present and to be injected.
pub(crate) fn time_step_warnings<L: ContactLaw>(cfg: &SceneConfig, sim: &Simulation<L>) -> Vec<String> {
    let mut sizes: Vec<(usize, f64)> = Vec::new();
    let p = &sim.particles;
    for i in 0..p.len() {
        sizes.push((p.material[i] as usize, p.radius[i]));
    }
    for j in &cfg.inject {
        let Some(m) = cfg.materials.keys().position(|k| *k == j.material) else { continue };
        if let Some(size) = &j.size {
            sizes.push((m, 0.5 * setup::min_diameter(size)));
        }
        for name in j.clumps.iter().flat_map(|c| c.templates.iter()) {
            if let Some(t) = sim.templates().iter().find(|t| &t.name == name) {
                sizes.push((m, t.spheres.iter().map(|s| s.1).fold(f64::INFINITY, f64::min)));
            }
        }
    }
    if let Some(pour) = &cfg.pour {
        if let Some(m) = cfg.materials.keys().position(|k| *k == pour.material) {
            sizes.push((m, 0.5 * setup::min_diameter(&pour.size)));
        }
    }
    let mats = sim.materials();
    let mut t_r = f64::INFINITY;
    let mut t_h = f64::INFINITY;
    // Highest impact speed: the configured one, or the fall speed across the scene plus initial speeds.
    let v = cfg.engine.impact_speed_m_s.unwrap_or_else(|| {
        // Height scale: particles, injection regions and mesh walls.
        let mut b = Aabb::EMPTY;
        for x in &p.pos {
            b = b.grown_to(*x);
        }
        let b = reach_bounds(b, cfg, sim);
        let h = if b.is_empty() { 0.0 } else { b.extent().length() };
        let v0 = p.vel.iter().map(|v| v.length()).fold(0.0, f64::max);
        let vi = cfg.inject.iter().map(|j| j.velocity_m_s.length()).fold(0.0, f64::max);
        (2.0 * cfg.gravity_m_s2.length() * h).sqrt() + v0.max(vi) + 1e-3
    });
    // Linear springs: the contact lasts π√(m*/k_n) of the pair's own stiffness, and the Rayleigh time
    // (elastic waves of the material) does not limit the step (docs/dem.md, "Time step").
    let hooke = (cfg.contact.normal == NormalKind::Hooke).then(|| hooke_stiffness(&cfg.contact));
    let mut seen = std::collections::BTreeSet::new();
    for (m, r) in sizes {
        if !seen.insert((m, r.to_bits())) {
            continue;
        }
        let Some(global) = hooke else {
            t_r = t_r.min(timestep::rayleigh(&mats[m], r));
            t_h = t_h.min(timestep::hertz(&mats[m], &mats[m], r, 2.0 * v, true));
            for w in &sim.walls {
                t_h = t_h.min(timestep::hertz(&mats[m], &mats[w.material as usize], r, v, false));
            }
            continue;
        };
        let mass = mats[m].density * spatter_core::math::sphere_volume(r);
        let duration = |b: usize, r_eff: f64, m_eff: f64| {
            let pp = sim.pair_props(m, b);
            let stiffness = pp.stiffness.map_or(global, HookeStiffness::Constant);
            let k = Hooke::stiffness(&HookeParams { e_star: pp.e_star, stiffness }, r_eff, m_eff);
            timestep::linear_contact_time(m_eff, k)
        };
        t_h = t_h.min(duration(m, 0.5 * r, 0.5 * mass));
        for w in &sim.walls {
            t_h = t_h.min(duration(w.material as usize, r, mass));
        }
    }
    let kind = if hooke.is_some() { timestep::ContactKind::Linear } else { timestep::ContactKind::Hertz };
    let mut out = Vec::new();
    if let Some(w) = timestep::check_dt(cfg.dt_s, t_r, t_h, kind) {
        out.push(w);
    }
    out
}

/// The run's totals over all ranks (the plain values on one rank).
struct Totals {
    energy: spatter_dem::EnergyReport,
    particles: u64,
    removed: u64,
    /// Rows of `bodies.csv` of every rank, in id order.
    bodies: Vec<Vec<f64>>,
}

fn summary<L: ContactLaw>(
    cfg: &SceneConfig,
    sim: &Simulation<L>,
    totals: &Totals,
    injectors: &[(Injector, Region)],
    warnings: &[String],
    ctx: &RunContext,
) -> RunSummary {
    let mut s = RunSummary::new(Finished::Completed);
    let e = totals.energy;
    s.headline.push(format!(
        "{} particles, {} steps of {:e} s to t = {:.6} s, {} list rebuilds, {} removed{}",
        totals.particles,
        sim.step_count(),
        cfg.dt_s,
        sim.time(),
        sim.rebuild_count(),
        totals.removed,
        if sim.ranks() > 1 { format!(" (on {} ranks)", sim.ranks()) } else { String::new() }
    ));
    s.headline.push(format!(
        "energy [J]: kinetic {:.4e}, rotational {:.4e}, elastic {:.4e}, dissipated {:.4e}, budget total {:.6e}",
        e.kinetic,
        e.rotational,
        e.elastic,
        e.dissipated,
        e.total()
    ));
    if !sim.templates().is_empty() {
        s.headline.push(format!(
            "{} rigid bodies (clumps) of {} templates",
            totals.bodies.len(),
            sim.templates().len()
        ));
        s.scalar("bodies", totals.bodies.len() as f64);
    }
    if !sim.wear().is_empty() {
        let mut total = 0.0;
        for w in (0..sim.walls.len()).filter(|&w| sim.is_mesh_wall(w)) {
            let m = sim.eroded_mass(w);
            total += m;
            s.scalar(&format!("eroded_mass_{}_kg", sim.walls[w].name), m);
        }
        s.scalar("eroded_mass_kg", total);
        s.headline.push(format!(
            "wear ({}): {total:.6e} kg eroded from the mesh walls",
            sim.wear().names().join(", ")
        ));
    }
    for (name, value) in [
        ("particles", totals.particles as f64),
        ("removed", totals.removed as f64),
        ("t_end_s", sim.time()),
        ("kinetic_J", e.kinetic),
        ("rotational_J", e.rotational),
        ("elastic_J", e.elastic),
        ("dissipated_J", e.dissipated),
        ("budget_total_J", e.total()),
    ] {
        s.scalar(name, value);
    }
    s.headline.push(format!(
        "contacts: {} particle-particle, {} particle-wall; time step {:.1} % of the Rayleigh time; {:.0} bytes \
         of state per particle",
        e.pair_contacts,
        e.wall_contacts,
        100.0 * cfg.dt_s / sim.rayleigh_time(),
        sim.bytes_per_particle()
    ));
    if !injectors.is_empty() {
        let placed = |f: fn(&InjectorState) -> f64| injectors.iter().map(|(i, _)| f(&i.state)).sum::<f64>();
        s.scalar("injected_count", placed(|st| st.inserted as f64));
        s.scalar("injected_mass_kg", placed(|st| st.mass));
    }
    for (k, (inj, _)) in injectors.iter().enumerate() {
        let t = sim.time();
        let target = match inj.rate {
            InjectionRate::ParticlesPerSecond(_) => format!("{:.0}", inj.target(t)),
            InjectionRate::KgPerSecond(_) => format!("{:.6e} kg", inj.target(t)),
        };
        s.headline.push(format!(
            "inject[{k}]: {} {}, {:.6e} kg placed (target {target})",
            inj.state.inserted,
            if inj.clumps.is_some() { "bodies" } else { "particles" },
            inj.state.mass
        ));
        if inj.state.postponed > 0 {
            s.headline.push(format!(
                "warning: inject[{k}]: the region was full at {} placement times; particles waited for room",
                inj.state.postponed
            ));
        }
    }
    for w in warnings {
        s.headline.push(format!("warning: {w}"));
    }
    s.artifacts.push(("energy budget".into(), ctx.dir.path("energy.csv")));
    if !sim.templates().is_empty() {
        s.artifacts.push(("rigid bodies over time".into(), ctx.dir.path("bodies.csv")));
    }
    if !sim.wear().is_empty() {
        s.artifacts.push(("eroded mass over time".into(), ctx.dir.path("wear.csv")));
    }
    if cfg.output.particles_vtu {
        s.artifacts.push(("particles (ParaView)".into(), ctx.dir.path("particles.pvd")));
    }
    mesh_artifacts(cfg, sim, ctx, &mut s);
    s
}
