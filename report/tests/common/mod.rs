//! A fake run folder, as the playback writes it, from synthetic images measured with the real
//! metrics: a scene whose right half brightens at the event frame (a light rotating), a
//! reference, and two "methods" with different noise that adapt to the change over some frames.

#![allow(dead_code)]

pub mod browser;

use std::fmt::Write as _;
use std::path::Path;

use metrics::synthetic::hash01;
use metrics::{
    DEFAULT_PPD, Image, Region, flip_hdr, mse, psnr, relative_mse, smape, write_exr, write_png_srgb,
};

pub const W: u32 = 64;
pub const H: u32 = 36;
pub const FRAMES: u32 = 30;
pub const EVENT: u32 = 20;
pub const METHODS: [&str; 2] = ["pt_1spp", "cache_ema"];

/// The shape of a fake run; `FakeRun::default()` is the run most tests use.
#[derive(Clone, Debug)]
pub struct FakeRun {
    pub width: u32,
    pub height: u32,
    pub frames: u32,
    pub event: u32,
    pub methods: Vec<String>,
    pub reference_frames: Vec<u32>,
    /// Noise that does not change from frame to frame: only the event changes the images.
    pub static_noise: bool,
    /// Seconds per frame, written to the manifest's settings (the viewer plays at 1 / this).
    pub time_step: Option<f64>,
    /// Whether the first method records motion vectors ([`motion`]).
    pub motion: bool,
    /// The manifest's scenario name, the event's label and the regions (names a scenario sets).
    pub scenario: String,
    pub event_label: String,
    pub regions: Vec<Region>,
}

/// The motion vectors the first method records when `FakeRun::motion` is set (pixels).
pub fn motion(x: u32, _y: u32, f: u32) -> [f32; 2] {
    [(x as f32 - 32.0) / 8.0 + 0.125 * f as f32, 0.75]
}

impl Default for FakeRun {
    fn default() -> Self {
        Self {
            width: W,
            height: H,
            frames: FRAMES,
            event: EVENT,
            methods: METHODS.map(String::from).to_vec(),
            reference_frames: vec![0, EVENT],
            static_noise: false,
            time_step: None,
            motion: false,
            scenario: "fake_box".into(),
            event_label: "rotate light 'sun' by 30°".into(),
            regions: regions(),
        }
    }
}

/// The scene: its right half brightens by `after_event` (0 before the event, 1 once adapted).
fn scene(w: u32, h: u32, after_event: f32) -> Image {
    Image::from_fn(w, h, |x, y| {
        let base = [0.2 + 0.5 * x as f32 / w as f32, 0.3, 0.2 + 0.4 * y as f32 / h as f32];
        let checker = 0.5 + 0.5 * ((x / 4 + y / 4) % 2) as f32;
        let light = if x >= w / 2 { 1.0 + 2.0 * after_event } else { 1.0 };
        base.map(|c| c * checker * light)
    })
}

/// The scene as method `m` renders frame `f`: noise, and a lag adapting to the event.
fn render(run: &FakeRun, m: usize, f: u32) -> Image {
    let lag = [1.0, 6.0, 2.0, 10.0, 3.0, 4.0][m % 6];
    let adapt = if f < run.event { 0.0 } else { (((f - run.event) as f32 + 1.0) / lag).min(1.0) };
    let clean = scene(run.width, run.height, adapt);
    let amp = [0.5, 0.1, 0.3, 0.05, 0.2, 0.15][m % 6];
    let seed = if run.static_noise { 0 } else { f * 7 } + m as u32;
    Image::from_fn(run.width, run.height, |x, y| {
        clean.get(x, y).map(|c| c * (1.0 + amp * (hash01(x, y, seed) - 0.5)))
    })
}

pub fn regions() -> Vec<Region> {
    vec![
        Region { name: "steady".into(), x: 0, y: 0, width: 16, height: 16 },
        Region { name: "changing".into(), x: 40, y: 10, width: 16, height: 16 },
    ]
}

/// Writes the run folder and returns its path.
pub fn fake_run(name: &str) -> tempfile::TempDir {
    fake_run_with(name, &FakeRun::default())
}

/// The frame that method `m` of `run` renders at `f` (as written to the run folder).
pub fn method_frame(run: &FakeRun, m: usize, f: u32) -> Image {
    render(run, m, f)
}

pub fn fake_run_with(name: &str, run: &FakeRun) -> tempfile::TempDir {
    let (w, h, event) = (run.width, run.height, run.event);
    let tmp =
        tempfile::Builder::new().prefix(&format!("report-fake-run-{name}-")).tempdir().unwrap();
    let dir = tmp.path().to_path_buf();
    std::fs::create_dir_all(dir.join("reference")).unwrap();
    let reference_frames = &run.reference_frames;
    for &f in reference_frames {
        let r = scene(w, h, if f >= event { 1.0 } else { 0.0 });
        write_exr(&r, dir.join(format!("reference/{f:04}.exr"))).unwrap();
        write_png_srgb(&r, dir.join(format!("reference/{f:04}.png"))).unwrap();
    }
    let mut csv = String::from(
        "method,frame,cpu_ms,gpu_ms_total,gpu_ms_trace,smape,smape_reprojected,disoccluded,flip,mse,rel_mse,psnr",
    );
    for r in &run.regions {
        write!(csv, ",{0}_flip,{0}_smape", r.name).unwrap();
    }
    csv.push('\n');
    for (m, method) in run.methods.iter().enumerate() {
        std::fs::create_dir_all(dir.join("frames").join(method)).unwrap();
        let mut prev: Option<Image> = None;
        for f in 0..run.frames {
            let img = render(run, m, f);
            write_exr(&img, dir.join(format!("frames/{method}/{f:04}.exr"))).unwrap();
            write_png_srgb(&img, dir.join(format!("frames/{method}/{f:04}.png"))).unwrap();
            if run.motion && m == 0 {
                std::fs::create_dir_all(dir.join(format!("frames/{method}/motion"))).unwrap();
                let mv = Image::from_fn(w, h, |x, y| {
                    let [dx, dy] = motion(x, y, f);
                    [dx, dy, 0.0]
                });
                write_exr(&mv, dir.join(format!("frames/{method}/motion/{f:04}.exr"))).unwrap();
            }
            let s = prev.as_ref().map(|p| smape(&img, p, 0.01));
            let gpu = [1.0, 2.5, 1.5, 4.0, 0.7, 3.0][m % 6] + 0.01 * f as f64;
            write!(csv, "{method},{f},{:.3},{gpu:.4},{gpu:.4},", gpu + 0.5).unwrap();
            write!(csv, "{},,,", s.as_ref().map(|s| format!("{:.6}", s.mean)).unwrap_or_default())
                .unwrap();
            let flip = reference_frames.contains(&f).then(|| {
                let r = scene(w, h, if f >= event { 1.0 } else { 0.0 });
                (
                    flip_hdr(&r, &img, DEFAULT_PPD),
                    mse(&r, &img),
                    relative_mse(&r, &img),
                    psnr(&r, &img),
                )
            });
            match &flip {
                Some((fl, e, rel, p)) => {
                    write!(csv, "{:.6},{e:.6},{rel:.6},{p:.4}", fl.mean).unwrap()
                }
                None => csv.push_str(",,,"),
            }
            for r in &run.regions {
                let rf = flip.as_ref().and_then(|(fl, ..)| r.mean_of(&fl.map, w));
                let rs = s.as_ref().and_then(|s| r.mean_of(&s.map, w));
                let cell = |v: Option<f64>| v.map(|v| format!("{v:.6}")).unwrap_or_default();
                write!(csv, ",{},{}", cell(rf), cell(rs)).unwrap();
            }
            csv.push('\n');
            prev = Some(img);
        }
    }
    std::fs::write(dir.join("frames.csv"), csv).unwrap();
    let manifest = serde_json::json!({
        "scenario": run.scenario, "scenario_file": "scenarios/fake_box.ron", "commit": "0000000",
        "adapter": {"name": "none", "backend": "test"}, "seed": 1, "resolution": [w, h], "frames": run.frames,
        "methods": run.methods, "reference": {"spp": 64, "frames": reference_frames},
        "events": [{"frame": event, "label": run.event_label}],
        "regions": run.regions, "settings": {"smape_epsilon": 0.01, "time_step": run.time_step}
    });
    std::fs::write(dir.join("manifest.json"), serde_json::to_string_pretty(&manifest).unwrap())
        .unwrap();
    tmp
}

pub fn read_json(path: &Path) -> serde_json::Value {
    serde_json::from_str(&std::fs::read_to_string(path).unwrap()).unwrap()
}

/// Names that a scenario (or a folder of frames) sets, holding markup and quotes. In a page
/// each must be text: `<img onerror>` run as markup calls alert, `<!--<script>` inside a
/// <script> element hides the next `</script>`, `</script>` ends one early.
pub const HOSTILE_METHODS: [&str; 2] = ["<img src=x onerror=alert(1)>\"'&", "<!--<script>\"'&"];
pub const HOSTILE_SCENARIO: &str = "</script><img src=x onerror=alert(2)>\"'&";
pub const HOSTILE_EVENT: &str = "</script><svg onload=alert(3)>\"'&";
pub const HOSTILE_REGIONS: [&str; 2] = ["<img src=x onerror=alert(4)>\"'&", "<!--\"'&"];

/// A short run whose methods, scenario, event and regions have hostile names.
pub fn hostile_run(name: &str) -> tempfile::TempDir {
    let regions = regions()
        .into_iter()
        .zip(HOSTILE_REGIONS)
        .map(|(r, n)| Region { name: n.into(), ..r })
        .collect();
    let spec = FakeRun {
        frames: 8,
        event: 4,
        reference_frames: vec![0, 4],
        methods: HOSTILE_METHODS.map(String::from).to_vec(),
        scenario: HOSTILE_SCENARIO.into(),
        event_label: HOSTILE_EVENT.into(),
        regions,
        ..FakeRun::default()
    };
    fake_run_with(name, &spec)
}
