//! `lme-mpm render` on a small run: one PNG per snapshot and a GIF with as
//! many frames, both decodable, the GIF's last frame the same picture as
//! the last PNG (up to its palette), particles and walls drawn; a folder
//! without snapshots, or a field the run does not have, exits 2 saying
//! why. Also the off-terminal progress of `study` and `bench`: their lines
//! arrive while the command is still running, and they say where their
//! outputs went.

use std::io::BufRead;
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};

fn bin() -> Command {
    let mut c = Command::new(env!("CARGO_BIN_EXE_lme-mpm"));
    c.env("NODEVICE_SELECT", "1");
    c
}

fn tmp(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("lme-mpm-render-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    d
}

fn case(name: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("cases")
        .join(name)
}

/// RGB pixels and size of a PNG file.
fn png(path: &Path) -> (Vec<u8>, (u32, u32)) {
    let dec = png::Decoder::new(std::io::BufReader::new(std::fs::File::open(path).unwrap()));
    let mut r = dec.read_info().unwrap();
    let mut buf = vec![0; r.output_buffer_size()];
    let info = r.next_frame(&mut buf).unwrap();
    assert_eq!(info.color_type, png::ColorType::Rgb, "{path:?}");
    buf.truncate(info.buffer_size());
    (buf, (info.width, info.height))
}

/// The GIF's frames composed onto its canvas (each frame a sub-rectangle
/// drawn over the last), as RGB.
fn gif_frames(path: &Path) -> (Vec<Vec<u8>>, (u32, u32)) {
    let mut opts = gif::DecodeOptions::new();
    opts.set_color_output(gif::ColorOutput::RGBA);
    let mut d = opts.read_info(std::fs::File::open(path).unwrap()).unwrap();
    let (w, h) = (u32::from(d.width()), u32::from(d.height()));
    let mut canvas = vec![255u8; (w * h * 3) as usize];
    let mut out = Vec::new();
    while let Some(f) = d.read_next_frame().unwrap() {
        for y in 0..usize::from(f.height) {
            for x in 0..usize::from(f.width) {
                let s = 4 * (y * usize::from(f.width) + x);
                let t = 3 * ((y + usize::from(f.top)) * w as usize + x + usize::from(f.left));
                canvas[t..t + 3].copy_from_slice(&f.buffer[s..s + 3]);
            }
        }
        out.push(canvas.clone());
    }
    (out, (w, h))
}

#[test]
fn render_writes_frames_and_a_gif_that_decode() {
    let run = tmp("column");
    // The column collapse, coarse and short: 800 particles, 11 snapshots.
    let o = bin()
        .args(["run"])
        .arg(case("column_collapse.toml"))
        .args([
            "--set",
            "grid.h=0.2",
            "--set",
            "solver.shape=linear",
            "--set",
            "solver.t_end=0.2",
            "--set",
            "output.vtk_interval=0.02",
            "--quiet",
            "--out",
        ])
        .arg(&run)
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let snapshots = std::fs::read_to_string(run.join("particles.pvd"))
        .unwrap()
        .matches("<DataSet")
        .count();
    assert!(snapshots >= 10, "{snapshots} snapshots");
    assert!(run.join("result.png").is_file());

    for field in ["eps_p", "stress", "speed", "pressure", "displacement"] {
        let o = bin()
            .arg("render")
            .arg(&run)
            .args(["--field", field, "--width", "480"])
            .output()
            .unwrap();
        let err = String::from_utf8_lossy(&o.stderr);
        assert!(o.status.success(), "{field}: {err}");
        assert!(
            err.contains("outputs:") && err.contains(&format!("{field}.gif")),
            "{err}"
        );
        let dir = run.join("render");
        let frames: Vec<PathBuf> = (0..snapshots)
            .map(|k| dir.join(format!("{field}_{k:05}.png")))
            .collect();
        let (last, size) = png(frames.last().unwrap());
        assert_eq!(size.0, 480);
        for f in &frames {
            assert_eq!(png(f).1, size, "{f:?}");
        }
        assert!(!dir.join(format!("{field}_{snapshots:05}.png")).exists());
        let (gif, gsize) = gif_frames(&dir.join(format!("{field}.gif")));
        assert_eq!(gif.len(), snapshots, "{field}: GIF frames");
        assert_eq!(gsize, size);
        // The GIF's last frame is the last PNG, each pixel within the
        // palette's step (5 bits a channel, then the nearest of 256
        // entries: measured at most about 40 per channel on anti-aliased text).
        const PALETTE_STEP: i32 = 64;
        let far = last
            .iter()
            .zip(&gif[gif.len() - 1])
            .filter(|(a, b)| (i32::from(**a) - i32::from(**b)).abs() > PALETTE_STEP)
            .count();
        assert!(far * 1000 < last.len(), "{field}: {far} channels differ");
        // Particles: viridis pixels (not grey, not the region colours) in
        // the last frame; the floor wall: near-black pixels.
        let coloured = last
            .chunks_exact(3)
            .filter(|p| p[1] > p[0] && p[2] > p[0] + 20)
            .count();
        assert!(coloured > 2000, "{field}: {coloured} particle pixels");
        let dark = last
            .chunks_exact(3)
            .filter(|p| p.iter().all(|c| *c < 60))
            .count();
        assert!(dark > 500, "{field}: {dark} dark pixels (walls, text)");
        if field == "eps_p" {
            if let Some(dump) = std::env::var_os("LME_MPM_RENDER_DUMP") {
                // For a look at the GIF as decoded: its last frame as PNG.
                let mut bytes = Vec::new();
                let mut e = png::Encoder::new(&mut bytes, size.0, size.1);
                e.set_color(png::ColorType::Rgb);
                e.write_header()
                    .unwrap()
                    .write_image_data(&gif[gif.len() - 1])
                    .unwrap();
                std::fs::write(dump, bytes).unwrap();
            }
        }
    }

    // A plastic field of an elastic run, and a run without snapshots.
    let elastic = tmp("dyka");
    let o = bin()
        .arg("run")
        .arg(case("dyka_bar.toml"))
        .args(["--set", "solver.t_end=1e-6", "--quiet", "--out"])
        .arg(&elastic)
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let o = bin()
        .arg("render")
        .arg(&elastic)
        .args(["--field", "eps_p"])
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&o.stderr).contains("plastic"));
    let none = tmp("none");
    let o = bin()
        .arg("run")
        .arg(case("dyka_bar.toml"))
        .args([
            "--set",
            "solver.t_end=1e-6",
            "--set",
            "output.vtk_final=false",
            "--quiet",
            "--out",
        ])
        .arg(&none)
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let o = bin().arg("render").arg(&none).output().unwrap();
    assert_eq!(o.status.code(), Some(2));
    assert!(
        String::from_utf8_lossy(&o.stderr).contains("output.vtk_interval"),
        "{}",
        String::from_utf8_lossy(&o.stderr)
    );
    for d in [run, elastic, none] {
        let _ = std::fs::remove_dir_all(d);
    }
}

/// Spawns `cmd` with stderr piped (not a terminal) and reads it line by
/// line: returns every line and whether the first line matching `progress`
/// arrived while the command was still running.
fn progress_off_terminal(mut cmd: Command, progress: &str) -> (Vec<String>, bool) {
    let mut child = cmd
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let err = child.stderr.take().unwrap();
    let mut lines = Vec::new();
    let mut early = None;
    for line in std::io::BufReader::new(err).lines() {
        let line = line.unwrap();
        if early.is_none() && line.contains(progress) {
            early = Some(child.try_wait().unwrap().is_none());
        }
        lines.push(line);
    }
    assert!(child.wait().unwrap().success(), "{lines:#?}");
    (lines, early.unwrap_or(false))
}

#[test]
fn study_and_bench_report_progress_off_a_terminal() {
    let out = tmp("study");
    let mut c = bin();
    c.args([
        "study",
        "block",
        "--quick",
        "--backend",
        "cpu",
        "--jobs",
        "1",
        "--out",
    ])
    .arg(&out);
    let (lines, early) = progress_off_terminal(c, "study block: 1/");
    assert!(early, "no progress line before the end: {lines:#?}");
    let n = lines.iter().filter(|l| l.contains("runs done")).count();
    assert!(n >= 2, "{lines:#?}");
    assert!(
        lines
            .iter()
            .any(|l| l.contains("outputs in") && l.contains("block")),
        "{lines:#?}"
    );
    // The report's images sit beside it.
    let report = std::fs::read_to_string(out.join("block/report.md")).unwrap();
    let links: Vec<&str> = report
        .split("](")
        .skip(1)
        .filter_map(|s| s.split(')').next())
        .filter(|l| l.ends_with(".png"))
        .collect();
    assert!(!links.is_empty());
    for l in links {
        assert!(out.join("block").join(l).is_file(), "report.md links {l}");
    }

    let bench = tmp("bench");
    let mut c = bin();
    c.args([
        "bench",
        "--backend",
        "cpu",
        "--cases",
        "linear",
        "--particles",
        "2000,4000",
        "--seconds",
        "0.5",
        "--out",
    ])
    .arg(&bench);
    let (lines, early) = progress_off_terminal(c, "bench: linear n=");
    assert!(early, "no progress line before the end: {lines:#?}");
    assert!(
        lines.iter().any(|l| l.starts_with("outputs:")
            && l.contains("bench.csv")
            && l.contains("bench.png")),
        "{lines:#?}"
    );
    assert!(bench.join("bench.csv").is_file() && bench.join("bench.png").is_file());
    let _ = std::fs::remove_dir_all(out);
    let _ = std::fs::remove_dir_all(bench);
}

/// Pixels of exactly the shading behind a wall (`render::WALL_FILL`,
/// 215 grey) in rows `rows` and columns `cols` of an RGB image `w` wide.
fn wall_shade(rgb: &[u8], w: u32, rows: std::ops::Range<u32>, cols: std::ops::Range<u32>) -> usize {
    rows.flat_map(|y| cols.clone().map(move |x| 3 * (y * w + x) as usize))
        .filter(|&k| rgb[k..k + 3] == [215, 215, 215])
        .count()
}

/// Issue 51: `--width 100000` panicked in plotters (exit 101), 0 and the
/// other degenerate sizes and rates were taken without a word, nothing
/// said how much a render would write, and a gate was drawn after it had
/// gone. Now every size and rate is bounded (exit 2 naming the flag, the
/// value and the range), the first frame gives an estimate of the rest,
/// and walls are drawn only while they act.
#[test]
fn render_bounds_its_sizes_estimates_its_output_and_draws_a_gate_until_it_goes() {
    let run = tmp("gate");
    let o = bin()
        .arg("run")
        .arg(PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("tests/scenes/gate_release.toml"))
        .args([
            "--backend",
            "cpu",
            "--set",
            "solver.t_end=0.2",
            "--set",
            "output.vtk_interval=0.05",
            "--quiet",
            "--out",
        ])
        .arg(&run)
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));

    for (flag, v, range) in [
        ("--width", "100000", "320..=4096"),
        ("--width", "0", "320..=4096"),
        ("--width", "319", "320..=4096"),
        ("--width", "99999999999", "320..=4096"),
        ("--fps", "0", "0.1..=50"),
        ("--fps", "nan", "0.1..=50"),
        ("--fps", "inf", "0.1..=50"),
        ("--fps", "51", "0.1..=50"),
        ("--every", "0", "at least 1"),
    ] {
        let o = bin()
            .arg("render")
            .arg(&run)
            .arg(format!("{flag}={v}"))
            .output()
            .unwrap();
        let err = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(2), "{flag} {v}: {err}");
        assert!(
            err.contains(flag) && err.contains(v) && err.contains(range),
            "{flag} {v}: {err}"
        );
        assert!(!run.join("render").exists(), "{flag} {v}: drew something");
    }
    // The library refuses them too, naming the flag.
    let opts = lme_mpm::output::render::RenderOptions {
        width: 100_000,
        ..Default::default()
    };
    let e = lme_mpm::output::render::render(&run, &opts).unwrap_err();
    assert_eq!(e.exit_code(), 2);
    assert!(e.to_string().contains("--width"), "{e}");

    // The estimate is said before the frames are drawn, and holds.
    let o = bin()
        .arg("render")
        .arg(&run)
        .args(["--width", "480"])
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(o.status.success(), "{err}");
    let said = err.lines().position(|l| l.contains("frames of 480 x"));
    let outputs = err.lines().position(|l| l.starts_with("outputs:"));
    assert!(
        matches!((said, outputs), (Some(a), Some(b)) if a < b),
        "{err}"
    );
    let opts = lme_mpm::output::render::RenderOptions {
        width: 480,
        out: Some(run.join("lib")),
        say_estimate: false,
        ..Default::default()
    };
    let r = lme_mpm::output::render::render(&run, &opts).unwrap();
    assert!(r.frames.len() >= 4, "{} frames", r.frames.len());
    assert_eq!(r.estimate.frames, r.frames.len());
    let png_bytes: u64 = r
        .frames
        .iter()
        .map(|f| std::fs::metadata(f).unwrap().len())
        .sum();
    let est = r.estimate.png_bytes();
    assert!(
        (0.5 * est..=2.0 * est).contains(&(png_bytes as f64)),
        "PNG frames: {png_bytes} bytes written, {est} estimated"
    );
    let gif_bytes = std::fs::metadata(&r.gif).unwrap().len() as f64;
    assert!(gif_bytes <= r.estimate.gif_bytes_at_most(), "{gif_bytes}");

    // The gate (x = 0.4, removed at 0.1 s) shades x > 0.4 while it acts:
    // the upper right of the plot, where no particle reaches. The floor
    // shades only the bottom, the back wall the left.
    let (first, (w, h)) = png(&r.frames[0]);
    let (last, size) = png(r.frames.last().unwrap());
    assert_eq!(size, (w, h));
    let (rows, cols) = (40..h / 2, w / 2..w - 130);
    let before = wall_shade(&first, w, rows.clone(), cols.clone());
    let after = wall_shade(&last, w, rows, cols);
    assert!(before > 1000, "the gate's side at t = 0: {before} pixels");
    assert_eq!(after, 0, "the gate drawn after its removal");
    // The other walls still are: the floor's side at the bottom.
    let floor = wall_shade(&last, w, h / 2..h, w / 2..w - 130);
    assert!(floor > 100, "the floor's side: {floor} pixels");
    let _ = std::fs::remove_dir_all(run);
}
