//! Run reports: which stages ran, with their parameters and times, as JSON and a table.

use std::path::{Path, PathBuf};

use serde::Serialize;

use crate::Error;

/// One stage that ran.
#[derive(Clone, Debug, Serialize)]
pub struct StageRecord {
    /// Stage name (see [`crate::Stage`]).
    pub stage: String,
    /// Wall time in milliseconds.
    pub millis: f64,
    /// Parameters and results worth reading (counts, levels, adapter, errors).
    pub params: serde_json::Value,
}

/// Everything a run did.
#[derive(Clone, Debug, Serialize)]
pub struct RunReport {
    /// Scene name.
    pub scene: String,
    /// Where the scene came from.
    pub origin: String,
    /// Effects requested, in stage order.
    pub effects: Vec<String>,
    /// Stages in the order they ran.
    pub stages: Vec<StageRecord>,
    /// Total wall time in milliseconds.
    pub total_millis: f64,
    /// Files written.
    pub outputs: Vec<PathBuf>,
}

impl RunReport {
    /// A readable table of the stages.
    pub fn table(&self) -> String {
        let mut out = format!(
            "run report: scene {:?} ({}), effects: [{}]\n",
            self.scene,
            self.origin,
            self.effects.join(", ")
        );
        let width = self
            .stages
            .iter()
            .map(|s| s.stage.len())
            .max()
            .unwrap_or(5)
            .max(5);
        out.push_str(&format!(
            "{:<width$}  {:>10}  parameters\n",
            "stage", "time (ms)"
        ));
        for s in &self.stages {
            let params = match &s.params {
                serde_json::Value::Object(map) => map
                    .iter()
                    .map(|(k, v)| format!("{k}={}", compact(v)))
                    .collect::<Vec<_>>()
                    .join(" "),
                other => compact(other),
            };
            out.push_str(&format!(
                "{:<width$}  {:>10.1}  {params}\n",
                s.stage, s.millis
            ));
        }
        out.push_str(&format!(
            "{:<width$}  {:>10.1}\n",
            "total", self.total_millis
        ));
        for o in &self.outputs {
            out.push_str(&format!("wrote {}\n", o.display()));
        }
        out
    }

    /// Write `run-report.json` and `run-report.txt` into `dir` (atomically each), naming the
    /// outputs — these two included, as returned — where they will be once `dir` (a run's
    /// temporary folder) is renamed to `final_dir`; pass the same folder twice when it is final.
    ///
    /// # Errors
    /// [`Error::Io`] naming the file.
    pub fn write(&mut self, dir: &Path, final_dir: &Path) -> Result<(PathBuf, PathBuf), Error> {
        // The outputs are named where they will be once `dir` is renamed to `final_dir`.
        for path in &mut self.outputs {
            if let Ok(name) = path.strip_prefix(dir) {
                *path = final_dir.join(name);
            }
        }
        let names = ["run-report.json", "run-report.txt"];
        let json = serde_json::to_string_pretty(self).map_err(|e| Error::Io {
            path: final_dir.join(names[0]),
            reason: e.to_string(),
        })?;
        write_atomic(&dir.join(names[0]), json.as_bytes())?;
        write_atomic(&dir.join(names[1]), self.table().as_bytes())?;
        Ok((final_dir.join(names[0]), final_dir.join(names[1])))
    }
}

fn compact(v: &serde_json::Value) -> String {
    match v {
        serde_json::Value::String(s) => s.clone(),
        other => other.to_string(),
    }
}

/// Write bytes to a temporary file beside `path` and rename it into place
/// ([`atomic_out::write_bytes`]).
///
/// # Errors
/// [`Error::Io`] naming `path` and the step that failed; no partial file is left behind.
pub fn write_atomic(path: &Path, bytes: &[u8]) -> Result<(), Error> {
    Ok(atomic_out::write_bytes(path, bytes)?)
}
