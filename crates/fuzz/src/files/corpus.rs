//! What the file groups mutate, and where a case's files live.
//!
//! * **Scenarios**: every `scenarios/**/*.toml` of the repository, and the broken and probe files
//!   of `crates/flight/tests/data` (lower weight), parsed as TOML documents. A file whose planner
//!   map would have more than [`CORPUS_MAX_VOXELS`] ESDF voxels (E4 and the point-cloud forests
//!   at 0.1–0.3 m) is coarsened in the corpus (its `esdf_voxel_m` and `spacing_m` raised until it
//!   fits), so that a case builds in milliseconds; mutations still drive voxel sizes to their
//!   caps, and a case the build budget does not cover is counted as heavy ([`super::Ctx`]).
//! * **Tracks**: the CSV files under `scenarios/data/` (the pedestrians' walkers).
//! * **Run logs**: flown in-process at start-up ([`generate_logs`]) through `trust_flight::fly`,
//!   briefly: quickstart with branch logging (quadrotor), quickstart without it (perfect
//!   tracking), the moving boxes of `boxes_on_curves`, and quickstart with a file point cloud
//!   (the log names `static_points.xyz`).
//! * **Case folder** ([`CaseDir`]): the folder a case's scenario or log is written to, furnished
//!   once per worker with what the special paths of [`super::mutate::special_path`] name: a
//!   folder, symbolic links (inside, out of the folder, to a device, to a folder, dangling, a
//!   loop), a FIFO, and files outside the folder.

use std::path::{Path, PathBuf};

use anyhow::{Context as _, Result, bail};
use trust_flight::scenario::Scenario;
use trust_world::scenario::PointCloudSpec;

/// Largest planner-map ESDF of a corpus scenario (voxels); larger ones are coarsened.
pub const CORPUS_MAX_VOXELS: f64 = 250_000.0;

/// One scenario of the corpus.
#[derive(Debug, Clone)]
pub struct ScenarioBase {
    /// Its path relative to the repository (for messages).
    pub name: String,
    /// The document.
    pub doc: toml::Table,
    /// How often it is drawn.
    pub weight: u32,
}

/// One run log of the corpus.
#[derive(Debug, Clone)]
pub struct BaseLog {
    /// Its name.
    pub name: String,
    /// The log's lines.
    pub lines: Vec<String>,
    /// Its static points file, if the header names one.
    pub points: Option<Vec<u8>>,
}

/// Everything the file groups mutate.
#[derive(Debug, Clone)]
pub struct Corpus {
    /// Scenario documents.
    pub scenarios: Vec<ScenarioBase>,
    /// Tracks: file name (under `data/`) and text.
    pub tracks: Vec<(String, Vec<u8>)>,
    /// A small points file (`x y z` lines) for the point-cloud cases.
    pub points: Vec<u8>,
    /// Run logs.
    pub logs: Vec<BaseLog>,
}

/// The repository root, from this crate's manifest folder.
pub fn repo_root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..")
}

fn toml_files(dir: &Path, out: &mut Vec<PathBuf>) -> Result<()> {
    let mut entries: Vec<PathBuf> = std::fs::read_dir(dir)
        .with_context(|| format!("reading {}", dir.display()))?
        .filter_map(|e| e.ok().map(|e| e.path()))
        .collect();
    entries.sort();
    for p in entries {
        if p.is_dir() {
            toml_files(&p, out)?;
        } else if p.extension().is_some_and(|x| x == "toml") {
            out.push(p);
        }
    }
    Ok(())
}

/// The ESDF voxels of the planner map `s` asks for (0 without a point cloud), as the
/// validation counts them.
pub fn esdf_voxels(s: &Scenario) -> f64 {
    let (Some(cloud), Some(b)) = (&s.static_map.point_cloud, s.bounds()) else {
        return 0.0;
    };
    let voxel = match cloud {
        PointCloudSpec::Shapes {
            esdf_voxel_m,
            spacing_m,
        } => esdf_voxel_m.min(spacing_m.unwrap_or(*esdf_voxel_m)),
        PointCloudSpec::Inline { esdf_voxel_m, .. } | PointCloudSpec::File { esdf_voxel_m, .. } => {
            *esdf_voxel_m
        }
    };
    let e = b.extent();
    (0..3)
        .map(|i| (e[i] / voxel).ceil().max(1.0) + 1.0)
        .product()
}

/// Raises the document's voxel size (and sampling spacing) until its map has at most
/// [`CORPUS_MAX_VOXELS`] voxels; returns whether it did.
fn coarsen(doc: &mut toml::Table, path: &Path) -> bool {
    let text = toml::to_string(doc).unwrap_or_default();
    let Ok(s) = Scenario::from_toml_str(&text, path) else {
        return false;
    };
    let voxels = esdf_voxels(&s);
    if voxels <= CORPUS_MAX_VOXELS {
        return false;
    }
    let factor = (voxels / CORPUS_MAX_VOXELS).cbrt() * 1.1;
    let Some(cloud) = doc
        .get_mut("static")
        .and_then(|s| s.get_mut("point_cloud"))
        .and_then(|c| c.as_table_mut())
    else {
        return false;
    };
    for key in ["esdf_voxel_m", "spacing_m"] {
        if let Some(v) = cloud.get_mut(key) {
            let x = v
                .as_float()
                .or_else(|| v.as_integer().map(|i| i as f64))
                .unwrap_or(0.2);
            *v = toml::Value::Float((x * factor * 100.0).ceil() / 100.0);
        }
    }
    true
}

/// Loads the scenario corpus of the repository at `root`.
///
/// # Errors
/// A file that cannot be read or is not TOML (the corpus must parse).
pub fn load_scenarios(root: &Path) -> Result<Vec<ScenarioBase>> {
    let mut out = Vec::new();
    for (dir, weight) in [
        ("scenarios", 10),
        ("crates/flight/tests/data/broken", 2),
        ("crates/flight/tests/data/probe", 2),
    ] {
        let mut files = Vec::new();
        toml_files(&root.join(dir), &mut files)?;
        for path in files {
            let text = std::fs::read_to_string(&path)
                .with_context(|| format!("reading {}", path.display()))?;
            let Ok(mut doc) = text.parse::<toml::Table>() else {
                // The broken corpus has a syntax error on purpose.
                continue;
            };
            coarsen(&mut doc, &path);
            let name = path
                .strip_prefix(root)
                .unwrap_or(&path)
                .display()
                .to_string();
            out.push(ScenarioBase { name, doc, weight });
        }
    }
    if out.is_empty() {
        bail!("no scenario under {}", root.join("scenarios").display());
    }
    Ok(out)
}

/// The CSV tracks under `scenarios/data/`.
///
/// # Errors
/// A folder that cannot be read.
pub fn load_tracks(root: &Path) -> Result<Vec<(String, Vec<u8>)>> {
    let dir = root.join("scenarios/data");
    let mut out = Vec::new();
    let mut entries: Vec<PathBuf> = std::fs::read_dir(&dir)
        .with_context(|| format!("reading {}", dir.display()))?
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| p.extension().is_some_and(|x| x == "csv"))
        .collect();
    entries.sort();
    for p in entries {
        let name = p
            .file_name()
            .unwrap_or_default()
            .to_string_lossy()
            .into_owned();
        out.push((name, std::fs::read(&p)?));
    }
    if out.is_empty() {
        bail!("no track under {}", dir.display());
    }
    Ok(out)
}

/// A small points file: 240 points on three posts of quickstart's world, after a comment.
pub fn points_file() -> Vec<u8> {
    let mut s = String::from("# three posts\n");
    for i in 0..240 {
        let k = f64::from(i % 80);
        let (cx, cy) = [(15.0, 4.0), (26.0, 15.0), (33.0, 5.0)][i as usize / 80];
        let a = k * 0.8;
        s.push_str(&format!(
            "{:.3} {:.3} {:.3}\n",
            cx + 0.3 * a.cos(),
            cy + 0.3 * a.sin(),
            k * 0.1
        ));
    }
    s.into_bytes()
}

/// The scenario of the point-cloud log and cases: quickstart's world with its planner map from
/// `cloud.xyz` (in the scenario's folder).
pub fn cloud_scenario(corpus: &[ScenarioBase]) -> Option<toml::Table> {
    let mut doc = corpus
        .iter()
        .find(|b| b.name.ends_with("scenarios/quickstart.toml"))?
        .doc
        .clone();
    let mut cloud = toml::Table::new();
    cloud.insert("source".into(), "file".into());
    cloud.insert("path".into(), "cloud.xyz".into());
    cloud.insert("esdf_voxel_m".into(), toml::Value::Float(0.5));
    let stat = doc
        .entry("static")
        .or_insert_with(|| toml::Value::Table(toml::Table::new()));
    stat.as_table_mut()?
        .insert("point_cloud".into(), toml::Value::Table(cloud));
    Some(doc)
}

/// Flies the corpus logs into `dir` (module docs); returns them.
///
/// # Errors
/// A scenario of the corpus that does not fly, or a file that cannot be written.
pub fn generate_logs(scenarios: &[ScenarioBase], dir: &Path) -> Result<Vec<BaseLog>> {
    use trust_flight::{RunOptions, fly};
    let find = |suffix: &str| {
        scenarios
            .iter()
            .find(|b| b.name.ends_with(suffix))
            .map(|b| b.doc.clone())
            .with_context(|| format!("no {suffix} in the corpus"))
    };
    let quick = find("scenarios/quickstart.toml")?;
    let boxes = find("scenarios/boxes_on_curves.toml")?;
    let mut perfect = quick.clone();
    if let Some(v) = perfect.get_mut("vehicle").and_then(|v| v.as_table_mut()) {
        v.insert("model".into(), "perfect".into());
    }
    let cloud = cloud_scenario(scenarios).context("no quickstart to add a cloud to")?;
    let mut out = Vec::new();
    for (name, doc, time_limit, branches) in [
        ("quickstart", quick, 1.6, true),
        ("perfect", perfect, 1.0, false),
        ("boxes", boxes, 1.0, true),
        ("cloud", cloud, 1.0, false),
    ] {
        let folder = dir.join(name);
        std::fs::create_dir_all(&folder)?;
        std::fs::write(folder.join("cloud.xyz"), points_file())?;
        let scenario_path = folder.join("scenario.toml");
        let text = toml::to_string(&doc)?;
        std::fs::write(&scenario_path, &text)?;
        let mut s = Scenario::from_toml_str(&text, &scenario_path)?;
        s.time_limit_s = time_limit;
        let world = trust_world::World::build(&s)?;
        let planner = trust_flight::scenario::resolve_planner(&s);
        let log_path = folder.join("run.jsonl");
        let options = RunOptions {
            log_path: Some(log_path.clone()),
            zero_timing: true,
            progress_every_s: None,
            log_branches: branches,
        };
        fly(&world, &planner, &options, |_| {})
            .with_context(|| format!("flying the corpus log {name}"))?;
        let text = std::fs::read_to_string(&log_path)?;
        let points_path = folder.join("static_points.xyz");
        out.push(BaseLog {
            name: name.to_string(),
            lines: text.lines().map(str::to_string).collect(),
            points: std::fs::read(&points_path).ok(),
        });
    }
    Ok(out)
}

/// The folder of a worker's cases: `root/case` is the scenario's (and the log's) folder, furnished
/// once (module docs); `root/out` takes what the entry points write; `root/outside.*` lie outside
/// the case folder.
#[derive(Debug, Clone)]
pub struct CaseDir {
    /// The case folder.
    pub case: PathBuf,
    /// Outputs (replay page and GIF, MCAP).
    pub out: PathBuf,
}

impl CaseDir {
    /// Creates and furnishes the folders under `root` (emptied first).
    ///
    /// # Errors
    /// A folder or file that cannot be created.
    pub fn create(root: &Path, corpus: &Corpus) -> Result<CaseDir> {
        if root.exists() {
            std::fs::remove_dir_all(root)
                .with_context(|| format!("emptying {}", root.display()))?;
        }
        let case = root.join("case");
        let out = root.join("out");
        std::fs::create_dir_all(case.join("data"))?;
        std::fs::create_dir_all(case.join("dir"))?;
        std::fs::create_dir_all(&out)?;
        let track = corpus
            .tracks
            .first()
            .map(|t| t.1.clone())
            .unwrap_or_default();
        std::fs::write(root.join("outside.csv"), &track)?;
        std::fs::write(root.join("outside.xyz"), &corpus.points)?;
        std::fs::write(case.join("inside.txt"), &track)?;
        #[cfg(unix)]
        {
            use std::os::unix::fs::symlink;
            symlink("inside.txt", case.join("link_in"))?;
            symlink("../outside.csv", case.join("link_out"))?;
            symlink("/dev/zero", case.join("link_dev"))?;
            symlink("dir", case.join("link_dir"))?;
            symlink("link_loop", case.join("link_loop"))?;
            symlink("nowhere.txt", case.join("link_dangling"))?;
            // A FIFO: refused by its metadata before anything opens (and blocks on) it.
            let _ = std::process::Command::new("mkfifo")
                .arg(case.join("fifo"))
                .status();
        }
        Ok(CaseDir { case, out })
    }

    /// Writes `name` (relative to the case folder) with `bytes`, creating its folder.
    ///
    /// # Errors
    /// The file cannot be written.
    pub fn write(&self, name: &str, bytes: &[u8]) -> std::io::Result<PathBuf> {
        let path = self.case.join(name);
        if let Some(dir) = path.parent() {
            std::fs::create_dir_all(dir)?;
        }
        std::fs::write(&path, bytes)?;
        Ok(path)
    }
}
