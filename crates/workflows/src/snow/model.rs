//! From the configuration to one impact: pair properties, the restitution of the run, the contact law
//! (chosen once per call from the configuration, then monomorphised), time step and check time.

use super::bed::Bed;
use super::bed_index::BedIndex;
use super::config::{ContactConfig, CorModulus, IntegrationConfig, NormalLawKind, TargetKind};
use super::impact::{
    run_impact, BedSphere, DriverSettings, Impact, ImpactResult, Sphere, Target, TracePoint,
};
use spatter_core::material::{effective_modulus, Material};
use spatter_dem::adhesion::{Jkr, JkrLaw};
use spatter_dem::contact::{
    Composed, ConstantTorque, ContactLaw, Hertz, Mindlin, NoRolling, PairProps, RestitutionDamping,
};
use spatter_dem::restitution_models::ImpactProps;

/// Calls `visit` with the contact law that `c` describes.
pub trait LawVisitor {
    type Output;
    fn visit<L: ContactLaw>(self, law: &L) -> Self::Output;
}

/// Instantiates the configured law (normal law × rolling on/off) and hands it to `v`.
pub fn with_law<V: LawVisitor>(c: &ContactConfig, v: V) -> V::Output {
    use spatter_dem::adhesion::{DmtLaw, SjkrLaw};
    let damping = RestitutionDamping {
        tensile_clamp: c.tensile_clamp,
        calibration: c.damping_calibration,
        tangential: c.tangential_damping,
    };
    let jkr = JkrLaw {
        break_criterion: c.break_criterion,
        damping: c.damping_stiffness,
        coulomb: c.coulomb_normal_force,
    };
    let dmt = DmtLaw { coulomb: c.coulomb_normal_force };
    let sjkr = SjkrLaw { coulomb: c.coulomb_normal_force };
    let rolling = c.rolling_friction > 0.0;
    match (c.normal_law, rolling) {
        (NormalLawKind::Jkr, false) => v.visit(&Composed::new(jkr, damping, Mindlin, NoRolling)),
        (NormalLawKind::Jkr, true) => v.visit(&Composed::new(jkr, damping, Mindlin, ConstantTorque)),
        (NormalLawKind::Dmt, false) => v.visit(&Composed::new(dmt, damping, Mindlin, NoRolling)),
        (NormalLawKind::Dmt, true) => v.visit(&Composed::new(dmt, damping, Mindlin, ConstantTorque)),
        (NormalLawKind::Sjkr, false) => v.visit(&Composed::new(sjkr, damping, Mindlin, NoRolling)),
        (NormalLawKind::Sjkr, true) => v.visit(&Composed::new(sjkr, damping, Mindlin, ConstantTorque)),
        (NormalLawKind::Hertz, false) => v.visit(&Composed::new(Hertz, damping, Mindlin, NoRolling)),
        (NormalLawKind::Hertz, true) => v.visit(&Composed::new(Hertz, damping, Mindlin, ConstantTorque)),
    }
}

/// Everything fixed for a family of impacts: materials, target, contact law and integration settings.
#[derive(Clone, Debug)]
pub struct ImpactModel {
    pub particle: Material,
    pub wall: Material,
    pub target: TargetKind,
    pub partner_diameter: Option<f64>,
    pub contact: ContactConfig,
    pub integration: IntegrationConfig,
}

/// Where the particle goes in one call of [`ImpactModel::simulate`].
#[derive(Clone, Copy, Debug)]
pub enum Surface<'a> {
    /// The configured target (wall, wall sphere or free particle).
    Configured,
    /// A bed of frozen wall-material spheres with its cell list.
    Bed { spheres: &'a [BedSphere], top: f64, sphere_radius: f64, index: &'a BedIndex },
}

impl<'a> Surface<'a> {
    /// The rough-wall bed `bed` with its cell list `index` (`BedIndex::new(&bed.spheres)`).
    pub fn bed(bed: &'a Bed, index: &'a BedIndex) -> Self {
        Surface::Bed { spheres: &bed.spheres, top: bed.top, sphere_radius: bed.sphere_radius, index }
    }
}

/// The numbers that set up one run, for logs and CSV files.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RunSetup {
    /// Coefficient of restitution given to the damping \[-\].
    pub restitution_input: f64,
    /// Time step \[s\].
    pub dt: f64,
    /// Check time \[s\].
    pub check_time: f64,
    /// Hertz contact time at the reference speed \[s\].
    pub hertz_time: f64,
    /// Effective modulus, radius and mass of the contact \[Pa, m, kg\].
    pub e_star: f64,
    pub r_star: f64,
    pub m_star: f64,
}

impl ImpactModel {
    /// Diameter \[m\] of the partner sphere of a `wall_sphere` or `particle` target for a particle of
    /// diameter `d` (1 µm and `d` by default); infinite for the flat wall.
    pub fn partner_diameter(&self, d: f64) -> f64 {
        match self.target {
            TargetKind::Wall => f64::INFINITY,
            TargetKind::WallSphere => self.partner_diameter.unwrap_or(1e-6),
            TargetKind::Particle => self.partner_diameter.unwrap_or(d),
        }
    }

    /// The pair (particle, partner) materials and partner radius/mass for diameter `d`.
    fn partner(&self, d: f64, surface: Surface<'_>) -> (Material, f64, Option<f64>) {
        match surface {
            Surface::Bed { sphere_radius, .. } => (self.wall.clone(), sphere_radius, None),
            Surface::Configured => match self.target {
                TargetKind::Wall => (self.wall.clone(), f64::INFINITY, None),
                TargetKind::WallSphere => (self.wall.clone(), 0.5 * self.partner_diameter(d), None),
                TargetKind::Particle => {
                    let dp = self.partner_diameter(d);
                    let mp = self.particle.density * std::f64::consts::PI / 6.0 * dp * dp * dp;
                    (self.particle.clone(), 0.5 * dp, Some(mp))
                }
            },
        }
    }

    /// Run parameters for diameter `d` \[m\] at normal speed `v_n` \[m/s\].
    pub fn setup(&self, d: f64, v_n: f64, surface: Surface<'_>) -> (PairProps, RunSetup) {
        let (partner_mat, rp, mp) = self.partner(d, surface);
        let sphere = Sphere::of_diameter(d, self.particle.density);
        let r = sphere.radius;
        let r_star = if rp.is_infinite() { r } else { r * rp / (r + rp) };
        let m_star = match mp {
            Some(mp) => sphere.mass * mp / (sphere.mass + mp),
            None => sphere.mass,
        };
        let e_star = effective_modulus(&self.particle, &partner_mat);
        let cor_e_star = match self.contact.restitution_modulus {
            CorModulus::Pair => e_star,
            CorModulus::Particle => effective_modulus(&self.particle, &self.particle),
        };
        let e = self.contact.restitution.restitution(
            v_n,
            &ImpactProps { e_star: cor_e_star, density: self.particle.density, r_star, m_star },
        );
        let mut props = PairProps::new(&self.particle, &partner_mat, self.contact.friction, e);
        props.work_of_adhesion = self.contact.work_of_adhesion_j_m2;
        props.rolling_friction = self.contact.rolling_friction;
        // Reference speed of the time step: the impact speed, but not below the elastic JKR sticking speed
        // (the time scale of the adhesive neck), so slow impacts are resolved as well as fast ones.
        let gamma = self.contact.work_of_adhesion_j_m2;
        let v_el = if gamma > 0.0 {
            Jkr::new(e_star, r_star, gamma).elastic_sticking_speed(m_star, self.contact.break_criterion)
        } else {
            0.0
        };
        let v_ref = v_n.max(v_el).max(1e-9);
        let hertz_time = spatter_core::timestep::hertz_time(m_star, r_star, e_star, v_ref);
        let dt = self.integration.dt_s.unwrap_or(hertz_time / self.integration.steps_per_contact);
        let check_time =
            self.integration.check_time_s.unwrap_or(self.integration.check_time_contacts * hertz_time);
        (props, RunSetup { restitution_input: e, dt, check_time, hertz_time, e_star, r_star, m_star })
    }

    /// One impact of a particle of diameter `d` \[m\] at normal speed `v_n` and tangential speed `v_t`
    /// \[m/s\], aimed at lateral point `aim` \[m\].
    pub fn simulate(
        &self,
        d: f64,
        v_n: f64,
        v_t: f64,
        aim: [f64; 2],
        surface: Surface<'_>,
    ) -> (ImpactResult, RunSetup) {
        self.simulate_traced(d, v_n, v_t, aim, surface, None)
    }

    /// [`ImpactModel::simulate`], recording every step into `trace` when given (the run then lasts to the
    /// check time).
    pub fn simulate_traced(
        &self,
        d: f64,
        v_n: f64,
        v_t: f64,
        aim: [f64; 2],
        surface: Surface<'_>,
        trace: Option<&mut Vec<TracePoint>>,
    ) -> (ImpactResult, RunSetup) {
        let (props, setup) = self.setup(d, v_n, surface);
        let (_, rp, mp) = self.partner(d, surface);
        let target = match surface {
            Surface::Bed { spheres, top, index, .. } => Target::Bed { spheres, top, index },
            Surface::Configured => match self.target {
                TargetKind::Wall => Target::Plane,
                _ => Target::Sphere { radius: rp, free_mass: mp },
            },
        };
        let settings = DriverSettings {
            dt: setup.dt,
            check_time: setup.check_time,
            criterion: self.integration.stick_criterion,
            static_slip_ratio: self.integration.static_slip_ratio,
            bound_margin: self.integration.bound_margin,
            predict_velocity: self.integration.predict_velocity,
        };
        let impact = Impact {
            particle: Sphere::of_diameter(d, self.particle.density),
            normal_speed: v_n,
            tangential_speed: v_t,
            aim,
        };
        struct Run<'a, 't> {
            trace: Option<&'t mut Vec<TracePoint>>,
            props: &'a PairProps,
            target: Target<'a>,
            impact: &'a Impact,
            settings: &'a DriverSettings,
            contact: &'a ContactConfig,
        }
        impl LawVisitor for Run<'_, '_> {
            type Output = ImpactResult;
            fn visit<L: ContactLaw>(self, law: &L) -> ImpactResult {
                let params = law.params(0, self.props);
                let (gamma, e_star, crit, kind) = (
                    self.contact.work_of_adhesion_j_m2,
                    self.props.e_star,
                    self.contact.break_criterion,
                    self.contact.normal_law,
                );
                let break_energy = move |r_eff: f64| -> f64 {
                    if kind == NormalLawKind::Jkr && gamma > 0.0 {
                        Jkr::new(e_star, r_eff, gamma).neck_work(crit)
                    } else {
                        0.0
                    }
                };
                run_impact(law, &params, &break_energy, self.target, self.impact, self.settings, self.trace)
            }
        }
        let result = with_law(
            &self.contact,
            Run {
                trace,
                props: &props,
                target,
                impact: &impact,
                settings: &settings,
                contact: &self.contact,
            },
        );
        (result, setup)
    }
}
