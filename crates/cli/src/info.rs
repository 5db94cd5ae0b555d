//! `fxbody info FILE [--json]`: what a flexible-body file holds and what it implies for
//! a simulation (frequencies, the explicit scheme's stable step, the mass).

use std::fmt::Write;
use std::path::PathBuf;
use std::sync::Arc;

use fxbody::body::Body;
use fxbody::body::mass_props::{MassProperties, mass_properties};

/// Arguments of `info`.
#[derive(Debug, clap::Args)]
pub struct InfoArgs {
    /// The `.fxb` file.
    pub file: PathBuf,
    /// Print one JSON object instead of text.
    #[arg(long)]
    pub json: bool,
    /// Also report, at these node IDs (and ranges A-B, separated by commas and/or
    /// blanks), each mode's participation: the share of the node's flexibility in the
    /// local modes (blocked bodies: of the static deflection; free bodies: relative to
    /// the frame, under inertia relief) carried by the modes up to it, and (free bodies
    /// whose modes carry mass with the rigid motion) the effective masses: what
    /// truncation costs. With --json, the `modes` key of the one object.
    #[arg(long, value_parser = crate::grammar::node_list)]
    pub nodes: Option<crate::grammar::NodeIds>,
}

/// What `info` reports, computed once for both output forms.
struct Info {
    body: Arc<Body>,
    nbmod: usize,
    idamp: bool,
    freq_max_hz: f64,
    dt_stab_s: f64,
    mass: Option<f64>,
    /// Free bodies: mass, centre of gravity and inertia from M_R.
    props: Option<MassProperties>,
    /// `--nodes`: the per-mode report (text, or the JSON value of `modes`).
    modes: Option<String>,
}

/// The stable step (before the 0.9 factor) the explicit method uses on `body`: the local
/// modes' (`Body::explicit_stable_step`) for a blocked body; for a free body the free
/// explicit solver's own, which also bounds the modes coupled to the rigid motion (a
/// truncated body's can be stiffer than its local modes). Falls back to the local
/// modes' value when the solver refuses the body (the solver says why when it is used).
fn explicit_stable_step(body: &Arc<Body>) -> f64 {
    if body.is_blocked() || body.node_ids().is_empty() {
        return body.explicit_stable_step();
    }
    // The body shared, not copied: a large body's modes are tens of MB.
    let scene = fxbody::scene::Scene::new(Arc::clone(body), vec![0], vec![[0.0; 3]]);
    match fxbody::solver::free::Explicit::new(&scene, &fxbody::solver::Options::default()) {
        Ok(s) => s.stable_step(),
        Err(_) => body.explicit_stable_step(),
    }
}

/// Run `info`: the report on stdout, or the error message (for exit code 2).
pub fn run(args: &InfoArgs) -> Result<(), String> {
    let progress = super::progress::Progress::start("checking");
    let how = fxbody::body::LoadOptions {
        progress: Some(&mut |done, total| progress.update(done, total)),
        ..Default::default()
    };
    let body = fxbody::body::load(&args.file, how)
        .map_err(|e| not_a_body(&args.file).unwrap_or_else(|| e.to_string()))?;
    let body = Arc::new(body);
    // The node list is checked before anything is printed.
    let modes = match &args.nodes {
        Some(ids) => {
            let nodes = fxbody::scene::reduce::node_indices(&body, &ids.0)
                .map_err(|e| format!("--nodes: {e}"))?;
            Some(super::info_modes::report(&body, &nodes, args.json))
        }
        None => None,
    };
    let info = Info {
        props: mass_properties(&body),
        modes,
        nbmod: body.nl(),
        idamp: body.damping().is_some(),
        freq_max_hz: body.freq_max_hz(),
        // The step the explicit solvers really use: from the largest computed frequency
        // (the stored Freq is printed beside it, and may be wrong), and for a free body
        // from its modes coupled to the rigid motion when those are stiffer.
        dt_stab_s: explicit_stable_step(&body),
        mass: body.total_mass(),
        body,
    };
    drop(progress);
    let out = if args.json {
        json(&info)
    } else {
        text(&info, &args.file)
    };
    print!("{out}");
    Ok(())
}

/// When `path` is a Radioss node deck (a `/NODE` keyword line in its first 64 KiB) rather
/// than a body: the message saying so, and where such a file goes.
pub fn not_a_body(path: &std::path::Path) -> Option<String> {
    use std::io::Read;
    // Only a regular file is looked into: a FIFO or a device would block or never end.
    if !std::fs::metadata(path).ok()?.is_file() {
        return None;
    }
    let mut head = Vec::new();
    std::fs::File::open(path)
        .ok()?
        .take(64 * 1024)
        .read_to_end(&mut head)
        .ok()?;
    let deck = head
        .split(|&c| c == b'\n')
        .any(|l| l.starts_with(b"/NODE") && l.get(5).is_none_or(|c| !c.is_ascii_alphanumeric()));
    deck.then(|| {
        format!(
            "{}: this is a node deck (/NODE), not a body: give it to `pack --coords` or \
             `import --coords`; info reads a flexible-body file (.fxb)",
            path.display()
        )
    })
}

/// A number that reads back to the same f64; `null` when not finite.
fn num(v: f64) -> String {
    if v.is_finite() {
        format!("{v:?}")
    } else {
        "null".into()
    }
}

fn json_str(s: &str) -> String {
    let mut out = String::with_capacity(s.len() + 2);
    out.push('"');
    for c in s.chars() {
        match c {
            '"' => out.push_str("\\\""),
            '\\' => out.push_str("\\\\"),
            c if (c as u32) < 0x20 => {
                let _ = write!(out, "\\u{:04x}", c as u32);
            }
            c => out.push(c),
        }
    }
    out.push('"');
    out
}

fn list<T>(items: &[T], f: impl Fn(&T) -> String) -> String {
    let v: Vec<String> = items.iter().map(f).collect();
    format!("[{}]", v.join(", "))
}

fn json(i: &Info) -> String {
    let b = &i.body;
    let flag = |x: bool| u8::from(x);
    let mut o = String::from("{\n");
    let _ = writeln!(o, "  \"nbmod\": {},", i.nbmod);
    let _ = writeln!(o, "  \"nbstat\": {},", b.nbstat());
    let _ = writeln!(o, "  \"nbnod\": {},", b.nnodes());
    let _ = writeln!(o, "  \"irot\": {},", flag(b.irot()));
    let _ = writeln!(o, "  \"idamp\": {},", flag(i.idamp));
    let _ = writeln!(o, "  \"iblo\": {},", flag(b.is_blocked()));
    let _ = writeln!(o, "  \"ifile\": {},", flag(b.ifile()));
    let _ = writeln!(
        o,
        "  \"node_ids\": {},",
        list(b.node_ids(), |v| v.to_string())
    );
    let _ = writeln!(o, "  \"freq_file_hz\": {},", num(b.freq_file()));
    let _ = writeln!(o, "  \"freq_max_hz\": {},", num(i.freq_max_hz));
    let _ = writeln!(
        o,
        "  \"frequencies_hz\": {},",
        list(b.frequencies_hz(), |v| num(*v))
    );
    let _ = writeln!(o, "  \"dt_stab_s\": {},", num(i.dt_stab_s));
    let _ = writeln!(o, "  \"mass\": {},", i.mass.map_or("null".into(), num));
    let (alpha, beta) = b.damping().map_or(("null".into(), "null".into()), |d| {
        (num(d.alpha), num(d.beta))
    });
    let _ = writeln!(o, "  \"rayleigh_alpha\": {alpha},");
    let _ = writeln!(o, "  \"rayleigh_beta\": {beta},");
    let (cog, inertia) = i
        .props
        .as_ref()
        .map_or(("null".into(), "null".into()), |p| {
            let c: Vec<f64> = p.cog_from_l0.iter().copied().collect();
            let rows: Vec<String> = (0..3)
                .map(|r| list(&[0, 1, 2], |&c| num(p.inertia[(r, c)])))
                .collect();
            (list(&c, |v| num(*v)), format!("[{}]", rows.join(", ")))
        });
    let _ = writeln!(o, "  \"cog_from_l0\": {cog},");
    let _ = writeln!(o, "  \"inertia_at_cog\": {inertia},");
    if let Some(m) = &i.modes {
        let _ = writeln!(o, "  \"modes\": {},", m.trim_end());
    }
    let _ = writeln!(o, "  \"warnings\": {}", list(b.warnings(), |w| json_str(w)));
    o.push_str("}\n");
    o
}

fn text(i: &Info, path: &std::path::Path) -> String {
    let b = &i.body;
    let flag = |x: bool| u8::from(x);
    let mut o = String::new();
    let _ = writeln!(o, "file: {}", path.display());
    let _ = writeln!(
        o,
        "Nbmod {}  Nbstat {}  Nbnod {}  Irot {}  Idamp {}  Iblo {}  Ifile {} (no effect)",
        i.nbmod,
        b.nbstat(),
        b.nnodes(),
        flag(b.irot()),
        flag(i.idamp),
        flag(b.is_blocked()),
        flag(b.ifile())
    );
    let _ = writeln!(
        o,
        "body: {}",
        if b.is_blocked() {
            "blocked (no rigid motion)"
        } else {
            "free"
        }
    );
    let _ = writeln!(o, "node IDs: {}", abbreviated_ids(b.node_ids()));
    if !b.is_blocked() {
        o.push_str(
            "node positions: fixed relative to the frame origin L0 by the rigid modes; \
             `pack` without --coords puts L0 at (0, 0, 0), a --coords file only places L0\n",
        );
    }
    o.push_str("eigenfrequencies of (K_L, m_L), Hz:");
    for (k, v) in b.frequencies_hz().iter().enumerate() {
        if k % 8 == 0 {
            o.push_str("\n ");
        }
        let _ = write!(o, " {:>11}", significant(*v, 7));
    }
    o.push('\n');
    let _ = writeln!(
        o,
        "stored Freq: {} Hz, largest computed: {} Hz",
        significant(b.freq_file(), 10),
        significant(i.freq_max_hz, 10)
    );
    if let Some(d) = b.damping() {
        let _ = writeln!(
            o,
            "Rayleigh damping: alpha {} 1/s, beta {} s",
            significant(d.alpha, 7),
            significant(d.beta, 7)
        );
    }
    let _ = writeln!(
        o,
        "stable step of the explicit scheme (from the largest computed frequency, as the solvers use it): {} s; the explicit method's internal steps are {} of it: {} s",
        significant(i.dt_stab_s, 7),
        fxbody::solver::Options::default().dt_factor,
        significant(
            fxbody::solver::Options::default().dt_factor * i.dt_stab_s,
            7
        )
    );
    match i.mass {
        Some(m) => {
            let _ = writeln!(o, "total mass (from M_R): {} kg", significant(m, 10));
        }
        None => o.push_str("total mass: not in the file (blocked body)\n"),
    }
    if let Some(p) = &i.props {
        let v = |x: &[f64]| {
            x.iter()
                .map(|v| significant(*v, 7))
                .collect::<Vec<_>>()
                .join(" ")
        };
        let c: Vec<f64> = p.cog_from_l0.iter().copied().collect();
        let _ = writeln!(
            o,
            "centre of gravity (from M_R), relative to the frame origin L0, global axes: {}",
            v(&c)
        );
        o.push_str("inertia tensor at the centre of gravity (from M_R), global axes:\n");
        for r in 0..3 {
            let row: Vec<f64> = (0..3).map(|c| p.inertia[(r, c)]).collect();
            let _ = writeln!(o, "  {}", v(&row));
        }
    }
    if b.warnings().is_empty() {
        o.push_str("warnings: none\n");
    }
    for w in b.warnings() {
        let _ = writeln!(o, "warning: {w}");
    }
    if let Some(m) = &i.modes {
        o.push_str(m);
    }
    o
}

/// Node IDs for reading: all of them up to 20, else the first 10, the last 5 and the count
/// (`--json` always lists every ID).
fn abbreviated_ids(ids: &[i64]) -> String {
    let join = |s: &[i64]| {
        s.iter()
            .map(ToString::to_string)
            .collect::<Vec<_>>()
            .join(" ")
    };
    if ids.len() <= 20 {
        join(ids)
    } else {
        format!(
            "{} ... {} ({} nodes)",
            join(&ids[..10]),
            join(&ids[ids.len() - 5..]),
            ids.len()
        )
    }
}

/// `v` with `digits` significant digits, in plain notation for magnitudes from 1e-4 to
/// below 1e7 and in scientific notation (`1.234e-5`) outside that range.
fn significant(v: f64, digits: usize) -> String {
    if v == 0.0 || !v.is_finite() {
        return format!("{v}");
    }
    let exp = v.abs().log10().floor() as i32;
    if (-4..7).contains(&exp) {
        let decimals = (digits as i32 - 1 - exp).max(0) as usize;
        format!("{v:.decimals$}")
    } else {
        format!("{v:.prec$e}", prec = digits - 1)
    }
}
