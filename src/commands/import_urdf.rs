//! `counterpoise import-urdf ROBOT.urdf`: write a case file from a URDF robot description.

use std::path::Path;
use std::process::ExitCode;

use anyhow::{Context, Result};
use counterpoise_urdf::{ImportOptions, import};

pub fn run(urdf: &Path, out: Option<&Path>, options: ImportOptions) -> Result<ExitCode> {
    let text =
        std::fs::read_to_string(urdf).with_context(|| format!("cannot read {}", urdf.display()))?;
    let imported = import(&text, &options).with_context(|| urdf.display().to_string())?;
    match out {
        Some(path) => {
            counterpoise_study::write_file(path, imported.json.as_bytes())?;
            let model = &imported.model;
            eprintln!(
                "wrote {}: {} bodies, {} coordinates, {} actuators",
                path.display(),
                model.bodies.len(),
                model.coordinates.len(),
                model.actuators.len()
            );
        }
        None => print!("{}", imported.json),
    }
    Ok(ExitCode::SUCCESS)
}
