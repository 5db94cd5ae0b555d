//! Writing the Radioss fixed-column layout: `I8` integers, `1P5E16.9` reals, five to a
//! line, every block and sub-block on a new line, two lines per node in the mode blocks
//! and a comment line naming each block. The text is a pure function of the numbers, so
//! writing twice gives identical text.

use std::fmt::Write;

use super::FxbFile;

/// Format a real the way Fortran `1PE16.9` does: ` 1.000000000E+00`, `-1.250000000E+01`,
/// always 16 characters. Exponents of three digits drop the letter, as Fortran does
/// (` 1.000000000-300`); the reader accepts that form. Non-finite values (which a read
/// file never holds) are written as `NaN`/`Infinity` right-aligned, which no reader
/// accepts, so they cannot pass silently.
pub fn format_real(v: f64) -> String {
    if !v.is_finite() {
        let s = if v.is_nan() {
            "NaN"
        } else if v > 0.0 {
            "Infinity"
        } else {
            "-Infinity"
        };
        return format!("{s:>16}");
    }
    let sign = if v.is_sign_negative() { '-' } else { ' ' };
    // `{:.9e}` rounds correctly, carrying into the exponent (9.9999999996 -> 1.000000000e1).
    let s = format!("{:.9e}", v.abs());
    let (mantissa, exp) = s.split_once('e').unwrap_or((&s, "0"));
    let exp: i32 = exp.parse().unwrap_or(0);
    let exp_sign = if exp < 0 { '-' } else { '+' };
    let e = exp.unsigned_abs();
    if e >= 100 {
        format!("{sign}{mantissa}{exp_sign}{e:03}")
    } else {
        format!("{sign}{mantissa}E{exp_sign}{e:02}")
    }
}

fn reals(out: &mut String, values: &[f64]) {
    for chunk in values.chunks(5) {
        for &v in chunk {
            out.push_str(&format_real(v));
        }
        out.push('\n');
    }
}

fn modes(out: &mut String, label: &str, values: &[f64], nodes: usize, first: usize) {
    let per_mode = (nodes * 6).max(1);
    for (m, mode) in values.chunks(per_mode).enumerate() {
        let _ = writeln!(out, "# {label} mode {}", first + m);
        let _ = writeln!(
            out,
            "#               X               Y               Z              XX              YY"
        );
        let _ = writeln!(out, "#              ZZ");
        for node in mode.chunks(6) {
            let (head, tail) = node.split_at(node.len().min(5));
            reals(out, head);
            reals(out, tail);
        }
    }
}

/// Write a file in the Radioss fixed-column layout. Blocks are written from the vectors
/// as they are; a file read by [`super::parse`] has consistent counts.
pub fn write(f: &FxbFile) -> String {
    let mut out = String::new();
    let flag = |b: bool| i64::from(b);
    out.push_str("# block 1: general data\n");
    out.push_str("#   Nbmod  Nbstat   Nbnod    Irot   Idamp    Iblo   Ifile\n");
    let _ = writeln!(
        out,
        "{:>8}{:>8}{:>8}{:>8}{:>8}{:>8}{:>8}",
        f.nbmod,
        f.nbstat,
        f.nbnod,
        flag(f.irot),
        flag(f.idamp),
        flag(f.iblo),
        flag(f.ifile)
    );
    out.push_str("# block 2: node IDs\n");
    for chunk in f.node_ids.chunks(10) {
        for id in chunk {
            let _ = write!(out, "{id:>8}");
        }
        out.push('\n');
    }
    out.push_str("# block 3: initial frame P0 (row-major) and Freq (Hz)\n");
    out.push_str(
        "#           P0_11           P0_12           P0_13           P0_21           P0_22\n",
    );
    out.push_str(
        "#           P0_23           P0_31           P0_32           P0_33            Freq\n",
    );
    let mut frame = f.p0.to_vec();
    frame.push(f.freq);
    reals(&mut out, &frame);
    if let Some((a, b)) = f.damping {
        out.push_str("# block 4: Rayleigh damping\n");
        out.push_str("#           Alpha            Beta\n");
        reals(&mut out, &[a, b]);
    }
    if !f.rigid_modes.is_empty() {
        let per_mode = f.nbnod * 6;
        let (b5, b6) = f
            .rigid_modes
            .split_at(f.rigid_modes.len().min(12 * per_mode));
        out.push_str("# block 5: rigid modes 1-12\n");
        modes(&mut out, "rigid", b5, f.nbnod, 1);
        if !b6.is_empty() {
            out.push_str("# block 6: rotational rigid modes 13-15\n");
            modes(&mut out, "rigid", b6, f.nbnod, 13);
        }
    }
    out.push_str("# block 7: local modes (static modes first)\n");
    modes(&mut out, "local", &f.local_modes, f.nbnod, 1);
    out.push_str("# block 8: local mass m_L (diagonal)\n");
    reals(&mut out, &f.m_l);
    out.push_str("# block 9: local stiffness K_L, full part (rows 1..Nbstat from the diagonal)\n");
    reals(&mut out, &f.k_full);
    out.push_str("# block 10: local stiffness K_L, diagonal part\n");
    reals(&mut out, &f.k_diag);
    if !f.m_r.is_empty() {
        out.push_str("# block 11: rigid mass M_R (upper triangle, row by row)\n");
        reals(&mut out, &f.m_r);
    }
    let sub_len = (f.m_c.len() / 9).max(1);
    for (number, name, sym, data) in [
        (12, "coupled mass", "M_C", &f.m_c),
        (13, "coupled stiffness", "K_C", &f.k_c),
    ] {
        if data.is_empty() {
            continue;
        }
        let _ = writeln!(out, "# block {number}: {name} {sym},kl, nine sub-blocks");
        for (m, sub) in data.chunks(sub_len).enumerate() {
            let _ = writeln!(
                out,
                "# {sym},{}{} (sub-block {})",
                m / 3 + 1,
                m % 3 + 1,
                m + 1
            );
            reals(&mut out, sub);
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::format_real;

    #[test]
    fn fortran_e16_9() {
        assert_eq!(format_real(1.0), " 1.000000000E+00");
        assert_eq!(format_real(-12.5), "-1.250000000E+01");
        assert_eq!(format_real(0.0), " 0.000000000E+00");
        assert_eq!(format_real(9.9999999996), " 1.000000000E+01");
        assert_eq!(format_real(9.9999999994), " 9.999999999E+00");
        assert_eq!(format_real(-4.652573369e-7), "-4.652573369E-07");
        assert_eq!(format_real(2.049574631e4), " 2.049574631E+04");
        assert_eq!(format_real(1.0e-300), " 1.000000000-300");
        assert_eq!(format_real(-1.5e300), "-1.500000000+300");
        assert_eq!(format_real(f64::MAX).len(), 16);
        assert_eq!(format_real(5e-324).len(), 16);
    }
}
