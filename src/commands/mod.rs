//! One module per subcommand.

pub mod check;
pub mod variants;

use std::path::Path;

use anyhow::Result;
use counterpoise_model::{Case, Model};

/// Loads a case, or prints every validation error (one per line, each naming its JSON path) and
/// returns `None`.
pub fn load(path: &Path) -> Result<Option<Model>> {
    match Case::from_path(path) {
        Ok(model) => Ok(Some(model)),
        Err(errors) => {
            eprintln!("{}: {} error(s)", path.display(), errors.len());
            for e in &errors {
                eprintln!("  {e}");
            }
            Ok(None)
        }
    }
}
