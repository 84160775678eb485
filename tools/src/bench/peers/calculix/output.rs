//! What ccx wrote, read back: totals of `*NODE PRINT` in the .dat file, and from its log
//! (standard output) the first error, the Newton iterations and its own run time.

use crate::api::Vec3;
use crate::runner::log::number_after;

/// The last "total force (fx,fy,fz) for set NAME" of a .dat file.
pub fn total_force(dat: &str, set: &str) -> Option<Vec3> {
    let key = format!("total force (fx,fy,fz) for set {set} ");
    let lines: Vec<&str> = dat.lines().collect();
    let i = lines.iter().rposition(|l| l.contains(&key))?;
    let v: Vec<f64> = lines[i + 1..]
        .iter()
        .find(|l| !l.trim().is_empty())?
        .split_whitespace()
        .filter_map(|x| x.parse().ok())
        .collect();
    (v.len() == 3).then(|| [v[0], v[1], v[2]])
}

/// Every "total force (fx,fy,fz) for set NAME and time T" of a .dat file, in order:
/// (T, force).
pub fn total_forces(dat: &str, set: &str) -> Vec<(f64, Vec3)> {
    let key = format!("total force (fx,fy,fz) for set {set} and time");
    let lines: Vec<&str> = dat.lines().collect();
    let mut out = Vec::new();
    for (i, l) in lines.iter().enumerate() {
        let Some(t) = l
            .split(&key)
            .nth(1)
            .and_then(|t| t.trim().parse::<f64>().ok())
        else {
            continue;
        };
        let v: Vec<f64> = lines[i + 1..]
            .iter()
            .find(|l| !l.trim().is_empty())
            .map(|l| {
                l.split_whitespace()
                    .filter_map(|x| x.parse().ok())
                    .collect()
            })
            .unwrap_or_default();
        if v.len() == 3 {
            out.push((t, [v[0], v[1], v[2]]));
        }
    }
    out
}

/// Largest |u| over every "displacements (vx,vy,vz) for set NAME and time T" block of a
/// .dat file (`*NODE PRINT` of U node by node): over the set's nodes and every increment.
pub fn max_displacement(dat: &str, set: &str) -> Option<f64> {
    let key = format!("displacements (vx,vy,vz) for set {set} and time");
    let mut max: Option<f64> = None;
    let mut lines = dat.lines();
    while let Some(l) = lines.next() {
        if !l.contains(&key) {
            continue;
        }
        // The node lines follow a blank line and end at the next blank line.
        for row in lines
            .by_ref()
            .skip_while(|r| r.trim().is_empty())
            .take_while(|r| !r.trim().is_empty())
        {
            let v: Vec<f64> = row
                .split_whitespace()
                .filter_map(|x| x.parse().ok())
                .collect();
            if let [_, x, y, z] = v[..] {
                let norm = (x * x + y * y + z * z).sqrt();
                max = Some(max.map_or(norm, |m: f64| m.max(norm)));
            }
        }
    }
    max
}

/// The last "displacements (vx,vy,vz) for set NAME and time T" block of a .dat file:
/// T and every node's (1-based id, u).
pub fn last_displacements(dat: &str, set: &str) -> Option<(f64, Vec<(usize, Vec3)>)> {
    let (t, rows) = last_rows(dat, &format!("displacements (vx,vy,vz) for set {set}"))?;
    let mut out = Vec::new();
    for v in rows {
        let [n, x, y, z] = v[..] else { return None };
        out.push((
            n.parse().ok()?,
            [x.parse().ok()?, y.parse().ok()?, z.parse().ok()?],
        ));
    }
    Some((t, out))
}

/// The last "contact stress (slave node,press,tang1,tang2) for all contact elements and
/// time T" block of a .dat file (`*CONTACT PRINT` of CSTR, node-to-surface pairs): T and
/// every listed slave node's (1-based id, contact pressure). ccx lists the nodes of its
/// contact elements.
pub fn last_contact_pressures(dat: &str) -> Option<(f64, Vec<(usize, f64)>)> {
    let (t, rows) = last_rows(dat, &contact_head("slave node"))?;
    let mut out = Vec::new();
    for v in rows {
        let [n, p, _, _] = v[..] else { return None };
        out.push((n.parse().ok()?, p.parse().ok()?));
    }
    Some((t, out))
}

/// The same block of surface-to-surface pairs ("slave element+face"): T and the contact
/// pressure at every integration point of the slave faces (ccx prints no positions).
pub fn last_face_contact_pressures(dat: &str) -> Option<(f64, Vec<f64>)> {
    let (t, rows) = last_rows(dat, &contact_head("slave element+face"))?;
    let mut out = Vec::new();
    for v in rows {
        let [_, _, p, _, _] = v[..] else { return None };
        out.push(p.parse().ok()?);
    }
    Some((t, out))
}

/// The heading of a contact stress block up to its time, whose slave is `what`.
fn contact_head(what: &str) -> String {
    format!("contact stress ({what},press,tang1,tang2) for all contact elements")
}

/// The time and the rows (split at white space) of the last block of a .dat file whose
/// heading is `head` followed by "and time T".
fn last_rows<'a>(dat: &'a str, head: &str) -> Option<(f64, Vec<Vec<&'a str>>)> {
    let key = format!("{head} and time");
    let lines: Vec<&str> = dat.lines().collect();
    let i = lines.iter().rposition(|l| l.contains(&key))?;
    let t: f64 = lines[i].split(&key).nth(1)?.trim().parse().ok()?;
    let rows = lines[i + 1..]
        .iter()
        .skip_while(|r| r.trim().is_empty())
        .take_while(|r| !r.trim().is_empty())
        .map(|r| r.split_whitespace().collect())
        .collect();
    Some((t, rows))
}

/// The first `*ERROR` line of the log: ccx exits with 0 after an input error too, so a
/// run is judged by its output.
pub fn error_line(log: &str) -> Option<&str> {
    log.lines().find(|l| l.contains("*ERROR")).map(str::trim)
}

/// Newton iterations over the whole run (contact iterations included).
pub fn newton_iterations(log: &str) -> usize {
    log.lines()
        .filter(|l| l.trim_start().starts_with("iteration "))
        .count()
}

/// ccx's own "Total CalculiX Time", seconds.
pub fn total_time(log: &str) -> Option<f64> {
    number_after(log, "Total CalculiX Time: ")
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The .dat file of the block on block at n = 10 as CalculiX 2.20 wrote it.
    const DAT: &str = "
 total force (fx,fy,fz) for set N_LOWER_BOTTOM and time  0.1000000E+01

       -1.356814E-05  4.374205E+00  1.356814E-05

 total force (fx,fy,fz) for set N_UPPER_TOP and time  0.1000000E+01

        1.356814E-05 -4.374205E+00 -1.356814E-05
";

    /// The same run's log, shortened (the lines of each iteration kept but one).
    const LOG: &str = "
CalculiX Version 2.20, Copyright(C) 1998-2022 Guido Dhondt

 increment 1 attempt 1 
 increment size= 1.000000e+00

 iteration 1

 Number of contact spring elements=121
 largest correction to disp= 8.657184e-03 in node 2481 and dof 2

 no convergence

 iteration 2

 no convergence

 iteration 3

 convergence

   plastic data points per material:            0

 Job finished

________________________________________

Total CalculiX Time: 0.626372
________________________________________
";

    #[test]
    fn totals_are_read() {
        let top = total_force(DAT, "N_UPPER_TOP").unwrap();
        assert_eq!(top, [1.356814e-5, -4.374205, -1.356814e-5]);
        let bottom = total_force(DAT, "N_LOWER_BOTTOM").unwrap();
        assert_eq!(bottom, [-1.356814e-5, 4.374205, 1.356814e-5]);
        // A set's name is matched whole, not as a prefix.
        assert!(total_force(DAT, "N_UPPER").is_none());
        assert!(total_force("", "N_UPPER_TOP").is_none());
    }

    /// Of several increments' totals the last counts.
    #[test]
    fn the_last_total_counts() {
        let two = format!(
            "{}\n total force (fx,fy,fz) for set N_UPPER_TOP and time  0.2E+01\n\n 1.0 2.0 3.0\n",
            DAT
        );
        assert_eq!(total_force(&two, "N_UPPER_TOP"), Some([1.0, 2.0, 3.0]));
    }

    #[test]
    fn log_is_read() {
        assert_eq!(newton_iterations(LOG), 3);
        assert_eq!(total_time(LOG), Some(0.626372));
        assert_eq!(error_line(LOG), None);
        let bad = " *ERROR reading *BOUNDARY: node set N_X has not yet been defined.\n";
        assert_eq!(
            error_line(&format!("{LOG}{bad}")),
            Some("*ERROR reading *BOUNDARY: node set N_X has not yet been defined.")
        );
        assert_eq!(total_time("Job finished"), None);
    }

    /// Node-by-node displacements of two increments: the largest |u| of either.
    #[test]
    fn largest_displacement_is_read() {
        let dat = "
 displacements (vx,vy,vz) for set N_AXIS and time  0.5000000E+00

         3  0.000000E+00 -1.000000E-02  0.000000E+00
         7  3.000000E-02 -4.000000E-02  0.000000E+00

 total force (fx,fy,fz) for set N_AXIS and time  0.5000000E+00

        1.0E+00 2.0E+00 0.0E+00

 displacements (vx,vy,vz) for set N_AXIS and time  0.1000000E+01

         3  0.000000E+00 -2.000000E-02  0.000000E+00
         7  0.000000E+00 -4.000000E-02  0.000000E+00
";
        assert_eq!(max_displacement(dat, "N_AXIS"), Some(0.05));
        assert_eq!(max_displacement(dat, "N_OTHER"), None);
    }

    /// The last block of node-by-node displacements, with its time.
    #[test]
    fn last_displacements_are_read() {
        let dat = "
 displacements (vx,vy,vz) for set N_TIP and time  0.5000000E+00

         3  0.000000E+00 -1.000000E-02  0.000000E+00

 displacements (vx,vy,vz) for set N_TIP and time  0.1000000E+01

         3  1.000000E-02 -2.000000E-02  0.000000E+00
        12  0.000000E+00  7.500000E+00  2.000000E-03
";
        assert_eq!(
            last_displacements(dat, "N_TIP"),
            Some((1.0, vec![(3, [0.01, -0.02, 0.0]), (12, [0.0, 7.5, 0.002])]))
        );
        assert_eq!(last_displacements(dat, "N_OTHER"), None);
    }

    /// The last block of contact pressures, with its time.
    #[test]
    fn last_contact_pressures_are_read() {
        let dat = "
 contact stress (slave node,press,tang1,tang2) for all contact elements and time  0.5000000E+00

        13  1.000000E+03  0.000000E+00  0.000000E+00

 contact stress (slave node,press,tang1,tang2) for all contact elements and time  0.1000000E+01

        13  6.656109E+04  0.000000E+00  0.000000E+00
        33  2.334395E+03  0.000000E+00  0.000000E+00
";
        assert_eq!(
            last_contact_pressures(dat),
            Some((1.0, vec![(13, 6.656109e4), (33, 2.334395e3)]))
        );
        assert_eq!(last_contact_pressures(" no contact here\n"), None);
        let faces = "
 contact stress (slave element+face,press,tang1,tang2) for all contact elements and time  0.1000000E+01

         5          1  4.125832E+03  0.000000E+00  0.000000E+00
       499          4  5.089609E+03  0.000000E+00  0.000000E+00
";
        assert_eq!(
            last_face_contact_pressures(faces),
            Some((1.0, vec![4.125832e3, 5.089609e3]))
        );
        assert_eq!(last_face_contact_pressures(dat), None);
        assert_eq!(last_contact_pressures(faces), None);
    }

    #[test]
    fn every_total_is_read_with_its_time() {
        let two = format!(
            "{DAT}\n total force (fx,fy,fz) for set N_UPPER_TOP and time  0.2000000E+01\n\n        2.0E+00 -8.5E+00 0.0E+00\n"
        );
        assert_eq!(
            total_forces(&two, "N_UPPER_TOP"),
            vec![
                (1.0, [1.356814e-05, -4.374205, -1.356814e-05]),
                (2.0, [2.0, -8.5, 0.0])
            ]
        );
        assert!(total_forces(&two, "N_OTHER").is_empty());
    }
}
