//! [`run_eval`]: `coseg eval RESULT --truth DIR [--json FILE]` as a library call.

use super::JobError;
use crate::evaluate::{EvaluateFolderOptions, FolderScores, evaluate_folder};
use std::path::{Path, PathBuf};

/// Options of [`run_eval`] (`coseg eval`).
#[derive(Debug, Clone, Default, PartialEq)]
#[non_exhaustive]
pub struct EvalJob {
    /// The scoring options ([`EvaluateFolderOptions::default`]: no correspondence map).
    pub evaluate: EvaluateFolderOptions,
    /// Also write the scores as JSON to this file, atomically (default: none).
    pub json: Option<PathBuf>,
}

/// Scores the result folder `result` (written by `coseg segment`, `pair` or `propagate`)
/// against the ground truth in `truth`, and writes the scores as JSON when asked.
///
/// Errors: [`JobError::Stage`] naming `result` when it cannot be scored;
/// [`JobError::Output`] when the JSON file cannot be written.
///
/// See also: [`evaluate_folder`], the scoring itself.
pub fn run_eval(result: &Path, truth: &Path, job: &EvalJob) -> Result<FolderScores, JobError> {
    let scores = evaluate_folder(result, truth, &job.evaluate).map_err(|e| JobError::Stage {
        context: format!("scoring {}", result.display()),
        source: Box::new(e),
    })?;
    if let Some(path) = &job.json {
        let text = serde_json::to_string_pretty(&scores)
            .map_err(|e| JobError::Invalid(format!("scores as JSON: {e}")))?;
        crate::mesh::write_atomic(path, |w| std::io::Write::write_all(w, text.as_bytes()))
            .map_err(|source| {
                crate::output::OutputError::Io(crate::FileError {
                    path: path.display().to_string(),
                    source,
                })
            })?;
    }
    Ok(scores)
}
