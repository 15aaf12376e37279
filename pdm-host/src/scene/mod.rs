//! Scenes: the user's own geometry from a file (TOML or JSON, one model: [`model`]), built into
//! surfaces and patches ([`mod@build`]), the form-factor matrices computed pair by pair
//! ([`matrix`]) and reported with their diagnostics ([`report`]). The file format is described
//! field by field in `SCENES.md`.
// Patch, surface and piece indices are made by `build` from the scene's own vectors (and the
// matrices are square by construction), so indexing cannot fail on any input; a panic here
// would be a bug in this module, not bad input, which is refused by `build` with an error.
#![allow(clippy::indexing_slicing)]

pub mod build;
pub mod bvh;
pub mod fold;
pub mod matrix;
pub mod mesh;
pub mod model;
pub mod part;
pub mod report;
pub mod separate;
pub mod shape;
pub mod vs3;

use std::fmt;
use std::path::Path;

pub use build::{build, Scene};
pub use model::SceneFile;

/// A scene file that cannot be used: the file, the line where known, the field, what is wrong.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct SceneError {
    /// The file.
    pub file: String,
    /// 1-based line, where the format tells it.
    pub line: Option<usize>,
    /// What is wrong, naming the surface and field.
    pub message: String,
}

impl fmt::Display for SceneError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self.line {
            Some(line) => write!(f, "{}:{line}: {}", self.file, self.message),
            None => write!(f, "{}: {}", self.file, self.message),
        }
    }
}

impl std::error::Error for SceneError {}

impl SceneError {
    /// A message that starts with its own `file:line: ` (a mesh file's) keeps only that.
    fn with_own_location(self) -> Self {
        match self.message.split_once(": ") {
            Some((place, rest)) if place.starts_with(&self.file) => {
                let line = place.rsplit(':').next().and_then(|l| l.parse().ok());
                Self { file: self.file, line, message: rest.to_string() }
            }
            _ => self,
        }
    }
}

/// The formats a scene file can be in.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Format {
    /// TOML (`.toml`, and any other extension).
    Toml,
    /// JSON (`.json`).
    Json,
    /// A View3D input file (`.vs3`): the scene is its surfaces, named as in the file.
    Vs3,
}

impl Format {
    /// By the file's extension: `.json` is JSON, everything else TOML.
    #[must_use]
    pub fn of(path: &Path) -> Self {
        match path.extension().and_then(|e| e.to_str()) {
            Some(e) if e.eq_ignore_ascii_case("json") => Self::Json,
            Some(e) if e.eq_ignore_ascii_case("vs3") => Self::Vs3,
            _ => Self::Toml,
        }
    }
}

fn one_line(s: &str) -> String {
    s.split_whitespace().collect::<Vec<_>>().join(" ")
}

/// 1-based line of byte `offset` in `text`.
fn line_of(text: &str, offset: usize) -> usize {
    text.get(..offset.min(text.len())).map_or(1, |t| t.matches('\n').count() + 1)
}

/// The line of the `k`-th `[[surface]]` table of a TOML text (0-based k), if it has one.
fn surface_line(text: &str, k: usize) -> Option<usize> {
    text.lines().enumerate().filter(|(_, l)| l.trim_start().starts_with("[[surface]]")).nth(k).map(|(n, _)| n + 1)
}

/// The scene of a View3D file `file` with text `text`: one `mesh` entry reading the file itself,
/// its surfaces named as in it (`prefix = false`), an enclosure if the file says `encl = 1`,
/// lengths in the file's (unnamed) unit.
fn vs3_scene(text: &str, file: &str) -> Result<SceneFile, SceneError> {
    let parsed =
        vs3::parse(text).map_err(|(line, message)| SceneError { file: file.to_string(), line: Some(line), message })?;
    let path = Path::new(file);
    let name = path.file_stem().and_then(|s| s.to_str()).unwrap_or("view3d");
    let mesh = path.file_name().and_then(|s| s.to_str()).unwrap_or(file);
    let spec = serde_json::json!({ "name": name, "kind": "mesh", "file": mesh, "prefix": false });
    let surface = serde_json::from_value(spec).map_err(|e| SceneError {
        file: file.to_string(),
        line: None,
        message: e.to_string(),
    })?;
    Ok(SceneFile { units: "unit".into(), enclosure: parsed.enclosure, surfaces: vec![surface] })
}

/// The notes on a View3D file's control settings that pdm does not use (empty for other
/// formats or an unreadable file).
#[must_use]
pub fn vs3_notes(path: &Path) -> Vec<String> {
    if Format::of(path) != Format::Vs3 {
        return Vec::new();
    }
    std::fs::read_to_string(path).ok().and_then(|t| vs3::parse(&t).ok()).map_or_else(Vec::new, |v| v.notes)
}

/// Parses a scene text in `format`; `file` names it in errors.
pub fn parse(text: &str, format: Format, file: &str) -> Result<SceneFile, SceneError> {
    match format {
        Format::Vs3 => vs3_scene(text, file),
        Format::Toml => toml::from_str::<SceneFile>(text).map_err(|e| {
            // A bad value names the key it belongs to where its line has one (`subdivide =
            // [-2, 2]`: "field `subdivide`: invalid value: integer `-2`, expected usize").
            let key = e.span().and_then(|s| key_before(text, s.start));
            let message = one_line(e.message());
            SceneError {
                file: file.to_string(),
                line: e.span().map(|s| line_of(text, s.start)),
                message: match key {
                    Some(key) if !message.contains(&format!("`{key}`")) => format!("field `{key}`: {message}"),
                    _ => message,
                },
            }
        }),
        Format::Json => serde_json::from_str::<SceneFile>(text).map_err(|e| {
            let message = one_line(&e.to_string());
            // serde_json appends " at line L column C": the line goes in front instead.
            let message = message.split(" at line ").next().unwrap_or(&message).to_string();
            SceneError { file: file.to_string(), line: (e.line() > 0).then_some(e.line()), message }
        }),
    }
}

/// The key of the `key = value` on the line of byte `at` whose value holds `at` (the
/// innermost, in an inline table: `rotate = { axis = [1, 0, 0], degrees = "x" }` gives
/// `degrees`).
fn key_before(text: &str, at: usize) -> Option<&str> {
    let at = at.min(text.len());
    let start = text.get(..at)?.rfind('\n').map_or(0, |k| k + 1);
    let (before, _) = text.get(start..at)?.rsplit_once('=')?;
    let key = before.rsplit(['{', ',']).next()?.trim();
    let bare = !key.is_empty() && key.chars().all(|c| c.is_ascii_alphanumeric() || c == '_' || c == '-' || c == '.');
    bare.then_some(key)
}

/// Parses and builds a scene text.
pub fn from_text(text: &str, format: Format, file: &str) -> Result<Scene, SceneError> {
    let model = parse(text, format, file)?;
    let base = Path::new(file).parent().unwrap_or(Path::new("."));
    build::build_in(&model, base).map_err(|e| {
        let line = if format == Format::Toml { surface_line(text, e.entry) } else { None };
        // A View3D file's errors name their own file and line already.
        if format == Format::Vs3 && e.field == "file" {
            return SceneError { file: file.to_string(), line: None, message: e.message }.with_own_location();
        }
        let who = if e.name.is_empty() {
            format!("surface #{}", e.entry + 1)
        } else {
            format!("surface #{} '{}'", e.entry + 1, e.name)
        };
        let message = if e.field.is_empty() {
            format!("{who}: {}", e.message)
        } else if e.field == "surface" {
            e.message.clone()
        } else {
            format!("{who}: field `{}` {}", e.field, e.message)
        };
        SceneError { file: file.to_string(), line, message }
    })
}

/// Reads, parses and builds a scene file.
pub fn load(path: &Path) -> Result<Scene, SceneError> {
    load_model(path).map(|(_, scene)| scene)
}

/// Reads, parses and builds a scene file; the model as read, and the scene.
pub fn load_model(path: &Path) -> Result<(SceneFile, Scene), SceneError> {
    let file = path.display().to_string();
    let text = std::fs::read_to_string(path).map_err(|e| SceneError {
        file: file.clone(),
        line: None,
        message: format!("cannot read: {e}"),
    })?;
    let format = Format::of(path);
    let model = parse(&text, format, &file)?;
    let scene = from_text(&text, format, &file)?;
    Ok((model, scene))
}

/// What `pdm-ff matrix --shard K/N` writes: the scene it belongs to (as read), how its pairs
/// were integrated, and its slice of them; `pdm-ff merge` joins the N slices.
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct SliceFile {
    /// The scene model.
    pub scene: SceneFile,
    /// The pair method.
    pub method: matrix::PairMethod,
    /// `f32` or `f64`.
    pub precision: String,
    /// The scene file's folder, where its mesh files are found.
    #[serde(default)]
    pub folder: Option<std::path::PathBuf>,
    /// The slice's pairs.
    pub result: matrix::MatrixResult,
}
