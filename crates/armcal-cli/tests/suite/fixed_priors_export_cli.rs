//! `export --cell` carries the fixed parameters' stated σ (issue 30 item 5): the exported
//! cell reads back with the σ the original gives every parameter — the kinds'
//! `fixed_prior`, the named `fixed_priors`, and a `[tool]` the original gives (which the
//! export writes as a link, so without an entry its parameters would read back as exact).

use crate::common::{armcal, scratch, simulate_and_identify_variant};
use armcal::Cell;

#[test]
fn an_exported_cell_reads_back_with_the_same_fixed_priors() {
    let dir = scratch("fixed_priors_export");
    let path = |f: &str| dir.join(f).to_str().unwrap().to_string();
    let text = std::fs::read_to_string("../../examples/paper-cell.toml")
        .unwrap()
        .replace(
            "[parameters]\n",
            "[tool]\nxyz_mm = [0, 0, 50]\nrpy_deg = [0, 0, 0]\n\n[parameters]\n\
             fixed_prior = { length_mm = 0.3, angle_deg = 0.05, unitless = 0.002 }\n\
             fixed_priors = { \"j6.d\" = { sigma_mm = 2.0 }, \"j1.theta\" = { sigma_deg = 0.2 }, \"tool.z\" = { sigma_mm = 1.5 }, \"j5.d\" = { sigma_mm = 0 } }\n",
        );
    let [cell_path, _, est] = simulate_and_identify_variant(&dir, &text, "2", true);
    let exported = path("exported.toml");
    let (ok, _, err) = armcal(&[
        "export",
        "--cell",
        &cell_path,
        "--estimate",
        &est,
        "--format",
        "cell",
        "--out",
        &exported,
    ]);
    assert!(ok, "{err}");
    let original = Cell::from_toml(&text, "original", dir.as_path()).unwrap();
    let back_text = std::fs::read_to_string(&exported).unwrap();
    let back = Cell::from_toml(&back_text, "exported", dir.as_path()).unwrap();
    let (a, b) = (&original.fixed_prior, &back.fixed_prior);
    assert_eq!(
        (a.length_mm, a.angle_rad, a.unitless),
        (b.length_mm, b.angle_rad, b.unitless),
        "{back_text}"
    );
    let mut compared = 0;
    for p in original.model.registry.iter() {
        let Some(i) = back.model.registry.index_of(&p.name) else {
            continue;
        };
        let (sa, sb) = (a.sigma(p), b.sigma(back.model.registry.get(i)));
        assert!(
            (sa - sb).abs() <= 1e-12 * sa.max(1e-300),
            "`{}`: σ {sa} in the cell, {sb} exported\n{back_text}",
            p.name
        );
        compared += 1;
    }
    assert!(compared >= 40, "{compared}");
    // The named ones, the given tool's and a kind's, as stated.
    let sigma = |name: &str| {
        b.sigma(
            back.model
                .registry
                .get(back.model.registry.index_of(name).unwrap()),
        )
    };
    assert_eq!(sigma("j6.d"), 2.0);
    assert_eq!(sigma("tool.z"), 1.5);
    assert_eq!(sigma("tool.x"), 0.3);
    assert_eq!(sigma("base.x"), 0.0);
    assert_eq!(sigma("j5.d"), 0.0);
}
