//! The fast path of the line reader: one pass over a line that is laid out the common
//! way, every number parsed once, nothing allocated; `None` for anything else, which
//! the reader then hands to the full two-way reading ([`super::fields::read_line`]).
//!
//! The full reading parses each line twice (fixed columns and blank-separated) and
//! compares the values. When every fixed-column field holds one unbroken run of
//! characters in plain syntax (`[+-] digits [. digits] [E [+-] digits]`), with blanks
//! (spaces only) around it, no blank field, no text past column 100, and runs that touch
//! only where the blank-separated reading splits them too (after a lettered exponent,
//! `...E+00-1.25...`), both readings see the same texts, hence the same numbers: the
//! fast path returns exactly what the full reading would, and parses each text once.
//! That the two give identical results is tested line by line and file by file
//! (`tests` below and the format tests over every fixture).
//!
//! Before that, lines of whole `1PE16.9` fields (how Radioss and our writer write every
//! real, so nearly every line of a large body) are recognised by their fixed layout and
//! read without searching for the runs ([`FastField::written_usual`]): the same numbers
//! by the same arithmetic, about a third less time on a 100 MB body.

use super::fields::{FieldValue, LINE_COLUMNS, decimal, eight_digits, parse_int, plain_real};

/// The most fields a line can hold (100 columns of 8-column integer fields).
pub const MAX_FIELDS: usize = LINE_COLUMNS.div_ceil(8);

/// A field kind the fast path can read.
pub trait FastField: FieldValue {
    /// The plain-syntax value at the start of `text`: its length (0 if none) and its
    /// value, exactly as [`FieldValue::parse`] reads that prefix (`None` where it
    /// refuses it: out of range).
    fn plain(text: &[u8]) -> (usize, Option<Self>);

    /// The values of a line written the way nearly every line of a large file is
    /// written, read faster still; `None` for any other line (or a value out of range).
    fn written_usual(_line: &[u8], _out: &mut [Self; MAX_FIELDS]) -> Option<usize> {
        None
    }
}

impl FastField for i64 {
    fn plain(text: &[u8]) -> (usize, Option<Self>) {
        let sign = usize::from(matches!(text.first(), Some(b'+' | b'-')));
        let digits = text[sign..]
            .iter()
            .take_while(|c| c.is_ascii_digit())
            .count();
        if digits == 0 {
            (0, None)
        } else {
            (sign + digits, parse_int(&text[..sign + digits]))
        }
    }
}

impl FastField for f64 {
    fn plain(text: &[u8]) -> (usize, Option<Self>) {
        plain_real(text)
    }

    /// Lines of whole 16-column fields each written as Fortran's `1PE16.9` writes them
    /// ([`e16_9`]), as Radioss and our writer do: every field's text is one run filling
    /// its columns (a sign or a blank first), and where a run touches the previous one
    /// (a `-` in the first column) the previous ends with a lettered exponent, where the
    /// blank-separated reading splits too. So both readings see these texts, and each is
    /// read once, by the arithmetic of [`plain_real`].
    fn written_usual(line: &[u8], out: &mut [Self; MAX_FIELDS]) -> Option<usize> {
        if line.is_empty() || !line.len().is_multiple_of(16) || line.len() > LINE_COLUMNS {
            return None;
        }
        for (k, field) in line.chunks_exact(16).enumerate() {
            out[k] = e16_9(field.try_into().ok()?)?;
        }
        Some(line.len() / 16)
    }
}

/// The value of a 16-column field written as `1PE16.9` (` d.dddddddddE+dd`, `-` for the
/// blank when negative; the exponent's sign `+` or `-`), exactly as [`plain_real`]
/// reads its text; `None` for any other field, or a value out of range.
fn e16_9(f: &[u8; 16]) -> Option<f64> {
    let digit = |c: u8| c.is_ascii_digit().then(|| u64::from(c - b'0'));
    let eight = u64::from_le_bytes(f[3..11].try_into().ok()?);
    let all_digits = (eight.wrapping_add(0x4646_4646_4646_4646)
        | eight.wrapping_sub(0x3030_3030_3030_3030))
        & 0x8080_8080_8080_8080
        == 0;
    if !(matches!(f[0], b' ' | b'-') && f[2] == b'.' && all_digits && f[12] == b'E') {
        return None;
    }
    let mantissa = digit(f[1])? * 1_000_000_000 + eight_digits(eight) * 10 + digit(f[11])?;
    let e = (digit(f[14])? * 10 + digit(f[15])?) as i64;
    let exponent = match f[13] {
        b'+' => e,
        b'-' => -e,
        _ => return None,
    };
    let text = if f[0] == b' ' { &f[1..] } else { &f[..] };
    decimal(f[0] == b'-', mantissa, 10, exponent - 9, text)
}

/// Read `line` into `out` when it is laid out the common way (module text); the number
/// of values, or `None` to ask the full reading.
pub fn read_line<T: FastField>(line: &[u8], out: &mut [T; MAX_FIELDS]) -> Option<usize> {
    if let Some(n) = T::written_usual(line, out) {
        return Some(n);
    }
    if line.len() > LINE_COLUMNS {
        return None;
    }
    let last = line.iter().rposition(|&c| c != b' ')? + 1;
    let line = &line[..last];
    let mut n = 0;
    // The previous run: where it starts and ends (exclusive).
    let mut prev: Option<(usize, usize)> = None;
    for (k, field) in line.chunks(T::WIDTH).enumerate() {
        let s = field.iter().position(|&c| c != b' ')?;
        let (len, value) = T::plain(&field[s..]);
        if len == 0 || field[s + len..].iter().any(|&c| c != b' ') {
            return None;
        }
        let (a, b) = (k * T::WIDTH + s, k * T::WIDTH + s + len);
        if let Some((p0, p1)) = prev
            && p1 == a
            && !super::fields::splits_at(line, p0, a)
        {
            // Glued to the previous run where the blank-separated reading does not
            // split: the two readings differ; the full reading says how.
            return None;
        }
        *out.get_mut(n)? = value?;
        n += 1;
        prev = Some((a, b));
    }
    Some(n)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::fxb::fields::{self, LineIssue};

    /// The fast path, when it answers, answers what the full reading answers.
    fn same<T: FastField + std::fmt::Debug>(line: &[u8]) -> bool {
        let mut buf = [T::ZERO; MAX_FIELDS];
        let fast = read_line::<T>(line, &mut buf);
        let full: Result<Vec<T>, LineIssue> = fields::read_line::<T>(line);
        if let Some(n) = fast {
            let full = full.unwrap_or_else(|e| {
                panic!(
                    "fast {:?}, full {e:?}: {:?}",
                    &buf[..n],
                    String::from_utf8_lossy(line)
                )
            });
            assert_eq!(full.len(), n, "{:?}", String::from_utf8_lossy(line));
            for (x, y) in full.iter().zip(&buf[..n]) {
                assert!(
                    x.show() == y.show() && x == y,
                    "{x} vs {y}: {:?}",
                    String::from_utf8_lossy(line)
                );
            }
        }
        fast.is_some()
    }

    #[test]
    fn common_lines_take_the_fast_path() {
        let reals: [&str; 5] = [
            " 3.784539706E-01-5.289955727E-03 0.000000000E+00 0.000000000E+00 0.000000000E+00",
            "-1.474280726E+00",
            "             1.0             2.5            -3.0",
            "   1.0            2.5         ",
            "  -0.0   ",
        ];
        for l in reals {
            assert!(same::<f64>(l.as_bytes()), "{l}");
        }
        for l in [
            "  100001  100002  100003",
            "     200       6    5151       1",
        ] {
            assert!(same::<i64>(l.as_bytes()), "{l}");
        }
    }

    #[test]
    fn unusual_lines_go_to_the_full_reading() {
        let reals = [
            "1.0\t2.0",                                         // tab
            "1.5D+02",                                          // D exponent
            "          1.0-03-2.000000000E+00",                 // letterless exponent
            "        1.2 5E+01",                                // blank inside a field
            "             1.0                             2.0", // blank field
            "     1.0000000-2.0",                               // glued, not split freely
            "1.0 2.0 3.0 4.0 5.0",                              // free format across fields
        ];
        for l in reals {
            assert!(!same::<f64>(l.as_bytes()), "{l}");
        }
        let long = format!("{}{}7.0", " 1.000000000E+00".repeat(5), " ".repeat(20));
        assert!(!same::<f64>(long.as_bytes()));
        assert!(!same::<f64>(b"1.0\xff 2.0"));
        assert!(
            !same::<f64>(b"1e999"),
            "overflow is the full reading's error"
        );
        assert!(!same::<i64>(b"21\t22"));
        assert!(!same::<i64>(b"3 0 2 0 0 1 0"), "ambiguous: full reading");
        assert!(!same::<i64>(b"99999999999999999999"));
    }

    /// Lines of `1PE16.9` fields, random digits, signs and exponents (glued where
    /// negative): the layout path answers every one, with the full reading's values;
    /// a field off the layout by one character sends the line to the general paths.
    #[test]
    fn e16_9_lines_are_read_as_the_full_reading_reads_them() {
        let mut rng = fxbody_testkit::Rng::new(0x0123_4567_89ab_cdef);
        let mut next = || rng.next_u64();
        for _ in 0..50_000 {
            let r = next();
            let fields = 1 + (r % 5) as usize;
            let mut line = String::new();
            for k in 0..fields {
                let r = next();
                let sign = if r & 1 == 0 { ' ' } else { '-' };
                let e = (r >> 1) % 100;
                let esign = if r & (1 << 10) == 0 { '+' } else { '-' };
                let digits = (r >> 11) % 10_000_000_000;
                let text = format!("{digits:010}");
                line.push_str(&format!(
                    "{sign}{}.{}E{esign}{e:02}",
                    &text[..1],
                    &text[1..]
                ));
                assert_eq!(line.len(), 16 * (k + 1));
            }
            let mut buf = [0.0; MAX_FIELDS];
            assert_eq!(
                f64::written_usual(line.as_bytes(), &mut buf),
                Some(fields),
                "{line}"
            );
            let full = fields::read_line::<f64>(line.as_bytes()).unwrap();
            for (x, y) in full.iter().zip(&buf) {
                assert_eq!(x.to_bits(), y.to_bits(), "{line}");
            }
            assert!(same::<f64>(line.as_bytes()));
        }
        let mut buf = [0.0; MAX_FIELDS];
        for off in [
            " 1.000000000E+0 ",
            " 1.000000000D+00",
            " 1,000000000E+00",
            "+1.000000000E+00",
            " 1.000000000E 00",
            " 1.00000000xE+00",
            " 1.000000000e+00",
            " 1.000000000E+00 ",
            "",
        ] {
            assert_eq!(f64::written_usual(off.as_bytes(), &mut buf), None, "{off}");
            same::<f64>(off.as_bytes());
        }
    }

    /// Every line made of a few pieces from the characters that matter, cut at every
    /// width: wherever the fast path answers, the full reading answers the same.
    #[test]
    fn fast_path_agrees_with_the_full_reading_on_generated_lines() {
        let pieces: [&str; 14] = [
            " ",
            "  ",
            "1",
            "-2",
            "3.5",
            "E+01",
            "e-3",
            "-",
            "+",
            ".",
            "D2",
            "0.000000000E+00",
            "-1.250000000E+01",
            "7",
        ];
        let mut rng = fxbody_testkit::Rng::new(0x2545_f491_4f6c_dd1d);
        let mut next = || rng.next_u64();
        let (mut fast, mut total) = (0, 0);
        for _ in 0..200_000 {
            let len = 1 + next() % 12;
            let mut line = String::new();
            for _ in 0..len {
                line.push_str(pieces[(next() % pieces.len() as u64) as usize]);
            }
            let line = line.as_bytes();
            total += 2;
            fast += usize::from(same::<f64>(line));
            fast += usize::from(same::<i64>(line));
            // The same text right-justified in 16- and 8-column fields.
            let mut fixed = String::new();
            for tok in std::str::from_utf8(line)
                .unwrap()
                .split(' ')
                .filter(|t| !t.is_empty())
            {
                fixed.push_str(&format!("{tok:>16}"));
            }
            total += 1;
            fast += usize::from(same::<f64>(fixed.as_bytes()));
        }
        // The generator reaches both paths often.
        assert!(
            fast > total / 20 && fast < total * 19 / 20,
            "{fast} of {total}"
        );
    }
}
