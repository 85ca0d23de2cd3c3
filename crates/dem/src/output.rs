//! Output files: particle and mesh VTU snapshots, the energy CSV columns.

use crate::clump::NO_BODY;
use crate::contact::ContactLaw;
use crate::sim::{EnergyReport, Simulation};
use crate::walls::{WallKinematics, WallShape};
use spatter_core::comm::{Comm, WireReader, WireWriter};
use spatter_core::Vec3;
use spatter_io::vtu::Vtu;
use std::io;
use std::path::Path;

/// Columns of `energy.csv` (units in the names).
pub const ENERGY_COLUMNS: &[&str] = &[
    "t_s",
    "step",
    "particles",
    "kinetic_J",
    "rotational_J",
    "elastic_J",
    "potential_J",
    "dissipated_J",
    "external_work_J",
    "wall_work_J",
    "total_J",
    "pair_contacts",
    "wall_contacts",
    "list_rebuilds",
    "removed",
];

/// One row of `energy.csv`.
pub fn energy_row<L: ContactLaw>(sim: &Simulation<L>, e: &EnergyReport) -> Vec<f64> {
    vec![
        e.time,
        sim.step_count() as f64,
        sim.particles.len() as f64,
        e.kinetic,
        e.rotational,
        e.elastic,
        e.potential,
        e.dissipated,
        e.external_work,
        e.wall_work,
        e.total(),
        e.pair_contacts as f64,
        e.wall_contacts as f64,
        sim.rebuild_count() as f64,
        sim.removed_count() as f64,
    ]
}

/// Writes the particles as a VTU point cloud with `id`, `material`, `radius_m`, `velocity_m_s`,
/// `angular_velocity_rad_s`, `force_N` and `frozen`. When the simulation has clump templates, also
/// `body_id` (the stable id of the member's rigid body, −1 for a free sphere), `template` (−1 for a free
/// sphere) and the body's orientation as the space directions of its first and third principal axes,
/// `body_axis_1` and `body_axis_3` (zero for a free sphere).
pub fn write_particles<L: ContactLaw>(sim: &Simulation<L>, path: &Path) -> io::Result<()> {
    particles_vtu(sim).write(path)
}

/// The particle output of [`write_particles`] before it is written (a run on ranks writes one piece per
/// rank and a `.pvtu` naming them).
pub fn particles_vtu<L: ContactLaw>(sim: &Simulation<L>) -> Vtu {
    let p = &sim.particles;
    let mut vtu = Vtu::point_cloud(&p.pos)
        .point_int("id", &p.id.iter().map(|&i| i as i64).collect::<Vec<_>>())
        .point_int("material", &p.material.iter().map(|&m| m as i64).collect::<Vec<_>>())
        .point_int("frozen", &p.inv_mass.iter().map(|&m| (m == 0.0) as i64).collect::<Vec<_>>())
        .point_scalar("radius_m", &p.radius)
        .point_vector("velocity_m_s", &p.vel)
        .point_vector("angular_velocity_rad_s", &p.omega)
        .point_vector("force_N", &p.force);
    if !sim.templates().is_empty() {
        let b = sim.bodies();
        let of = |i: usize| (p.body[i] != NO_BODY).then_some(p.body[i] as usize);
        let n = p.len();
        let id: Vec<i64> = (0..n).map(|i| of(i).map_or(-1, |k| b.id[k] as i64)).collect();
        let tpl: Vec<i64> = (0..n).map(|i| of(i).map_or(-1, |k| b.template[k] as i64)).collect();
        let axis =
            |e: Vec3| -> Vec<Vec3> { (0..n).map(|i| of(i).map_or(Vec3::ZERO, |k| b.quat[k] * e)).collect() };
        vtu = vtu
            .point_int("body_id", &id)
            .point_int("template", &tpl)
            .point_vector("body_axis_1", &axis(Vec3::X))
            .point_vector("body_axis_3", &axis(Vec3::Z));
    }
    vtu
}

/// Columns of `bodies.csv` (one row per rigid body per output).
pub const BODY_COLUMNS: &[&str] = &[
    "t_s", "id", "template", "x_m", "y_m", "z_m", "qw", "qx", "qy", "qz", "vx_m_s", "vy_m_s", "vz_m_s",
    "wx_rad_s", "wy_rad_s", "wz_rad_s",
];

/// [`body_rows`] of every rank, in id order (collective on a run split over ranks, where each rank holds
/// the bodies whose centre is in its box; the plain rows otherwise, whose body order is the id order).
pub fn body_rows_with<L: ContactLaw>(sim: &Simulation<L>, comm: &dyn Comm) -> Vec<Vec<f64>> {
    let rows = body_rows(sim);
    if sim.ranks() == 1 {
        return rows;
    }
    let mut w = WireWriter::with_capacity(8 * BODY_COLUMNS.len() * rows.len());
    for x in rows.iter().flatten() {
        w.f64(*x);
    }
    let mut all = Vec::new();
    for buf in comm.all_gather_bytes(&w.finish()) {
        let mut r = WireReader::new(&buf);
        while !r.is_done() {
            let row: Vec<f64> = (0..BODY_COLUMNS.len())
                .map(|_| r.f64().expect("body rows from another rank of this run"))
                .collect();
            all.push(row);
        }
    }
    // Column 1 is the id (an integer below 2³², exact in an f64).
    all.sort_by(|a, b| a[1].total_cmp(&b[1]));
    all
}

/// Rows of `bodies.csv` at the current time, in body order: id, template index, centre of mass,
/// orientation quaternion (principal frame → space), velocity, angular velocity.
pub fn body_rows<L: ContactLaw>(sim: &Simulation<L>) -> Vec<Vec<f64>> {
    let b = sim.bodies();
    (0..b.len())
        .map(|k| {
            let (x, q, v, w) = (b.pos[k], b.quat[k], b.vel[k], b.omega[k]);
            vec![
                sim.time(),
                b.id[k] as f64,
                b.template[k] as f64,
                x.x,
                x.y,
                x.z,
                q.w,
                q.x,
                q.y,
                q.z,
                v.x,
                v.y,
                v.z,
                w.x,
                w.y,
                w.z,
            ]
        })
        .collect()
}

/// Writes mesh wall `w` at its current position with the per-triangle impact records as cell data:
/// `normal_impulse_N_s`, `tangential_impulse_N_s`, `impacts`, `mean_impact_speed_m_s`,
/// `mean_impact_angle_deg` (to the wall plane), `eroded_mass_kg` and `eroded_depth_m` (eroded mass over
/// wall density × triangle area). Returns false for an analytic wall (nothing written).
pub fn write_mesh<L: ContactLaw>(sim: &Simulation<L>, w: usize, path: &Path) -> io::Result<bool> {
    let wall = &sim.walls[w];
    let WallShape::Mesh(m) = &wall.shape else {
        return Ok(false);
    };
    let k = WallKinematics::of(&wall.motion, sim.time());
    let verts: Vec<_> = m.mesh.vertices.iter().map(|v| k.pose.apply(*v)).collect();
    let r = &m.records;
    let per_impact = |sum: &[f64]| -> Vec<f64> {
        sum.iter().zip(&r.impacts).map(|(s, &n)| if n > 0 { s / n as f64 } else { 0.0 }).collect()
    };
    let rho = sim.materials()[wall.material as usize].density;
    let depth: Vec<f64> =
        r.eroded_mass.iter().enumerate().map(|(t, &dm)| dm / (rho * m.mesh.area(t))).collect();
    Vtu::triangles(&verts, &m.mesh.triangles)
        .cell_scalar("normal_impulse_N_s", &r.normal_impulse)
        .cell_scalar("tangential_impulse_N_s", &r.tangential_impulse)
        .cell_int("impacts", &r.impacts.iter().map(|&i| i as i64).collect::<Vec<_>>())
        .cell_scalar("mean_impact_speed_m_s", &per_impact(&r.impact_speed_sum))
        .cell_scalar("mean_impact_angle_deg", &per_impact(&r.impact_angle_sum))
        .cell_scalar("eroded_mass_kg", &r.eroded_mass)
        .cell_scalar("eroded_depth_m", &depth)
        .write(path)?;
    Ok(true)
}
