//! The study behind `fxbody-study` (src/bin): speed against accuracy (issue 8). For the standard scenes it runs every
//! method over a range of communication steps, measures the error against the reference
//! and the CPU time per simulated second, finds each method's largest stable step as a
//! multiple of dt_fx, sweeps the mode count of the cantilever (truncation with residual
//! flexibility), and times the dense products a step cannot avoid. Writes `study.csv`,
//! `modes.csv`, `stability.csv`, `bound.csv`, `study.svg` and `study_results.md` to the
//! output folder; peer results (`peers.csv`, written by `study/peers.py`) and the Model
//! Exchange + CVode points (`me.csv`, written by `study/me.py`) are added to the chart
//! and the tables when present.

mod accept;
mod bound;
mod me;
mod modes;
mod run;
mod scenes;
mod stability;

use std::fmt::Write as _;
use std::path::PathBuf;
use std::time::Instant;

use fxbody::fxb::coords::{read_coords, to_map};

use fxbody_chart::{Curve, Panel, Scale, Style, svg};
use scenes::{Case, Load, Reference, Variant, doublings, fe_response, fixture, variants};

/// Arguments of `fxbody-study`.
#[derive(Debug, clap::Args)]
pub struct StudyArgs {
    /// Folder with the shipped fixtures.
    #[arg(long, default_value = "fixtures")]
    pub fixtures: PathBuf,
    /// Output folder (created if needed). The default is a folder of its own in the
    /// current directory; `--out docs` refreshes the repository's committed results.
    #[arg(long, default_value = "study-out")]
    pub out: PathBuf,
    /// A few seconds' version: three steps per scene, short runs and timings (for the
    /// smoke test).
    #[arg(long)]
    pub quick: bool,
    /// Run only the spin-rate stability study of the explicit free-body method and
    /// write `spin.csv` (the other outputs are left as they are).
    #[arg(long)]
    pub spin_only: bool,
}

/// One CSV row.
struct Row {
    scene: String,
    method: String,
    h: f64,
    point: run::Point,
}

fn build_cases(args: &StudyArgs) -> Result<Vec<Case>, String> {
    let dir = &args.fixtures;
    let (cant, cj) = fixture(dir, "cantilever")?;
    let (free, fj) = fixture(dir, "freefree")?;
    let cant_steps = if args.quick {
        doublings(2e-4, -1, 1)
    } else {
        doublings(2e-4, -2, 5)
    };
    let free_steps = if args.quick {
        doublings(2.5e-5, 1, 3)
    } else {
        doublings(2.5e-5, 0, 6)
    };
    let mut cases = Vec::new();
    for name in ["step", "pulse"] {
        let (r, load, duration) = fe_response(&cj, name)?;
        cases.push(Case {
            name: format!("cantilever {name}"),
            scene: cant.clone(),
            load,
            duration,
            components: 1,
            steps: cant_steps.clone(),
            reference: Some(r),
        });
    }
    // The loaded plane's first frequency (fy bends about z: the second mode here).
    let f_loaded = cj
        .get("frequencies_hz")
        .and_then(|f| f.get("euler_bernoulli_planes"))
        .and_then(|p| p.get("xy"))
        .and_then(scenes::nums)
        .and_then(|v| v.first().copied())
        .unwrap_or(cant.body.frequencies_hz()[0]);
    cases.push(Case {
        name: format!("cantilever chirp 0-{:.0} Hz", 5.0 * f_loaded),
        scene: cant.clone(),
        load: Load::Chirp {
            f: 1.0,
            f1: 5.0 * f_loaded,
            t_end: 1.0,
        },
        duration: if args.quick { 0.2 } else { 1.0 },
        components: 1,
        steps: cant_steps.clone(),
        reference: None,
    });
    let (r, load, duration) = fe_response(&fj, "pulse")?;
    // H = 1e-3 s as well: a master's step the acceptance of issue 18 names.
    let mut pulse_steps = free_steps.clone();
    if !args.quick {
        pulse_steps.push(1e-3);
        pulse_steps.sort_by(f64::total_cmp);
    }
    cases.push(Case {
        name: "free-free pulse".into(),
        scene: free.clone(),
        load,
        duration,
        components: 1,
        steps: pulse_steps,
        reference: Some(r),
    });
    let mut tumble = free.clone();
    tumble.w0 = [2.0, 5.0, 20.0];
    cases.push(Case {
        name: "free tumble".into(),
        scene: tumble,
        load: Load::None,
        duration: if args.quick { 0.05 } else { 0.3 },
        components: 3,
        steps: free_steps,
        reference: None,
    });
    // The free truss: the body the Exudyn peer can take (translational DOFs only).
    let (truss, tj) = fixture(dir, "truss")?;
    let (r, load, duration) = fe_response(&tj, "pulse")?;
    cases.push(Case {
        name: "truss pulse".into(),
        scene: truss,
        load,
        duration,
        components: 1,
        steps: if args.quick {
            doublings(2.5e-6, 2, 4)
        } else {
            doublings(2.5e-6, 1, 5)
        },
        reference: Some(r),
    });
    Ok(cases)
}

/// Fine-step references where the fixtures have no FE history: the exact method for the
/// chirp, the implicit method (rho 0.9) for the tumble, each cross-checked against a
/// second method at the same fine step (the difference is reported).
fn fine_references(
    cases: &mut [Case],
    vs: &[Variant],
    fe_chirp: &std::path::Path,
    notes: &mut String,
) -> Result<(), String> {
    for case in cases.iter_mut().filter(|c| c.reference.is_none()) {
        let grid = case.steps[0];
        let sub = 8;
        let h = grid / sub as f64;
        let (main, check) = if case.scene.body.is_blocked() {
            (&vs[0], &vs[1])
        } else {
            (&vs[1], &vs[3])
        };
        eprintln!("reference for {}: {} at h = {h:.3e}", case.name, main.label);
        let u = run::history(case, main, h, sub, case.components)?;
        let mut w = run::history(case, check, h, sub, case.components)?;
        let mut reference = Reference {
            dt: grid,
            u,
            what: format!("{} at h = {h:.3e} s (not independent)", main.label),
        };
        let mut vs_label = check.label;
        if let Some(fe) = chirp_fe(case, grid, fe_chirp)? {
            // The independent FE reference replaces the fine run, which is compared to it.
            w = std::mem::replace(&mut reference, fe).u;
            vs_label = main.label;
        }
        let peak = reference.peak();
        let diff = reference
            .u
            .iter()
            .zip(&w)
            .map(|(a, b)| {
                a.iter()
                    .zip(b)
                    .map(|(x, y)| (x - y) * (x - y))
                    .sum::<f64>()
                    .sqrt()
            })
            .fold(0.0, f64::max)
            / peak;
        let _ = writeln!(
            notes,
            "- {}: reference = {}; {} at h = {h:.3e} s differs from it by {:.2e} of the peak.",
            case.name, reference.what, vs_label, diff
        );
        case.reference = Some(reference);
    }
    Ok(())
}

/// The full-FE chirp response written by `study/chirp_ref.py`, when it exists and was
/// made for this case's chirp and grid; `None` otherwise.
fn chirp_fe(case: &Case, grid: f64, path: &std::path::Path) -> Result<Option<Reference>, String> {
    let Load::Chirp { f1, t_end, .. } = case.load else {
        return Ok(None);
    };
    let Some(text) = read_optional(path)? else {
        return Ok(None);
    };
    let mut lines = text.lines();
    let head = lines.next().unwrap_or("");
    let param = |key: &str| -> Option<f64> {
        head.trim_start_matches('#')
            .split(',')
            .find_map(|kv| kv.trim().strip_prefix(key)?.strip_prefix('=')?.parse().ok())
    };
    let same = |a: Option<f64>, b: f64| a.is_some_and(|a| (a - b).abs() <= 1e-9 * b.abs());
    // The file's grid must divide the case's grid: every `every`-th sample is kept.
    let every = param("grid").map_or(0.0, |g| (grid / g).round());
    let fits = every >= 1.0 && same(param("grid").map(|g| g * every), grid);
    if !(same(param("f1"), f1) && same(param("t_end"), t_end) && fits) {
        eprintln!(
            "{}: made for another chirp or grid, ignored",
            path.display()
        );
        return Ok(None);
    }
    let every = every as usize;
    let mut u = Vec::new();
    for (no, l) in lines.enumerate().filter(|(no, _)| no % every == 0) {
        let mut it = l.split(',');
        let (Some(t), Some(v)) = (it.next(), it.next()) else {
            return Err(format!(
                "{}: line {}: expected t,uy",
                path.display(),
                no + 2
            ));
        };
        let bad = |_| format!("{}: line {}: not a number", path.display(), no + 2);
        let t: f64 = t.trim().parse().map_err(bad)?;
        if t > case.duration * (1.0 + 1e-9) {
            break;
        }
        u.push(vec![v.trim().parse::<f64>().map_err(bad)?]);
    }
    let modes = param("modes").unwrap_or(0.0);
    Ok(Some(Reference {
        dt: grid,
        u,
        what: format!("full FE model, all {modes:.0} modes (study/chirp_ref.py)"),
    }))
}

/// Peer rows from `peers.csv`: peer, scene, h, error, ns_per_step, cpu_per_s, note.
fn read_peers(path: &std::path::Path) -> Result<Vec<Vec<String>>, String> {
    Ok(read_optional(path)?
        .map(|t| {
            t.lines()
                .skip(1)
                .filter(|l| !l.trim().is_empty())
                .map(|l| l.split(',').map(|s| s.trim().to_string()).collect())
                .filter(|r: &Vec<String>| r.len() >= 6)
                .collect()
        })
        .unwrap_or_default())
}

/// A file of the output folder the study reads when it is there (`--out`: the
/// references and peer results the Python scripts write): `None` when missing, refused
/// when it is no regular text file of a sane size ([`fxbody::fxb::input::read_input`]).
fn read_optional(path: &std::path::Path) -> Result<Option<String>, String> {
    use fxbody::fxb::input::{Limit, read_input};
    if !path.exists() {
        return Ok(None);
    }
    let bytes = read_input("--out", path, Limit::Reference).map_err(|e| e.to_string())?;
    String::from_utf8(bytes)
        .map(Some)
        .map_err(|_| format!("--out {}: not UTF-8 text", path.display()))
}

/// Run the study.
pub fn run(args: &StudyArgs) -> Result<(), String> {
    let start = Instant::now();
    std::fs::create_dir_all(&args.out)
        .map_err(|e| format!("{}: cannot create: {e}", args.out.display()))?;
    if args.spin_only {
        return spin_map(args);
    }
    let vs = variants();
    let mut cases = build_cases(args)?;
    let mut notes = String::new();
    fine_references(&mut cases, &vs, &args.out.join("chirp_ref.csv"), &mut notes)?;
    for c in cases.iter().filter(|c| c.reference.is_some()) {
        let r = c
            .reference
            .as_ref()
            .map(|r| r.what.clone())
            .unwrap_or_default();
        if !notes.contains(&format!("- {}:", c.name)) {
            let _ = writeln!(notes, "- {}: reference = {r}.", c.name);
        }
    }
    let min_time = if args.quick { 0.005 } else { 0.25 };
    let total: usize = cases
        .iter()
        .map(|c| c.steps.len() * vs.iter().filter(|v| v.offered(&c.scene)).count())
        .sum();
    let mut rows = Vec::new();
    for case in &cases {
        for v in vs.iter().filter(|v| v.offered(&case.scene)) {
            for &h in &case.steps {
                let p = run::measure(case, v, h, min_time);
                eprintln!(
                    "[{:>3}/{total}] {:<34} {:<17} h = {h:.3e}  error {:.3e}  cpu/s {:.3e}{}",
                    rows.len() + 1,
                    case.name,
                    v.label,
                    p.error,
                    p.cpu_per_s,
                    p.outcome
                        .as_ref()
                        .map(|f| format!("  {f}"))
                        .unwrap_or_default()
                );
                rows.push(Row {
                    scene: case.name.clone(),
                    method: v.label.to_string(),
                    h,
                    point: p,
                });
            }
        }
    }
    let mut csv = String::from(
        "scene,method,h_s,steps,error_rel_peak,cpu_s_per_sim_s,ns_per_step,compared_samples,outcome\n",
    );
    for r in &rows {
        let case = cases
            .iter()
            .find(|c| c.name == r.scene)
            .expect("case of the row");
        let _ = writeln!(
            csv,
            "{},{},{:.6e},{},{:.6e},{:.6e},{:.1},{},{}",
            r.scene,
            r.method,
            r.h,
            (case.duration / r.h).round(),
            r.point.error,
            r.point.cpu_per_s,
            r.point.ns_per_step,
            r.point.compared,
            r.point
                .outcome
                .as_ref()
                .map_or(String::new(), |f| f.to_string().replace(',', ";"))
        );
    }
    write(&args.out.join("study.csv"), &csv)?;

    // Mode-count sweep: cantilever step and pulse (full-FE references), exact and
    // implicit (rho 0.9) at the base step 2e-4 s.
    eprintln!("mode-count sweep");
    let f1 = match cases[2].load {
        Load::Chirp { f1, .. } => f1 / 5.0,
        _ => cases[0].scene.body.frequencies_hz()[0],
    };
    let mode_h = 2e-4;
    let mrows = modes::sweep(
        &[&cases[0], &cases[1]],
        &[&vs[0], &vs[1]],
        f1,
        mode_h,
        min_time,
    )?;
    let (mcsv, mmd) = modes::report(&mrows);
    write(&args.out.join("modes.csv"), &mcsv)?;

    // Stability map.
    eprintln!(
        "stability map (bisection on energy growth over {} steps)",
        stability::STEPS
    );
    let mut stab = String::from("body,method,dt_fx_s,largest_stable_h_over_dt_fx,why_beyond\n");
    let mut stab_md = String::from(
        "| body | method | dt_fx (s) | largest stable h / dt_fx | beyond it |\n|---|---|---|---|---|\n",
    );
    let (damped, _) = fixture(&args.fixtures, "cantilever_damped")?;
    let bodies = [
        ("cantilever (blocked)", &cases[0].scene),
        ("cantilever_damped (blocked; Rayleigh)", &damped),
        ("free-free (free)", &cases[3].scene),
    ];
    for (body, scene) in bodies {
        let dt = stability::dt_fx(scene);
        for v in vs.iter().filter(|v| v.offered(scene)) {
            let (ratio, why) = stability::largest_stable(scene, v);
            let shown = ratio.map_or(format!(">= {:.0e}", stability::MAX_RATIO), |r| {
                format!("{r:.4}")
            });
            eprintln!("  {body:<22} {:<17} {shown} {why}", v.label);
            let _ = writeln!(
                stab,
                "{body},{},{dt:.6e},{shown},{}",
                v.label,
                why.replace(',', ";")
            );
            let _ = writeln!(
                stab_md,
                "| {body} | {} | {dt:.3e} | {shown} | {why} |",
                v.label
            );
        }
    }
    write(&args.out.join("stability.csv"), &stab)?;
    // The spin-rate part of the map (explicit free bodies): spin.csv.
    spin_map(args)?;

    // The physical limit.
    eprintln!("dense-product bound");
    let cant = &cases[0].scene;
    let deck = args.fixtures.join("cantilever.nodes.rad");
    let xyz = to_map(&read_coords(&deck).map_err(|e| format!("{}: {e}", deck.display()))?);
    let all: Vec<usize> = (0..cant.body.nnodes()).collect();
    let all_x0: Vec<[f64; 3]> = cant
        .body
        .node_ids()
        .iter()
        .map(|id| xyz.get(id).copied().unwrap_or([0.0; 3]))
        .collect();
    let h = 0.999 * 0.9 * stability::dt_fx(cant);
    let rounds = if args.quick { 3 } else { 25 };
    let mut brows = Vec::new();
    let blocked: Vec<Variant> = vs.iter().filter(|v| v.offered(cant)).copied().collect();
    for (nodes, x0) in [(cant.nodes.clone(), cant.x0.clone()), (all, all_x0)] {
        brows.push(bound::measure(cant, nodes, x0, &blocked, h, rounds)?);
    }
    let mut bcsv = String::from("nodes,modes,h_s,bound_ns,method,ns_per_cycle,ratio\n");
    let mut bmd = String::from(
        "| exposed nodes | modes | bound (ns) | method | ns per cycle | x bound |\n|---|---|---|---|---|---|\n",
    );
    for b in &brows {
        for (m, ns) in &b.methods {
            let _ = writeln!(
                bcsv,
                "{},{},{:.4e},{:.1},{m},{ns:.1},{:.2}",
                b.nodes,
                b.modes,
                b.h,
                b.bound_ns,
                ns / b.bound_ns
            );
            let _ = writeln!(
                bmd,
                "| {} | {} | {:.0} | {m} | {ns:.0} | {:.1} |",
                b.nodes,
                b.modes,
                b.bound_ns,
                ns / b.bound_ns
            );
        }
    }
    write(&args.out.join("bound.csv"), &bcsv)?;

    // Peers (written beforehand by study/peers.py, same body, scene and step), and the
    // Model Exchange points (study/me.py, same scenes and error measure).
    let peers = read_peers(&args.out.join("peers.csv"))?;
    let me_csv = args.out.join("me.csv");
    let me_points = me::parse(read_optional(&me_csv)?.as_deref(), &me_csv)?;
    let mut pmd = String::new();
    if !peers.is_empty() {
        pmd.push_str("| peer | scene | h (s) | peer error | peer ns/step | ours | our error | our ns/step | peer / ours (time) |\n|---|---|---|---|---|---|---|---|---|\n");
        for p in &peers {
            let h: f64 = p[2].parse().unwrap_or(f64::NAN);
            // Same method as the peer where we have it (numpy: exact), else all.
            let same_method = |r: &&Row| !p[0].starts_with("numpy") || r.method == "exact";
            for r in rows
                .iter()
                .filter(|r| {
                    r.scene == p[1] && ((r.h - h).abs() < 1e-9 * h) && r.point.outcome.is_none()
                })
                .filter(same_method)
            {
                let ns: f64 = p[4].parse().unwrap_or(f64::NAN);
                let _ = writeln!(
                    pmd,
                    "| {} | {} | {h:.2e} | {} | {ns:.0} | {} | {:.2e} | {:.0} | {:.1} |",
                    p[0],
                    p[1],
                    p[3],
                    r.method,
                    r.point.error,
                    r.point.ns_per_step,
                    ns / r.point.ns_per_step
                );
            }
        }
    }

    // Chart.
    let mut panels = Vec::new();
    for case in &cases {
        let mut curves = Vec::new();
        for v in vs.iter() {
            let pts: Vec<(f64, f64)> = rows
                .iter()
                .filter(|r| r.scene == case.name && r.method == v.label)
                .map(|r| (r.point.cpu_per_s, r.point.error))
                .collect();
            if !pts.is_empty() {
                curves.push(Curve {
                    label: v.label.to_string(),
                    color: v.color.to_string(),
                    points: pts,
                    style: Style::Line,
                });
            }
        }
        for (name, color) in [
            ("numpy exact state space", "#7b3294"),
            ("exudyn", "#e08214"),
        ] {
            let pts: Vec<(f64, f64)> = peers
                .iter()
                .filter(|p| p[0] == name && p[1] == case.name)
                .filter_map(|p| Some((p[5].parse().ok()?, p[3].parse().ok()?)))
                .collect();
            if !pts.is_empty() {
                curves.push(Curve {
                    label: name.to_string(),
                    color: color.to_string(),
                    points: pts,
                    style: Style::Markers,
                });
            }
        }
        curves.extend(me::curve(&me_points, &case.name));
        let fe = case
            .reference
            .as_ref()
            .is_some_and(|r| r.what.starts_with("full FE"));
        panels.push(Panel {
            title: format!(
                "{} (ref: {})",
                case.name,
                if fe { "full FE" } else { "fine-step run" }
            ),
            x_label: "CPU s per simulated s".into(),
            y_label: "max error / peak".into(),
            x: Scale::Log,
            y: Scale::Log,
            curves,
        });
    }
    write(
        &args.out.join("study.svg"),
        &svg(
            "fxbody: error vs CPU time, one point per communication step",
            &panels,
            3,
            (360.0, 260.0),
        ),
    )?;

    let mut md = String::from("# Study results (generated by `fxbody-study`; do not edit)\n\n");
    let _ = writeln!(md, "References:\n{notes}");
    md.push_str("## Mode count\n\n");
    let _ = writeln!(
        md,
        "Local modes kept up to fmax = k f1 (f1 = {f1:.2} Hz, the loaded plane's first frequency), the dropped modes' static (residual) flexibility added at the tip; h = {mode_h:e} s; error against the full FE model (all modes).\n"
    );
    md.push_str(&mmd);
    md.push('\n');
    let pts: Vec<accept::Pt> = rows
        .iter()
        .map(|r| {
            (
                r.scene.as_str(),
                r.method.as_str(),
                r.h,
                r.point.error,
                r.point.cpu_per_s,
            )
        })
        .collect();
    let (accept_md, failed) = accept::report(&pts);
    md.push_str(&accept_md);
    md.push_str("## Stability map\n\n");
    md.push_str(&stab_md);
    let _ = writeln!(
        md,
        "\nA trial: one step of load of impulse {:e} on all six tip components, then {} steps of free vibration without sub-cycling; unstable when the final energy exceeds {} times the largest of the first ten steps, or a step fails.\n",
        stability::IMPULSE,
        stability::STEPS,
        stability::GROWTH
    );
    md.push_str("## The physical limit\n\n");
    let _ = writeln!(
        md,
        "One communication cycle (`set_loads + step + positions`) at h = {h:.3e} s (one internal explicit step) against the two dense products no step can avoid (load projection nL x 6m, position output 3m x nL), same run.\n"
    );
    md.push_str(&bmd);
    if !pmd.is_empty() {
        md.push_str("\n## Peers\n\n");
        md.push_str(&pmd);
    }
    if !me_points.is_empty() {
        md.push_str("\n## Model Exchange + CVode (fmpy, study/me.py)\n\n");
        md.push_str(&me::table(&me_points));
    }
    md.push_str(
        "\n## Error and CPU time per point\n\nSee `study.csv` (all points) and `study.svg`.\n",
    );
    write(&args.out.join("study_results.md"), &md)?;
    eprintln!(
        "wrote study.csv, modes.csv, stability.csv, bound.csv, study.svg, study_results.md to {} in {:.0} s",
        args.out.display(),
        start.elapsed().as_secs_f64()
    );
    if failed.is_empty() {
        Ok(())
    } else {
        Err(format!("acceptance check failed: {}", failed.join("; ")))
    }
}

fn write(path: &std::path::Path, text: &str) -> Result<(), String> {
    std::fs::write(path, text).map_err(|e| format!("{}: {e}", path.display()))
}

/// The spin-rate stability map of the explicit free-body method (`spin.csv`): for each
/// free fixture and rotation per step on the grid, the largest frame error and the
/// energy change of a free spin (stability.rs, `spin`).
fn spin_map(args: &StudyArgs) -> Result<(), String> {
    use stability::spin;
    let steps = if args.quick { 200 } else { spin::SPIN_STEPS };
    let mut csv = String::from(
        "body,axis,dt_fx_s,h_s,omega_rad_s,omega_h,max_frame_error,energy_change,passes,method\n",
    );
    for (name, axis_name) in [
        ("freefree", "e3"),
        ("freefree", "e1"),
        ("freefree", "tumble"),
        ("truss", "e3"),
        ("truss", "tumble"),
    ] {
        let (scene, _) = fixture(&args.fixtures, name)?;
        let dt = stability::dt_fx(&scene);
        let p0 = scene.body.p0();
        let axis = match axis_name {
            "e1" => [p0[(0, 0)], p0[(1, 0)], p0[(2, 0)]],
            "e3" => [p0[(0, 2)], p0[(1, 2)], p0[(2, 2)]],
            _ => spin::TUMBLE,
        };
        for (r, split) in spin::grid()
            .into_iter()
            .flat_map(|r| [(r, false), (r, true)])
        {
            let t = spin::trial(&scene, axis, r, steps, split);
            let method = if split { "split" } else { "explicit" };
            eprintln!(
                "  spin {method:<8} {name:<9} {axis_name:<6} omega h = {r:<6} omega = {:.4e} frame error {:.3e} energy {:+.3e} {}",
                t.omega,
                t.frame_error,
                t.energy_change,
                if t.passes() {
                    "within tolerance"
                } else {
                    "beyond tolerance"
                }
            );
            let _ = writeln!(
                csv,
                "{name},{axis_name},{dt:.6e},{:.6e},{:.6e},{r},{:.3e},{:.3e},{},{method}",
                spin::SPIN_H_OVER_DT_FX * dt,
                t.omega,
                t.frame_error,
                t.energy_change,
                t.passes()
            );
        }
    }
    write(&args.out.join("spin.csv"), &csv)
}
