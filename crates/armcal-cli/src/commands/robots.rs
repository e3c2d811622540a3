//! `armcal robots`

pub fn run() -> anyhow::Result<()> {
    println!("{:<16} description", "name");
    for (name, summary) in armcal::Cell::robots() {
        println!("{name:<16} {summary}");
    }
    println!("\nThe paper's notional family is also available as paper-<λ mm>-<μ mm>, e.g. paper-1100-1000.");
    Ok(())
}
