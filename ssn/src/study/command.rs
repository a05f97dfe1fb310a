//! `ssn study SCENE STUDY.toml --out DIR` and `ssn study merge DIR`: the command line of
//! [`super::run`].

use std::path::PathBuf;

use super::run::{merge, run_study, RunOptions, Shard};
use super::Study;
use crate::exit::CliError;
use crate::io::{printable, write_text};
use crate::scene::Override;
use crate::source::SceneSource;

/// What `ssn study` reads: a scene, a study file and where the records go; or `merge`.
#[derive(Debug, Clone, clap::Args)]
#[command(args_conflicts_with_subcommands = true, subcommand_negates_reqs = true)]
pub struct StudyArgs {
    /// `merge DIR`: the table of a study run in shards.
    #[command(subcommand)]
    pub command: Option<StudyCommand>,
    /// Scene file (TOML).
    #[arg(required = true)]
    pub scene: Option<PathBuf>,
    /// Study file (TOML): `run`, `[grid]`, `[[case]]`, `[random]`.
    #[arg(required = true)]
    pub study: Option<PathBuf>,
    /// Directory of the records (`cases/`), the manifest and the tables.
    #[arg(long, required = true)]
    pub out: Option<PathBuf>,
    /// Run only the I-th of N shards (cases numbered I - 1 modulo N), e.g. one task of a
    /// job array; then `ssn study merge DIR`.
    #[arg(long, value_name = "I/N", value_parser = Shard::parse)]
    pub shard: Option<Shard>,
    /// Worker threads, 1 to 1024 [default: every core].
    #[arg(long, allow_hyphen_values = true, value_parser = clap::value_parser!(u16).range(1..=MAX_JOBS))]
    pub jobs: Option<u16>,
    /// Replace a scene key for every case (as in `ssn solve --set`).
    #[arg(long = "set", value_name = "KEY=VALUE", value_parser = parse_override)]
    pub set: Vec<Override>,
}

/// Most worker threads of `--jobs` (more only costs the time to create them: each case runs
/// on one thread, and a machine has far fewer cores).
pub const MAX_JOBS: i64 = 1024;

/// `ssn study merge DIR`.
#[derive(Debug, Clone, clap::Subcommand)]
pub enum StudyCommand {
    /// Join the records of a study run in shards into its tables (refused while cases are
    /// missing).
    Merge {
        /// The study's --out directory.
        dir: PathBuf,
    },
}

fn parse_override(text: &str) -> Result<Override, String> {
    Override::parse(text).map_err(|e| e.to_string())
}

/// Runs `ssn study`: exit 0 when every case converged, 1 when some did not (the table is
/// written all the same), 2 for a bad scene, study or case, 3 when a record or a table
/// could not be written.
pub fn command(args: &StudyArgs) -> Result<(), CliError> {
    if let Some(StudyCommand::Merge { dir }) = &args.command {
        let table = merge(dir)?;
        let failed = table.column("converged").map_or(0, |c| {
            c.cells
                .iter()
                .filter(|v| **v != super::table::Cell::Bool(true))
                .count()
        });
        write_text(&format!(
            "merged {} cases ({failed} not converged) into {}\n",
            table.rows(),
            tables_written(dir)
        ))?;
        return if failed == 0 {
            Ok(())
        } else {
            Err(CliError::NotConverged)
        };
    }
    let (Some(scene_path), Some(study_path), Some(out)) = (&args.scene, &args.study, &args.out)
    else {
        return Err(CliError::BadInput(
            "ssn study needs SCENE STUDY.toml --out DIR (or `ssn study merge DIR`)".into(),
        ));
    };
    // The limits every case would apply, refused once here rather than in every case.
    crate::limits::work_limit().map_err(CliError::BadInput)?;
    crate::limits::memory_limit().map_err(CliError::BadInput)?;
    let scene = SceneSource::from_path(scene_path)
        .map_err(|e| CliError::BadInput(e.to_string()))?
        .with(&args.set);
    scene
        .scene()
        .map_err(|e| CliError::BadInput(e.to_string()))?;
    let study_text = crate::io::read_regular_file(study_path, crate::io::SCENE_SIZE_LIMIT)
        .map_err(|e| {
            CliError::BadInput(format!(
                "{}: cannot read study: {e}",
                printable(&study_path.display().to_string())
            ))
        })?;
    let study = Study::from_toml(&study_text, study_path, &scene)
        .map_err(|e| CliError::BadInput(e.to_string()))?;
    let shard = args.shard.unwrap_or(Shard::ALL);
    let outcome = run_study(
        &scene,
        &study,
        &study_text,
        out,
        RunOptions {
            shard,
            jobs: args.jobs.map(usize::from),
        },
    )?;
    let mut text = format!(
        "study             {} cases ({} each), {}\n",
        outcome.cases,
        study.run.name(),
        if shard == Shard::ALL {
            "the whole study".to_string()
        } else {
            format!(
                "shard {}/{}: {} cases",
                shard.index, shard.count, outcome.in_shard
            )
        }
    );
    text += &format!(
        "cases             {} already done, {} run now, {} not converged\n",
        outcome.skipped, outcome.ran, outcome.not_converged
    );
    text += &if outcome.table_written {
        format!("wrote             {}\n", tables_written(out))
    } else {
        format!(
            "records           {}/cases; when every shard is done: ssn study merge {}\n",
            printable(&out.display().to_string()),
            printable(&out.display().to_string())
        )
    };
    write_text(&text)?;
    if outcome.not_converged == 0 {
        Ok(())
    } else {
        Err(CliError::NotConverged)
    }
}

/// The table files of `dir` in words.
fn tables_written(dir: &std::path::Path) -> String {
    let dir = printable(&dir.display().to_string());
    if cfg!(feature = "parquet") {
        format!("{dir}/results.csv and {dir}/results.parquet")
    } else {
        format!("{dir}/results.csv")
    }
}
