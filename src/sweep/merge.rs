//! `merge` of shards' CSV files: the identity files beside them checked
//! (one sweep), the rows merged ([`super::table::merge`]) into a file put
//! in place only when the merge succeeds, and `summary.json` beside it.

use std::io::Write;
use std::path::{Path, PathBuf};

use csv::ReaderBuilder;
use thiserror::Error;

use super::error::SweepError;
use super::table::{
    ARC_COLUMNS, Columns, MergeError, MergeReport, OUTCOME_COLUMNS, RELEASE_COLUMNS, merge,
};

/// [`merge`] of files into the file `output`, through a temporary file
/// beside it that is renamed into place only when the merge succeeds (a
/// refused merge leaves no file). Unless `overwrite`, an existing
/// `output` is an error and stays untouched. A shard without its identity
/// file beside it is refused unless `unverified`, and the summary then
/// says that the identity was not verified.
pub fn merge_files(
    output: &Path,
    inputs: &[PathBuf],
    expected: Option<u64>,
    allow_missing: bool,
    overwrite: bool,
    unverified: bool,
) -> Result<MergeReport, MergeFilesError> {
    let io = |source| MergeFilesError::Output {
        path: output.to_owned(),
        source,
    };
    // Every shard with an identity file beside it must be of one sweep.
    let mut known: Option<(PathBuf, super::resume::Identity)> = None;
    let mut without_identity = false;
    for path in inputs {
        let Some(meta) = super::resume::meta_beside(path)? else {
            if !unverified {
                return Err(MergeFilesError::NoIdentity {
                    shard: path.clone(),
                    meta: super::resume::meta_path(path),
                });
            }
            without_identity = true;
            continue;
        };
        match &known {
            None => known = Some((path.clone(), meta.identity)),
            Some((first, identity)) => {
                if let Some((field, a, b)) = super::resume::differs(identity, &meta.identity) {
                    return Err(MergeFilesError::DifferentSweeps {
                        first: first.clone(),
                        other: path.clone(),
                        field,
                        first_value: a,
                        other_value: b,
                    });
                }
            }
        }
    }
    let expected = expected.or(known.as_ref().map(|(_, i)| i.samples));
    // Both outputs are checked before either is written.
    crate::output::check_target(&output.with_file_name("summary.json"), overwrite)?;
    let mut staged = crate::output::Staged::new(output, overwrite)?;
    let mut readers = Vec::with_capacity(inputs.len());
    for path in inputs {
        let file = crate::input::open_regular(path).map_err(|source| MergeFilesError::Open {
            path: path.clone(),
            source,
        })?;
        readers.push((path.clone(), std::io::BufReader::new(file)));
    }
    let mut buffered = std::io::BufWriter::new(staged.file());
    let report = merge(readers, &mut buffered, expected, allow_missing)?;
    buffered.flush().map_err(io)?;
    drop(buffered);
    staged.commit()?;
    let verified = if without_identity {
        "unverified"
    } else {
        "verified"
    };
    write_merged_summary(output, known.map(|(_, i)| i), verified, overwrite)?;
    Ok(report)
}

/// The keys, probe signals and optional columns of a sweep CSV's header.
pub fn layout_of(header: &[u8]) -> Option<(Vec<String>, Vec<String>, Columns)> {
    let mut reader = ReaderBuilder::new().has_headers(false).from_reader(header);
    let mut row = csv::StringRecord::new();
    if !reader.read_record(&mut row).ok()? {
        return None;
    }
    let names: Vec<&str> = row.iter().collect();
    let outcome_at = names.iter().position(|n| *n == OUTCOME_COLUMNS[0])?;
    let keys = names
        .get(1..outcome_at)?
        .iter()
        .map(|s| (*s).to_owned())
        .collect();
    let signals = names
        .iter()
        .filter_map(|n| n.strip_suffix(".edges"))
        .map(str::to_owned)
        .collect();
    let columns = Columns {
        coil: names.contains(&RELEASE_COLUMNS[0]),
        ideal: names.iter().any(|n| n.ends_with(".ideal_edges")),
        arc: names.contains(&ARC_COLUMNS[0]),
    };
    Some((keys, signals, columns))
}

/// `summary.json` beside the merged CSV `output`, from its rows (the
/// worst sample's values read from its row); `identity` says whether the
/// sweep was a grid and its seed, when the shards carried it.
fn write_merged_summary(
    output: &Path,
    identity: Option<super::resume::Identity>,
    verified: &'static str,
    overwrite: bool,
) -> Result<(), MergeFilesError> {
    // The header only: the rows are read one at a time below.
    let mut header = Vec::new();
    crate::input::open_regular(output)
        .and_then(|file| {
            std::io::BufRead::read_until(&mut std::io::BufReader::new(file), b'\n', &mut header)
        })
        .map_err(|source| MergeFilesError::Output {
            path: output.to_owned(),
            source,
        })?;
    let header = &header[..];
    let Some((keys, signals, columns)) = layout_of(header) else {
        return Ok(());
    };
    let summary_error = |e: SweepError| MergeFilesError::Summary(e.to_string());
    let mut collected = super::summary::Collected::new(keys.clone(), signals.clone());
    super::resume::all_rows(output, header, keys.len(), signals.len(), columns, |r| {
        collected.add(&r).map_err(summary_error)
    })?;
    let seed = identity.as_ref().and_then(|i| i.seed);
    let grid = identity.as_ref().is_some_and(|i| i.seed.is_none());
    // The worst sample's values: a second pass over the rows.
    let mut worst_values = Vec::new();
    if let Some(worst) = collected.worst_index() {
        let mut found = false;
        super::resume::all_rows(output, header, keys.len(), signals.len(), columns, |r| {
            if !found && r.index == worst {
                worst_values = r.values;
                found = true;
            }
            Ok::<_, MergeFilesError>(())
        })?;
    }
    let mut summary = collected
        .summary_with(grid, seed, |_| Ok(worst_values.clone()))
        .map_err(summary_error)?;
    summary.identity = Some(verified);
    let path = output.with_file_name("summary.json");
    crate::output::write_new_file(&path, summary.to_json().as_bytes(), overwrite)?;
    Ok(())
}

/// Why [`merge_files`] failed.
#[derive(Debug, Error)]
#[non_exhaustive]
pub enum MergeFilesError {
    /// An input could not be opened (or is not a regular file).
    #[error("{}: cannot open it", path.display())]
    Open {
        /// The input.
        path: PathBuf,
        /// Why it could not be opened.
        #[source]
        source: std::io::Error,
    },
    /// The inputs could not be merged.
    #[error(transparent)]
    Merge(#[from] MergeError),
    /// A shard has no identity file beside it (as `scp shards/*.csv`
    /// leaves them): its seed, scenario and sample count cannot be checked
    /// against the other shards'.
    #[error(
        "{}: its identity file {} is missing, so it cannot be checked to be a shard of the \
         same sweep as the others (seed, scenario, sample count); copy the .meta.json files \
         with the CSVs, or merge with --unverified to accept the rows unchecked",
        shard.display(),
        meta.display()
    )]
    NoIdentity {
        /// The shard's CSV.
        shard: PathBuf,
        /// The identity file that should be beside it.
        meta: PathBuf,
    },
    /// Two inputs belong to different sweeps, by the identity files beside
    /// them.
    #[error(
        "{} and {} are shards of different sweeps: their {field} differs ({first_value} \
         against {other_value}); merge only the shards of one sweep",
        first.display(),
        other.display()
    )]
    DifferentSweeps {
        /// The first input with an identity file.
        first: PathBuf,
        /// The input that differs from it.
        other: PathBuf,
        /// What differs: `seed`, `scenario (...)`, `sample count`, ...
        field: &'static str,
        /// Its value for `first`.
        first_value: String,
        /// Its value for `other`.
        other_value: String,
    },
    /// An identity file beside an input cannot be read, or the merged
    /// rows cannot be read back for the summary.
    #[error(transparent)]
    Identity(#[from] super::resume::ResumeError),
    /// The summary of the merged rows could not be made.
    #[error("cannot summarize the merged rows: {0}")]
    Summary(String),
    /// The output could not be created or put in place (e.g. it exists
    /// and overwriting was not asked for).
    #[error(transparent)]
    Write(#[from] crate::output::WriteError),
    /// The merged rows could not be flushed to the temporary output file.
    #[error("{}: cannot write the merged CSV", path.display())]
    Output {
        /// The output.
        path: PathBuf,
        /// Why it could not be written.
        #[source]
        source: std::io::Error,
    },
}
