//! A cell file of a (calibrated) model that the commands accept unchanged: the model's links
//! (in whatever convention the export chose) together with everything else of the cell it
//! was identified in — the instrument's kind, noise model and incidence limit, targets,
//! capsules (re-expressed in the exported frames), working poses, obstacles, the design
//! clearances, joint limits,
//! the data columns, the measurement type, what the cell fixed or gave a prior, the stated
//! σ of the fixed parameters (`fixed_prior`, `fixed_priors`), and `free = "auto"`.

use super::{Cell, NoiseModel, Obstacle};
use crate::model::complete::LinkForm;
use crate::model::export::{self as model_export, to_cell_toml_with, CellSections};
use crate::model::{urdf, Model, ModelSpec, ParameterStatus};
use crate::robots::transfer_capsules;
use crate::toml_text;
use crate::Error;
use std::fmt::Write;

/// `spec` (a model of `cell`'s robot, e.g. an identified model converted to DH; `identified`
/// is the model the capsules' frames refer to, the one `spec` was converted from) as a cell
/// file carrying the rest of `cell`.
pub fn to_cell_toml(cell: &Cell, identified: &Model, spec: &ModelSpec) -> Result<String, Error> {
    let exported = Model::from_spec(spec)?;
    let mut s = CellSections {
        name: Some(cell.name.clone()),
        ..Default::default()
    };
    for c in transfer_capsules(identified, &exported, &cell.capsules)? {
        let _ = writeln!(
            s.robot,
            "[[robot.capsules]]\nframe = {}\na_mm = {:?}\nb_mm = {:?}\nradius_mm = {:?}\n",
            toml_text::string(&c.frame),
            c.a,
            c.b,
            c.radius
        );
    }
    // The controller convention, joint by joint (a preset's name would not fit the exported
    // links; the identity is the default).
    if !cell.controller.is_identity() {
        let _ = writeln!(s.robot, "[robot.controller]");
        for (j, m) in exported.joints.iter().zip(&cell.controller.joints) {
            let unit = match j.kind {
                crate::model::JointKind::Revolute => "offset_rad",
                crate::model::JointKind::Prismatic => "offset_mm",
            };
            let _ = writeln!(
                s.robot,
                "{} = {{ sign = {:?}, {unit} = {:?} }}",
                toml_text::string(&j.name),
                m.sign,
                m.offset
            );
        }
        let _ = writeln!(s.robot);
    }
    if let Some(i) = &cell.instrument {
        let _ = writeln!(s.instrument, "kind = {}", toml_text::string(&i.kind));
        let noise = noise_toml(&i.noise);
        let _ = writeln!(s.instrument, "noise = {noise}");
        if let Some(a) = i.max_incidence {
            let _ = writeln!(s.instrument, "max_incidence_deg = {:?}", a.to_degrees());
        }
    }
    s.parameters = Some(parameters(cell, &exported));
    let display = |q: &[f64]| -> Vec<f64> {
        q.iter()
            .zip(&cell.model.joints)
            .map(|(v, j)| v * j.kind.unit().display_factor())
            .collect()
    };
    for w in &cell.working {
        let _ = writeln!(
            s.tail,
            "\n[[working]]\nname = {}\njoints_deg = {:?}\nweight = {:?}",
            toml_text::string(&w.name),
            display(&w.q),
            w.weight
        );
    }
    // A path read from a file is written inline, so that the exported cell stands alone.
    for p in &cell.working_paths {
        let q: Vec<Vec<f64>> = p.q.iter().map(|q| display(q)).collect();
        let _ = writeln!(
            s.tail,
            "\n[[working_path]]\nname = {}\nweight = {:?}\njoints_deg = {q:?}",
            toml_text::string(&p.name),
            p.weight
        );
    }
    for o in &cell.obstacles {
        let _ = match o {
            Obstacle::Capsule { name, a, b, radius } => writeln!(
                s.tail,
                "\n[[obstacles]]\nname = {}\nkind = \"capsule\"\na_mm = {a:?}\nb_mm = {b:?}\nradius_mm = {radius:?}",
                toml_text::string(name)
            ),
            Obstacle::Box {
                name,
                center,
                size,
                rpy,
            } => writeln!(
                s.tail,
                "\n[[obstacles]]\nname = {}\nkind = \"box\"\ncenter_mm = {center:?}\nsize_mm = {size:?}\nrpy_deg = {:?}",
                toml_text::string(name),
                rpy.map(f64::to_degrees)
            ),
            Obstacle::HalfSpace {
                name,
                normal,
                offset,
            } => writeln!(
                s.tail,
                "\n[[obstacles]]\nname = {}\nkind = \"half-space\"\nnormal = {normal:?}\noffset_mm = {offset:?}",
                toml_text::string(name)
            ),
        };
    }
    let _ = writeln!(
        s.tail,
        "\n[design]\nclearance_mm = {:?}\njoint_margin_deg = {:?}\nincidence_margin_deg = {:?}\nline_of_sight_margin_mm = {:?}",
        cell.design.clearance,
        cell.design.joint_margin.to_degrees(),
        cell.design.incidence_margin.to_degrees(),
        cell.design.line_of_sight_margin
    );
    if let Some(d) = &cell.data_columns {
        let _ = writeln!(s.tail, "\n[data]\n{}", d.format.to_toml());
    }
    to_cell_toml_with(spec, &s)
}

/// A noise model as the inline table of `[instrument] noise`.
pub(crate) fn noise_toml(noise: &NoiseModel) -> String {
    match noise {
        NoiseModel::Constant { sigma, sigma_angle } => format!(
            "{{ model = \"constant\", sigma_mm = {:?}, sigma_angle_deg = {:?} }}",
            sigma,
            sigma_angle.to_degrees()
        ),
        NoiseModel::Range { a, b_per_m } => format!(
            "{{ model = \"range\", a_mm = {a:?}, b_um_per_m = {:?} }}",
            b_per_m * 1000.0
        ),
        NoiseModel::PerMeasurement { floor } => {
            format!("{{ model = \"per-measurement\", floor_mm = {floor:?} }}")
        }
    }
}

/// The `[parameters]` body: `free = "auto"` (or `"all"`, as the cell had it), the cell's
/// measurement type, the parameters the cell fixed and the priors it gave, for every one the
/// exported model has under the same name.
fn parameters(cell: &Cell, exported: &Model) -> String {
    let declared = cell.declared_model();
    let mut fixed = Vec::new();
    let mut priors = Vec::new();
    for p in declared.registry.iter() {
        if exported.registry.index_of(&p.name).is_none() {
            continue;
        }
        match p.status {
            ParameterStatus::Fixed => fixed.push(toml_text::string(&p.name)),
            ParameterStatus::Prior { sigma } => priors.push(format!(
                "{} = {{ sigma{} = {:?} }}",
                toml_text::string(&p.name),
                model_export::suffix(p.unit),
                sigma * p.unit.display_factor()
            )),
            ParameterStatus::Free => {}
        }
    }
    let free = if cell.auto_free { "auto" } else { "all" };
    let measurement = format!("{:?}", cell.measurement).to_lowercase();
    let mut out = format!("free = \"{free}\"\nmeasurement = \"{measurement}\"\n");
    if !fixed.is_empty() {
        let _ = writeln!(out, "fixed = [{}]", fixed.join(", "));
    }
    if !priors.is_empty() {
        let _ = writeln!(out, "priors = {{ {} }}", priors.join(", "));
    }
    out + &fixed_priors(cell, &declared, exported)
}

/// `fixed_prior` (the cell's σ per kind) and `fixed_priors`: the σ of every parameter the
/// cell named (0 included), and of every base and tool parameter with a σ — the exported
/// cell gives its base and tool as links, not as `[base]`/`[tool]`, and a reader takes a
/// frame the cell does not give as a definition (σ 0), so a zero σ there needs no entry.
fn fixed_priors(cell: &Cell, declared: &Model, exported: &Model) -> String {
    let prior = &cell.fixed_prior;
    let mut out = format!(
        "fixed_prior = {{ length_mm = {:?}, angle_deg = {:?}, unitless = {:?} }}\n",
        prior.length_mm,
        prior.angle_rad.to_degrees(),
        prior.unitless
    );
    let entries: Vec<String> = declared
        .registry
        .iter()
        .filter(|p| exported.registry.index_of(&p.name).is_some())
        .filter(|p| {
            let named = prior.parameters.iter().any(|(n, _)| *n == p.name);
            let frame = matches!(p.frame(), "base" | "tool");
            (named && !frame) || (frame && prior.sigma(p) > 0.0)
        })
        .map(|p| {
            format!(
                "{} = {{ sigma{} = {:?} }}",
                toml_text::string(&p.name),
                model_export::suffix(p.unit),
                prior.sigma(p) * p.unit.display_factor()
            )
        })
        .collect();
    if !entries.is_empty() {
        let _ = writeln!(out, "fixed_priors = {{ {} }}", entries.join(", "));
    }
    out
}

/// The formats of `armcal export`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum ExportFormat {
    /// A cell file with the links in this form (DH, modified DH, zero reference, or as
    /// identified), with a parameter table.
    Cell(LinkForm),
    /// The model spec as JSON.
    Json,
    /// URDF (the model's links as joints and fixed frames).
    Urdf,
    /// URDF with the joint offsets against the nominal model as `<calibration rising>`
    /// (`urdf::calibration`); `Some(k)`: the conservative variant, keeping only the
    /// corrections beyond `k σ`.
    UrdfCalibration(Option<f64>),
    /// Universal Robots kinematics YAML ([`crate::model::ur_kinematics`]).
    UrKinematics,
    /// Per-joint corrections against the nominal model as a ROS 2 parameter file
    /// ([`urdf::joint_corrections`]).
    JointCorrections,
}

impl ExportFormat {
    /// `dh`, `mdh`, `zrp`, `cell` (links as identified), `json`, `urdf`,
    /// `urdf-calibration`, `urdf-conservative` (k = [`urdf::calibration::DEFAULT_K_SIGMA`]),
    /// `ur-yaml` or `ros-params`.
    pub fn from_name(s: &str) -> Option<ExportFormat> {
        Some(match s {
            "dh" => ExportFormat::Cell(LinkForm::Dh),
            "mdh" => ExportFormat::Cell(LinkForm::Mdh),
            "zrp" => ExportFormat::Cell(LinkForm::Zrp),
            "cell" => ExportFormat::Cell(LinkForm::AsGiven),
            "json" => ExportFormat::Json,
            "urdf" => ExportFormat::Urdf,
            "urdf-calibration" => ExportFormat::UrdfCalibration(None),
            "urdf-conservative" => {
                ExportFormat::UrdfCalibration(Some(urdf::calibration::DEFAULT_K_SIGMA))
            }
            "ur-yaml" => ExportFormat::UrKinematics,
            "ros-params" => ExportFormat::JointCorrections,
            _ => return None,
        })
    }

    /// Whether the format writes corrections against the nominal model (which
    /// [`export_model`] does not have: [`crate::export_estimate`]).
    pub fn needs_nominal(self) -> bool {
        matches!(
            self,
            ExportFormat::UrdfCalibration(_) | ExportFormat::JointCorrections
        )
    }
}

/// An exported model: the file's content, the parameter table (CSV) of a cell export, and
/// the values a user should look at before loading it
/// ([`model_export::suspicious_values`]).
#[derive(Clone, Debug)]
pub struct Exported {
    /// The exported file.
    pub content: String,
    /// The parameter table beside a cell export.
    pub table_csv: Option<String>,
    /// Values to check before loading the export, and what the format does not hold with
    /// the TCP shift its omission causes, each as a sentence.
    pub warnings: Vec<String>,
    /// What a reader should know besides (the corrections a conservative export dropped),
    /// each as a sentence; the file carries them as comments.
    pub notes: Vec<String>,
}

/// Exports the identified model `identified` (the estimate's spec) in `format`
/// ([`model_export::export_form`]); with the `cell` it was identified in, a cell export
/// carries the cell's other sections ([`to_cell_toml`]), else the model alone, and the
/// suspicious values are judged against the cell's nominal model in the same form. The
/// formats that write corrections against the nominal model need it:
/// [`export_against_nominal`].
///
/// ```
/// use armcal::{export_model, perturbed_truth, ExportFormat, Perturbation};
///
/// # fn main() -> armcal::Result<()> {
/// let cell = armcal::cell::builtin::paper_cell()?;
/// let model = &cell.model;
/// // An identified robot (here a perturbed one) as a URDF file.
/// let identified = model.spec_at(&perturbed_truth(model, &Perturbation::default(), 1));
/// let urdf = export_model(&identified, Some(&cell), ExportFormat::Urdf)?;
/// assert!(urdf.content.contains("<robot"));
/// // Corrections against the nominal model need the estimate, not a model alone.
/// assert!(export_model(&identified, None, ExportFormat::JointCorrections).is_err());
/// # Ok(())
/// # }
/// ```
pub fn export_model(
    identified: &ModelSpec,
    cell: Option<&Cell>,
    format: ExportFormat,
) -> Result<Exported, Error> {
    if format.needs_nominal() {
        return Err(Error::Input(format!(
            "{format:?} writes corrections against the nominal model: export an estimate"
        )));
    }
    export_against_nominal(identified, None, cell, format)
}

/// The nominal model and the σ of the estimate a model was identified with: what
/// corrections are written against.
pub struct NominalReference<'a> {
    /// The nominal model: the same chain at its nominal values.
    pub nominal: &'a ModelSpec,
    /// σ of a parameter by name (internal units); `None` for a parameter not estimated.
    pub sigma: &'a dyn Fn(&str) -> Option<f64>,
    /// Where the model comes from, for the file's header.
    pub source: &'a str,
}

/// [`export_model`], with the nominal model and σ the `urdf-calibration`,
/// `urdf-conservative` and `ros-params` formats need (`reference`); the UR kinematics file
/// names its source from it. Every format's [`Exported::warnings`] say what it does not hold
/// and by how much the TCP moves without it; the file says so too.
pub fn export_against_nominal(
    identified: &ModelSpec,
    reference: Option<&NominalReference>,
    cell: Option<&Cell>,
    format: ExportFormat,
) -> Result<Exported, Error> {
    let form = match format {
        ExportFormat::Cell(form) => form,
        _ => LinkForm::AsGiven,
    };
    let model = Model::from_spec(identified)?;
    let spec = model_export::export_form(identified, form)?;
    let reference_spec = match cell {
        Some(c) => model_export::export_form(&c.model.spec(), form)?,
        None => spec.clone(),
    };
    let mut warnings = model_export::suspicious_values(&Model::from_spec(&reference_spec)?, &spec)?;
    let mut notes = Vec::new();
    let source = reference.map_or("an armcal model", |r| r.source);
    let need = || {
        reference.ok_or_else(|| {
            Error::Input(format!(
                "{format:?} writes corrections against the nominal model: export an estimate"
            ))
        })
    };
    let mut not_held = Vec::new();
    let (content, table_csv) = match format {
        ExportFormat::Json => (
            serde_json::to_string_pretty(&spec).map_err(|e| Error::Input(e.to_string()))?,
            None,
        ),
        ExportFormat::Urdf => {
            let (rigid, lost) = crate::model::tcp_shift::without_nongeometric(&spec)?;
            not_held.extend(lost);
            (urdf::to_urdf(&rigid)?, None)
        }
        ExportFormat::UrdfCalibration(k) => {
            let r = need()?;
            let (rigid, lost) = crate::model::tcp_shift::without_nongeometric(&spec)?;
            let (nominal, _) = crate::model::tcp_shift::without_nongeometric(r.nominal)?;
            not_held.extend(lost);
            let written = match k {
                None => rigid,
                Some(k) => {
                    let (kept, dropped, total) =
                        urdf::calibration::conservative(&rigid, &nominal, r.sigma, k)?;
                    notes.push(format!(
                        "conservative: kept the corrections beyond {k} σ; dropped {} (the TCP \
                         moves up to {total:.4} mm without them, max over {} random \
                         configurations, seed {})",
                        dropped.len(),
                        crate::model::tcp_shift::SHIFT_CONFIGURATIONS,
                        crate::model::tcp_shift::SHIFT_SEED
                    ));
                    let unit = |name: &str| {
                        model
                            .registry
                            .index_of(name)
                            .map_or(crate::model::Unit::Mm, |i| model.registry.get(i).unit)
                    };
                    for d in &dropped {
                        let u = unit(&d.name);
                        notes.push(format!(
                            "dropped {}: correction {:.6} ± σ {:.6} {} (TCP shift {:.4} mm)",
                            d.name,
                            d.correction * u.display_factor(),
                            d.sigma * u.display_factor(),
                            u.display_name(),
                            d.tcp_shift_mm
                        ));
                    }
                    kept
                }
            };
            let (text, ignored) = urdf::calibration::to_urdf_calibrated(&written, &nominal)?;
            notes.extend(ignored.map(|n| n.sentence()));
            (text, None)
        }
        ExportFormat::UrKinematics => {
            let f = crate::model::ur_kinematics::to_ur_kinematics(&spec, source)?;
            not_held.extend(f.not_held);
            (f.text, None)
        }
        ExportFormat::JointCorrections => {
            let r = need()?;
            let f = urdf::joint_corrections::to_joint_corrections(&spec, r.nominal, source)?;
            not_held.extend(f.not_held);
            (f.text, None)
        }
        ExportFormat::Cell(_) => (
            match cell {
                Some(c) => to_cell_toml(c, &model, &spec)?,
                None => model_export::to_cell_toml(&spec)?,
            },
            Some(model_export::to_table_csv(&spec)),
        ),
    };
    // The UR and ROS files carry their own header; URDF gets the lines as comments.
    let content = match format {
        ExportFormat::Urdf | ExportFormat::UrdfCalibration(_) => {
            let lines: Vec<String> = not_held
                .iter()
                .map(|n| n.sentence())
                .chain(notes.iter().cloned())
                .collect();
            let comments: String = lines
                .iter()
                .map(|l| format!("<!-- {} -->\n", l.replace("--", "- -")))
                .collect();
            comments + &content
        }
        _ => content,
    };
    warnings.extend(not_held.iter().map(|n| n.sentence()));
    Ok(Exported {
        content,
        table_csv,
        warnings,
        notes,
    })
}
