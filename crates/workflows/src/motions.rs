//! One description of prescribed motion for every scene kind: a `[[motions]]` tree whose nodes move
//! relative to their parents (a wheel spinning on a moving chassis), and walls or bodies that name the node
//! they follow. The `sph`, `wading` and `dem` kinds read it; see `docs/scenario.md` ("Motions").

use serde::{Deserialize, Serialize};
use spatter_core::check::Checker;
use spatter_core::motion::{KinematicTree, Motion, MotionTable};
use spatter_core::Vec3;
use std::path::PathBuf;

/// `type` of a `[[motions]]` node.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum MotionType {
    Fixed,
    Translation,
    Rotation,
    Table,
}

/// One node of the kinematic tree; it moves relative to its parent.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MotionConfig {
    pub name: String,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub parent: Option<String>,
    #[serde(rename = "type")]
    pub kind: MotionType,
    /// Translation.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub velocity_m_s: Option<Vec3>,
    /// Rotation: axis point, axis direction and speed (right-hand rule).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub center_m: Option<Vec3>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub axis: Option<Vec3>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub angular_speed_rad_s: Option<f64>,
    /// Table: `t vx vy vz wx wy wz` rows, ω about `reference_point_m` (which moves with the body).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub file: Option<PathBuf>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub reference_point_m: Option<Vec3>,
}

/// Checks every node of a `[[motions]]` list: unique names, parents listed earlier, the keys of each type.
pub fn check_tree(c: &mut Checker, motions: &[MotionConfig]) {
    let motion_names: Vec<&str> = motions.iter().map(|m| m.name.as_str()).collect();
    for (i, m) in motions.iter().enumerate() {
        c.element("motions", i, |c| {
            if let Some(p) = &m.parent {
                match motion_names.iter().position(|n| n == p) {
                    Some(k) if k < i => {}
                    Some(_) => {
                        c.fail("parent", format!("parent \"{p}\" must be listed before \"{}\"", m.name))
                    }
                    None => c.fail(
                        "parent",
                        format!("parent \"{p}\" is not a motion name ({})", motion_names.join(", ")),
                    ),
                }
            }
            if motion_names.iter().filter(|n| **n == m.name).count() > 1 {
                c.fail("name", format!("name \"{}\" is used by more than one motion", m.name));
            }
            match m.kind {
                MotionType::Fixed => {}
                MotionType::Translation => match m.velocity_m_s {
                    Some(v) => c.finite_vec("velocity_m_s", v),
                    None => c.fail("velocity_m_s", "a translation needs `velocity_m_s = [vx, vy, vz]`"),
                },
                MotionType::Rotation => {
                    match m.center_m {
                        Some(v) => c.finite_vec("center_m", v),
                        None => c.fail("center_m", "a rotation needs `center_m = [x, y, z]`"),
                    }
                    match m.axis {
                        Some(a) if a.length() > 0.0 && spatter_core::math::is_finite(a) => {}
                        _ => c.fail("axis", "a rotation needs a non-zero `axis = [x, y, z]`"),
                    }
                    match m.angular_speed_rad_s {
                        Some(w) => c.finite("angular_speed_rad_s", w),
                        None => c.fail("angular_speed_rad_s", "a rotation needs `angular_speed_rad_s`"),
                    }
                }
                MotionType::Table => {
                    match &m.file {
                        Some(f) => c.motion_table_file("file", f),
                        None => c.fail("file", "a table motion needs `file` (rows `t vx vy vz wx wy wz`)"),
                    }
                    if let Some(p) = m.reference_point_m {
                        c.finite_vec("reference_point_m", p);
                    }
                }
            }
        });
    }
}

/// Checks that `name` (the value of `key`, if given) is a node of `motions`.
pub fn check_reference(c: &mut Checker, key: &str, name: Option<&str>, motions: &[MotionConfig]) {
    if let Some(m) = name {
        if !motions.iter().any(|n| n.name == m) {
            c.fail(key, format!("motion \"{m}\" is not defined in [[motions]]"));
        }
    }
}

/// The node's own motion relative to its parent (a table file is read here). The error names the key
/// inside the node and the file.
pub fn own_motion(m: &MotionConfig) -> Result<Motion, String> {
    Ok(match m.kind {
        MotionType::Fixed => Motion::Fixed,
        MotionType::Translation => Motion::Translation { velocity: m.velocity_m_s.unwrap_or(Vec3::ZERO) },
        MotionType::Rotation => Motion::rotation(
            m.center_m.unwrap_or(Vec3::ZERO),
            m.axis.unwrap_or(Vec3::Z),
            m.angular_speed_rad_s.unwrap_or(0.0),
        ),
        MotionType::Table => {
            let path = m.file.as_deref().ok_or("file is missing")?;
            let at = |e: &dyn std::fmt::Display| format!("file = \"{}\": {e}", path.display());
            let text = std::fs::read_to_string(path).map_err(|e| at(&e))?;
            let table =
                MotionTable::parse(&text, m.reference_point_m.unwrap_or(Vec3::ZERO)).map_err(|e| at(&e))?;
            Motion::Tabulated(table)
        }
    })
}

/// The index of each node's parent in `motions` (checked by [`check_tree`]: parents come first).
pub fn parent_index(motions: &[MotionConfig], i: usize) -> Option<usize> {
    motions[i].parent.as_deref().and_then(|p| motions[..i].iter().position(|n| n.name == p))
}

/// The whole tree, for an engine that moves each wall by one motion: node `i` of the result is
/// `motions[i]`. Errors are `(node index, message)`.
pub fn tree(motions: &[MotionConfig]) -> Result<KinematicTree, (usize, String)> {
    let mut tree = KinematicTree::new();
    for (i, m) in motions.iter().enumerate() {
        tree.add(own_motion(m).map_err(|e| (i, e))?, parent_index(motions, i));
    }
    Ok(tree)
}
