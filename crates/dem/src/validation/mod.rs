//! Verification cases of `spatter validate`: Chung & Ooi (2011) tests 1–8 (tests 2, 3, 4 and 6 also
//! against an STL plane with the impact on a face, a shared edge and a shared vertex), energy
//! conservation of an elastic gas, a settled pile, rigid multi-sphere bodies (template inertia,
//! torque-free rotation, one-sphere clump, dumbbell impacts), erosion wear (Finnie's f(γ), single
//! impacts) and the integrator study (Jasion 2013, Appendices A and B).

pub mod bulk;
pub mod chung_ooi;
pub mod clumps;
pub mod impact;
pub mod integrator_study;
pub mod wear;

use spatter_core::validation::Case;

/// Every DEM validation case; `run(true)` is the quick variant that CI runs.
pub fn validation_cases() -> Vec<Case> {
    vec![
        Case { name: "chung_ooi_1_two_spheres_elastic", run: chung_ooi::test1 },
        Case { name: "chung_ooi_2_sphere_plane_elastic", run: chung_ooi::test2 },
        Case { name: "chung_ooi_3_restitution", run: chung_ooi::test3 },
        Case { name: "chung_ooi_4_oblique_impact", run: chung_ooi::test4 },
        Case { name: "chung_ooi_5_small_sphere_sliding", run: chung_ooi::test5 },
        Case { name: "chung_ooi_6_spinning_sphere_on_plane", run: chung_ooi::test6 },
        Case { name: "chung_ooi_7_opposite_spins", run: chung_ooi::test7 },
        Case { name: "chung_ooi_8_small_on_large_sphere", run: chung_ooi::test8 },
        Case { name: "dem_elastic_box_energy", run: bulk::elastic_box },
        Case { name: "dem_settled_pile", run: bulk::settled_pile },
        Case { name: "clump_template_inertia", run: clumps::template_inertia },
        Case { name: "clump_torque_free_invariants", run: clumps::torque_free_body },
        Case { name: "clump_intermediate_axis_flip", run: clumps::intermediate_axis },
        Case { name: "clump_one_sphere_equals_free_sphere", run: clumps::one_sphere_clump },
        Case { name: "clump_dumbbell_flat", run: clumps::dumbbell_flat },
        Case { name: "clump_dumbbell_on_end", run: clumps::dumbbell_on_end },
        Case { name: "wear_finnie_angle_function", run: wear::finnie_table },
        Case { name: "wear_single_impact", run: wear::single_oblique_impact },
        Case { name: "integrator_normal_impact", run: integrator_study::normal_impact },
        Case { name: "integrator_smooth_orders", run: integrator_study::smooth_orders },
        Case { name: "integrator_discontinuity_orders", run: integrator_study::discontinuity_orders },
    ]
}

#[cfg(test)]
mod tests {
    use super::*;

    fn print_and_count(case: &Case, quick: bool) -> usize {
        let checks = (case.run)(quick);
        assert!(!checks.is_empty(), "{} produced no checks", case.name);
        let mut failed = 0;
        for c in &checks {
            let flag = if c.passed() { "ok  " } else { "FAIL" };
            println!(
                "{flag} {:40} {:42} ref {:>12.5e} ours {:>12.5e} err {:.2e}",
                c.case,
                c.quantity,
                c.reference,
                c.ours,
                c.error()
            );
            if !c.passed() {
                failed += 1;
            }
        }
        failed
    }

    #[test]
    fn quick_validation_cases_pass() {
        let mut failed = 0;
        for case in validation_cases() {
            failed += print_and_count(&case, true);
        }
        assert_eq!(failed, 0, "{failed} validation checks failed (run with --nocapture)");
    }

    /// The full set, as `spatter validate` runs it.
    #[test]
    #[ignore]
    fn full_validation_cases_pass() {
        let mut failed = 0;
        for case in validation_cases() {
            failed += print_and_count(&case, false);
        }
        assert_eq!(failed, 0, "{failed} validation checks failed");
    }
}
