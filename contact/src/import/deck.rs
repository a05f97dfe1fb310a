//! The lines of a CalculiX or Abaqus input deck with every `*INCLUDE, INPUT=file` replaced by
//! the lines of the named file: a relative name is taken from the including file's directory,
//! includes nest at most [`MAX_INCLUDE_DEPTH`] deep, and a file that includes itself (directly
//! or through others) is refused with the chain of files. Each line keeps its file and its
//! 1-based number, so a defect found later names where it is.

use std::path::{Path, PathBuf};

use super::dof_map::read_text;
use super::DofMapError;

/// Deepest nesting of `*INCLUDE` (the top deck is depth 0).
pub const MAX_INCLUDE_DEPTH: usize = 16;

/// Why an `*INCLUDE` could not be followed.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum IncludeError {
    /// The included file could not be read.
    #[error("{0}")]
    File(DofMapError),
    /// The `*INCLUDE` line names no file, a file that includes itself, or nests too deep.
    #[error(
        "{path}: line {line}: *INCLUDE: {problem}: allowed `*INCLUDE, INPUT=file` naming a \
         readable deck, at most 16 deep, no file including itself"
    )]
    Line {
        /// The including file.
        path: PathBuf,
        /// 1-based line of the `*INCLUDE`.
        line: usize,
        /// What is wrong.
        problem: String,
    },
}

/// One line of a deck: its file (an index into [`Deck::files`]), its 1-based number there
/// and its text, trimmed.
#[derive(Debug, Clone, PartialEq)]
pub(super) struct DeckLine {
    pub file: usize,
    pub line: usize,
    pub text: String,
}

/// A deck with its includes expanded (module documentation).
#[derive(Debug, Clone, PartialEq, Default)]
pub(super) struct Deck {
    /// Every file read, the top deck first.
    pub files: Vec<PathBuf>,
    /// The lines in reading order, blank lines and `**` comments left out.
    pub lines: Vec<DeckLine>,
}

impl Deck {
    /// The deck whose top file `path` has the text `text`; included files are read.
    pub fn parse(text: &str, path: &Path) -> Result<Self, IncludeError> {
        let mut deck = Self::default();
        let mut chain = vec![identity(path)];
        deck.expand(text, path, &mut chain)?;
        Ok(deck)
    }

    /// The file of `line`.
    pub fn file_of(&self, line: &DeckLine) -> &Path {
        &self.files[line.file]
    }

    /// Appends the lines of `text` (the file `path`, included through `chain`).
    fn expand(
        &mut self,
        text: &str,
        path: &Path,
        chain: &mut Vec<PathBuf>,
    ) -> Result<(), IncludeError> {
        let file = self.files.len();
        self.files.push(path.to_path_buf());
        for (k, raw) in text.lines().enumerate() {
            let t = raw.trim();
            if t.is_empty() || t.starts_with("**") {
                continue;
            }
            let keyword = t.split(',').next().unwrap_or("").trim();
            if !keyword.eq_ignore_ascii_case("*INCLUDE") {
                self.lines.push(DeckLine {
                    file,
                    line: k + 1,
                    text: t.to_string(),
                });
                continue;
            }
            let error = |problem: String| IncludeError::Line {
                path: path.to_path_buf(),
                line: k + 1,
                problem,
            };
            let name = include_target(t).ok_or_else(|| error("no INPUT=file".into()))?;
            let target = path.parent().unwrap_or(Path::new("")).join(name);
            if chain.len() > MAX_INCLUDE_DEPTH {
                return Err(error(format!(
                    "`{}` would be include {} deep",
                    target.display(),
                    chain.len()
                )));
            }
            let id = identity(&target);
            if let Some(first) = chain.iter().position(|p| *p == id) {
                let mut cycle: Vec<String> = chain[first..]
                    .iter()
                    .map(|p| p.display().to_string())
                    .collect();
                cycle.push(target.display().to_string());
                return Err(error(format!(
                    "a cycle of includes: {}",
                    cycle.join(" -> ")
                )));
            }
            let included = read_text(&target).map_err(IncludeError::File)?;
            chain.push(id);
            self.expand(&included, &target, chain)?;
            chain.pop();
        }
        Ok(())
    }
}

/// The file an `*INCLUDE` line names (`INPUT=name`, optionally quoted).
fn include_target(line: &str) -> Option<&str> {
    line.split(',').skip(1).find_map(|p| {
        let (key, value) = p.split_once('=')?;
        key.trim()
            .eq_ignore_ascii_case("INPUT")
            .then(|| value.trim().trim_matches('"'))
            .filter(|v| !v.is_empty())
    })
}

/// The path that identifies a file in a chain of includes: its canonical form where it
/// exists, else the path itself.
fn identity(path: &Path) -> PathBuf {
    std::fs::canonicalize(path).unwrap_or_else(|_| path.to_path_buf())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn scratch(name: &str) -> PathBuf {
        let dir = std::env::temp_dir().join(format!("deck-{name}-{}", std::process::id()));
        std::fs::create_dir_all(dir.join("sub")).unwrap();
        dir
    }

    #[test]
    fn an_include_is_read_relative_to_the_including_file_and_keeps_its_line_numbers() {
        let dir = scratch("nested");
        std::fs::write(
            dir.join("sub/a.inp"),
            "*NODE\n1, 0, 0, 0\n*INCLUDE, INPUT=b.inp\n",
        )
        .unwrap();
        std::fs::write(dir.join("sub/b.inp"), "** comment\n2, 1, 0, 0\n").unwrap();
        let top = dir.join("top.inp");
        let text = "*HEADING\n*INCLUDE, input=\"sub/a.inp\"\n3, 2, 0, 0\n";
        let deck = Deck::parse(text, &top).unwrap();
        let seen: Vec<(String, usize, &str)> = deck
            .lines
            .iter()
            .map(|l| {
                let file = deck
                    .file_of(l)
                    .file_name()
                    .unwrap()
                    .to_string_lossy()
                    .to_string();
                (file, l.line, l.text.as_str())
            })
            .collect();
        let want = [
            ("top.inp", 1, "*HEADING"),
            ("a.inp", 1, "*NODE"),
            ("a.inp", 2, "1, 0, 0, 0"),
            ("b.inp", 2, "2, 1, 0, 0"),
            ("top.inp", 3, "3, 2, 0, 0"),
        ];
        assert_eq!(seen.len(), want.len(), "{seen:?}");
        for (got, want) in seen.iter().zip(want) {
            assert_eq!((got.0.as_str(), got.1, got.2), want);
        }
        std::fs::remove_dir_all(dir).unwrap();
    }

    #[test]
    fn a_cycle_of_includes_is_refused_with_the_chain_of_files() {
        let dir = scratch("cycle");
        std::fs::write(dir.join("a.inp"), "*INCLUDE, INPUT=b.inp\n").unwrap();
        std::fs::write(dir.join("b.inp"), "*NODE\n*INCLUDE, INPUT=a.inp\n").unwrap();
        let top = dir.join("a.inp");
        let e = Deck::parse("*INCLUDE, INPUT=b.inp\n", &top)
            .unwrap_err()
            .to_string();
        assert!(e.contains("b.inp: line 2: *INCLUDE"), "{e}");
        assert!(e.contains("a cycle of includes"), "{e}");
        assert!(e.contains("a.inp -> ") && e.ends_with("allowed `*INCLUDE, INPUT=file` naming a readable deck, at most 16 deep, no file including itself"), "{e}");
        std::fs::remove_dir_all(dir).unwrap();
    }

    #[test]
    fn includes_deeper_than_the_limit_and_missing_files_are_refused() {
        let dir = scratch("deep");
        // d0 includes d1 includes ... : a chain of MAX_INCLUDE_DEPTH + 2 distinct files.
        for k in 0..MAX_INCLUDE_DEPTH + 2 {
            let next = format!("*INCLUDE, INPUT=d{}.inp\n", k + 1);
            std::fs::write(dir.join(format!("d{k}.inp")), next).unwrap();
        }
        let top = dir.join("d0.inp");
        let text = std::fs::read_to_string(&top).unwrap();
        let e = Deck::parse(&text, &top).unwrap_err().to_string();
        assert!(e.contains("17 deep"), "{e}");
        let e = Deck::parse("*INCLUDE, INPUT=missing.inp\n", &top)
            .unwrap_err()
            .to_string();
        assert!(e.contains("missing.inp"), "{e}");
        let e = Deck::parse("*INCLUDE\n", &top).unwrap_err().to_string();
        assert!(e.contains("line 1: *INCLUDE: no INPUT=file"), "{e}");
        std::fs::remove_dir_all(dir).unwrap();
    }
}
