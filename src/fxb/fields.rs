//! One line of numbers, read the two ways a `.fxb` file can be written.
//!
//! Radioss reads fixed columns (Fortran `I8`, `F16.0`): only the first 100 columns count,
//! blanks inside a field are ignored, a blank field between others reads as zero, and
//! numbers may touch (`0.000000000E+00-1.250000000E+01` is two values). Hand-written files
//! separate values by blanks or tabs instead. [`read_line`] reads a line both ways and
//! accepts it only when the readings agree or exactly one of them is possible, so that a
//! file is never read differently from what its author meant without saying so.
//!
//! Details: a tab counts as one blank column in the fixed reading (so integers separated
//! by single tabs or blanks, `21<tab>22`, are ambiguous: Radioss would read 2122); the
//! blank-separated reading also splits numbers glued after an exponent with a letter
//! (`0.0E+00-1.25E+01`), which no Fortran number can continue; values must be finite.

use std::fmt::Display;

/// Columns of a line that Radioss reads; the rest is ignored by the fixed reading.
pub const LINE_COLUMNS: usize = 100;

/// A value kind that lives in fixed-width fields: integers (`I8`) or reals (`F16.0`).
pub trait FieldValue: Copy + PartialEq + Display {
    /// Field width in columns.
    const WIDTH: usize;
    /// The value of an all-blank field between non-blank ones.
    const ZERO: Self;
    /// What a field of this kind holds, for messages.
    const WHAT: &'static str;
    /// Parse the text of one field or token (blanks already removed), `None` if invalid.
    fn parse(text: &[u8]) -> Option<Self>;
    /// Short text for messages.
    fn show(&self) -> String {
        self.to_string()
    }
}

impl FieldValue for i64 {
    const WIDTH: usize = 8;
    const ZERO: Self = 0;
    const WHAT: &'static str = "an integer (8-column fields)";
    fn parse(text: &[u8]) -> Option<Self> {
        parse_int(text)
    }
}

impl FieldValue for f64 {
    const WIDTH: usize = 16;
    const ZERO: Self = 0.0;
    const WHAT: &'static str = "a real number (16-column fields)";
    fn parse(text: &[u8]) -> Option<Self> {
        parse_real(text)
    }
    fn show(&self) -> String {
        crate::num::num(*self)
    }
}

/// Blank characters: inside a fixed field they are ignored, between tokens they separate.
pub fn is_blank(b: u8) -> bool {
    matches!(b, b' ' | b'\t' | b'\r' | b'\x0c' | b'\x0b')
}

/// An integer `[sign] digits`, as Fortran `I` editing reads it (blanks removed first).
pub fn parse_int(text: &[u8]) -> Option<i64> {
    let (neg, digits) = match text.first() {
        Some(b'-') => (true, &text[1..]),
        Some(b'+') => (false, &text[1..]),
        _ => (false, text),
    };
    if digits.is_empty() || !digits.iter().all(u8::is_ascii_digit) {
        return None;
    }
    let mut v: i64 = 0;
    for &d in digits {
        let d = i64::from(d - b'0');
        v = v.checked_mul(10)?;
        v = if neg {
            v.checked_sub(d)?
        } else {
            v.checked_add(d)?
        };
    }
    Some(v)
}

/// A real number as Fortran `F` editing reads it (blanks removed first): an optional
/// sign, digits with an optional decimal point, and an optional exponent written
/// `E`/`D` (either case) with optional sign, or just a sign (`1.0-3` is 1.0e-3).
/// Non-finite results (overflow, `NaN`, `Inf`) are rejected: the file must hold numbers.
///
/// Text already in Rust's own syntax (no `D`, no letterless exponent) is read by
/// `plain_real`; the rest is rewritten into that syntax and given to `str::parse`. Both
/// are correctly rounded values of the same decimal number, so they agree bit for bit
/// (tested).
pub fn parse_real(text: &[u8]) -> Option<f64> {
    match plain_real(text) {
        (len, value) if len == text.len() => value,
        _ => parse_real_rewritten(text),
    }
}

/// The real in Rust's own syntax (`[+-] digits [. digits] [e|E [+-] digits]`, at least
/// one mantissa digit) at the start of `text`: the length of that prefix (0 if none; a
/// bare exponent letter, `1.0E`, is not part of it) and its value (`None` if not finite).
///
/// The value is correctly rounded: with at most 19 digits, a mantissa below 2^53 and a
/// power of ten at most 22 in size, both factors are exact doubles and one IEEE
/// multiplication or division rounds their product once (Clinger's fast path, the one
/// `str::parse` itself takes first); any other text goes to `str::parse`.
pub(crate) fn plain_real(text: &[u8]) -> (usize, Option<f64>) {
    let neg = text.first() == Some(&b'-');
    let mut i = usize::from(matches!(text.first(), Some(b'+' | b'-')));
    let mut mantissa: u64 = 0;
    let int_digits = digit_run(text, &mut i, &mut mantissa);
    let mut frac_digits = 0;
    if text.get(i) == Some(&b'.') {
        i += 1;
        frac_digits = digit_run(text, &mut i, &mut mantissa);
    }
    let digits = int_digits + frac_digits;
    let frac_digits = frac_digits as i64;
    if digits == 0 {
        return (0, None);
    }
    let mut exponent: i64 = 0;
    if matches!(text.get(i), Some(b'e' | b'E')) {
        let mut j = i + 1;
        let exp_neg = text.get(j) == Some(&b'-');
        if matches!(text.get(j), Some(b'+' | b'-')) {
            j += 1;
        }
        let e0 = j;
        while let Some(d) = text.get(j).filter(|c| c.is_ascii_digit()) {
            exponent = (exponent * 10 + i64::from(d - b'0')).min(1 << 40);
            j += 1;
        }
        if j > e0 {
            i = j;
            if exp_neg {
                exponent = -exponent;
            }
        } else {
            exponent = 0;
        }
    }
    (
        i,
        decimal(neg, mantissa, digits, exponent - frac_digits, &text[..i]),
    )
}

/// The double nearest to `mantissa * 10^power` (negated when `neg`), where `mantissa`
/// holds the value of `digits` decimal digits (wrapped beyond 19) and `text` is the same
/// number in Rust's syntax; `None` if not finite. Clinger's fast path (see
/// [`plain_real`]) where it is exact, else `str::parse` of `text`: both correctly
/// rounded, so every reader that goes through here agrees bit for bit.
#[inline]
pub(crate) fn decimal(
    neg: bool,
    mantissa: u64,
    digits: usize,
    power: i64,
    text: &[u8],
) -> Option<f64> {
    /// Exact powers of ten as doubles (a `static`: a `const` array indexed at run time
    /// is copied onto the stack at every call).
    static POW10: [f64; 23] = [
        1e0, 1e1, 1e2, 1e3, 1e4, 1e5, 1e6, 1e7, 1e8, 1e9, 1e10, 1e11, 1e12, 1e13, 1e14, 1e15, 1e16,
        1e17, 1e18, 1e19, 1e20, 1e21, 1e22,
    ];
    let value = if digits <= 19 && mantissa < 1 << 53 && power.abs() <= 22 {
        // Exact: the mantissa converts without rounding, the power is exact.
        let m = mantissa as f64;
        let p = POW10[power.unsigned_abs() as usize];
        let v = if power < 0 { m / p } else { m * p };
        Some(if neg { -v } else { v })
    } else {
        std::str::from_utf8(text)
            .ok()
            .and_then(|t| t.parse::<f64>().ok())
    };
    value.filter(|v| v.is_finite())
}

/// Read the digits of `text` from `*i` on into `mantissa` (`mantissa * 10 + d` each,
/// wrapping: only trusted for 19 digits or fewer), moving `*i` past them; their count.
/// Eight digits at a time where eight follow (the usual 9-digit fraction of a
/// `%16.9E` number takes one step and one digit).
fn digit_run(text: &[u8], i: &mut usize, mantissa: &mut u64) -> usize {
    let start = *i;
    while let Some(chunk) = text.get(*i..*i + 8) {
        let v = u64::from_le_bytes(chunk.try_into().unwrap_or([0; 8]));
        // Each byte is a digit when it is >= '0' and adding 0x46 keeps it below 0x80.
        let is_digits = (v.wrapping_add(0x4646_4646_4646_4646)
            | v.wrapping_sub(0x3030_3030_3030_3030))
            & 0x8080_8080_8080_8080
            == 0;
        if !is_digits {
            break;
        }
        *mantissa = mantissa
            .wrapping_mul(100_000_000)
            .wrapping_add(eight_digits(v));
        *i += 8;
    }
    while let Some(d) = text.get(*i).filter(|c| c.is_ascii_digit()) {
        *mantissa = mantissa.wrapping_mul(10).wrapping_add(u64::from(d - b'0'));
        *i += 1;
    }
    *i - start
}

/// The value of eight ASCII digits read little-endian into `v` (the first digit in the
/// low byte): pairs, then fours, then the eight, by multiply-and-shift.
pub(crate) fn eight_digits(v: u64) -> u64 {
    let v = v - 0x3030_3030_3030_3030;
    let v = (v * 10) + (v >> 8);
    let pairs_lo = (v & 0x0000_00FF_0000_00FF).wrapping_mul(100 + (1_000_000 << 32));
    let pairs_hi = ((v >> 16) & 0x0000_00FF_0000_00FF).wrapping_mul(1 + (10_000 << 32));
    (pairs_lo.wrapping_add(pairs_hi) >> 32) & 0xFFFF_FFFF
}

/// [`parse_real`] for any Fortran form: the number rewritten into Rust's syntax (a `0`
/// for missing digits, `e` for the exponent letter or sign), then parsed.
pub(crate) fn parse_real_rewritten(text: &[u8]) -> Option<f64> {
    let mut i = 0;
    let mut norm = Norm::default();
    if let Some(&s @ (b'+' | b'-')) = text.first() {
        if s == b'-' {
            norm.push(b'-');
        }
        i = 1;
    }
    let int_start = i;
    while i < text.len() && text[i].is_ascii_digit() {
        i += 1;
    }
    let int_digits = &text[int_start..i];
    let mut frac_digits: &[u8] = &[];
    if i < text.len() && text[i] == b'.' {
        i += 1;
        let f0 = i;
        while i < text.len() && text[i].is_ascii_digit() {
            i += 1;
        }
        frac_digits = &text[f0..i];
    }
    if int_digits.is_empty() && frac_digits.is_empty() {
        return None;
    }
    push_digits(&mut norm, int_digits);
    norm.push(b'.');
    push_digits(&mut norm, frac_digits);
    if i < text.len() {
        match text[i] {
            b'E' | b'e' | b'D' | b'd' => i += 1,
            b'+' | b'-' => {}
            _ => return None,
        }
        norm.push(b'e');
        if let Some(&s @ (b'+' | b'-')) = text.get(i) {
            if s == b'-' {
                norm.push(b'-');
            }
            i += 1;
        }
        let e0 = i;
        while i < text.len() && text[i].is_ascii_digit() {
            i += 1;
        }
        if i == e0 || i != text.len() {
            return None;
        }
        push_digits(&mut norm, &text[e0..i]);
    }
    let v: f64 = std::str::from_utf8(norm.as_bytes()).ok()?.parse().ok()?;
    v.is_finite().then_some(v)
}

fn push_digits(out: &mut Norm, digits: &[u8]) {
    if digits.is_empty() {
        out.push(b'0');
    }
    for &d in digits {
        out.push(d);
    }
}

/// The normalised text of a number, on the stack unless it is unusually long (reading
/// millions of values should not allocate for each).
struct Norm {
    stack: [u8; 64],
    len: usize,
    heap: Vec<u8>,
}

impl Default for Norm {
    fn default() -> Self {
        Norm {
            stack: [0; 64],
            len: 0,
            heap: Vec::new(),
        }
    }
}

impl Norm {
    fn push(&mut self, b: u8) {
        if let Some(slot) = self.stack.get_mut(self.len) {
            *slot = b;
        } else {
            if self.heap.is_empty() {
                self.heap.extend_from_slice(&self.stack);
            }
            self.heap.push(b);
        }
        self.len += 1;
    }

    fn as_bytes(&self) -> &[u8] {
        self.stack.get(..self.len).unwrap_or(&self.heap)
    }
}

/// Why a line could not be read.
#[derive(Debug, Clone, PartialEq)]
pub enum LineIssue {
    /// Neither reading is possible; the text says where each one fails.
    Unparsable(String),
    /// Both readings are possible and give different numbers.
    Ambiguous {
        /// The fixed-column values.
        fixed: String,
        /// The blank-separated values.
        free: String,
        /// Why the readings may differ (text past column 100, tabs), or empty.
        note: String,
    },
}

/// Tokens kept from the blank-separated reading: more than any fixed reading can give.
const MAX_FREE: usize = 16;

/// Read the values of one data line (see the module text for the rule).
pub fn read_line<T: FieldValue>(line: &[u8]) -> Result<Vec<T>, LineIssue> {
    let fixed = read_fixed::<T>(line);
    let free = read_free::<T>(line);
    match (fixed, free) {
        (Ok(a), Ok((b, count))) => {
            if a == b && count == b.len() {
                Ok(a)
            } else {
                let mut note = String::new();
                if line.len() > LINE_COLUMNS && line[LINE_COLUMNS..].iter().any(|&c| !is_blank(c)) {
                    note.push_str("; text past column 100 is ignored by the fixed reading");
                }
                if line.contains(&b'\t') {
                    note.push_str("; a tab counts as one column in the fixed reading");
                }
                let mut free = list(&b);
                if count > b.len() {
                    free = format!("{} values {}...", count, &free[..free.len() - 1]);
                }
                Err(LineIssue::Ambiguous {
                    fixed: list(&a),
                    free,
                    note,
                })
            }
        }
        (Ok(a), Err(_)) => Ok(a),
        (Err(_), Ok((b, count))) if count == b.len() => Ok(b),
        (Err(_), Ok((_, count))) => Err(LineIssue::Unparsable(format!(
            "the fixed-column reading fails and the blank-separated reading finds {count} values"
        ))),
        (Err(f), Err(w)) => Err(LineIssue::Unparsable(format!(
            "the fixed-column reading finds {f}, the blank-separated reading finds {w}"
        ))),
    }
}

fn list<T: FieldValue>(v: &[T]) -> String {
    let items: Vec<String> = v.iter().map(|x| x.show()).collect();
    format!("[{}]", items.join(", "))
}

/// Show at most 40 characters of raw text, lossily decoded.
pub fn shown(text: &[u8]) -> String {
    let cut = &text[..text.len().min(40)];
    let mut s = String::from_utf8_lossy(cut).into_owned();
    if text.len() > 40 {
        s.push_str("...");
    }
    s
}

/// The blank-separated reading alone, when every token is a valid value (used to say
/// more about an ambiguous header line).
pub fn free_values<T: FieldValue>(line: &[u8]) -> Option<Vec<T>> {
    match read_free::<T>(line) {
        Ok((v, count)) if count == v.len() => Some(v),
        _ => None,
    }
}

/// Where one reading of a line fails: the first text that is not a value. Shown inside
/// [`LineIssue::Unparsable`], which names the file and line.
#[derive(Debug, thiserror::Error)]
enum Misread {
    /// The fixed-column reading: a field's text and columns (1-based, inclusive).
    #[error("'{text}' in columns {first}-{last}, not {what}")]
    Field {
        /// The field's text, trimmed.
        text: String,
        /// Its first column.
        first: usize,
        /// Its last column.
        last: usize,
        /// What was expected.
        what: &'static str,
    },
    /// The blank-separated reading: the token's position (1-based) and text.
    #[error("value {index} '{text}', not {what}")]
    Token {
        /// Its position among the tokens.
        index: usize,
        /// Its text.
        text: String,
        /// What was expected.
        what: &'static str,
    },
}

/// Fixed-column reading of the first 100 columns: one value per non-blank field,
/// blank fields before the last non-blank one read as zero.
fn read_fixed<T: FieldValue>(line: &[u8]) -> Result<Vec<T>, Misread> {
    let line = &line[..line.len().min(LINE_COLUMNS)];
    let last = line
        .iter()
        .rposition(|&c| !is_blank(c))
        .map_or(0, |p| p + 1);
    let mut out = Vec::with_capacity(LINE_COLUMNS / T::WIDTH + 1);
    for (k, field) in line[..last].chunks(T::WIDTH).enumerate() {
        let mut buf = [0u8; 16];
        let mut n = 0;
        for &c in field.iter().filter(|&&c| !is_blank(c)) {
            if let Some(slot) = buf.get_mut(n) {
                *slot = c;
            }
            n += 1;
        }
        if n == 0 {
            out.push(T::ZERO);
            continue;
        }
        match buf.get(..n).and_then(T::parse) {
            Some(v) => out.push(v),
            None => {
                let c0 = k * T::WIDTH + 1;
                return Err(Misread::Field {
                    text: shown(field).trim().to_string(),
                    first: c0,
                    last: c0 + T::WIDTH - 1,
                    what: T::WHAT,
                });
            }
        }
    }
    Ok(out)
}

/// Blank-separated reading of the whole line: the first [`MAX_FREE`] values and the
/// total number of tokens.
fn read_free<T: FieldValue>(line: &[u8]) -> Result<(Vec<T>, usize), Misread> {
    let mut out = Vec::new();
    let mut count = 0;
    let tokens = line
        .split(|&c| is_blank(c))
        .filter(|t| !t.is_empty())
        .flat_map(split_touching);
    for tok in tokens {
        count += 1;
        match T::parse(tok) {
            Some(v) if out.len() < MAX_FREE => out.push(v),
            Some(_) => {}
            None => {
                return Err(Misread::Token {
                    index: count,
                    text: shown(tok),
                    what: T::WHAT.split(" (").next().unwrap_or(T::WHAT),
                });
            }
        }
    }
    Ok((out, count))
}

/// Split a token where one number ends with an exponent written with a letter and the
/// next begins with a sign: `0.000000000E+00-1.250000000E+01` is two numbers whichever
/// columns they sit in (a Fortran number cannot go on after `E+00`). The letterless
/// exponent form (`1.0-3`) is never split: `1.0-3-2.0` stays one (invalid) token.
fn split_touching(tok: &[u8]) -> impl Iterator<Item = &[u8]> {
    let mut start = 0;
    let mut i = 1;
    let mut done = false;
    std::iter::from_fn(move || {
        if done {
            return None;
        }
        while i < tok.len() {
            let at = i;
            i += 1;
            if splits_at(tok, start, at) {
                let piece = &tok[start..at];
                start = at;
                return Some(piece);
            }
        }
        done = true;
        Some(&tok[start..])
    })
}

/// Whether the blank-separated reading splits `text` before position `i`, the current
/// piece starting at `start` (see [`split_touching`]): a sign after the digits of an
/// exponent written with a letter. The fast line reader asks the same question.
pub(crate) fn splits_at(text: &[u8], start: usize, i: usize) -> bool {
    if !matches!(text[i], b'+' | b'-') || !text[i - 1].is_ascii_digit() {
        return false;
    }
    let mut j = i - 1;
    while j > start && text[j].is_ascii_digit() {
        j -= 1;
    }
    if j > start && matches!(text[j], b'+' | b'-') {
        j -= 1;
    }
    j > start && matches!(text[j], b'E' | b'e' | b'D' | b'd')
}

#[cfg(test)]
mod tests {
    use super::*;

    fn reals(s: &str) -> Result<Vec<f64>, LineIssue> {
        read_line::<f64>(s.as_bytes())
    }

    #[test]
    fn fortran_real_forms() {
        let cases: [(&str, f64); 12] = [
            ("1.0", 1.0),
            ("-1.250000000E+01", -12.5),
            ("1.5D+02", 150.0),
            ("1.5d-2", 0.015),
            ("1.0-3", 1.0e-3),
            ("2.5+2", 250.0),
            ("3", 3.0),
            ("+.5", 0.5),
            ("7.", 7.0),
            ("1.000000000-300", 1.0e-300),
            ("-0.0", -0.0),
            ("6.02e23", 6.02e23),
        ];
        for (text, want) in cases {
            assert_eq!(parse_real(text.as_bytes()), Some(want), "{text}");
        }
        let long = format!("{}.5E-{}", "1".repeat(80), "0".repeat(70) + "79");
        assert_eq!(parse_real(long.as_bytes()), Some(1.1111111111111111));
        for bad in [
            "", ".", "E5", "1.0E", "1.0E+", "1..0", "NaN", "Inf", "1e999", "1.0x", "--1",
        ] {
            assert_eq!(parse_real(bad.as_bytes()), None, "{bad}");
        }
    }

    /// The plain-syntax reader gives `str::parse`'s value bit for bit, on both sides of
    /// every limit of its exact branch and on random numbers of every length and exponent;
    /// and the rewriting branch of [`parse_real`] agrees with it.
    #[test]
    fn plain_reals_are_read_exactly_as_str_parse_reads_them() {
        let check = |t: &str| {
            let want = t.parse::<f64>().ok().filter(|v| v.is_finite());
            let (len, got) = plain_real(t.as_bytes());
            assert_eq!(len, t.len(), "{t}");
            assert_eq!(got.map(f64::to_bits), want.map(f64::to_bits), "{t}");
            let rewritten = parse_real_rewritten(t.as_bytes());
            assert_eq!(rewritten.map(f64::to_bits), want.map(f64::to_bits), "{t}");
        };
        for t in [
            "9007199254740992",
            "9007199254740993",
            "9007199254740995",
            "1e22",
            "1e23",
            "1E-22",
            "1e-23",
            "0.1",
            "-0.0",
            "+.5",
            "7.",
            "1234567890123456789",
            "12345678901234567890",
            "0.000000000000000000001",
            "1.7976931348623157e308",
            "1.8e308",
            "4.9e-324",
            "2.4703282292062327e-324",
            "-3.784539706E-01",
            "1.0E+00000000000000000000000001",
            "1e-99999999999999999999",
        ] {
            check(t);
        }
        let mut next = crate::testing::xorshift(0x9e37_79b9_7f4a_7c15u64);
        for _ in 0..200_000 {
            let r = next();
            let digits = 1 + (r % 22) as usize;
            let mut t = String::new();
            if r & (1 << 8) != 0 {
                t.push('-');
            }
            let point = (r >> 9) as usize % (digits + 1);
            let mut d = next();
            for k in 0..digits {
                if k == point {
                    t.push('.');
                }
                t.push(char::from(b'0' + (d % 10) as u8));
                d /= 10;
            }
            if r & (1 << 20) != 0 {
                let e = (r >> 21) % 80;
                t.push_str(&format!(
                    "E{}{e:02}",
                    if r & (1 << 30) != 0 { '-' } else { '+' }
                ));
            }
            check(&t);
        }
        // A bare exponent letter is not part of the number.
        assert_eq!(plain_real(b"1.0E").0, 3);
        assert_eq!(plain_real(b"1.0E+").0, 3);
        assert_eq!(plain_real(b"-.E1"), (0, None));
    }

    #[test]
    fn eight_digits_at_once() {
        for (text, want) in [
            (b"00000000", 0),
            (b"12345678", 12_345_678),
            (b"99999999", 99_999_999),
            (b"07000001", 7_000_001),
        ] {
            assert_eq!(eight_digits(u64::from_le_bytes(*text)), want);
        }
        let mut m = 0;
        let mut i = 0;
        assert_eq!(digit_run(b"1234567890123x", &mut i, &mut m), 13);
        assert_eq!((i, m), (13, 1_234_567_890_123));
        let mut i = 0;
        assert_eq!(digit_run(b"1234567/9", &mut i, &mut m), 7);
        let mut i = 0;
        assert_eq!(digit_run(b"12345678:", &mut i, &mut m), 8);
    }

    #[test]
    fn integers() {
        assert_eq!(parse_int(b"-42"), Some(-42));
        assert_eq!(parse_int(b"+7"), Some(7));
        assert_eq!(parse_int(b"9223372036854775807"), Some(i64::MAX));
        assert_eq!(parse_int(b"-9223372036854775808"), Some(i64::MIN));
        assert_eq!(parse_int(b"9223372036854775808"), None);
        assert_eq!(parse_int(b"1.0"), None);
        assert_eq!(parse_int(b"-"), None);
    }

    #[test]
    fn touching_numbers_read_by_columns() {
        let line =
            " 0.000000000E+00-1.250000000E+01 0.000000000E+00         3.5D+00           1.0-3";
        assert_eq!(reals(line).unwrap(), vec![0.0, -12.5, 0.0, 3.5, 1.0e-3]);
        // Only the columns tell where "1.0-03" ends and "-2.0E+00" begins.
        let line = "          1.0-03-2.000000000E+00";
        assert_eq!(reals(line).unwrap(), vec![1.0e-3, -2.0]);
    }

    #[test]
    fn touching_numbers_out_of_column_are_split_after_an_exponent() {
        // As printed in the reference guide, without the leading blank of column 1.
        let v = reals(
            "0.000000000E+00-1.250000000E+01 0.000000000E+00 0.000000000E+00 0.000000000E+00",
        );
        assert_eq!(v.unwrap(), vec![0.0, -12.5, 0.0, 0.0, 0.0]);
        // The letterless exponent form is never split.
        assert!(reals("1.0-3-2.0").is_err());
    }

    #[test]
    fn blanks_inside_a_field_are_ignored() {
        // Fixed columns read "1.2 5E+0" + "1" as [12.5, 1]; blank-separated [1.2, 50].
        let r = reals("        1.2 5E+01");
        assert!(matches!(r, Err(LineIssue::Ambiguous { .. })), "{r:?}");
        // With a token no blank-separated reader accepts ("5E+"), the fixed reading is
        // the only one, and Fortran reads "1.2 5E+ 01" as 1.25E+01.
        assert_eq!(reals("     1.2 5E+ 01").unwrap(), vec![12.5]);
    }

    #[test]
    fn free_format_with_tabs() {
        assert_eq!(
            reals("1.092357846E+01\t\t4.652573369E-07").unwrap(),
            vec![10.92357846, 4.652573369e-7]
        );
        assert_eq!(
            reals("1.0 2.0\t3.0   4.0 5.0").unwrap(),
            vec![1.0, 2.0, 3.0, 4.0, 5.0]
        );
    }

    #[test]
    fn integers_that_both_readings_see_differently_are_ambiguous() {
        match read_line::<i64>(b"21\t22") {
            Err(LineIssue::Ambiguous { fixed, note, .. }) => {
                assert_eq!(fixed, "[2122]");
                assert!(note.contains("tab"));
            }
            other => panic!("{other:?}"),
        }
        match read_line::<i64>(b"3 0 2 0 0 1 0") {
            Err(LineIssue::Ambiguous { fixed, free, .. }) => {
                assert_eq!(fixed, "[3020, 10]");
                assert_eq!(free, "[3, 0, 2, 0, 0, 1, 0]");
            }
            other => panic!("{other:?}"),
        }
        assert_eq!(read_line::<i64>(b"      21      22").unwrap(), vec![21, 22]);
    }

    #[test]
    fn only_100_columns_count_for_the_fixed_reading() {
        let mut line = " 1.000000000E+00".repeat(5);
        line.push_str(&" ".repeat(20));
        line.push_str("ignored-text");
        assert_eq!(reals(&line).unwrap(), vec![1.0; 5]);
        let mut line = " 1.000000000E+00".repeat(5);
        line.push_str(&" ".repeat(20));
        line.push_str("7.0");
        match reals(&line) {
            Err(LineIssue::Ambiguous { note, .. }) => assert!(note.contains("column 100")),
            other => panic!("{other:?}"),
        }
    }

    #[test]
    fn blank_field_between_values_reads_zero_in_fixed_columns() {
        // Fixed: [1, 0, 2]; blank-separated: [1, 2]: the line is ambiguous.
        let line = format!("{:>16}{:16}{:>16}", "1.0", "", "2.0");
        assert!(matches!(reals(&line), Err(LineIssue::Ambiguous { .. })));
    }

    #[test]
    fn ambiguity_messages_keep_numbers_short() {
        let line = format!("{:>16}{:>16}", "1.0E-300", "");
        // Fixed [1e-300]; blank-separated [1e-300]: no ambiguity, one value.
        assert_eq!(reals(&line).unwrap(), vec![1e-300]);
        match reals("1.0E-30 1") {
            Err(LineIssue::Ambiguous { fixed, free, .. }) => {
                assert_eq!(fixed, "[1e-301]");
                assert_eq!(free, "[1e-30, 1]");
            }
            other => panic!("{other:?}"),
        }
    }

    #[test]
    fn reference_guide_example_lines() {
        let ints = |s: &str| read_line::<i64>(s.as_bytes()).unwrap();
        assert_eq!(
            ints("     45       15      18      1       0      1       0"),
            vec![45, 15, 18, 1, 0, 1, 0]
        );
        assert_eq!(
            ints("     31      32      33      34      35      36      37      38"),
            vec![31, 32, 33, 34, 35, 36, 37, 38]
        );
        // Block 8 of the guide: irregular spacing, read blank-separated.
        let v = reals(
            "5.596016869E+03   8.234274572E+03  2.320889319E+04  1.215104250E+03  1.729160225E+02",
        );
        assert_eq!(
            v.unwrap(),
            vec![
                5.596016869e3,
                8.234274572e3,
                2.320889319e4,
                1.215104250e3,
                1.729160225e2
            ]
        );
    }

    #[test]
    fn non_utf8_bytes_are_unparsable() {
        let r = read_line::<f64>(b"1.0\xff\xfe 2.0");
        assert!(matches!(r, Err(LineIssue::Unparsable(_))), "{r:?}");
    }
}
