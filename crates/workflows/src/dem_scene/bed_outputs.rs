//! The bed outputs of a finished scene: the pour's summary and pictures, `bed.txt`, and the packing
//! density of the `[[output.packing]]` boxes (`packing.csv`). Keys in `docs/bed.md`.

use super::config::SceneConfig;
use super::pour::{kinetic_and_scale, profile_box, PourState};
use spatter_core::{Aabb, Vec3};
use spatter_dem::contact::ContactLaw;
use spatter_dem::error::DemError;
use spatter_dem::packing::packing_fraction;
use spatter_dem::sim::Simulation;
use spatter_io::run::{RunContext, RunSummary};

/// Adds the pour's results, `bed.txt` and the packing densities to `s`.
pub(crate) fn finish<L: ContactLaw>(
    cfg: &SceneConfig,
    sim: &Simulation<L>,
    pour: Option<&PourState>,
    ctx: &RunContext,
    s: &mut RunSummary,
) -> Result<(), DemError> {
    let io = |p: &std::path::Path| {
        let p = p.to_owned();
        move |source| DemError::Io { path: p, source }
    };
    // On several ranks every rank's particles (collective), and only rank 0 writes the files.
    let gathered;
    let p = if sim.ranks() > 1 {
        gathered = sim.gathered_particles(ctx.comm);
        &gathered
    } else {
        &sim.particles
    };
    if !ctx.comm.is_root() {
        return Ok(());
    }
    if let (Some(pc), Some(state)) = (&cfg.pour, pour) {
        s.scalar("poured", state.poured as f64);
        let (ke, scale) = kinetic_and_scale(p, sim.gravity.length());
        let ratio = if scale > 0.0 { ke / scale } else { 0.0 };
        s.scalar("kinetic_energy_ratio", ratio);
        if state.postponed > 0 {
            s.headline.push(format!(
                "pour: {} additions waited for the next interval (no place clear of the falling spheres)",
                state.postponed
            ));
        }
        match state.settled_s {
            Some(t) => {
                s.scalar("settled_s", t);
                s.headline.push(format!(
                    "pour: {} spheres poured, settled at t = {t:.4} s (kinetic energy {ratio:.2e} × Σ m g d, \
                     threshold {:.1e})",
                    state.poured, pc.settled_energy_ratio
                ));
            }
            None => s.headline.push(format!(
                "warning: pour: {} of {} spheres poured; not settled by t = {:.4} s (kinetic energy {ratio:.2e} \
                 × Σ m g d, threshold {:.1e}) — lengthen duration_s",
                state.poured,
                pc.count,
                sim.time(),
                pc.settled_energy_ratio
            )),
        }
        if let Some(b) = profile_box(pc) {
            let top = (0..p.len()).map(|i| p.pos[i].z + p.radius[i]).fold(b.min.z, f64::max).min(b.max.z);
            let d_mean = 2.0 * p.radius.iter().sum::<f64>() / p.len().max(1) as f64;
            if top > b.min.z && d_mean > 0.0 {
                let slabs = (((top - b.min.z) / d_mean).floor() as usize).clamp(1, 400);
                let h = (top - b.min.z) / slabs as f64;
                let profile: Vec<(f64, f64)> = (0..slabs)
                    .map(|k| {
                        let z0 = b.min.z + k as f64 * h;
                        let slab =
                            Aabb::new(Vec3::new(b.min.x, b.min.y, z0), Vec3::new(b.max.x, b.max.y, z0 + h));
                        (packing_fraction(&p.pos, &p.radius, &slab), (z0 + 0.5 * h - b.min.z) / d_mean)
                    })
                    .collect();
                let png = ctx.dir.path("packing_profile.png");
                spatter_io::plot::Chart::new(
                    "Packing density of the poured bed, slabs one mean diameter thick",
                    "solid volume fraction",
                    "height above the region's bottom [mean diameters]",
                )
                .x_range(0.0, 0.8)
                .line("bed", &profile)
                .dashed(
                    "random close packing 0.64",
                    &[(0.64, 0.0), (0.64, profile.len() as f64)],
                    (120, 120, 120),
                )
                .save_png(&png)
                .map_err(io(&png))?;
                s.artifacts.push(("packing density against height".into(), png));
            }
            // Side view: the sphere centres in x–z.
            let pts: Vec<(f64, f64)> = p.pos.iter().map(|x| (x.x, x.z)).collect();
            let png = ctx.dir.path("bed_side.png");
            spatter_io::plot::Chart::new(
                &format!("Poured bed seen from the side: {} sphere centres", p.len()),
                "x [m]",
                "z [m]",
            )
            .markers("sphere centres", &pts, (0, 114, 178))
            .save_png(&png)
            .map_err(io(&png))?;
            s.artifacts.push(("bed seen from the side".into(), png));
        }
    }
    if cfg.output.writes_bed(cfg.pour.is_some()) {
        let names = cfg.material_names();
        let spheres = crate::bed_lab::bed_file::from_particles(p, &names);
        let path = ctx.dir.path("bed.txt");
        crate::bed_lab::bed_file::write(&path, &spheres).map_err(io(&path))?;
        s.headline.push(format!(
            "bed file: {} spheres in bed.txt (start another run from it with [bed] file)",
            spheres.len()
        ));
        s.artifacts.push(("bed file".into(), path));
    }
    if !cfg.output.packing.is_empty() {
        let path = ctx.dir.path("packing.csv");
        let mut text = String::from("name,x_min_m,y_min_m,z_min_m,x_max_m,y_max_m,z_max_m,solid_fraction\n");
        for r in &cfg.output.packing {
            let b = Aabb::new(r.min_m, r.max_m);
            let phi = packing_fraction(&p.pos, &p.radius, &b);
            s.scalar(&format!("packing_{}", r.name), phi);
            s.headline.push(format!("packing density of `{}`: {phi:.4}", r.name));
            text.push_str(&format!(
                "{},{},{},{},{},{},{},{}\n",
                r.name, r.min_m.x, r.min_m.y, r.min_m.z, r.max_m.x, r.max_m.y, r.max_m.z, phi
            ));
        }
        std::fs::write(&path, text).map_err(io(&path))?;
        s.artifacts.push(("packing densities".into(), path));
    }
    Ok(())
}
