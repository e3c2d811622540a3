//! `armcal import`: a data file as the cell's `[data]` section maps it, written in armcal's
//! own CSV (to see what armcal reads, or to keep a converted copy).

use super::output::{load_cell, Outputs};
use std::path::{Path, PathBuf};

#[derive(clap::Args)]
pub struct Args {
    /// Cell file whose `[data]` section says how the file is laid out.
    #[arg(long)]
    pub cell: String,
    /// The data file as it comes from the instrument or vendor.
    #[arg(long)]
    pub data: PathBuf,
    /// Output (armcal's CSV).
    #[arg(long)]
    pub out: PathBuf,
    /// Overwrite existing output files (never an input file).
    #[arg(long)]
    pub force: bool,
}

pub fn run(a: &Args) -> anyhow::Result<()> {
    let outputs = Outputs::plan(a.force, &[Path::new(&a.cell), &a.data], &[&a.out])?;
    let cell = load_cell(&a.cell)?;
    let import = cell.import_data(&a.data)?;
    outputs.commit(&[(&a.out, &cell.with_controller_columns(import.csv.clone())?)])?;
    super::output::print_read_report(&import.report);
    println!(
        "read {} measurements at {} configurations from {} → {}",
        import.data.measurements.len(),
        import.data.configurations.len(),
        a.data.display(),
        a.out.display()
    );
    Ok(())
}
