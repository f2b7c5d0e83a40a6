//! One module per subcommand: each calls the study library with the parsed arguments, prints
//! what it returns and writes its files. The work is in `counterpoise_study`.

pub mod import_urdf;
pub mod progress;
pub mod run;
pub mod text;

use std::path::Path;
use std::process::ExitCode;

use counterpoise_model::Model;
use counterpoise_study::StudyError;

/// Loads a case, or prints every validation error (one per line, each naming its JSON path,
/// line and column) and returns `None`.
pub fn load(path: &Path) -> Option<Model> {
    counterpoise_study::load_case(path)
        .map_err(|e| eprintln!("{e}"))
        .ok()
}

/// Ends a command on `e`: a case's problems are listed as they are (exit 1); any other error
/// is printed after `error:` with its causes (exit 1).
pub fn failed(e: StudyError) -> ExitCode {
    if let StudyError::Case { .. } | StudyError::Problems(_) = e {
        eprintln!("{e}");
    } else {
        eprintln!("error: {}", counterpoise_study::error::with_causes(&e));
    }
    ExitCode::FAILURE
}

/// Prints a command's text, or ends on its error.
pub fn print_or_fail(result: Result<String, StudyError>) -> ExitCode {
    match result {
        Ok(text) => {
            print!("{text}");
            ExitCode::SUCCESS
        }
        Err(e) => failed(e),
    }
}
