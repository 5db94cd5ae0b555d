//! `fxbody demo`: the main job end to end. Packs the shipped cantilever into `out/`,
//! loads the packed library through its own C ABI (as any FMI master would), applies a
//! 1 N tip step load, and reports the tip response against the fixture's full
//! finite-element reference, the cost per communication step, and writes a CSV and an
//! SVG plot of the tip motion.

use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use std::time::Instant;

use fxbody::fmu::pack::{PackOptions, PackRequest, find_library, pack};
use fxbody::scene::io::load_resources;
use fxbody::solver::{self, Options};
use fxbody_chart::{Curve, Panel, Scale, Style, svg};
use fxbody_host::{FmuLibrary, file_uri};
use serde_json::Value as Json;

/// Arguments of `demo`.
#[derive(Debug, clap::Args)]
pub struct DemoArgs {
    /// Folder with the shipped fixtures.
    #[arg(long, default_value = "fixtures")]
    pub fixtures: PathBuf,
    /// Output folder (created if needed).
    #[arg(long, default_value = "out")]
    pub out: PathBuf,
    /// The FMU library to embed (default: $FXBODY_LIB, else next to this executable).
    #[arg(long)]
    pub lib: Option<PathBuf>,
}

/// The reference step response of the fixture.
struct Reference {
    tip: i64,
    amplitude: f64,
    t: Vec<f64>,
    uy: Vec<f64>,
    static_uy: Option<f64>,
}

/// The numbers of a JSON array; `None` if it is not an array of numbers.
fn nums(v: &Json) -> Option<Vec<f64>> {
    v.as_array()?.iter().map(Json::as_f64).collect()
}

fn reference(path: &Path) -> Result<Reference, String> {
    use fxbody::fxb::input::{Limit, read_input};
    let text = read_input("--fixtures", path, Limit::Reference).map_err(|e| e.to_string())?;
    let j =
        serde_json::from_slice::<Json>(&text).map_err(|e| format!("{}: {e}", path.display()))?;
    let bad = |what: &str| format!("{}: missing or malformed {what}", path.display());
    let tip = j
        .get("tip_node")
        .and_then(Json::as_f64)
        .ok_or_else(|| bad("tip_node"))? as i64;
    let step = j
        .get("responses")
        .and_then(Json::as_array)
        .into_iter()
        .flatten()
        .find(|r| r.get("name").and_then(Json::as_str) == Some("step"))
        .ok_or_else(|| bad("responses[name=step]"))?;
    let key = tip.to_string();
    let static_uy = j
        .get("static")
        .and_then(Json::as_array)
        .into_iter()
        .flatten()
        .find_map(|s| {
            (s.get("load_dof").and_then(Json::as_str) == Some("fy")
                && s.get("load_node").and_then(Json::as_f64) == Some(tip as f64))
            .then(|| {
                s.get("displacements")?
                    .get(&key)
                    .and_then(nums)?
                    .get(1)
                    .copied()
            })
            .flatten()
        });
    Ok(Reference {
        tip,
        amplitude: step
            .get("amplitude")
            .and_then(Json::as_f64)
            .ok_or_else(|| bad("amplitude"))?,
        t: step.get("t").and_then(nums).ok_or_else(|| bad("t"))?,
        uy: step
            .get("nodes")
            .and_then(|n| n.get(&key))
            .and_then(|n| n.get("uy"))
            .and_then(nums)
            .ok_or_else(|| bad("uy"))?,
        static_uy,
    })
}

/// Run `demo`.
pub fn run(args: &DemoArgs) -> Result<(), String> {
    let body = args.fixtures.join("cantilever.fxb");
    if !body.is_file() {
        return Err(format!(
            "{}: not found: demo runs on the fixtures shipped in the repository's fixtures/ folder \
             (cantilever.fxb, cantilever.nodes.rad, cantilever.ref.json); run it from the repository \
             root or give --fixtures PATH/TO/fixtures",
            body.display()
        ));
    }
    let r = reference(&args.fixtures.join("cantilever.ref.json"))?;
    std::fs::create_dir_all(&args.out)
        .map_err(|e| format!("{}: cannot create: {e}", args.out.display()))?;
    let lib = find_library(args.lib.as_deref()).map_err(|e| crate::pack::worded(&e, "--out"))?;
    let fmu = args.out.join("cantilever.fmu");
    let req = PackRequest {
        body,
        coords: Some(args.fixtures.join("cantilever.nodes.rad")),
        nodes: Some(vec![r.tip]),
        name: Some("cantilever".into()),
        units: Some("SI".into()),
        ..PackRequest::default()
    };
    let p = pack(&req, &PackOptions::default(), &lib, &fmu, None)
        .map_err(|e| crate::pack::worded(&e, "--out"))?;
    let size = std::fs::metadata(&fmu).map(|m| m.len()).unwrap_or(0);
    println!(
        "packed {} ({:.1} MB, GUID {})",
        fmu.display(),
        size as f64 / 1e6,
        p.guid
    );

    // Unpack as a master does, then drive the library through the C ABI.
    let dir = std::path::absolute(args.out.join("cantilever")).map_err(|e| e.to_string())?;
    let bytes = std::fs::read(&fmu).map_err(|e| e.to_string())?;
    for (name, data) in fxbody_host::zip::read(&bytes)? {
        let path = dir.join(&name);
        if let Some(parent) = path.parent() {
            std::fs::create_dir_all(parent).map_err(|e| format!("{}: {e}", parent.display()))?;
        }
        std::fs::write(&path, data).map_err(|e| format!("{}: {e}", path.display()))?;
    }
    let so = dir.join(format!(
        "binaries/linux64/{}.so",
        p.options.model_identifier()
    ));
    let library = FmuLibrary::open(&so)?;
    let inst = library.instantiate("demo", &p.guid, &file_uri(&dir.join("resources")), false)?;
    let vr = |n: &str| {
        p.table
            .vars
            .iter()
            .find(|v| v.name == n)
            .map(|v| v.vr)
            .ok_or(format!("no variable {n}"))
    };
    let tip = r.tip;
    let vr_f = vr(&format!("node_{tip}.fy"))?;
    let outs = [
        vr(&format!("node_{tip}.y"))?,
        vr(&format!("node_{tip}.vy"))?,
    ];
    inst.setup(0.0, None)?;
    inst.enter_init()?;
    inst.exit_init()?;
    let mut y0 = [0.0; 2];
    inst.get_real(&outs, &mut y0)?;
    let n = r.t.len();
    let h = r.t[1] - r.t[0];
    let (mut uy, mut vy) = (vec![0.0; n], vec![0.0; n]);
    let mut o = [0.0; 2];
    let started = Instant::now();
    for k in 1..n {
        inst.set_real(&[vr_f], &[r.amplitude])?;
        inst.do_step(r.t[k - 1], h)?;
        inst.get_real(&outs, &mut o)?;
        uy[k] = o[0] - y0[0];
        vy[k] = o[1];
    }
    let scene_time = started.elapsed().as_secs_f64();
    inst.terminate()?;
    drop(inst);

    let (kpk, peak) = uy.iter().enumerate().fold((0, 0.0f64), |(kb, b), (k, &v)| {
        if v.abs() > b.abs() { (k, v) } else { (kb, b) }
    });
    let ref_peak =
        r.uy.iter()
            .fold(0.0f64, |b, &v| if v.abs() > b.abs() { v } else { b });
    let err = uy
        .iter()
        .zip(&r.uy)
        .map(|(a, b)| (a - b).abs())
        .fold(0.0, f64::max);
    println!(
        "\ncantilever, 1 N step load on tip node {tip} (exact method, h = {h} s, {} steps):",
        n - 1
    );
    println!(
        "  peak tip deflection  {peak:.6e} m at t = {:.4} s",
        r.t[kpk]
    );
    println!(
        "  full-FE reference    {ref_peak:.6e} m (difference {:.3}% of peak)",
        100.0 * (peak - ref_peak).abs() / ref_peak.abs()
    );
    println!(
        "  largest deviation from the full-FE history: {err:.3e} m ({:.3}% of peak)",
        100.0 * err / ref_peak.abs()
    );
    if let Some(s) = r.static_uy {
        let mean = uy.iter().sum::<f64>() / n as f64;
        println!(
            "  static deflection (full FE) {s:.6e} m; dynamic amplification {:.3} (undamped step: 2); mean over the run {mean:.6e} m",
            peak / s
        );
    }
    println!(
        "  whole scene through the C ABI: {:.3} ms",
        scene_time * 1e3
    );

    // Cost per communication step: C ABI vs the solver called directly, with a load
    // that changes every step (as in a coupled run) so that neither side can skip work.
    let steps = 200_000;
    let load = |k: usize| r.amplitude * (1e-3 * k as f64).sin();
    let inst = library.instantiate("timing", &p.guid, &file_uri(&dir.join("resources")), false)?;
    inst.setup(0.0, None)?;
    inst.enter_init()?;
    inst.exit_init()?;
    let started = Instant::now();
    let mut t = 0.0;
    for k in 0..steps {
        inst.set_real(&[vr_f], &[load(k)])?;
        inst.do_step(t, h)?;
        inst.get_real(&outs[..1], &mut o[..1])?;
        t = (k + 1) as f64 * h;
    }
    let abi = started.elapsed().as_secs_f64() / steps as f64;
    drop(inst);
    let res = load_resources(&dir.join("resources")).map_err(|e| e.to_string())?;
    let mut s = solver::build(
        &res.scene,
        fxbody::solver::Method::Exact,
        &Options::default(),
    )
    .map_err(|e| e.to_string())?;
    let mut loads = [0.0; 6];
    let mut pos = [0.0; 3];
    let started = Instant::now();
    for k in 0..steps {
        loads[1] = load(k);
        s.set_loads(&loads).map_err(|e| e.to_string())?;
        s.step(h).map_err(|e| e.to_string())?;
        s.positions(&mut pos);
    }
    let direct = started.elapsed().as_secs_f64() / steps as f64;
    std::hint::black_box(pos);
    println!(
        "  per step (setReal + doStep + getReal), {} modes: {:.3} us through the C ABI, {:.3} us calling the solver directly",
        res.scene.body.nl(),
        abi * 1e6,
        direct * 1e6
    );

    let csv = args.out.join("cantilever_tip.csv");
    let mut text = String::from("time,fy,uy_fmu,vy_fmu,uy_full_fe\n");
    for k in 0..n {
        let _ = writeln!(
            text,
            "{},{},{:e},{:e},{:e}",
            r.t[k], r.amplitude, uy[k], vy[k], r.uy[k]
        );
    }
    std::fs::write(&csv, text).map_err(|e| format!("{}: {e}", csv.display()))?;
    let plot = args.out.join("cantilever_tip.svg");
    let ms: Vec<f64> = r.t.iter().map(|t| t * 1e3).collect();
    let curve = |label: &str, y: &[f64], color: &str, style| Curve {
        label: label.into(),
        color: color.into(),
        points: ms.iter().copied().zip(y.iter().copied()).collect(),
        style,
    };
    let chart = svg(
        &format!("Cantilever tip, 1 N step load at node {tip}"),
        &[Panel {
            title: "the FMU against the full FE model".into(),
            x_label: "time (ms)".into(),
            y_label: "tip deflection uy (m)".into(),
            x: Scale::Linear,
            y: Scale::Linear,
            curves: vec![
                curve("FMU (exact method)", &uy, "#1f77b4", Style::Line),
                curve("full FE model", &r.uy, "#d62728", Style::Dashed),
            ],
        }],
        1,
        (640.0, 360.0),
    );
    std::fs::write(&plot, chart).map_err(|e| format!("{}: {e}", plot.display()))?;
    println!("\nwrote {} and {}", csv.display(), plot.display());
    Ok(())
}
