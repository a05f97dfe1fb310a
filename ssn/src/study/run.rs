//! Running a study: each case a run of the command line's kind, its record (the case's
//! values and the JSON document of `ssn solve --json`, `ssn sweep --json` or
//! `ssn solutions --json`) written to `DIR/cases/case-NNNNNN.json` as soon as it is done
//! (atomically: a killed run leaves whole files only), so that a run that is started again
//! skips the cases already done, a shard (`I/N`: the cases whose number is `I - 1` modulo
//! `N`) runs beside the others on a shared directory, and [`merge`] makes the table from
//! the records alone.
//!
//! `DIR/study.json` records the scene and the study texts; it is created exclusively, so of
//! two studies started together on one new directory the second finds the first's manifest,
//! and a run into a directory that holds another study is refused. Every record carries the
//! study's identity ([`study_id`]): a run or a merge takes no record of another study, so
//! records of two studies never mix.

use std::path::{Path, PathBuf};

use serde_json::{json, Value};

use super::table::Table;
use super::{Case, RunKind};
use crate::exit::CliError;
use crate::io::{printable, write_atomically};
use crate::source::SceneSource;
// The study runner of `ssn study` (its thread pool, progress bar and manifest).
#[cfg(feature = "cli")]
use {
    super::Study,
    crate::io::prepare_directory,
    rayon::prelude::*,
    std::sync::atomic::{AtomicUsize, Ordering},
};

/// The `I`-th of `N` shards of a study (`--shard I/N`, `1 <= I <= N`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Shard {
    /// `I`, from 1.
    pub index: usize,
    /// `N`.
    pub count: usize,
}

impl Shard {
    /// The whole study.
    pub const ALL: Shard = Shard { index: 1, count: 1 };

    /// Reads `I/N` with `1 <= I <= N`.
    pub fn parse(text: &str) -> Result<Shard, String> {
        let parsed = text.split_once('/').and_then(|(i, n)| {
            Some(Shard {
                index: i.trim().parse().ok()?,
                count: n.trim().parse().ok()?,
            })
        });
        match parsed {
            Some(s) if s.index >= 1 && s.index <= s.count => Ok(s),
            _ => Err(format!(
                "invalid shard `{text}`: allowed I/N with 1 <= I <= N (e.g. 3/8; Slurm: \
                 $((SLURM_ARRAY_TASK_ID + 1))/$SLURM_ARRAY_TASK_COUNT)"
            )),
        }
    }

    /// Whether case `case` belongs to this shard (round robin, so that every shard gets
    /// cases from every part of a grid).
    pub fn owns(self, case: usize) -> bool {
        case % self.count == self.index - 1
    }
}

/// Runs one case: the scene with the case's values, run as `kind`; the record is
/// `{case, values, converged, result}` with the command line's JSON as `result`, or
/// `{case, values, converged: false, error}` when the run could not be carried out (the
/// message the command line would print).
pub fn run_case(scene: &SceneSource, case: &Case, kind: RunKind) -> Value {
    let mut record = json!({
        "case": case.index,
        "values": case.values_json(),
    });
    match run_document(&scene.with(&case.values), kind) {
        Ok((document, converged)) => {
            record["converged"] = converged.into();
            record["result"] = document;
        }
        Err(e) => {
            record["converged"] = false.into();
            record["error"] = e.to_string().into();
        }
    }
    record
}

/// Runs the scene as `kind` and returns the command line's JSON document and whether the
/// run converged (the exit code 0 of the command).
pub fn run_document(scene: &SceneSource, kind: RunKind) -> Result<(Value, bool), CliError> {
    let loaded = scene.load(match kind {
        RunKind::Solve => crate::load::Workload::Solve,
        RunKind::Sweep | RunKind::Solutions => crate::load::Workload::Branch,
    })?;
    let path = &scene.path;
    let bad = |e: semismooth_contact::solve::RunError| {
        CliError::BadInput(format!("{}: {e}", path.display()))
    };
    match kind {
        RunKind::Solve => {
            let solution = semismooth_contact::solve(
                &loaded.structure,
                loaded.omega,
                &loaded.scene.solver,
                None,
            )
            .map_err(bad)?;
            Ok((
                crate::json::solution_json(path, &solution),
                solution.converged(),
            ))
        }
        RunKind::Sweep => {
            let Some(sweep) = loaded.scene.sweep.as_ref() else {
                return Err(CliError::BadInput(format!(
                    "{}: no [sweep] section: add omega_ratio_from and omega_ratio_to (units of \
                     omega_1)",
                    path.display()
                )));
            };
            let response = semismooth_contact::sweep::frequency_response(
                &loaded.structure,
                &loaded.scene.solver,
                sweep,
                None,
            )
            .map_err(bad)?;
            Ok((crate::json::response_json(&response), response.converged()))
        }
        RunKind::Solutions => {
            let set = semismooth_contact::solutions::find_solutions(
                &loaded.structure,
                loaded.omega,
                &loaded.scene.solver,
                loaded.scene.sweep.as_ref(),
            )
            .map_err(bad)?;
            let document = crate::solutions::document(&set);
            let complete = document["converged"] == true;
            Ok((document, complete))
        }
    }
}

/// The file of case `case`'s record in the study directory `dir`.
pub fn case_file(dir: &Path, case: usize) -> PathBuf {
    dir.join("cases").join(format!("case-{case:06}.json"))
}

/// Writes a case's record atomically (a temporary file beside it, renamed into place), so
/// that a killed run leaves whole records only. Unlike the other outputs it is not synced to
/// the disk: a record is checked when it is read ([`finished_record`]), so one damaged by a
/// machine crash is run again, and a sync per case would cost more than a small solve.
#[cfg(feature = "cli")]
fn write_record(path: &Path, bytes: &[u8]) -> Result<(), CliError> {
    use std::io::Write;
    use std::os::unix::fs::PermissionsExt;
    let io = |e: std::io::Error| {
        CliError::Output(format!("{}: {e}", printable(&path.display().to_string())))
    };
    let dir = path.parent().unwrap_or(Path::new("."));
    let mut tmp = tempfile::Builder::new()
        .prefix(".case.")
        .suffix(".tmp")
        .permissions(std::fs::Permissions::from_mode(0o644))
        .tempfile_in(dir)
        .map_err(io)?;
    tmp.write_all(bytes).map_err(io)?;
    tmp.persist(path).map_err(|e| io(e.error))?;
    Ok(())
}

/// The record of `case` in `dir` when it is there and is this study's record of these
/// values.
#[cfg(feature = "cli")]
fn finished_record(dir: &Path, case: &Case, id: &str) -> Option<Value> {
    let text = std::fs::read_to_string(case_file(dir, case.index)).ok()?;
    let record: Value = serde_json::from_str(&text).ok()?;
    (record["case"] == json!(case.index)
        && record["values"] == case.values_json()
        && record_error(&record, id).is_none())
    .then_some(record)
}

/// What is wrong with `record` as a record of the study `id` (`None`: nothing): it must
/// carry the study's identity, its values, whether it converged, and its result or error.
fn record_error(record: &Value, id: &str) -> Option<&'static str> {
    if record["study"] != json!(id) {
        Some("a record of another study (its `study` differs from the manifest's)")
    } else if !record["values"].is_object() || !record["converged"].is_boolean() {
        Some("not a whole record (`values` and `converged` missing)")
    } else if record["result"].is_null() == record["error"].is_null() {
        Some("not a whole record (one of `result` and `error` expected)")
    } else {
        None
    }
}

/// The identity of the study of `manifest`: FNV-1a (64 bits, as 16 hex digits) of its
/// scene text, overrides, study text and case count.
pub fn study_id(manifest: &Value) -> String {
    let identity = json!([
        manifest["format"],
        manifest["scene_text"],
        manifest["scene_overrides"],
        manifest["study_text"],
        manifest["cases"]
    ])
    .to_string();
    let hash = identity.bytes().fold(0xcbf2_9ce4_8422_2325u64, |h, b| {
        (h ^ u64::from(b)).wrapping_mul(0x0000_0100_0000_01b3)
    });
    format!("{hash:016x}")
}

/// What a study run did.
#[derive(Debug, Clone, PartialEq)]
pub struct StudyOutcome {
    /// Cases of the study.
    pub cases: usize,
    /// Cases of this shard.
    pub in_shard: usize,
    /// Cases of this shard already done (skipped).
    pub skipped: usize,
    /// Cases run now.
    pub ran: usize,
    /// Cases of this shard that did not converge or could not run.
    pub not_converged: usize,
    /// Whether the table was written (the whole study ran in this process).
    pub table_written: bool,
}

/// The manifest of a study directory: the scene and the study as written.
#[cfg(feature = "cli")]
fn manifest(scene: &SceneSource, study: &Study, study_text: &str) -> Value {
    json!({
        "format": "ssn-study",
        "version": 1,
        "scene": scene.path.display().to_string(),
        "scene_text": scene.text,
        "scene_overrides": scene.overrides.iter().map(|o| o.to_string()).collect::<Vec<_>>(),
        "study": study.path.display().to_string(),
        "study_text": study_text,
        "run": study.run.name(),
        "cases": study.cases.len(),
        "keys": study.keys,
    })
}

/// Claims `dir` for this study: creates its manifest (exclusively: of two studies started
/// together, one creates it and the other reads it), or checks that the one there is this
/// study's (the scene and study texts and the case count; the paths may differ).
#[cfg(feature = "cli")]
fn claim_directory(dir: &Path, manifest: &Value) -> Result<(), CliError> {
    prepare_directory(&dir.join("cases"))?;
    let path = dir.join("study.json");
    create_manifest(&path, manifest)?;
    match std::fs::read_to_string(&path) {
        Ok(text) => {
            let found: Value = serde_json::from_str(&text).map_err(|e| {
                CliError::BadInput(format!(
                    "{}: not a study manifest ({e}): allowed a directory of one study",
                    printable(&path.display().to_string())
                ))
            })?;
            for key in [
                "format",
                "scene_text",
                "scene_overrides",
                "study_text",
                "cases",
            ] {
                if found[key] != manifest[key] {
                    return Err(CliError::BadInput(format!(
                        "{}: holds another study (its `{key}` differs): allowed the same scene \
                         and study to continue a run, or a new --out directory",
                        printable(&dir.display().to_string())
                    )));
                }
            }
            Ok(())
        }
        Err(e) => Err(CliError::Output(format!(
            "{}: {e}",
            printable(&path.display().to_string())
        ))),
    }
}

/// Writes `manifest` to `path` unless a file is there already: staged beside it and linked
/// into place without replacing anything, so the manifest is whole when it appears.
#[cfg(feature = "cli")]
fn create_manifest(path: &Path, manifest: &Value) -> Result<(), CliError> {
    use std::io::Write;
    if path.exists() {
        return Ok(());
    }
    let io = |e: std::io::Error| {
        CliError::Output(format!("{}: {e}", printable(&path.display().to_string())))
    };
    let text = serde_json::to_string_pretty(manifest)
        .map_err(|e| CliError::Output(format!("cannot format the manifest: {e}")))?;
    let mut tmp = tempfile::Builder::new()
        .prefix(".study.")
        .suffix(".tmp")
        .tempfile_in(path.parent().unwrap_or(Path::new(".")))
        .map_err(io)?;
    tmp.write_all(format!("{text}\n").as_bytes())
        .and_then(|()| tmp.as_file().sync_all())
        .map_err(io)?;
    match tmp.persist_noclobber(path) {
        Ok(_) => Ok(()),
        Err(e) if e.error.kind() == std::io::ErrorKind::AlreadyExists => Ok(()),
        Err(e) => Err(io(e.error)),
    }
}

/// Options of [`run_study`].
#[cfg(feature = "cli")]
#[derive(Debug, Clone, Copy)]
pub struct RunOptions {
    /// The shard to run.
    pub shard: Shard,
    /// Worker threads (`None`: every core).
    pub jobs: Option<usize>,
}

/// Runs the cases of `shard` not yet done into `dir`, on `jobs` threads of a rayon pool
/// (each case single-threaded: faer's own parallelism is switched off, so cases do not
/// compete for the cores and every case's arithmetic is that of a serial run); writes the
/// table when the shard is the whole study.
#[cfg(feature = "cli")]
pub fn run_study(
    scene: &SceneSource,
    study: &Study,
    study_text: &str,
    dir: &Path,
    options: RunOptions,
) -> Result<StudyOutcome, CliError> {
    let manifest = manifest(scene, study, study_text);
    claim_directory(dir, &manifest)?;
    let id = study_id(&manifest);
    crate::io::keep_on_interrupt(format!(
        "the records of the cases done are kept in {}/cases (run the study again to \
         continue: it skips them)",
        printable(&dir.display().to_string())
    ));
    let mine: Vec<&Case> = study
        .cases
        .iter()
        .filter(|c| options.shard.owns(c.index))
        .collect();
    let pending: Vec<&Case> = mine
        .iter()
        .copied()
        .filter(|c| finished_record(dir, c, &id).is_none())
        .collect();
    let skipped = mine.len() - pending.len();
    let bar = crate::progress::progress_bar_with_estimate(
        pending.len() as u64,
        &format!("study ({} already done)", skipped),
    );
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(options.jobs.unwrap_or(0))
        .build()
        .map_err(|e| CliError::BadInput(format!("cannot start the worker threads: {e}")))?;
    faer::set_global_parallelism(faer::Par::Seq);
    let ran = AtomicUsize::new(0);
    let written: Result<(), CliError> = pool.install(|| {
        pending.par_iter().try_for_each(|case| {
            let mut record = run_case(scene, case, study.run);
            record["study"] = id.clone().into();
            let text = serde_json::to_string_pretty(&record)
                .map_err(|e| CliError::Output(format!("cannot format a record: {e}")))?;
            write_record(&case_file(dir, case.index), format!("{text}\n").as_bytes())?;
            ran.fetch_add(1, Ordering::Relaxed);
            bar.inc(1);
            Ok(())
        })
    });
    bar.finish_and_clear();
    written?;
    let records: Vec<Value> = mine
        .iter()
        .filter_map(|c| finished_record(dir, c, &id))
        .collect();
    let not_converged = records
        .iter()
        .filter(|r| r["converged"] != json!(true))
        .count();
    let whole = options.shard == Shard::ALL;
    if whole {
        write_tables(dir, study.run, &study.keys, &records)?;
    }
    Ok(StudyOutcome {
        cases: study.cases.len(),
        in_shard: mine.len(),
        skipped,
        ran: ran.into_inner(),
        not_converged,
        table_written: whole,
    })
}

/// Writes `results.csv` (and `results.parquet` with the `parquet` feature) into `dir`.
pub fn write_tables(
    dir: &Path,
    kind: RunKind,
    keys: &[String],
    records: &[Value],
) -> Result<Table, CliError> {
    let table = Table::from_records(kind, keys, records);
    write_atomically(&dir.join("results.csv"), table.csv().as_bytes())?;
    #[cfg(feature = "parquet")]
    write_atomically(
        &dir.join("results.parquet"),
        &table
            .parquet()
            .map_err(|e| CliError::Output(format!("cannot write the Parquet table: {e}")))?,
    )?;
    Ok(table)
}

/// `ssn study merge DIR`: the table of a study run in shards, from the records in `dir`;
/// refused (bad input) while cases are missing, with their numbers.
pub fn merge(dir: &Path) -> Result<Table, CliError> {
    let path = dir.join("study.json");
    let text = std::fs::read_to_string(&path).map_err(|e| {
        CliError::BadInput(format!(
            "{}: {e}: allowed a directory written by `ssn study`",
            printable(&path.display().to_string())
        ))
    })?;
    let manifest: Value = serde_json::from_str(&text).map_err(|e| {
        CliError::BadInput(format!(
            "{}: not a study manifest: {e}",
            printable(&path.display().to_string())
        ))
    })?;
    let shown = printable(&path.display().to_string());
    let (Some(cases), Some(kind), Some(keys)) = (
        manifest["cases"].as_u64(),
        manifest["run"].as_str().and_then(RunKind::from_name),
        manifest["keys"].as_array(),
    ) else {
        return Err(CliError::BadInput(format!(
            "{shown}: not a study manifest (cases, run, keys)"
        )));
    };
    let cases = usize::try_from(cases)
        .ok()
        .filter(|n| (1..=super::MAX_CASES).contains(n))
        .ok_or_else(|| {
            CliError::BadInput(format!(
                "{shown}: `cases` is {cases}: allowed 1..={} (the manifest `ssn study` wrote)",
                super::MAX_CASES
            ))
        })?;
    let keys: Vec<String> = keys
        .iter()
        .filter_map(|k| k.as_str().map(str::to_string))
        .collect();
    let id = study_id(&manifest);
    let mut records = Vec::new();
    let mut missing = Vec::new();
    for case in 0..cases {
        let file = case_file(dir, case);
        let record = std::fs::read_to_string(&file)
            .ok()
            .and_then(|t| serde_json::from_str::<Value>(&t).ok())
            .filter(|r| r["case"] == json!(case));
        match record {
            Some(r) => {
                if let Some(wrong) = record_error(&r, &id) {
                    return Err(CliError::BadInput(format!(
                        "{}: {wrong}: allowed the records `ssn study` wrote for the study of \
                         {shown} (run it again to replace the record)",
                        printable(&file.display().to_string())
                    )));
                }
                records.push(r)
            }
            None => missing.push(case),
        }
    }
    if !missing.is_empty() {
        let listed: Vec<String> = missing.iter().take(10).map(|c| c.to_string()).collect();
        return Err(CliError::BadInput(format!(
            "{}: {} of {cases} cases not done yet ({}{}): run the missing shards (a re-run \
             skips the cases done), then merge",
            printable(&dir.display().to_string()),
            missing.len(),
            listed.join(", "),
            if missing.len() > 10 { ", ..." } else { "" }
        )));
    }
    write_tables(dir, kind, &keys, &records)
}
