//! Bed files: a settled particle bed saved as text and read back as the start of another run.
//!
//! The format (documented for users in `docs/bed.md`):
//!
//! ```text
//! # spatter bed file, format 1
//! # units: m, m/s, rad/s (SI); one sphere per line
//! # particles: 2
//! # columns: id radius_m material x_m y_m z_m vx_m_s vy_m_s vz_m_s wx_rad_s wy_rad_s wz_rad_s
//! 0 0.002 glass 0.01 0.02 0.002 0 0 0 0 0 0
//! 1 0.002 glass 0.014 0.02 0.002 0 0 0 0 0 0
//! ```
//!
//! The first line is required as written; other lines starting with `#` and blank lines are ignored.
//! Numbers are written in the shortest form that reads back to the same `f64` (Rust's `Display`), so a
//! bed written, read and written again is the same file byte for byte, and the particles read are the
//! particles written bit for bit.

use spatter_core::Vec3;
use spatter_dem::particles::Particles;
use std::fmt::Write as _;
use std::path::Path;

/// The first line of every bed file.
pub const MAGIC: &str = "# spatter bed file, format 1";

/// The column names, in order.
pub const COLUMNS: [&str; 12] = [
    "id", "radius_m", "material", "x_m", "y_m", "z_m", "vx_m_s", "vy_m_s", "vz_m_s", "wx_rad_s", "wy_rad_s",
    "wz_rad_s",
];

/// One sphere of a bed.
#[derive(Clone, Debug, PartialEq)]
pub struct BedSphere {
    /// Identifier in the file (unique; the spheres are numbered 0, 1, … in the order of their ids in
    /// the run that wrote them).
    pub id: u64,
    /// Radius \[m\].
    pub radius: f64,
    /// Material name (a key of the scene's `[materials]`).
    pub material: String,
    /// Centre \[m\].
    pub pos: Vec3,
    /// Velocity \[m/s\].
    pub vel: Vec3,
    /// Angular velocity \[rad/s\].
    pub omega: Vec3,
}

/// The free spheres of `p` (frozen spheres and clump members left out) in the order of their ids,
/// numbered from 0; `materials` are the names of the material indices.
pub fn from_particles(p: &Particles, materials: &[&str]) -> Vec<BedSphere> {
    let free =
        |i: usize| p.inv_mass[i] > 0.0 && p.body.get(i).is_none_or(|&b| b == spatter_dem::clump::NO_BODY);
    let mut order: Vec<usize> = (0..p.len()).filter(|&i| free(i)).collect();
    order.sort_by_key(|&i| p.id[i]);
    order
        .iter()
        .enumerate()
        .map(|(k, &i)| BedSphere {
            id: k as u64,
            radius: p.radius[i],
            material: materials.get(p.material[i] as usize).copied().unwrap_or("?").to_string(),
            pos: p.pos[i],
            vel: p.vel[i],
            omega: p.omega[i],
        })
        .collect()
}

/// The text of a bed file holding `spheres`.
pub fn format(spheres: &[BedSphere]) -> String {
    let mut s = String::with_capacity(64 + 160 * spheres.len());
    s.push_str(MAGIC);
    s.push('\n');
    s.push_str("# units: m, m/s, rad/s (SI); one sphere per line\n");
    let _ = writeln!(s, "# particles: {}", spheres.len());
    let _ = writeln!(s, "# columns: {}", COLUMNS.join(" "));
    for b in spheres {
        let _ = write!(s, "{} {} {}", b.id, b.radius, b.material);
        for v in [b.pos, b.vel, b.omega] {
            let _ = write!(s, " {} {} {}", v.x, v.y, v.z);
        }
        s.push('\n');
    }
    s
}

/// Writes a bed file.
pub fn write(path: &Path, spheres: &[BedSphere]) -> std::io::Result<()> {
    if let Some(dir) = path.parent() {
        std::fs::create_dir_all(dir)?;
    }
    std::fs::write(path, format(spheres))
}

/// Parses the text of a bed file; every material must be one of `materials`. The error names the line
/// (1-based), the field and the value.
pub fn parse(text: &str, materials: &[&str]) -> Result<Vec<BedSphere>, String> {
    let mut lines = text.lines().enumerate();
    match lines.next() {
        Some((_, l)) if l.trim_end() == MAGIC => {}
        Some((_, l)) => {
            return Err(format!("line 1: expected the header \"{MAGIC}\", found \"{}\"", clip(l)));
        }
        None => return Err(format!("the file is empty; a bed file starts with \"{MAGIC}\"")),
    }
    let mut out = Vec::new();
    let mut ids = std::collections::HashSet::new();
    for (n, line) in lines {
        let line_no = n + 1;
        let t = line.trim();
        if t.is_empty() || t.starts_with('#') {
            continue;
        }
        let fields: Vec<&str> = t.split_whitespace().collect();
        if fields.len() != COLUMNS.len() {
            return Err(format!(
                "line {line_no}: {} fields, expected {} ({})",
                fields.len(),
                COLUMNS.len(),
                COLUMNS.join(" ")
            ));
        }
        let id: u64 = fields[0].parse().map_err(|_| {
            format!("line {line_no}: field `id` = \"{}\" is not a non-negative integer", clip(fields[0]))
        })?;
        if !ids.insert(id) {
            return Err(format!("line {line_no}: field `id` = {id} appears on an earlier line"));
        }
        let num = |k: usize| -> Result<f64, String> {
            let v: f64 = fields[k].parse().map_err(|_| {
                format!("line {line_no}: field `{}` = \"{}\" is not a number", COLUMNS[k], clip(fields[k]))
            })?;
            if !v.is_finite() {
                return Err(format!("line {line_no}: field `{}` = {v} is not finite", COLUMNS[k]));
            }
            Ok(v)
        };
        let radius = num(1)?;
        if radius <= 0.0 {
            return Err(format!("line {line_no}: field `radius_m` = {radius} must be positive"));
        }
        let material = fields[2];
        if !materials.contains(&material) {
            return Err(format!(
                "line {line_no}: field `material` = \"{}\" is not in [materials] (defined: {})",
                clip(material),
                materials.join(", ")
            ));
        }
        let v3 = |k: usize| -> Result<Vec3, String> { Ok(Vec3::new(num(k)?, num(k + 1)?, num(k + 2)?)) };
        out.push(BedSphere {
            id,
            radius,
            material: material.to_string(),
            pos: v3(3)?,
            vel: v3(6)?,
            omega: v3(9)?,
        });
    }
    Ok(out)
}

/// Reads and parses a bed file; the error names the file.
pub fn read(path: &Path, materials: &[&str]) -> Result<Vec<BedSphere>, String> {
    if path.is_dir() {
        return Err(format!("{} is a folder, not a bed file", path.display()));
    }
    let text = std::fs::read_to_string(path).map_err(|e| format!("{}: {e}", path.display()))?;
    parse(&text, materials).map_err(|e| format!("{}: {e}", path.display()))
}

/// At most 40 characters of a user's text for a message.
fn clip(s: &str) -> String {
    match s.char_indices().nth(40) {
        Some((i, _)) => format!("{}…", &s[..i]),
        None => s.to_string(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use spatter_dem::particles::NewParticle;

    fn sample() -> Particles {
        let mut p = Particles::new();
        for k in 0..5 {
            let x = 0.1 * k as f64 + 1.0 / 3.0;
            let mut np = NewParticle::at(Vec3::new(x, -x / 7.0, 1e-300 * x), 0.001 + 1e-17 * k as f64, k % 2);
            np.vel = Vec3::new(-0.0, std::f64::consts::PI, -1e-7 * x);
            np.omega = Vec3::new(1e20, -2.5, x.sqrt());
            p.push(np, 2500.0);
        }
        p
    }

    #[test]
    fn round_trip_is_bit_for_bit() {
        let names = ["glass", "sand"];
        let beds = from_particles(&sample(), &names);
        let text = format(&beds);
        let read = parse(&text, &names).unwrap();
        assert_eq!(read.len(), beds.len());
        for (a, b) in beds.iter().zip(&read) {
            assert_eq!(a.id, b.id);
            assert_eq!(a.material, b.material);
            assert_eq!(a.radius.to_bits(), b.radius.to_bits());
            for (u, v) in [(a.pos, b.pos), (a.vel, b.vel), (a.omega, b.omega)] {
                for k in 0..3 {
                    assert_eq!(u[k].to_bits(), v[k].to_bits(), "sphere {}: {u} vs {v}", a.id);
                }
            }
        }
        assert_eq!(format(&read), text, "written again, the same bytes");
    }

    #[test]
    fn bad_files_name_line_and_field() {
        let names = ["glass"];
        let head = format!("{MAGIC}\n# comment\n");
        let good = "0 0.001 glass 0 0 0 0 0 0 0 0 0";
        for (body, want) in [
            ("0 0.001 gold 0 0 0 0 0 0 0 0 0", "line 3: field `material` = \"gold\" is not in [materials]"),
            ("0 0.001 glass 0 0 0 0 0", "line 3: 8 fields, expected 12"),
            ("0 -1 glass 0 0 0 0 0 0 0 0 0", "line 3: field `radius_m` = -1 must be positive"),
            ("0 0.001 glass 0 zero 0 0 0 0 0 0 0", "line 3: field `y_m` = \"zero\" is not a number"),
            ("0 0.001 glass 0 0 0 0 0 0 0 0 NaN", "line 3: field `wz_rad_s` = NaN is not finite"),
            ("x 0.001 glass 0 0 0 0 0 0 0 0 0", "line 3: field `id` = \"x\" is not a non-negative integer"),
            (good, "line 4: field `id` = 0 appears on an earlier line"),
        ] {
            let text =
                if body == good { format!("{head}{good}\n{good}\n") } else { format!("{head}{body}\n") };
            let e = parse(&text, &names).unwrap_err();
            assert!(e.contains(want), "{e} (wanted {want})");
        }
        assert!(parse("", &names).unwrap_err().contains("empty"));
        assert!(parse("1 2 3\n", &names).unwrap_err().contains("line 1: expected the header"));
        let e = read(Path::new("/nonexistent/bed.txt"), &names).unwrap_err();
        assert!(e.contains("/nonexistent/bed.txt"), "{e}");
    }
}
